"""The area intervals and fit intervals reach Python as the command line writes them: the rows
carry ``area_m2_lo``/``area_m2_hi`` (SI) where ``areas.csv`` has ``area_um2_lo``/``_hi``, and the
fits their ``exponent_ci95``."""

import csv

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
        assert mine["area_m2_lo"] <= mine["area_m2"] <= mine["area_m2_hi"]
        for key in ("area_um2_lo", "area_um2_hi"):
            si = key.replace("um2", "m2")
            assert mine[si] * 1e12 == pytest.approx(float(theirs[key]), rel=1e-12), key
    law = r["fits"]["power_law"]
    lo, hi = law["exponent_ci95"]
    assert lo < law["exponent"] < hi
    # The prefactor's interval, in the prefactor's own units, holds the prefactor.
    name = next(k for k in law if k.startswith("prefactor") and not k.endswith("_ci95"))
    c_lo, c_hi = law[name + "_ci95"]
    assert 0 < c_lo < law[name] < c_hi
    assert np.isfinite(r["area_interval"]["band_half_width"])
