"""Both front-ends apply the same checks: a test that walks the parameters the requests check
(the table `_contactscope._params()` exports from `contactscope_formats::param`) and, for every
command and every physical parameter that the command line and the Python function both take,
gives each front-end a value beyond the parameter's plausible range. Both must refuse it: the
command line naming its flag (`--pixel-size`), Python its keyword (`pixel_size=`), each with the
range. A parameter one front-end takes and the other does not is listed, so that the two
vocabularies cannot drift apart unnoticed. Warnings come from the same jobs and are checked on
two cases (edge contact, a force in the wrong unit)."""

import inspect
import os
import re
import subprocess
import warnings

import numpy as np
import pytest

import contactscope as cs
import contactscope._contactscope as ext

from conftest import _binary
from test_commands import squeeze_csv, trace

PARAMS = [p for p in ext._params() if "quantity" in p]

# Command → its Python function.
FUNCTIONS = {
    "analyze": cs.analyze,
    "simulate": cs.simulate,
    "compare": cs.compare,
    "fit-hardening": cs.fit_hardening,
    "psf": cs.psf,
    "newton": cs.newton,
    "autocorr": cs.autocorrelation,
    "topography": cs.read_topography,
    "surface": cs.surface,
    "friction": cs.friction,
    "hertz": cs.hertz,
}

# Physical parameters one front-end names differently, with the reason (to be unified).
NAMED_DIFFERENTLY = {
    ("fit-hardening", "--psf-fwhm"): "Python's fit_hardening calls it imaging_fwhm",
    ("fit-hardening", "--hardening"): "the command line fits k over --k-range",
    ("fit-hardening", "--forces"): "the command line reads the measured forces from "
                                   "--areas (areas.csv); Python also takes numbers",
}


def run(*args):
    binary = _binary()
    if binary is None or not binary.exists():
        if os.environ.get("CONTACTSCOPE_REQUIRE_CLI") == "1":
            pytest.fail("the contactscope binary is needed: cargo build --release")
        pytest.skip("no contactscope binary")
    return subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True,
                          timeout=300)


def flags_of(command):
    text = run(command, "--help").stdout
    return set(re.findall(r"--[a-z][a-z-]+", text))


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("checks")
    forces = [2e-3, 4e-3, 8e-3]
    s = cs.synth_series(96, 96, 200e-9, forces, seed=11)
    cs.write_tiff(d / "series.tif", s.images, 200e-9)
    np.save(d / "h.npy", cs.surface(64, 64, 1e-7, rms_height=5e-8, seed=3))
    sim = d / "sim"
    done = run("simulate", "--topography", d / "h.npy", "--pixel-size", "100nm", "--radius",
               "20um", "--modulus", "1GPa", "--model", "elastic", "--forces", "20uN,40uN",
               "--out", sim, "-q")
    assert done.returncode == 0, done.stderr
    # Maps at the micrographs' forces, for compare (the contact outgrows the small map: the
    # outputs are written, exit status 4).
    done = run("simulate", "--topography", d / "h.npy", "--pixel-size", "200nm", "--radius",
               "290um", "--modulus", "3.7GPa", "--model", "elastic", "--forces", "2,4,8mN",
               "--out", d / "sim3", "-q")
    assert done.returncode == 4, done.stderr
    beads = cs.synth_beads(seed=5)
    cs.write_tiff(d / "beads.tif", beads, 1e-7)
    rings = cs.synth_newton(seed=7)
    cs.write_tiff(d / "refl.tif", rings.reflection, 2e-7)
    cs.write_tiff(d / "fluo.tif", rings.fluorescence, 2e-7)
    (d / "trace.csv").write_text(trace(2e-3, 1, 40e-3))
    squeeze_csv(d / "squeeze.csv")
    return {"dir": d, "images": s.images, "forces": forces, "beads": beads, "rings": rings}


def bases(i):
    """Valid calls of both front-ends, per command: (command-line arguments, Python arguments
    and keywords). Several bases where one model's parameters exclude another's."""
    d = i["dir"]
    out = d / "out"
    return {
        "analyze": [(["analyze", d / "series.tif", "--forces", "2,4,8mN", "--pixel-size",
                      "200nm", "--radius", "290um", "--modulus", "3.7GPa", "--out", out],
                     ([i["images"]], dict(forces=i["forces"], pixel_size=2e-7, radius=2.9e-4,
                                          modulus=3.7e9)))],
        "simulate": [
            (["simulate", "--topography", d / "h.npy", "--pixel-size", "100nm", "--radius",
              "20um", "--modulus", "1GPa", "--model", "hardening", "--hardening", "4MPa/nm",
              "--initial-hardness", "1MPa", "--height-unit", "1m", "--forces", "20uN", "--out",
              out],
             ([d / "h.npy", 1e-7, 1e9, [2e-5], "hardening"],
              dict(k=4e15, initial_hardness=1e6, radius=2e-5, height_unit=1.0))),
            (["simulate", "--topography", d / "h.npy", "--pixel-size", "100nm", "--modulus",
              "1GPa", "--model", "hardness", "--hardness", "370MPa", "--forces", "20uN", "--out",
              out],
             ([d / "h.npy", 1e-7, 1e9, [2e-5], "hardness"], dict(hardness=3.7e8))),
        ],
        "compare": [(["compare", "--micrographs", d / "series.tif", "--forces", "2,4,8mN",
                      "--simulation", d / "sim3", "--psf-fwhm", "450nm", "--pixel-size",
                      "200nm", "--out", out],
                     ([i["images"], i["forces"], 2e-7, d / "sim3", None, None, 450e-9], {}))],
        "fit-hardening": [(["fit-hardening", "--areas", d / "sim" / "areas.csv",
                            "--topography", d / "h.npy", "--pixel-size", "100nm", "--radius",
                            "20um", "--modulus", "1GPa", "--height-unit", "1m", "--models",
                            "elastic", "--out", out],
                           ([d / "sim" / "areas.csv", None, d / "h.npy", 1e-7, 1e9],
                            dict(radius=2e-5, family="elastic")))],
        "psf": [(["psf", d / "beads.tif", "--pixel-size", "100nm", "--bead-diameter", "100nm",
                  "--out", out], ([i["beads"], 1e-7], dict(bead_diameter=1e-7)))],
        "newton": [(["newton", d / "refl.tif", "--contact", d / "fluo.tif", "--pixel-size",
                     "200nm", "--wavelength", "488nm", "--out", out],
                    ([i["rings"].reflection, i["rings"].fluorescence, 2e-7],
                     dict(wavelength=4.88e-7)))],
        "autocorr": [(["autocorr", d / "series.tif", "--pixel-size", "200nm", "--max-lag", "5um",
                       "--out", out], ([i["images"]], dict(pixel_size=2e-7, max_lag=5e-6)))],
        "topography": [(["topography", d / "h.npy", "--pixel-size", "100nm", "--height-unit",
                         "1m"], ([d / "h.npy"], dict(pixel_size=1e-7, height_unit=1.0)))],
        "surface": [(["surface", "--size", "32", "--pixel-size", "100nm", "--rms-height", "50nm",
                      "--out", d / "s.npy"], ([32, 32, 1e-7], dict(rms_height=5e-8)))],
        "friction": [(["friction", d / "trace.csv", "--forces", "40mN", "--out", out],
                      ([[d / "trace.csv"]], dict(normal_force=40e-3)))],
        "hertz": [(["hertz", d / "squeeze.csv", "--radius", "290um", "--forces", "4mN", "--out",
                    out], ([d / "squeeze.csv", 2.9e-4], dict(loads=[4e-3])))],
    }


def keywords(function):
    return set(inspect.signature(function).parameters)


def test_the_bases_are_valid(inputs):
    """Every base call succeeds on both sides (so a refusal below is the bad value's doing)."""
    for command, cases in bases(inputs).items():
        for cli_args, (args, kwargs) in cases:
            done = run(*cli_args)
            # 4: written, but every contact of these small fields touches the border.
            assert done.returncode in (0, 4), (command, done.stderr)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                FUNCTIONS[command](*args, **kwargs)


def test_every_physical_parameter_is_checked_by_both_front_ends(inputs):
    checked = []
    for command, cases in bases(inputs).items():
        cli_flags = flags_of(command)
        python_keywords = keywords(FUNCTIONS[command])
        for p in PARAMS:
            flag, keyword = p["flag"], p["keyword"]
            # One flag may stand for parameters Python names apart (`--forces`: forces=,
            # loads=, normal_force=): the command's Python function has one of them.
            same_flag = [q["keyword"] for q in PARAMS if q["flag"] == flag]
            if keyword not in python_keywords and any(k in python_keywords for k in same_flag):
                continue
            on_cli, in_python = flag in cli_flags, keyword in python_keywords
            if (command, flag) in NAMED_DIFFERENTLY:
                continue
            assert on_cli == in_python, (
                f"{command}: {flag} on the command line: {on_cli}; {keyword}= in Python: "
                f"{in_python}")
            if not on_cli:
                continue
            cli_args, (args, kwargs) = next(
                (c for c in cases if flag in map(str, c[0])), cases[0])
            bad = p["highest"] * 1e3  # SI, far beyond the range
            text = f"{bad * p['factor']:g}{p['unit']}"
            cli_args = [str(a) for a in cli_args]
            # Lists (forces, loads) take the bad value for each entry.
            count = 1
            if flag in cli_args:
                k = cli_args.index(flag)
                count = cli_args[k + 1].count(",") + 1
                cli_args[k + 1] = ",".join([f"{bad * p['factor']:g}"] * count) + p["unit"]
            else:
                cli_args += [flag, text]
            done = run(*cli_args)
            assert done.returncode != 0, (command, flag, done.stdout)
            message = done.stderr
            assert flag in message and "plausible range" in message, (command, message)
            value = [bad] * count if isinstance(kwargs.get(keyword), list) else bad
            names = list(inspect.signature(FUNCTIONS[command]).parameters)
            args = list(args)
            position = names.index(keyword)
            if position < len(args):
                args[position] = value if not isinstance(args[position], list) \
                    else [bad] * len(args[position])
            else:
                kwargs = {**kwargs, keyword: value}
            with pytest.raises(cs.InputError) as e:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    FUNCTIONS[command](*args, **kwargs)
            assert f"{keyword}=" in str(e.value) and "plausible range" in str(e.value), (
                command, keyword, str(e.value))
            checked.append((command, flag))
    # The walk reached every command and the parameters labs set most.
    assert {c for c, _ in checked} == set(FUNCTIONS), {c for c, _ in checked}
    for must in [("analyze", "--pixel-size"), ("simulate", "--modulus"),
                 ("simulate", "--hardening"), ("compare", "--psf-fwhm"),
                 ("newton", "--wavelength"), ("hertz", "--radius")]:
        assert must in checked, must


def test_warnings_reach_both_front_ends(inputs):
    d = inputs["dir"]
    # Forces given in the wrong unit (4 N for 4 mN): an implausible mean pressure.
    done = run("analyze", d / "series.tif", "--forces", "2,4,8N", "--out", d / "w1", "-q")
    assert done.returncode in (0, 4) and "beyond any solid contact" in done.stderr
    with pytest.warns(cs.ContactscopeWarning, match="beyond any solid contact") as record:
        r = cs.analyze(inputs["images"], forces=[2.0, 4.0, 8.0], pixel_size=2e-7)
    assert any("forces=" in str(w.message) for w in record)
    assert any("beyond any solid contact" in w for w in r.warnings)
    # A contact reaching the border of the map: not a valid free-boundary result.
    done = run("simulate", "--topography", d / "h.npy", "--pixel-size", "100nm", "--modulus",
               "1GPa", "--model", "elastic", "--forces", "2mN", "--out", d / "w2", "-q")
    assert done.returncode == 4 and "border of the map" in done.stderr
    with pytest.warns(cs.ContactscopeWarning, match="border of the map"):
        cs.simulate(d / "h.npy", 1e-7, 1e9, [2e-3], maps=False)
