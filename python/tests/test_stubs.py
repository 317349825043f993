"""The stubs (`_contactscope.pyi`) against what the functions return: every result is a job's
outcome serialised in SI units, and each `TypedDict` of the stubs must name exactly its keys
(all of them for a total TypedDict, a subset otherwise), nested TypedDicts included. A field
added to an outcome type in Rust without the stub (or the other way round) fails here."""

import ast
import math
import pathlib

import numpy as np
import pytest

import contactscope as cs
import contactscope._contactscope as ext

from test_commands import friction_inputs, squeeze_csv  # noqa: F401 (fixture)

STUB = pathlib.Path(cs.__file__).with_name("_contactscope.pyi")
TREE = ast.parse(STUB.read_text(encoding="utf-8"))


def _typed_dicts():
    out = {}
    for node in TREE.body:
        if isinstance(node, ast.ClassDef) and any(getattr(b, "id", "") == "TypedDict"
                                                  for b in node.bases):
            total = all(not (k.arg == "total" and isinstance(k.value, ast.Constant)
                             and k.value.value is False) for k in node.keywords)
            fields = {s.target.id: s.annotation for s in node.body
                      if isinstance(s, ast.AnnAssign)}
            out[node.name] = (fields, total)
    return out


TYPED = _typed_dicts()
RETURNS = {n.name: n.returns for n in TREE.body if isinstance(n, ast.FunctionDef)}
# Methods of the stubs' classes, as "function_that_makes_it.method" (e.g. batch_plan.run).
METHODS = {f"batch_plan.{m.name}": m.returns for c in TREE.body if isinstance(c, ast.ClassDef)
           and c.name == "BatchPlan" for m in c.body if isinstance(m, ast.FunctionDef)}


def check(value, annotation, where):
    """`value` against the stub annotation (only TypedDicts and containers of them are
    checked; scalars, arrays and plain dicts are taken as declared)."""
    if isinstance(annotation, ast.Name) and annotation.id in TYPED:
        fields, total = TYPED[annotation.id]
        assert isinstance(value, dict), f"{where}: {type(value)} is not a {annotation.id}"
        keys = set(value)
        assert keys <= set(fields), f"{where}: not in {annotation.id}: {keys - set(fields)}"
        if total:
            assert keys == set(fields), f"{where}: missing from the result: {set(fields) - keys}"
        for k in keys:
            check(value[k], fields[k], f"{where}.{k}")
    elif isinstance(annotation, ast.Subscript) and isinstance(annotation.value, ast.Name):
        kind = annotation.value.id
        if kind == "Optional":
            if value is not None:
                check(value, annotation.slice, where)
        elif kind == "List":
            assert isinstance(value, list), f"{where}: {type(value)} is not a list"
            for i, item in enumerate(value):
                check(item, annotation.slice, f"{where}[{i}]")


def results(tmp_path, friction_inputs):  # noqa: F811
    """One result of every function whose stub returns a TypedDict, on small generated data."""
    forces = [2e-3, 4e-3, 8e-3]
    s = cs.synth_series(96, 96, 200e-9, forces, seed=3)
    tif = tmp_path / "s.tif"
    cs.write_tiff(tif, s.images, 200e-9)
    beads = cs.synth_beads(seed=5)
    rings = cs.synth_newton(seed=7)
    heights = cs.surface(64, 64, 1e-7, rms_height=5e-8, seed=2)
    npy = tmp_path / "h.npy"
    np.save(npy, heights)
    sim = cs.simulate(heights, 1e-7, 1e9, [2e-5, 4e-5], "hardening", k=4e15, radius=2e-5)
    traces, areas = friction_inputs
    sheet = tmp_path / "sheet.csv"
    sheet.write_text(f'id,input,forces\ns1,{tif},"2,4,8mN"\n')
    spec = {"inputs": [str(tif)], "manifest": None, "series": None, "channel": None, "z": None,
            "t": None, "axes": None, "load_axis": None, "forces": forces}
    return {
        "read_series": cs.read_series(tif, forces=forces),
        "otsu_threshold": ext.otsu_threshold(spec),
        "analyze": cs.analyze(s.images, forces=forces, pixel_size=2e-7),
        "psf": cs.psf(beads, 1e-7),
        "autocorrelation": cs.autocorrelation(s.images[2], 2e-7),
        "newton": cs.newton(rings.reflection, rings.fluorescence, 2e-7),
        "compare": cs.compare(s.images, forces, 2e-7, np.stack([s.truth[i] for i in range(3)]),
                              forces, 2e-7, 450e-9),
        "read_topography": cs.read_topography(npy, pixel_size=1e-7),
        "surface": cs.surface_with_stats(64, 64, 1e-7, rms_height=5e-8, seed=2),
        "simulate": sim,
        "ramp": cs.ramp(heights, 1e-7, 1e9, "hardening", 4e15, [2e-5, 4e-5], radius=2e-5),
        "fit_hardening": cs.fit_hardening([2e-5, 4e-5], [r["area_m2"] for r in sim.rows],
                                          heights, 1e-7, 1e9, radius=2e-5, grid=3),
        "friction": cs.friction(traces, normal_force=40e-3, areas=areas),
        "hertz": cs.hertz(squeeze_csv(tmp_path / "sq.csv"), 290e-6),
        "info": cs.info(tif, stats=True),
        "synth_series": cs.synth_series(96, 96, 2e-7, forces),
        "batch_plan.run": ext.batch_plan("file", str(sheet), str(tmp_path / "batch")).run(),
    }


@pytest.mark.filterwarnings("ignore::contactscope.ContactscopeWarning")
def test_stubs_describe_every_result(tmp_path, friction_inputs):  # noqa: F811
    got = results(tmp_path, friction_inputs)
    typed_returns = {name for name, ann in RETURNS.items()
                     if isinstance(ann, ast.Name) and ann.id in TYPED}
    # Every function whose stub promises a TypedDict is exercised here.
    assert typed_returns <= set(got), typed_returns - set(got)
    for name, value in got.items():
        check(dict(value), RETURNS.get(name) or METHODS[name], name)


def test_an_outcome_key_missing_from_the_stub_is_found():
    # The checker itself: an extra key, or a missing one, fails.
    with pytest.raises(AssertionError, match="not in"):
        check({"threshold": 1.0, "extra": 2}, ast.Name(id="ThresholdResult"), "t")
    with pytest.raises(AssertionError, match="missing"):
        check({"threshold": 1.0}, ast.Name(id="ThresholdResult"), "t")
    assert math.isfinite(1.0)
