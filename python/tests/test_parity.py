"""Parity of the two front-ends on every real TIFF, CZI, ND2 and LIF file of the shared test data:
the command line and Python read the same images (Python in their stored sample type), find the
same global Otsu threshold and measure the same contact pixels and areas, or both refuse the
file. Skipped, with the reason, when ../shared/data is not beside the checkout."""

import csv
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import contactscope as cs

from conftest import ROOT, _binary

DATA = ROOT.parent / "shared" / "data"
CONFOCAL = (".czi", ".nd2", ".lif")


def _files():
    if not DATA.exists():
        return []
    found = []
    for sub in ("real-tiff", "synthetic-tiff-formats", "real-formats"):
        for p in sorted((DATA / sub).rglob("*")):
            if "mitocheck" in p.parts:
                continue
            if p.suffix.lower() in (".tif", ".tiff") + CONFOCAL and "park-tiff" not in p.parts:
                found.append(p)
    movie = DATA / "real-tiff" / "neubias" / "mitocheck-movie"
    if movie.is_dir():
        found.append(movie)  # a folder of files is a series too
    return found


FILES = _files()


def _run(*args):
    binary = _binary()
    if binary is None or not binary.exists():
        if os.environ.get("CONTACTSCOPE_REQUIRE_CLI") == "1":
            pytest.fail("the contactscope binary is needed: cargo build --release")
        pytest.skip("no contactscope binary")
    return subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True,
                          timeout=600)


def _selection(path):
    """The selection that makes a load series of the file: the first channel, and for CZI, ND2
    and LIF files the planes along Z (else T) of the first series, index 0 on every other axis."""
    if path.is_dir():
        return {}
    info = _run("info", path, "--json")
    if info.returncode != 0:
        return {}
    series = json.loads(info.stdout)["series"]
    axes = series[0]["axes"]
    sel = {}
    if axes.get("C", 1) > 1:
        sel["channel"] = 0
    if path.suffix.lower() in CONFOCAL:
        if len(series) > 1:
            sel["series"] = 0
        if axes.get("Z", 1) > 1:
            sel["load_axis"] = "z"
            if axes.get("T", 1) > 1:
                sel["t"] = 0
        elif axes.get("T", 1) > 1:
            sel["load_axis"] = "t"
        extra = {k: 0 for k, n in axes.items() if k not in "TZCYX" and n > 1}
        if extra:
            sel["axes"] = extra
    return sel


def _flags(sel):
    flags = []
    for key in ("series", "channel", "z", "t"):
        if key in sel:
            flags += [f"--{key}", sel[key]]
    if "load_axis" in sel:
        flags += ["--load-axis", sel["load_axis"]]
    for name, index in sel.get("axes", {}).items():
        flags += ["--axis", f"{name}={index}"]
    return flags


@pytest.mark.skipif(not FILES, reason=f"shared test data not found at {DATA}")
@pytest.mark.filterwarnings("ignore::contactscope.ContactscopeWarning")
@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(DATA)))
def test_cli_and_python_agree(path, tmp_path):
    sel = _selection(path)
    flags = _flags(sel)
    threshold = _run("threshold", path, *flags, "--json")
    if threshold.returncode != 0:
        # The command line refuses the file: Python refuses it too, naming it.
        with pytest.raises((cs.InputError, cs.FileError)) as e:
            cs.read_series(path, **sel)
        assert path.name in str(e.value) or str(path) in str(e.value)
        return
    theirs = json.loads(threshold.stdout)
    series = cs.read_series(path, **sel)
    images = series.images
    # The stored sample type, as tifffile would return it.
    assert images.dtype in (np.uint8, np.uint16, np.int16, np.float32), images.dtype
    assert len(images) == theirs["images"]
    assert cs.otsu_threshold(images) == theirs["threshold"]
    assert cs.otsu_threshold(series) == theirs["threshold"]
    if not path.is_dir():
        one = cs.read_image(path, **{k: v for k, v in sel.items()})
        assert one.images.dtype == images.dtype
        np.testing.assert_array_equal(one.images, images)
    # Areas: the same forces on both sides.
    n = len(images)
    forces_mn = list(range(1, n + 1))
    forces_n = [f * 1e-3 for f in forces_mn]
    analyze = _run("analyze", path, *flags, "--forces", ",".join(map(str, forces_mn)) + "mN",
                   "--out", tmp_path / "an", "-q")
    # 4: written, but no load valid (sample files that are not contact experiments).
    if analyze.returncode not in (0, 4):
        # The command line refuses to analyse the file (its pixel size metadata, say): so does
        # Python, with the same reason.
        with pytest.raises(cs.InputError) as e:
            cs.analyze(series, forces=forces_n)
        reason = analyze.stderr.strip().removeprefix("contactscope: error: ")
        assert reason.split(": ", 1)[-1] in str(e.value), (analyze.stderr, str(e.value))
        return
    with open(tmp_path / "an" / "areas.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    mine = cs.analyze(images, forces=forces_n, pixel_size=series.pixel_size_m).rows
    files = cs.analyze(series, forces=forces_n).rows
    assert len(mine) == len(rows) == len(files) == n
    area_key = "area_um2" if "area_um2" in rows[0] else "area_px"
    for a, b, c in zip(mine, files, rows):
        assert a["threshold"] == b["threshold"] == float(c["threshold"])
        assert a["contact_pixels"] == b["contact_pixels"] == int(c["contact_pixels"])
        if area_key == "area_um2":
            assert a["area_m2"] * 1e12 == pytest.approx(float(c["area_um2"]), rel=1e-12)
            assert b["area_m2"] == a["area_m2"]
        else:
            assert a["area_px"] == b["area_px"] == float(c["area_px"])
