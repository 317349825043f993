"""Every Python entry point that takes heights or a pixel size checks them as the command line
does (a scan in nanometres given as metres once gave a 1-pixel contact at 650 GPa and
no warning). The table below must name every such function and keyword: a new one fails
``test_every_entry_point_is_in_the_table`` until it is added here."""

import inspect

import numpy as np
import pytest

import contactscope as cs
import contactscope.distributed as dist

PIXEL_KEYWORDS = ("pixel_size", "imaging_pixel_size", "map_pixel_size", "image_pixel_size")
HEIGHT_KEYWORDS = ("heights",)

NM_AS_METRES = 200.0  # "200" meant as 200 nm
RNG = np.random.default_rng(5)
HEIGHTS_NM = RNG.normal(0.0, 40.0, (64, 64))  # a scan in nanometres, given as metres
HEIGHTS = HEIGHTS_NM * 1e-9
STACK = RNG.integers(0, 4095, (3, 64, 64)).astype(np.uint16)
FORCES = [4e-3, 10e-3, 25e-3]
AREAS = [1e-11, 2e-11, 4e-11]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("plausibility")
    tif = folder / "stack.tif"
    cs.write_tiff(tif, STACK, 2e-7)
    npy = folder / "scan.npy"
    np.save(npy, HEIGHTS)
    return {"tif": tif, "npy": npy}


def calls(files):
    """(function, keyword) → a call with that keyword's value `v`, every other argument valid."""
    newton = cs.synth_newton(width=64, height=64)
    return {
        (cs.analyze, "pixel_size"): lambda v: cs.analyze(STACK, FORCES, v),
        (cs.autocorrelation, "pixel_size"): lambda v: cs.autocorrelation(STACK, v),
        (cs.blur_and_resample, "pixel_size"): lambda v: cs.blur_and_resample(
            STACK[0] > 2000, v, 450e-9, 2e-7),
        (cs.blur_and_resample, "image_pixel_size"): lambda v: cs.blur_and_resample(
            STACK[0] > 2000, 2e-7, 450e-9, v),
        (cs.compare, "pixel_size"): lambda v: cs.compare(
            STACK, FORCES, v, STACK > 2000, FORCES, 2e-7),
        (cs.compare, "map_pixel_size"): lambda v: cs.compare(
            STACK, FORCES, 2e-7, STACK > 2000, FORCES, v),
        (cs.fit_hardening, "heights"): lambda v: cs.fit_hardening(FORCES, AREAS, v, 78e-9, 3.7e9),
        (cs.fit_hardening, "pixel_size"): lambda v: cs.fit_hardening(
            FORCES, AREAS, HEIGHTS, v, 3.7e9),
        (cs.fit_hardening, "imaging_pixel_size"): lambda v: cs.fit_hardening(
            FORCES, AREAS, HEIGHTS, 78e-9, 3.7e9, imaging_fwhm=450e-9, imaging_pixel_size=v),
        (cs.measure, "pixel_size"): lambda v: cs.measure(STACK[0], 2000, v),
        (cs.newton, "pixel_size"): lambda v: cs.newton(
            newton["reflection"], newton["fluorescence"], v),
        (cs.psf, "pixel_size"): lambda v: cs.psf(cs.synth_beads(), v),
        (cs.ramp, "heights"): lambda v: cs.ramp(v, 78e-9, 3.7e9, "elastic", None, [1e-3]),
        (cs.ramp, "pixel_size"): lambda v: cs.ramp(HEIGHTS, v, 3.7e9, "elastic", None, [1e-3]),
        (cs.ramp, "imaging_pixel_size"): lambda v: cs.ramp(
            HEIGHTS, 78e-9, 3.7e9, "elastic", None, [1e-3], imaging_fwhm=450e-9,
            imaging_pixel_size=v),
        (cs.read_image, "pixel_size"): lambda v: cs.read_image(files["tif"], pixel_size=v),
        (cs.read_series, "pixel_size"): lambda v: cs.read_series(
            [files["tif"]], FORCES, pixel_size=v),
        (cs.read_topography, "pixel_size"): lambda v: cs.read_topography(files["npy"], v),
        (cs.simulate, "heights"): lambda v: cs.simulate(v, 78e-9, 3.7e9, [1e-3]),
        (cs.simulate, "pixel_size"): lambda v: cs.simulate(HEIGHTS, v, 3.7e9, [1e-3]),
        (cs.surface, "pixel_size"): lambda v: cs.surface(64, 64, v, rms_height=1e-6),
        (cs.surface_with_stats, "pixel_size"): lambda v: cs.surface_with_stats(
            64, 64, v, rms_height=1e-6),
        (cs.synth_newton, "pixel_size"): lambda v: cs.synth_newton(64, 64, v),
        (cs.synth_series, "pixel_size"): lambda v: cs.synth_series(128, 128, v),
        (cs.write_tiff, "pixel_size"): lambda v: cs.write_tiff(
            files["tif"].with_name("out.tif"), STACK, v),
        (dist.fit_hardening, "heights"): lambda v: dist.fit_hardening(
            FORCES, AREAS, v, 78e-9, 3.7e9),
        (dist.fit_hardening, "pixel_size"): lambda v: dist.fit_hardening(
            FORCES, AREAS, HEIGHTS, v, 3.7e9),
        (dist.fit_hardening, "imaging_pixel_size"): lambda v: dist.fit_hardening(
            FORCES, AREAS, HEIGHTS, 78e-9, 3.7e9, imaging_fwhm=450e-9, imaging_pixel_size=v),
        (dist.sweep, "heights"): lambda v: dist.sweep([1e-3], 78e-9, 3.7e9, heights=v),
        (dist.sweep, "pixel_size"): lambda v: dist.sweep([1e-3], v, 3.7e9, heights=HEIGHTS),
        (dist.sweep, "imaging_pixel_size"): lambda v: dist.sweep(
            [1e-3], 78e-9, 3.7e9, heights=HEIGHTS, imaging_fwhm=450e-9, imaging_pixel_size=v),
    }


def entry_points():
    found = set()
    for module in (cs, dist):
        for name in getattr(module, "__all__", dir(module)):
            f = getattr(module, name, None)
            if inspect.isfunction(f) and f.__module__.startswith("contactscope"):
                for keyword in inspect.signature(f).parameters:
                    if keyword in PIXEL_KEYWORDS + HEIGHT_KEYWORDS:
                        found.add((f, keyword))
    return found


def test_every_entry_point_is_in_the_table(files):
    table = set(calls(files))
    missing = {f"{f.__module__}.{f.__name__}({k}=)" for f, k in entry_points() - table}
    assert not missing, f"entry points without a plausibility case: {sorted(missing)}"


def refusal(call, value):
    """The message of the InputError `call(value)` raises, or of the row a sweep fails with."""
    try:
        result = call(value)
    except cs.InputError as e:
        return str(e)
    rows = result.get("rows", []) if isinstance(result, dict) else []
    errors = [r.get("error") for r in rows if isinstance(r, dict) and r.get("error")]
    assert errors, f"no error for {value!r}: {result!r:.200}"
    return errors[0]


def cases(keywords):
    return pytest.mark.parametrize(
        "case",
        sorted((f.__module__, f.__name__, k) for f, k in entry_points() if k in keywords),
        ids=lambda case: f"{case[1]}-{case[2]}-{case[0].split('.')[-1]}")


def refusal_of(files, case, value):
    module, name, keyword = case
    f = getattr(cs if module == "contactscope" else dist, name)
    return refusal(calls(files)[(f, keyword)], value)


@cases(PIXEL_KEYWORDS)
def test_a_pixel_size_in_nanometres_given_as_metres_is_refused(files, case):
    message = refusal_of(files, case, NM_AS_METRES)
    assert "plausible range" in message and "nm" in message, message


@cases(HEIGHT_KEYWORDS)
def test_heights_in_nanometres_given_as_metres_are_refused(files, case):
    message = refusal_of(files, case, HEIGHTS_NM)
    assert "heights=" in message and "beyond ±1 m" in message, message
