"""friction, hertz, info, topography, surface and synth-series from Python against the command
line on the same files: the Python result is the command's JSON (or printed numbers) in SI units
with SI keys (``force_mN`` → ``force_n``, ``area_um2`` → ``area_m2``)."""

import csv
import json
import math

import numpy as np
import pytest

import contactscope as cs

E_STAR = 3.7e9
RADIUS = 290e-6
TAU = 50e6  # Pa
LOADS = [4e-3, 10e-3, 20e-3, 40e-3]  # N


def read_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def area_m2(load_n):
    """Sublinear areas as in Fig. 3a of the paper: 40 µm² at 4 mN, A ∝ N^0.8."""
    return 40e-12 * (load_n / 4e-3) ** 0.8


def trace(static_n, seed, normal_n=None):
    """A rheometer trace as CSV text: a loading ramp over 20 µm to F_s, a sharp drop to
    0.8 F_s and a noisy kinetic plateau (displacement in µm, forces in mN)."""
    rng = np.random.default_rng(seed)
    x = np.arange(600) * 0.05  # µm
    f = np.where(x <= 20.0, static_n * x / 20.0, 0.8 * static_n)
    f = f + rng.normal(0.0, 0.003 * static_n, x.size)
    header = "displacement_um,friction_mN" + (",normal_force_mN" if normal_n else "")
    rows = [f"{a:.6f},{b * 1e3:.9f}" + (f",{normal_n * 1e3}" if normal_n else "")
            for a, b in zip(x, f)]
    return "\n".join([header, *rows]) + "\n"


@pytest.fixture
def friction_inputs(tmp_path):
    traces = []
    for i, n in enumerate(LOADS):
        # The last trace has no normal-force column: it takes normal_force (40 mN).
        path = tmp_path / f"trace_{i + 1}.csv"
        path.write_text(trace(TAU * area_m2(n), i, n if i < 3 else None))
        traces.append(path)
    areas = tmp_path / "areas.csv"
    areas.write_text("force_mN,area_um2\n" + "".join(
        f"{n * 1e3 * 1.005},{area_m2(n) * 1e12}\n" for n in LOADS))
    return traces, areas


def test_friction_matches_cli(cli, friction_inputs, tmp_path):
    traces, areas = friction_inputs
    out = tmp_path / "fr"
    cli("friction", *traces, "--forces", "40mN", "--areas", areas, "--out", out)
    theirs = json.loads((out / "summary.json").read_text())
    # normal_force applies to the last trace; the others' columns differ from it: warned, in
    # the terms of each front-end.
    with pytest.warns(cs.ContactscopeWarning, match="differs from normal_force="):
        mine = cs.friction(traces, normal_force=40e-3, areas=areas)
    assert len(mine.warnings) == len(theirs["warnings"]) == 3
    assert [w.replace("normal_force=", "--forces") for w in mine.warnings] \
        == theirs["warnings"]
    # The same keys, in SI units.
    assert set(mine) == {"inputs", "method", "tau_pa", "tau_se_pa", "r2", "static_shear_fit",
                         "kinetic_shear_fit", "mu_static_vs_load", "traces", "warnings"}
    assert set(theirs) - set(mine) == {"contactscope_version", "source_revision", "command_line",
                                       "tau_MPa", "tau_se_MPa"}
    assert mine.tau_pa * 1e-6 == pytest.approx(theirs["tau_MPa"], rel=1e-12)
    assert mine.tau_pa == pytest.approx(TAU, rel=0.03)
    assert mine.tau_se_pa * 1e-6 == pytest.approx(theirs["tau_se_MPa"], rel=1e-12)
    assert mine.r2 == theirs["r2"]
    assert mine.static_shear_fit["points"] == 4
    assert mine.mu_static_vs_load == theirs["mu_static_vs_load"]
    assert mine.inputs == {"traces": [str(t) for t in traces], "areas": str(areas),
                           "normal_force_n": 40e-3, "rotation_radius_m": None,
                           "force_tolerance_fraction": 0.02}
    assert theirs["inputs"]["force_tolerance_pct"] == 2.0
    assert mine.method == theirs["method"]
    assert len(mine.rows) == 4
    rows = read_csv(out / "friction.csv")
    for m, t, r in zip(mine.rows, theirs["traces"], rows):
        assert m["file"] == t["file"] == r["file"]
        assert m["normal_force_n"] * 1e3 == pytest.approx(t["normal_force_mN"], rel=1e-12)
        assert m["static_friction_n"] * 1e3 == pytest.approx(t["static_friction_mN"], rel=1e-12)
        assert m["static_friction_n"] * 1e3 == pytest.approx(float(r["static_friction_mN"]),
                                                             abs=1e-6)
        assert m["area_m2"] * 1e12 == pytest.approx(t["area_um2"], rel=1e-12)
        assert (m["mu_static"], m["mu_kinetic"]) == (t["mu_static"], t["mu_kinetic"])
        assert (m["slip_sample"], m["slip_criterion"]) == (t["slip_sample"], t["slip_criterion"])
        # The slip position in SI units (m) where the command line writes µm.
        assert (m["slip_at_unit"], t["slip_at_unit"]) == ("m", "um")
        assert m["slip_at"] * 1e6 == pytest.approx(t["slip_at"], rel=1e-12)
        assert 19e-6 < m["slip_at"] < 21e-6
    assert mine.rows[3]["normal_force_n"] == 40e-3
    # μ_s = τ·A/N falls with N as N^(0.8 − 1).
    assert mine.mu_static_vs_load["exponent"] == pytest.approx(-0.2, abs=0.03)


def test_friction_refusals_name_keywords(friction_inputs):
    traces, areas = friction_inputs
    with pytest.raises(cs.InputError, match="normal_force="):
        cs.friction(traces[3])
    with pytest.raises(cs.InputError, match="normal_force="):
        cs.friction(traces, normal_force=-1.0)
    with pytest.raises(cs.InputError, match="force_tolerance="):
        cs.friction(traces, normal_force=40e-3, force_tolerance=2.0)
    with pytest.raises(cs.InputError, match="rotation_radius="):
        cs.friction(traces, normal_force=40e-3, rotation_radius=5.0e3)
    with pytest.raises(cs.InputError, match="no friction traces"):
        cs.friction([])
    # A normal-force column that disagrees with normal_force: a warning, the column wins.
    with pytest.warns(cs.ContactscopeWarning, match="normal_force="):
        r = cs.friction(traces[0], normal_force=5e-3)
    assert r.rows[0]["normal_force_n"] == 4e-3 and r.warnings


def squeeze_csv(path):
    """Squeeze data for 2…50 mN: 2δ from Hertz (δ = (3P/(4E*√R))^(2/3)), two pre-contact rows."""
    lines = ["force_mN,displacement_um", "-0.001,0", "0,0"]
    for i in range(1, 26):
        p = 2e-3 * i
        delta = (3 * p / (4 * E_STAR * math.sqrt(RADIUS))) ** (2 / 3)
        lines.append(f"{p * 1e3:.12f},{2 * delta * 1e6:.12f}")
    path.write_text("\n".join(lines) + "\n")
    return path


def test_hertz_matches_cli(cli, tmp_path):
    squeeze = squeeze_csv(tmp_path / "squeeze.csv")
    out = tmp_path / "hz"
    cli("hertz", squeeze, "--radius", "290um", "--forces", "4mN,40mN", "--out", out)
    theirs = json.loads((out / "hertz.json").read_text())
    mine = cs.hertz(squeeze, RADIUS, loads=[4e-3, 40e-3])
    assert mine.contact_modulus_pa == pytest.approx(E_STAR, rel=1e-9)
    assert mine.contact_modulus_pa * 1e-9 == pytest.approx(theirs["contact_modulus_GPa"],
                                                           rel=1e-12)
    assert mine.contact_modulus_se_pa * 1e-9 == pytest.approx(
        theirs["contact_modulus_se_GPa"], rel=1e-9, abs=1e-15)
    assert (mine.r2, mine.points_used) == (theirs["r2"], theirs["points_used"]) == (mine.r2, 25)
    assert mine.radius_m * 1e6 == pytest.approx(theirs["radius_um"], rel=1e-12)
    assert mine.method == theirs["method"]
    assert mine.offset_fit["contact_modulus_pa"] * 1e-9 == pytest.approx(
        theirs["offset_fit"]["contact_modulus_GPa"], rel=1e-12)
    assert [p["force_n"] for p in mine.rows] == [4e-3, 40e-3]
    for m, t in zip(mine.rows, theirs["predicted"]):
        assert m["contact_radius_m"] * 1e6 == pytest.approx(t["contact_radius_um"], rel=1e-12)
        assert m["contact_area_m2"] == pytest.approx(math.pi * m["contact_radius_m"] ** 2,
                                                     rel=1e-12)
    # Hertz: a = (3PR/4E*)^(1/3).
    a = (3 * 40e-3 * RADIUS / (4 * E_STAR)) ** (1 / 3)
    assert mine.rows[1]["contact_radius_m"] == pytest.approx(a, rel=1e-9)
    # `points` is hertz_fit.csv (nine decimals there).
    rows = read_csv(out / "hertz_fit.csv")
    assert len(mine.points) == len(rows) == 25
    for m, r in zip(mine.points, rows):
        assert m["force_n"] * 1e3 == pytest.approx(float(r["force_mN"]), abs=1e-9)
        assert m["delta_m"] * 1e6 == pytest.approx(float(r["delta_um"]), abs=1e-9)
        assert m["residual_n"] * 1e3 == pytest.approx(float(r["residual_mN"]), abs=1e-9)
    # Default loads: the measured forces.
    assert [p["force_n"] for p in cs.hertz(squeeze, RADIUS).predicted] == pytest.approx(
        [p["force_n"] for p in mine.points], rel=1e-15)
    with pytest.raises(cs.InputError, match="radius="):
        cs.hertz(squeeze, 2.0)
    with pytest.raises(cs.InputError, match="loads="):
        cs.hertz(squeeze, RADIUS, loads=[-1e-3])


def test_info_matches_cli(cli, tmp_path):
    stack = np.arange(3 * 12, dtype=np.uint16).reshape(3, 3, 4) * 7
    path = tmp_path / "stack.tif"
    cs.write_tiff(path, stack, (0.2e-6, 0.25e-6))
    theirs = json.loads(cli("info", path, "--json", "--stats"))
    mine = cs.info(path, stats=True)
    assert (mine.file, mine.format) == (theirs["file"], "tiff")
    (m,), (t,) = mine.series, theirs["series"]
    for key in ("index", "name", "axes", "dtype", "pixel_size_source", "planes"):
        assert m[key] == t[key], key
    assert "pixel_size_um" not in m
    for axis in "xy":
        assert m["pixel_size_m"][axis] * 1e6 == pytest.approx(t["pixel_size_um"][axis],
                                                              rel=1e-12)
    assert m["pixel_size_m"]["x"] == pytest.approx(0.2e-6, rel=1e-6)
    assert [p["sum"] for p in m["planes"]] == [float(s.sum()) for s in stack]
    plain = cs.info(path)
    assert "planes" not in plain.series[0]
    assert plain.series[0]["axes"] == {"T": 1, "Z": 3, "C": 1, "Y": 3, "X": 4}
    with pytest.raises(cs.FileError):
        cs.info(tmp_path / "nope.tif")


def si(key):
    """The SI key of a lab key, as the package writes it."""
    tokens = {"um": "m", "nm": "m"}
    return "_".join(tokens.get(t, t) for t in key.split("_"))


def test_read_topography_describes_like_cli(cli, surface_npy):
    theirs = json.loads(cli("topography", surface_npy, "--pixel-size", "100nm", "--json"))
    t = cs.read_topography(surface_npy, pixel_size=100e-9)
    s = t.summary
    assert set(s) == {si(k) for k in theirs}
    assert set(s["detrended"]) == {si(k) for k in theirs["detrended"]}
    for key in ("file", "format", "channel", "nx", "ny", "valid_points",
                "h_prime_rms_as_stored"):
        assert s[key] == theirs[key], key
    for key in ("height_min_um", "height_max_um", "height_mean_um", "h_rms_as_stored_um"):
        assert s[si(key)] * 1e6 == pytest.approx(theirs[key], rel=1e-12), key
    assert s["pixel_size_m"] == {"x": 100e-9, "y": 100e-9}
    d, e = s["detrended"], theirs["detrended"]
    assert d["detrend"] == e["detrend"] == "plane"
    assert d["h_rms_m"] * 1e9 == pytest.approx(e["h_rms_nm"], rel=1e-12)
    assert d["h_prime_rms"] == e["h_prime_rms"]
    assert d["h_double_prime_rms_per_m"] * 1e-6 == pytest.approx(
        e["h_double_prime_rms_per_um"], rel=1e-12)
    # The heights returned are the ones described.
    assert t.heights.std() == pytest.approx(d["h_rms_m"], rel=1e-9)
    assert t.pixel_size_m == (100e-9, 100e-9) and t.notes == []
    # Range checks name the keyword.
    with pytest.raises(cs.InputError, match="height_unit="):
        cs.read_topography(surface_npy, pixel_size=100e-9, height_unit=10.0)
    with pytest.raises(cs.InputError, match="pixel_size="):
        cs.read_topography(surface_npy, pixel_size=1.0)


def test_surface_defaults_and_stats_match_cli(cli, tmp_path):
    out = tmp_path / "s.npy"
    # No --seed and no --hurst: the command line's defaults (seed 7, H = 0.8) are Python's.
    printed = cli("surface", "--size", 64, "--pixel-size", "32nm", "--rms-slope", 0.1,
                  "--out", out)
    s = cs.surface_with_stats(64, 64, 32e-9, rms_slope=0.1)
    np.testing.assert_array_equal(s.heights, np.load(out))
    np.testing.assert_array_equal(cs.surface(64, 64, 32e-9, rms_slope=0.1), s.heights)
    assert (s.nx, s.ny, s.pixel_size_m) == (64, 64, 32e-9)
    assert s.h_prime_rms == pytest.approx(0.1, rel=1e-9)
    h_rms_nm = float(printed.split("h_rms = ")[1].split()[0])
    assert s.h_rms_m * 1e9 == pytest.approx(h_rms_nm, abs=1e-4)
    assert s.h_rms_m == pytest.approx(s.heights.std(), rel=1e-9)
    curvature = float(printed.split("h''_rms = ")[1].split()[0])
    assert s.h_double_prime_rms_per_m * 1e-6 == pytest.approx(curvature, abs=1e-5)
    with pytest.raises(cs.InputError, match="rolloff="):
        cs.surface(64, 64, 32e-9, rms_slope=0.1, rolloff=10.0)
    with pytest.raises(cs.InputError, match="rms_height="):
        cs.surface(64, 64, 32e-9, rms_height=10.0)
    with pytest.raises(cs.InputError, match="hurst="):
        cs.surface(64, 64, 32e-9, rms_slope=0.1, hurst=1.5)


def test_synth_series_matches_cli(cli, tmp_path):
    out = tmp_path / "s1"
    printed = cli("synth-series", "--out", out, "--size", 96, "--forces", "2,4mN", "--seed", 3)
    assert printed.split() == [str(out / n) for n in ("series.tif", "manifest.csv",
                                                      "truth.csv")]
    mine = cs.synth_series(96, 96, forces=[2e-3, 4e-3], seed=3)
    np.testing.assert_array_equal(mine.images, cs.read_image(out / "series.tif").images)
    truth = read_csv(out / "truth.csv")
    assert mine.forces_n == [2e-3, 4e-3]
    assert mine.true_contact_pixels == [int(r["true_contact_pixels"]) for r in truth]
    assert [a * 1e12 for a in mine.true_area_m2] == pytest.approx(
        [float(r["true_area_um2"]) for r in truth], abs=1e-6)
    assert list(mine.truth.sum(axis=(1, 2))) == mine.true_contact_pixels
    # Without arguments: the command line's defaults (the bundled fixture).
    default = cs.synth_series()
    assert default.images.shape == (8, 256, 256)
    assert default.forces_n == pytest.approx([f * 1e-3 for f in (4, 6, 10, 16, 25, 40, 63,
                                                                 100)], rel=1e-15)
    with pytest.raises(cs.InputError, match="pixel_size="):
        cs.synth_series(pixel_size=-1.0)
    with pytest.raises(cs.InputError, match="forces="):
        cs.synth_series(forces=[1e3])
    # The generator's own refusal, as the command line's.
    with pytest.raises(cs.InputError, match="more than half"):
        cs.synth_series(64, 64, forces=[4e-3, 10e-3], seed=3)
