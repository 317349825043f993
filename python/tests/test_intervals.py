"""The area intervals and fit intervals reach Python as the command line writes them: the rows
carry ``area_m2_lo``/``area_m2_hi`` (SI) where ``areas.csv`` has ``area_um2_lo``/``_hi``, and the
fits their ``exponent_ci95``."""

import csv
import json

import numpy as np
import pytest

import contactscope as cs


def test_python_rows_carry_the_intervals_of_areas_csv(tmp_path, cli):
    cli("synth-series", "--size", "128", "--forces", "2mN..8mN:4", "--seed", "5", "--out",
        str(tmp_path / "s"))
    cli("analyze", str(tmp_path / "s"), "--out", str(tmp_path / "a"), "-q")
    rows = list(csv.DictReader((tmp_path / "a" / "areas.csv").open()))
    r = cs.analyze(cs.read_series(tmp_path / "s"))
    assert len(r.rows) == len(rows)
    for mine, theirs in zip(r.rows, rows):
        assert mine["area_m2_lo"] <= mine["area_corrected_m2"] <= mine["area_m2_hi"]
        for key in ("area_um2_lo", "area_um2_hi"):
            si = key.replace("um2", "m2")
            assert mine[si] * 1e12 == pytest.approx(float(theirs[key]), rel=1e-12), key
    law = r["fits"]["power_law"]
    lo, hi = law["exponent_ci95"]
    assert lo < law["exponent_corrected"] < hi
    # The prefactor's interval, in the prefactor's own units, holds the prefactor.
    name = next(k for k in law if k.startswith("prefactor") and not k.endswith("_ci95"))
    c_lo, c_hi = law[name + "_ci95"]
    assert 0 < c_lo < law[name] < c_hi
    assert r["area_interval"]["psf_source"].startswith("not given")
    # A PSF given moves the intervals, not the contact pixels.
    given = cs.analyze(cs.read_series(tmp_path / "s"), psf_fwhm=450e-9)
    assert given["area_interval"]["psf_source"] == "given"
    assert [g["area_m2"] for g in given.rows] == [m["area_m2"] for m in r.rows]
    assert np.all([g["area_m2_lo"] <= g["area_corrected_m2"] <= g["area_m2_hi"]
                   for g in given.rows])


def test_a_pixel_size_uncertainty_widens_the_areas_and_the_prefactor_not_beta(tmp_path, cli):
    cli("synth-series", "--size", "128", "--forces", "2mN..8mN:4", "--seed", "6", "--out",
        str(tmp_path / "s"))
    series = cs.read_series(tmp_path / "s")
    exact = cs.analyze(series)
    calibrated = cs.analyze(series, pixel_size_uncertainty=0.02)
    for a, b in zip(exact.rows, calibrated.rows):
        assert b["area_m2"] == a["area_m2"]
        assert b["area_m2_lo"] == pytest.approx(a["area_m2_lo"] * 0.98 ** 2, rel=1e-12)
        assert b["area_m2_hi"] == pytest.approx(a["area_m2_hi"] * 1.02 ** 2, rel=1e-12)
        assert b["pixel_size_uncertainty_fraction"] == pytest.approx(0.02)
    assert calibrated["area_interval"]["pixel_size_uncertainty_fraction"] == pytest.approx(0.02)
    la, lb = exact["fits"]["power_law"], calibrated["fits"]["power_law"]
    name = next(k for k in la if k.startswith("prefactor") and k.endswith("_ci95"))
    assert lb[name][1] - lb[name][0] > la[name][1] - la[name][0]
    # The same resamples of β: a factor shared by every area cannot move it.
    assert lb["exponent_ci95"] == pytest.approx(la["exponent_ci95"], abs=0.02)
    # The command line's flags give the same table.
    cli("analyze", str(tmp_path / "s"), "--pixel-size-uncertainty", "2%", "--out",
        str(tmp_path / "a"), "-q")
    rows = list(csv.DictReader((tmp_path / "a" / "areas.csv").open()))
    for mine, theirs in zip(calibrated.rows, rows):
        assert mine["area_m2_hi"] * 1e12 == pytest.approx(float(theirs["area_um2_hi"]), rel=1e-12)
        assert float(theirs["pixel_size_uncertainty_pct"]) == pytest.approx(2.0)
    with pytest.raises(cs.InputError, match="pixel_size_uncertainty"):
        cs.analyze(series, pixel_size_uncertainty=0.5)


def test_k_has_an_interval_from_the_measured_areas_intervals(tmp_path, cli):
    # The reduced demo writes a measured areas.csv (with intervals) and its height map.
    out = tmp_path / "demo"
    cli("demo", "--small", "--out", str(out), "-q")
    fit = json.loads((out / "fit" / "fit.json").read_text())
    k_cli = next(m for m in fit["models"] if m["model"] == "hardening")
    lo, hi = k_cli["k_MPa_per_nm_ci95"]
    assert lo < k_cli["k_MPa_per_nm"] < hi
    rows = list(csv.DictReader((out / "analysis" / "areas.csv").open()))
    forces = [float(r["force_mN"]) * 1e-3 for r in rows]
    areas = [float(r["area_um2"]) * 1e-12 for r in rows]
    area_lo = [float(r["area_um2_lo"]) * 1e-12 for r in rows]
    area_hi = [float(r["area_um2_hi"]) * 1e-12 for r in rows]
    common = dict(heights=str(out / "data" / "topography.npy"), pixel_size=80e-9,
                  modulus=3.7e9, radius=50e-6, detrend="none", grid=5, ln_tolerance=0.02,
                  imaging_fwhm=450e-9, imaging_pixel_size=200e-9)
    with_intervals = cs.fit_hardening(forces, areas, area_intervals=(area_lo, area_hi), **common)
    from_file = cs.fit_hardening(str(out / "analysis" / "areas.csv"), None, **common)
    assert with_intervals.parameter_ci95 == pytest.approx(from_file.parameter_ci95, rel=1e-12)
    assert with_intervals.parameter_ci95 == pytest.approx((lo * 1e15, hi * 1e15), rel=1e-9)
    # Without the areas' intervals: the bootstrap over the loads alone, narrower.
    bare = cs.fit_hardening(forces, areas, **common)
    assert bare.parameter == pytest.approx(with_intervals.parameter, rel=1e-12)
    b_lo, b_hi = bare.parameter_ci95
    assert b_hi - b_lo < hi * 1e15 - lo * 1e15
    with pytest.raises(cs.InputError, match="area_intervals"):
        cs.fit_hardening(forces, areas, area_intervals=area_lo, **common)
