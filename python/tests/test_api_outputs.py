"""The API the napari plugin is built on (no napari needed): ``analyze(out=…)`` writes the
command line's folder by its own writer, ``analyze(progress=…)`` reports both passes,
``compare(images=True)`` returns the registered pairs the scores are computed on, and
``parse_forces`` and ``parse_pixel_size`` read ``--forces`` and ``--pixel-size`` as the command
line does."""

import json
import pathlib

import numpy as np
import pytest

import contactscope as cs
from conftest import FORCES


def test_parse_forces_is_the_command_lines():
    assert cs.parse_forces("4,10,20,40mN") == pytest.approx([4e-3, 10e-3, 20e-3, 40e-3])
    assert cs.parse_forces("0,4mN") == pytest.approx([0.0, 4e-3])
    assert cs.parse_forces("4mN..400mN:3") == pytest.approx([4e-3, 40e-3, 400e-3])
    with pytest.raises(cs.InputError, match="oops"):
        cs.parse_forces("4,oops")


def test_parse_pixel_size_is_the_command_lines():
    assert cs.parse_pixel_size("200nm") == pytest.approx((2e-7, 2e-7))
    assert cs.parse_pixel_size("0.2um") == pytest.approx((2e-7, 2e-7))
    assert cs.parse_pixel_size("200x210nm") == pytest.approx((2e-7, 2.1e-7))
    with pytest.raises(cs.InputError):
        cs.parse_pixel_size("200")  # a bare number has no unit


def test_analyze_out_is_the_cli_folder(series_tif, tmp_path, cli):
    path, _ = series_tif
    series = cs.read_series(path, forces=FORCES)
    words = ["contactscope", "analyze", str(path), "--forces", "2,4,8mN", "--out",
             str(tmp_path / "py")]
    calls = []
    r = cs.analyze(series, out=tmp_path / "py", command_line=words, overlays=True,
                   save_masks=True, progress=lambda *a: calls.append(a))
    names = sorted(pathlib.Path(p).name for p in r.written)
    assert {"areas.csv", "summary.json", "area_vs_load.png", "area_vs_load.svg"} <= set(names)
    assert sum(n.startswith("overlay_") for n in names) == 3
    assert sum(n.startswith("mask_") for n in names) == 3
    cli("analyze", path, "--forces", "2,4,8mN", "--out", tmp_path / "cli", "--overlays",
        "--save-masks")
    for name in names:
        if name != "summary.json":
            mine_bytes = (tmp_path / "py" / name).read_bytes()
            assert mine_bytes == (tmp_path / "cli" / name).read_bytes(), name
    mine = json.loads((tmp_path / "py" / "summary.json").read_text())
    theirs = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert mine.pop("command_line") == words
    theirs.pop("command_line")
    assert mine == theirs
    # Both passes reported, each up to every image.
    assert {c[0] for c in calls} == {"histogram", "measure"}
    assert ("measure", 3, 3) in calls
    # The outcome is the in-memory analysis' outcome.
    assert r.rows == cs.analyze(series).rows
    with pytest.raises(cs.InputError, match="save_masks"):
        cs.analyze(series, out=tmp_path / "x", masks=True)


def test_compare_images_are_what_the_scores_count(series_tif, tmp_path):
    _, s = series_tif
    maps = np.stack([s.truth[i] for i in range(3)]).astype(float)
    plain = cs.compare(s.images, FORCES, 2e-7, maps, FORCES, 2e-7, 450e-9)
    assert "micrographs" not in plain
    r = cs.compare(s.images, FORCES, 2e-7, maps, FORCES, 2e-7, 450e-9, images=True)
    assert [x["dice"] for x in r.rows] == [x["dice"] for x in plain.rows]
    for key in ("micrographs", "simulated_images", "experiment_contact", "simulated_contact"):
        assert r[key].shape == s.images.shape, key
    np.testing.assert_array_equal(r.micrographs, s.images.astype(float))
    for i, row in enumerate(r.rows):
        a, b = r.experiment_contact[i], r.simulated_contact[i]
        assert 2 * (a & b).sum() / (a.sum() + b.sum()) == pytest.approx(row["dice"], abs=1e-12)
        # The imaged map is NaN only outside the simulated region, where no contact is counted.
        outside = np.isnan(r.simulated_images[i])
        assert not (b & outside).any()


def test_compare_out_is_the_cli_folder(series_tif, tmp_path, cli, hardening_sim):
    """compare(out=) writes the command line's compare folder by its own writer: compare.csv
    byte for byte, compare.json equal but for the command recorded, the panels."""
    path, _ = series_tif
    sim = hardening_sim
    cli("compare", "--micrographs", path, "--forces", "2,4,8mN", "--simulation", sim,
        "--psf-fwhm", "450nm", "--out", tmp_path / "cli")
    words = ["contactscope", "compare", "--micrographs", str(path), "--forces", "2,4,8mN",
             "--simulation", str(sim), "--psf-fwhm", "450nm", "--out", str(tmp_path / "py")]
    r = cs.compare(cs.read_series(path, forces=FORCES), None, None, sim, psf_fwhm=450e-9,
                   out=tmp_path / "py", command_line=words)
    assert {pathlib.Path(p).name for p in r["written"]} == \
        {p.name for p in (tmp_path / "cli").iterdir() if p.name != ".contactscope-run.json"}
    mine, theirs = tmp_path / "py", tmp_path / "cli"
    assert (mine / "compare.csv").read_bytes() == (theirs / "compare.csv").read_bytes()
    a = json.loads((mine / "compare.json").read_text())
    b = json.loads((theirs / "compare.json").read_text())
    assert a.pop("command_line") == words
    assert b.pop("command_line")[1:-1] == words[1:-1]
    assert a == b
