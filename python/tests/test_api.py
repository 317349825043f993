"""Every API function against the command line's outputs on the same inputs, and bad input
against the exception classes."""

import csv
import json
import pathlib

import numpy as np
import pytest

import contactscope as cs

from conftest import FORCES, ROOT


def read_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def columns(rows):
    """A result's rows as columns (numpy arrays), without pandas (an optional dependency)."""
    return {k: np.array([r[k] for r in rows]) for k in rows[0]}


def test_read_image_round_trip(tmp_path):
    stack = np.random.default_rng(1).random((3, 20, 30)).astype(np.float32)
    cs.write_tiff(tmp_path / "f.tif", stack, (1e-7, 2e-7))
    r = cs.read_image(tmp_path / "f.tif")
    assert r.images.shape == (3, 20, 30)
    # The stored sample type, as tifffile returns it.
    assert r.images.dtype == np.float32
    np.testing.assert_array_equal(r.images, stack)
    assert r.pixel_size_m == pytest.approx((1e-7, 2e-7), rel=1e-6)
    # An override replaces the file's pixel size.
    assert cs.read_image(tmp_path / "f.tif", pixel_size=5e-8).pixel_size_m == (5e-8, 5e-8)


def test_read_series_keeps_sample_type_and_forces(series_tif):
    path, s = series_tif
    r = cs.read_series(path, forces=FORCES)
    assert r.images.dtype == np.uint16
    np.testing.assert_array_equal(r.images, s.images)
    assert r.forces_n == FORCES
    assert r.pages == [0, 1, 2]
    assert r.pixel_size_m == pytest.approx((2e-7, 2e-7))
    assert r.forces_n == FORCES


def test_read_series_manifest_matches_cli(cli, tmp_path):
    manifest = ROOT / "fixtures" / "synthetic-series" / "manifest.csv"
    r = cs.read_series(manifest)
    assert all(f is not None and f > 0 for f in r.forces_n)
    a = cs.analyze(r)
    cli("analyze", "--manifest", manifest, "--out", tmp_path / "an", "-q")
    rows = read_csv(tmp_path / "an" / "areas.csv")
    assert len(rows) == len(a.rows) == len(r.forces_n)
    for mine, theirs in zip(a.rows, rows):
        assert mine["force_n"] * 1e3 == pytest.approx(float(theirs["force_mN"]), rel=1e-12)
        assert mine["contact_pixels"] == int(theirs["contact_pixels"])
        assert mine["area_m2"] * 1e12 == pytest.approx(float(theirs["area_um2"]), rel=1e-9)


def test_otsu_threshold_matches_cli(cli, series_tif):
    path, s = series_tif
    out = cli("threshold", path)
    assert cs.otsu_threshold(s.images) == float(out.split()[0])
    # The threshold separates: the brightest pixels are above, the darkest below.
    t = cs.otsu_threshold(s.images)
    assert s.images.min() < t < s.images.max()
    # The same levels in any integer type numpy may hand over are the same exact threshold.
    for dtype in (np.int16, np.int32, np.int64, np.uint32):
        assert cs.otsu_threshold(s.images.astype(dtype)) == t, dtype
    # Floats holding those levels take the binned float path, and say so.
    with pytest.warns(cs.ContactscopeWarning, match="floats holding integer values"):
        cs.otsu_threshold(s.images.astype(np.float64))


def test_analyze_matches_cli(cli, series_tif, tmp_path):
    path, s = series_tif
    cli("analyze", path, "--forces", "2,4,8mN", "--out", tmp_path / "an", "-q")
    rows = read_csv(tmp_path / "an" / "areas.csv")
    a = cs.analyze(cs.read_series(path, forces=FORCES))
    df = columns(a.rows)
    assert list(df["contact_pixels"]) == [int(r["contact_pixels"]) for r in rows]
    np.testing.assert_allclose(df["area_m2"] * 1e12, [float(r["area_um2"]) for r in rows],
                               rtol=1e-12)
    np.testing.assert_allclose(df["mean_intensity"], [float(r["mean_intensity"]) for r in rows],
                               rtol=1e-12)
    assert list(df["patches"]) == [int(r["patches"]) for r in rows]
    np.testing.assert_allclose(df["mean_pressure_pa"] * 1e-6,
                               [float(r["mean_pressure_MPa"]) for r in rows], rtol=1e-12)
    np.testing.assert_allclose(df["equivalent_radius_m"] * 1e6,
                               [float(r["equivalent_radius_um"]) for r in rows], rtol=1e-12)
    assert a.threshold["value"] == float(rows[0]["threshold"])
    summary = json.loads((tmp_path / "an" / "summary.json").read_text())
    # The same outcome: the summary's fits in lab units are the result's in SI units.
    assert a.fits["power_law"]["exponent"] == summary["fits"]["power_law"]["exponent"]
    assert a.threshold == summary["threshold"]
    # And the areas are near the generator's truth.
    np.testing.assert_allclose(df["area_m2"], s.true_area_m2, rtol=0.1)


def test_measure_agrees_with_analyze(series_tif):
    _, s = series_tif
    a = cs.analyze(s.images, forces=FORCES, pixel_size=2e-7)
    for i, row in enumerate(a.rows):
        m = cs.measure(s.images[i], a.threshold["value"], pixel_size=2e-7)
        assert m.contact_pixels == row["contact_pixels"] == int(m.mask.sum())
        assert m.area_m2 == pytest.approx(row["area_m2"])
        np.testing.assert_array_equal(m.mask, s.images[i] > a.threshold["value"])


# The command line writes its JSON files in lab units (force_mN, fwhm_nm_mean); Python returns
# the same outcome in SI units with SI keys (force_n, fwhm_m_mean).
_LAB_UNITS = {"mN": ("n", 1e-3), "uN": ("n", 1e-6), "um": ("m", 1e-6), "nm": ("m", 1e-9),
              "mm": ("m", 1e-3), "um2": ("m2", 1e-12), "um3": ("m3", 1e-18),
              "MPa": ("pa", 1e6), "GPa": ("pa", 1e9)}


def si_key(key):
    """The SI key of a lab key and the factor from its unit to SI (``fwhm_nm_mean`` →
    ``fwhm_m_mean``, 1e-9)."""
    tokens, factor, invert = [], 1.0, False
    for token in key.split("_"):
        si, f = _LAB_UNITS.get(token, (token, 1.0))
        factor *= 1.0 / f if invert else f
        invert = token == "per"
        tokens.append(si)
    return "_".join(tokens), factor


def in_si(value, factor=1.0):
    """A value of the command line's JSON in the SI form the Python result has."""
    if isinstance(value, dict):
        return {k: in_si(v, f) for key, v in value.items() for k, f in [si_key(key)]}
    if isinstance(value, list):
        return [in_si(v, factor) for v in value]
    if isinstance(value, (int, float)) and not isinstance(value, bool) and factor != 1.0:
        return value * factor
    return value


def assert_same_outcome(mine, theirs_lab, rel=1e-12, ignore=()):
    """Every entry of the command line's JSON (but its version, source revision, command line and
    ``ignore``) is in the Python result, in SI units."""
    theirs = in_si({k: v for k, v in theirs_lab.items()
                    if k not in ("contactscope_version", "source_revision", "command_line",
                                 *ignore)})

    def same(a, b, where):
        if isinstance(b, dict):
            assert isinstance(a, dict), where
            for k in b:
                assert k in a, f"{where}.{k} missing"
                same(a[k], b[k], f"{where}.{k}")
        elif isinstance(b, list):
            assert isinstance(a, list) and len(a) == len(b), where
            for i, (x, y) in enumerate(zip(a, b)):
                same(x, y, f"{where}[{i}]")
        elif isinstance(b, float):
            assert a == pytest.approx(b, rel=rel, abs=0), where
        else:
            assert a == b, where

    same(mine, theirs, "result")


def test_psf_matches_cli(cli, tmp_path):
    beads = cs.synth_beads(seed=5)
    assert beads.dtype == np.uint16
    cs.write_tiff(tmp_path / "beads.tif", beads, 1e-7)
    cli("psf", tmp_path / "beads.tif", "--out", tmp_path / "psf")
    theirs = json.loads((tmp_path / "psf" / "psf.json").read_text())
    # The file, read as the command line reads it: the same outcome.
    from_file = cs.psf(tmp_path / "beads.tif")
    assert_same_outcome(from_file, theirs)
    # The array in its stored type (uint16): the same saturation level (12-bit data: 4095), so
    # the same beads and widths.
    mine = cs.psf(beads, 1e-7)
    assert mine.saturation_level == theirs["saturation_level"] == 4095
    assert_same_outcome(mine, theirs, rel=1e-9, ignore=("input", "pixel_size_source"))
    assert mine.fwhm_m_mean * 1e9 == pytest.approx(theirs["fwhm_nm_mean"], rel=1e-9)
    # The rows are beads.csv.
    rows = read_csv(tmp_path / "psf" / "beads.csv")
    assert len(mine.rows) == len(rows) == theirs["beads_found"]
    for m, t in zip(mine.rows, rows):
        assert m["used"] == (t["used"] == "true")
        assert m["x_px"] == pytest.approx(float(t["x_px"]), abs=1e-4)
        if m["used"]:
            assert m["sigma_m"] * 1e9 == pytest.approx(float(t["sigma_nm"]), abs=1e-3)
            assert m["fwhm_m"] * 1e9 == pytest.approx(float(t["fwhm_nm"]), abs=1e-3)
    assert sum(r["used"] for r in mine.rows) == mine.beads_used
    # σ = 1.91 px of 100 nm: FWHM ≈ 450 nm.
    assert mine.fwhm_m_mean == pytest.approx(2.3548 * 1.91e-7, rel=0.03)
    # Float data have no saturation level unless one is given.
    assert cs.psf(beads.astype(np.float32), 1e-7).saturation_level is None
    assert cs.psf(beads, 1e-7, saturation_level=65535).saturation_level == 65535


def test_psf_of_a_z_stack_matches_cli(cli, tmp_path):
    stack = cs.synth_beads(planes=5, seed=8)
    cs.write_tiff(tmp_path / "stack.tif", stack, 1e-7)
    cli("psf", tmp_path / "stack.tif", "--bead-diameter", "100nm", "--out", tmp_path / "psf")
    theirs = json.loads((tmp_path / "psf" / "psf.json").read_text())
    mine = cs.psf(stack, 1e-7, bead_diameter=100e-9)
    assert mine.planes == theirs["planes"] == 5
    assert mine.bead_diameter_m == pytest.approx(1e-7) and mine.bead_correction_applied
    assert_same_outcome(mine, theirs, rel=1e-9, ignore=("input", "pixel_size_source"))


def test_autocorrelation_matches_cli(cli, series_tif, tmp_path):
    path, s = series_tif
    cli("autocorr", path, "--out", tmp_path / "ac")
    theirs = json.loads((tmp_path / "ac" / "autocorr.json").read_text())
    rows = read_csv(tmp_path / "ac" / "autocorr.csv")
    assert_same_outcome(cs.autocorrelation(path), theirs)
    # The stack as an array: each plane one image, the same numbers.
    mine = cs.autocorrelation(s.images, 2e-7)
    # (Labels differ: "images:page 0" for "series.tif:page 0".)
    assert_same_outcome(mine, theirs, rel=1e-9, ignore=("images", "warnings"))
    assert len(mine.warnings) == len(theirs["warnings"])
    assert len(mine.rows) == len(theirs["images"]) == 3
    for m, t in zip(mine.rows, theirs["images"]):
        assert m["image"].endswith(t["image"].split(":")[1])  # "images:page 0"
        assert m["correlation_length_m_1e"] * 1e6 == pytest.approx(
            t["correlation_length_um_1e"], rel=1e-9)
        assert m["max_lag_m"] * 1e6 == pytest.approx(t["max_lag_um"], rel=1e-9)
        curve = [r for r in rows if r["image"] == t["image"]]
        assert len(m["acf"]) == len(m["lag_m"]) == len(curve)
        np.testing.assert_allclose(m["acf"], [float(r["acf"]) for r in curve], atol=1e-8)
        np.testing.assert_allclose(m["lag_m"] * 1e6, [float(r["lag_um"]) for r in curve],
                                   atol=1e-6)
        assert m["acf"][0] == pytest.approx(1.0)
    # One 2-D image, a clamped lag: the warning of the command line, named in Python terms.
    with pytest.warns(cs.ContactscopeWarning, match="max_lag="):
        one = cs.autocorrelation(s.images[0], 2e-7, max_lag=1e-3)
    assert len(one.rows) == 1 and one.rows[0]["max_lag_m"] == pytest.approx(
        theirs["images"][0]["max_lag_um"] * 1e-6, rel=1e-9)


def test_newton_matches_cli(cli, tmp_path):
    n = cs.synth_newton(seed=3)
    cs.write_tiff(tmp_path / "r.tif", n.reflection, 2e-7)
    cs.write_tiff(tmp_path / "f.tif", n.fluorescence, 2e-7)
    cli("newton", tmp_path / "r.tif", "--contact", tmp_path / "f.tif", "--out", tmp_path / "nw")
    theirs = json.loads((tmp_path / "nw" / "newton.json").read_text())
    # The files, read as the command line reads them: the same outcome.
    from_files = cs.newton(tmp_path / "r.tif", tmp_path / "f.tif")
    assert_same_outcome(from_files, theirs)
    # The arrays in their stored type (uint16) with the defaults of the command line.
    mine = cs.newton(n.reflection, n.fluorescence, 2e-7)
    assert_same_outcome(mine, theirs, rel=1e-9, ignore=("inputs",))
    assert mine.wavelength_m == pytest.approx(488e-9) and mine.medium_index == 1.447
    assert mine.phase == "half" and mine.profiles_total == 20 == len(mine.rows)
    assert mine.detection_gap_m_mean * 1e9 == pytest.approx(theirs["detection_gap_nm_mean"],
                                                          rel=1e-9)
    assert mine.sphere_radius_R_m_mean * 1e3 == pytest.approx(theirs["sphere_radius_R_mm_mean"],
                                                             rel=1e-9)
    # The ring points are newton_rings.csv.
    rings = read_csv(tmp_path / "nw" / "newton_rings.csv")
    assert len(mine.rings) == len(rings) > 0
    for m, t in zip(mine.rings, rings):
        assert (m["profile"], m["side"], m["order"]) == (int(t["profile"]), t["side"],
                                                          int(t["order"]))
        assert m["r_m"] * 1e6 == pytest.approx(float(t["r_um"]), rel=1e-9)
        assert m["gap_m"] * 1e9 == pytest.approx(float(t["gap_nm"]), rel=1e-12)
    assert mine.detection_gap_m_mean == pytest.approx(n.detection_gap_m, abs=2e-9)


def test_blur_and_resample_keeps_area():
    m = np.zeros((64, 64))
    m[20:40, 10:30] = 1.0
    img = cs.blur_and_resample(m, 50e-9, 300e-9, 200e-9)
    assert img.shape == (16, 16)
    # 400 map pixels of (50 nm)² = 25 image pixels of (200 nm)²; the blur keeps the sum.
    assert img.sum() == pytest.approx(25.0, rel=1e-6)
    # No blur: the block average.
    sharp = cs.blur_and_resample(m, 50e-9, 0.0, 200e-9)
    np.testing.assert_allclose(sharp, m.reshape(16, 4, 16, 4).mean(axis=(1, 3)), atol=1e-12)


def test_surface_matches_cli(cli, surface_npy):
    mine = cs.surface(128, 128, 100e-9, rms_height=50e-9, seed=3)
    theirs = np.load(surface_npy)
    np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-20)
    assert mine.std() == pytest.approx(50e-9, rel=1e-9)


def test_read_topography_matches_cli(cli, surface_npy):
    t = cs.read_topography(surface_npy, pixel_size=100e-9)
    out = cli("topography", surface_npy, "--pixel-size", "100nm")
    h_rms_nm = float(out.split("h_rms:")[1].split()[0])
    assert t.heights.std() * 1e9 == pytest.approx(h_rms_nm, rel=1e-5)
    assert t.pixel_size_m == (100e-9, 100e-9)
    raw = cs.read_topography(surface_npy, pixel_size=100e-9, detrend="none")
    np.testing.assert_array_equal(raw.heights, np.load(surface_npy))


def test_simulate_matches_cli(cli, surface_npy, tmp_path):
    out = tmp_path / "sim"
    cli("simulate", "--topography", surface_npy, "--pixel-size", "100nm", "--radius", "20um",
        "--modulus", "1GPa", "--model", "hardening", "--hardening", "4MPa/nm",
        "--forces", "20,40,80uN", "--out", out, "-q")
    rows = read_csv(out / "areas.csv")
    h = cs.read_topography(surface_npy, pixel_size=100e-9).heights
    r = cs.simulate(h, 100e-9, 1e9, [20e-6, 40e-6, 80e-6], "hardening", k=4e15, radius=20e-6)
    df = columns(r.rows)
    np.testing.assert_allclose(df["area_m2"] * 1e12, [float(x["area_um2"]) for x in rows],
                               rtol=1e-12)
    np.testing.assert_allclose(df["approach_m"] * 1e6, [float(x["approach_um"]) for x in rows],
                               rtol=1e-12)
    assert list(df["iterations"]) == [int(x["iterations"]) for x in rows]
    for i in range(3):
        p = cs.read_image(out / f"load_{i + 1:03}_pressure_MPa.tif").images[0]
        np.testing.assert_allclose(r.pressure[i] * 1e-6, p, rtol=1e-6, atol=1e-6)
        c = cs.read_image(out / f"load_{i + 1:03}_contact.tif").images[0]
        np.testing.assert_array_equal(r.contact[i], c > 0.5)
        g = cs.read_image(out / f"load_{i + 1:03}_gap_um.tif").images[0]
        np.testing.assert_allclose(r.gap[i] * 1e6, g, rtol=1e-6, atol=1e-9)
    # Force balance: Σ p·ΔA = load.
    assert (r.pressure.sum(axis=(1, 2)) * 1e-14) == pytest.approx([20e-6, 40e-6, 80e-6],
                                                                  rel=1e-6)
    assert (r.plastic >= 0).all() and r.plastic.sum() > 0


def test_simulate_gt_and_elastic_models(surface_npy):
    h = cs.read_topography(surface_npy, pixel_size=100e-9).heights
    e = cs.simulate(h, 100e-9, 1e9, [20e-6], radius=20e-6, maps=False)
    assert "pressure" not in e and e.rows[0]["plastic_volume_m3"] == 0.0
    gt = cs.simulate(h, 100e-9, 1e9, [20e-6, 40e-6], "gt", radius=20e-6)
    assert gt.rows[1]["area_m2"] > gt.rows[0]["area_m2"] > 0
    assert gt.contact.shape == (2, 128, 128)
    # The bearing-area map is the contact; GT has no pressure field.
    np.testing.assert_allclose(gt.contact.sum(axis=(1, 2)) * 1e-14,
                               [r["area_m2"] for r in gt.rows], rtol=1e-12)
    assert np.isnan(gt.pressure).all()


def test_simulate_maps_choice(surface_npy):
    # maps= chooses the stacks returned, as --maps chooses the files; the solution is the same.
    h = cs.read_topography(surface_npy, pixel_size=100e-9).heights
    run = lambda **kw: cs.simulate(h, 100e-9, 1e9, [20e-6, 40e-6], "hardening", k=4e15,
                                   radius=20e-6, **kw)
    stacks = {"pressure", "gap", "plastic", "contact"}
    a, c, n = run(), run(maps="contact"), run(maps="none")
    assert (a["maps"], c["maps"], n["maps"]) == ("all", "contact", "none")
    assert stacks <= set(a)
    assert stacks & set(c) == {"contact"}
    assert not stacks & set(n)
    np.testing.assert_array_equal(c.contact, a.contact)
    assert c.contact.shape == (2, 128, 128) and c.contact.any()
    assert [r["area_m2"] for r in n.rows] == [r["area_m2"] for r in a.rows]
    # The older spelling: True and False.
    assert run(maps=False)["maps"] == "none" and run(maps=True)["maps"] == "all"
    with pytest.raises(cs.InputError, match='maps="pressure"'):
        run(maps="pressure")
    gt = cs.simulate(h, 100e-9, 1e9, [20e-6], "gt", radius=20e-6, maps="contact")
    assert stacks & set(gt) == {"contact"} and gt.contact.any()


def test_compare_matches_cli(cli, series_tif, tmp_path, hardening_sim):
    path, s = series_tif
    sim = hardening_sim
    cli("compare", "--micrographs", path, "--forces", "2,4,8mN", "--simulation", sim,
        "--psf-fwhm", "450nm", "--out", tmp_path / "cmp")
    theirs = read_csv(tmp_path / "cmp" / "compare.csv")
    maps = np.stack([cs.read_image(sim / f"load_{i:03}_contact.tif").images[0]
                     for i in (1, 2, 3)])
    mine = cs.compare(s.images, FORCES, 2e-7, maps, FORCES, 2e-7, 450e-9)
    assert len(mine.rows) == len(theirs) == 3
    # The simulate folder itself, as the command line reads it: the same scores.
    same = cs.compare(s.images, FORCES, 2e-7, sim, None, None, 450e-9)
    assert [x["dice"] for x in same.rows] == [x["dice"] for x in mine.rows]
    dice_col = next(k for k in theirs[0] if k.startswith("dice"))
    for m, t in zip(mine.rows, theirs):
        assert m["dice"] == pytest.approx(float(t[dice_col]), abs=1e-5)  # CSV: 5 decimals
        assert 0.0 <= m["dice"] <= 1.0


def test_fit_hardening_matches_cli(cli, surface_npy, tmp_path):
    out = tmp_path / "sim"
    cli("simulate", "--topography", surface_npy, "--pixel-size", "100nm", "--radius", "20um",
        "--modulus", "1GPa", "--model", "hardening", "--hardening", "4MPa/nm",
        "--forces", "20,40,80uN", "--out", out, "-q")
    cli("fit-hardening", "--areas", out / "areas.csv", "--topography", surface_npy,
        "--pixel-size", "100nm", "--radius", "20um", "--modulus", "1GPa",
        "--models", "hardening", "--out", tmp_path / "fit", "-q")
    theirs = json.loads((tmp_path / "fit" / "fit.json").read_text())["models"][0]
    rows = read_csv(out / "areas.csv")
    forces = [float(r["force_mN"]) * 1e-3 for r in rows]
    areas = [float(r["area_um2"]) * 1e-12 for r in rows]
    # The same files and the default arguments: the command line's numbers.
    mine = cs.fit_hardening(out / "areas.csv", None, surface_npy, 100e-9, 1e9, radius=20e-6)
    assert mine.parameter * 1e-15 == theirs["k_MPa_per_nm"]
    assert mine.misfit == theirs["misfit_rms_ln_area"]
    assert mine.parameter == pytest.approx(4e15, rel=0.1)
    # The measured curve as numbers (N, m²) and the heights as an array give the same fit.
    h = cs.read_topography(surface_npy, pixel_size=100e-9, detrend="none").heights
    again = cs.fit_hardening(forces, areas, h, 100e-9, 1e9, radius=20e-6)
    assert again.parameter == pytest.approx(mine.parameter, rel=1e-9)
    assert again.models[0]["model"] == "hardening" and again.trace


def test_ramp_and_misfit_agree_with_simulate(surface_npy):
    h = cs.read_topography(surface_npy, pixel_size=100e-9).heights
    loads = [20e-6, 40e-6]
    r = cs.ramp(h, 100e-9, 1e9, "hardening", 4e15, loads, radius=20e-6)
    s = cs.simulate(h, 100e-9, 1e9, loads, "hardening", k=4e15, radius=20e-6, maps=False)
    np.testing.assert_allclose(r.areas_m2, [x["area_m2"] for x in s.rows], rtol=1e-12)
    assert cs.misfit(loads, r.areas_m2, r.areas_m2) == 0.0
    assert cs.misfit(loads, r.areas_m2, np.e * r.areas_m2) == pytest.approx(1.0)


def test_threads_setting():
    before = cs.get_num_threads()
    cs.set_num_threads(1)
    assert cs.get_num_threads() == 1
    cs.set_num_threads(0)
    assert cs.get_num_threads() == before or cs.get_num_threads() >= 1


# ----- bad input → the right exception, with the library's message -----

def test_missing_file_is_oserror(tmp_path):
    with pytest.raises(cs.FileError) as e:
        cs.read_image(tmp_path / "nope.tif")
    assert isinstance(e.value, OSError) and "nope.tif" in str(e.value)
    with pytest.raises(OSError):
        cs.read_series([tmp_path / "nope.tif"], forces=[1e-3])
    with pytest.raises(OSError):
        cs.read_topography(tmp_path / "nope.npy", pixel_size=1e-7)


def test_garbage_tiff_is_valueerror(tmp_path):
    (tmp_path / "bad.tif").write_bytes(b"II*\x00garbage" * 3)
    with pytest.raises(cs.InputError) as e:
        cs.read_image(tmp_path / "bad.tif")
    assert isinstance(e.value, ValueError) and "bad.tif" in str(e.value)


@pytest.mark.parametrize("call", [
    lambda h: cs.simulate(h, -1e-7, 1e9, [1e-6]),
    lambda h: cs.simulate(h, 1e-7, 1e9, [1e-6], model="plastic"),
    lambda h: cs.simulate(h, 1e-7, 1e9, [1e-6], model="hardening"),
    lambda h: cs.simulate(h, 1e-7, -1e9, [1e-6]),
    lambda h: cs.simulate(h, 1e-7, 1e9, []),
    lambda h: cs.simulate(np.full((8, 8), np.nan), 1e-7, 1e9, [1e-6]),
    lambda h: cs.simulate(h, (1e-7, 1e-7, 1e-7), 1e9, [1e-6]),
    lambda h: cs.simulate(h, 1e-7, 1e9, [1e-6], model="gt"),
    lambda h: cs.surface(64, 64, 1e-7),
    lambda h: cs.surface(64, 64, 1e-7, rms_height=1e-8, hurst=2.0),
    lambda h: cs.analyze(np.zeros((2, 8, 8), np.uint16)),
    lambda h: cs.analyze(np.zeros((1, 0, 0), np.uint16)),
    lambda h: cs.analyze(np.arange(64, dtype=np.uint16).reshape(1, 8, 8), forces=[1, 2]),
    lambda h: cs.analyze(np.arange(64, dtype=np.uint16).reshape(1, 8, 8), forces=[-1.0]),
    lambda h: cs.analyze(np.arange(64, dtype=np.uint16).reshape(1, 8, 8), method="median"),
    lambda h: cs.analyze(np.zeros(8)),
    lambda h: cs.measure(np.zeros((8, 8)), float("nan")),
    lambda h: cs.autocorrelation(np.ones((16, 16)), 1e-7, max_lag=-1.0),
    lambda h: cs.autocorrelation(np.ones((16, 16))),
    lambda h: cs.autocorrelation(np.ones((16, 16)), 1e-7, z=1),
    lambda h: cs.autocorrelation([], 1e-7),
    lambda h: cs.blur_and_resample(np.ones((8, 8)), 1e-7, -1.0, 2e-7),
    lambda h: cs.psf(np.zeros((16, 16)), 1e-7),
    lambda h: cs.psf(np.zeros((16, 16))),
    lambda h: cs.psf(np.zeros((16, 16)), 1e-7, bead_diameter=-1e-7),
    lambda h: cs.psf(np.zeros((16, 16)), 1e-7, saturation_level=float("nan")),
    lambda h: cs.newton(np.zeros((2, 8, 8)), np.zeros((8, 8)), 1e-7),
    lambda h: cs.newton(np.zeros((8, 8)), np.zeros((8, 8)), 1e-7, phase="quarter"),
    lambda h: cs.newton(np.zeros((8, 8)), np.zeros((8, 8)), 1e-7, profiles=0),
    lambda h: cs.newton(np.zeros((8, 8)), np.zeros((8, 8)), 1e-7, medium_index=-1.0),
    lambda h: cs.fit_hardening([1e-6], [1e-12], h, 1e-7, 1e9, radius=1e-5),
    lambda h: cs.fit_hardening([1e-6, 2e-6], [1e-12, 2e-12], h, 1e-7, 1e9, family="x"),
    lambda h: cs.ramp(h, 1e-7, 1e9, "hardness", None, [1e-6]),
    lambda h: cs.misfit([1e-6, 2e-6], [1e-12, 2e-12], [1e-12]),
    lambda h: cs.read_topography("x.npy", detrend="cubic"),
])
def test_bad_input_is_valueerror(call):
    h = cs.surface(32, 32, 1e-7, rms_height=1e-8, seed=1)
    with pytest.raises(ValueError) as e:
        call(h)
    assert str(e.value)  # the library's message, never empty
    assert not isinstance(e.value, cs.InternalError)


def test_areas_in_another_unit_are_refused():
    # mN and µm² given where N and m² are meant: a measured area larger than the whole map.
    h = cs.surface(32, 32, 1e-7, rms_height=1e-8, seed=1)
    with pytest.raises(cs.InputError, match=r"larger than the whole height map \(10\.2 µm², heights"):
        cs.fit_hardening([4, 40, 100], [10, 50, 120], h, 1e-7, 3.7e9, radius=50e-6)


def test_optics_refusals_name_the_keyword():
    a = np.zeros((8, 8), np.uint16)
    with pytest.raises(cs.InputError, match="wavelength="):
        cs.newton(a, a, 2e-7, wavelength=488.0)  # 488 m, not nm
    with pytest.raises(cs.InputError, match="pixel_size="):
        cs.psf(a)
    with pytest.raises(cs.InputError, match="max_lag="):
        cs.autocorrelation(a, 2e-7, max_lag=-1e-6)


def test_results_are_plain_data():
    s = cs.synth_series(96, 96, 2e-7, FORCES)
    a = cs.analyze(s.images, forces=FORCES, pixel_size=2e-7)
    assert a["rows"] is a.rows
    with pytest.raises(AttributeError):
        a.nothing
    assert pathlib.Path  # noqa: B018 (imports used)


def test_stubs_name_every_function():
    import ast

    import contactscope._contactscope as ext

    stub = pathlib.Path(cs.__file__).with_name("_contactscope.pyi")
    tree = ast.parse(stub.read_text(encoding="utf-8"))
    functions = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    exceptions = {n.name for n in tree.body if isinstance(n, ast.ClassDef)
                  and not any(getattr(b, "id", "") == "TypedDict" for b in n.bases)}
    assert functions | exceptions == {n for n in dir(ext) if not n.startswith("_")}
    assert set(cs.__all__) <= set(dir(cs))


def test_float_series_matches_cli(cli, series_tif, tmp_path):
    # Float data take the library's float histogram path (finite range, then bins).
    _, s = series_tif
    stack = (s.images.astype(np.float32) / 4095.0)
    cs.write_tiff(tmp_path / "f.tif", stack, 2e-7)
    r = cs.read_series(tmp_path / "f.tif", forces=FORCES)
    assert r.images.dtype == np.float32
    a = cs.analyze(r)
    cli("analyze", tmp_path / "f.tif", "--forces", "2,4,8mN", "--out", tmp_path / "an", "-q")
    rows = read_csv(tmp_path / "an" / "areas.csv")
    assert [x["contact_pixels"] for x in a.rows] == [int(x["contact_pixels"]) for x in rows]
    assert a.threshold["value"] == pytest.approx(float(rows[0]["threshold"]), rel=1e-6)
    assert 0.0 < a.threshold["value"] < 1.0


def test_read_topography_gsf_carries_its_pixel_size(cli, tmp_path):
    gsf = tmp_path / "s.gsf"
    cli("surface", "--size", 64, "--pixel-size", "50nm", "--rms-height", "20nm", "--seed", 9,
        "--out", gsf)
    t = cs.read_topography(gsf, detrend="none")
    assert t.pixel_size_m == pytest.approx((50e-9, 50e-9), rel=1e-9)
    np.testing.assert_allclose(t.heights, cs.surface(64, 64, 50e-9, rms_height=20e-9, seed=9),
                               rtol=1e-6, atol=1e-15)
    # A pixel size beside the file's own replaces it, with the command line's warning.
    with pytest.warns(cs.ContactscopeWarning, match="replaces the pixel size the file states"):
        t = cs.read_topography(gsf, pixel_size=60e-9, detrend="none")
    assert t.pixel_size_m == pytest.approx((60e-9, 60e-9), rel=1e-12)
    # The content decides, not the extension: one row of numbers is a profile.
    with pytest.raises(cs.InputError, match="line scan"):
        (tmp_path / "s.xyz").write_text("1 2 3")
        cs.read_topography(tmp_path / "s.xyz", pixel_size=1e-7)


def test_to_pandas_gives_the_rows_as_a_table():
    pd = pytest.importorskip("pandas", reason="to_pandas() needs pandas, an optional dependency")
    s = cs.synth_series(96, 96, 2e-7, FORCES)
    a = cs.analyze(s.images, forces=FORCES, pixel_size=2e-7)
    df = a.to_pandas()
    assert isinstance(df, pd.DataFrame) and len(df) == len(FORCES)
    assert list(df["force_n"]) == FORCES
    assert list(df.columns) == list(a.rows[0])


def test_simulate_and_fit_say_which_device_ran(surface_npy):
    """``device``: "auto" runs on the CPU where no GPU is usable and says so; "cuda" there is a
    one-line InputError naming the choice as Python writes it (device=cuda); an unknown name
    lists the choices."""
    h = cs.read_topography(surface_npy, pixel_size=100e-9).heights
    loads = [20e-6, 40e-6]
    auto = cs.simulate(h, 100e-9, 1e9, loads, "hardening", k=4e15, radius=20e-6, maps=False,
                       device="auto")
    ran = auto["solver"]["device"]
    cpu = cs.simulate(h, 100e-9, 1e9, loads, "hardening", k=4e15, radius=20e-6, maps=False)
    assert cpu["solver"]["device"] == "cpu"
    if ran == "cpu":
        with pytest.raises(cs.InputError) as e:
            cs.simulate(h, 100e-9, 1e9, loads, "hardening", k=4e15, radius=20e-6, device="cuda")
        assert "device=cuda" in str(e.value) and "\n" not in str(e.value)
        np.testing.assert_array_equal([r["area_m2"] for r in auto.rows],
                                      [r["area_m2"] for r in cpu.rows])
    else:
        assert ran.startswith("cuda: ")
    with pytest.raises(cs.InputError, match="cpu, cuda, auto"):
        cs.simulate(h, 100e-9, 1e9, loads, device="tpu")
    fit = cs.fit_hardening(loads, [r["area_m2"] for r in cpu.rows], h, 100e-9, 1e9,
                           radius=20e-6, grid=3, device="auto")
    assert fit["device"] == ran
