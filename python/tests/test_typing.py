"""The package ships `py.typed`: a lab's script that calls it is type-checked against our stubs
and annotations. Three checks with mypy (installed by scripts/test-all; skipped with a message
elsewhere unless CONTACTSCOPE_REQUIRE_MYPY is set):

* the installed package type-checks (its Python modules against the extension's stubs);
* `stubtest` finds the extension's stubs equal to what it exports (names, parameters, defaults),
  apart from the names that exist only in the stubs (the results' TypedDicts, listed in
  `stubtest-allowlist.txt`);
* a script written as the README's examples are type-checks, and a script with a wrong call
  does not (the check can fail)."""

import os
import pathlib
import subprocess
import sys
import textwrap

import pytest

HERE = pathlib.Path(__file__).resolve().parent
ALLOWLIST = HERE / "stubtest-allowlist.txt"


def _mypy_or_skip():
    try:
        import mypy  # noqa: F401
    except ImportError:
        if os.environ.get("CONTACTSCOPE_REQUIRE_MYPY"):
            pytest.fail("CONTACTSCOPE_REQUIRE_MYPY is set but mypy is not installed")
        pytest.skip("mypy is not installed (scripts/test-all installs it)")


def _run(args, cwd):
    return subprocess.run([sys.executable, "-m", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=600)


def _mypy(tmp_path, *targets):
    return _run(["mypy", "--cache-dir", str(tmp_path / "cache"), "--ignore-missing-imports",
                 "--no-error-summary", *targets], tmp_path)


def test_the_installed_package_type_checks(tmp_path):
    _mypy_or_skip()
    r = _mypy(tmp_path, "-p", "contactscope")
    assert r.returncode == 0, r.stdout + r.stderr


def test_the_stubs_are_what_the_extension_exports(tmp_path):
    _mypy_or_skip()
    r = _run(["mypy.stubtest", "contactscope._contactscope", "--allowlist", str(ALLOWLIST),
              "--mypy-config-file", os.devnull], tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr


SCRIPT = """
    from typing import List

    import numpy as np

    import contactscope as cs

    forces: List[float] = [4e-3, 8e-3, 16e-3]
    s = cs.synth_series(64, 64, 200e-9, forces, seed=1)
    cs.write_tiff("s.tif", s.images, 200e-9)
    series = cs.read_series(["s.tif"], forces=forces)
    result = cs.analyze(series, out=None)
    threshold: float = cs.otsu_threshold(series)
    names: List[str] = ["s.tif"]
    acf = cs.autocorrelation(names, pixel_size=200e-9)
    heights = cs.surface(64, 64, 1e-7, rms_height=5e-8, seed=2)
    sim = cs.simulate(heights, 1e-7, 1e9, [2e-5, 4e-5], "elastic", radius=2e-5, maps="contact")
    area: float = sim["loads"][0]["area_m2"]
    t = cs.read_topography("h.npy", pixel_size=1e-7, channel=0, measurement=None)
    """


def test_a_script_calling_the_package_type_checks_and_a_wrong_call_does_not(tmp_path):
    _mypy_or_skip()
    good = tmp_path / "good.py"
    good.write_text(textwrap.dedent(SCRIPT), encoding="utf-8")
    r = _mypy(tmp_path, str(good))
    assert r.returncode == 0, r.stdout + r.stderr
    bad = tmp_path / "bad.py"
    lines = len(textwrap.dedent(SCRIPT).splitlines())
    # A load that is not a list of loads, and a pixel size as text.
    bad.write_text(textwrap.dedent(SCRIPT) + "cs.simulate(heights, 1e-7, 1e9, 4e-5)\n"
                   "cs.synth_series(64, 64, '200nm', forces)\n", encoding="utf-8")
    r = _mypy(tmp_path, str(bad))
    assert r.returncode != 0
    out = r.stdout
    assert f"bad.py:{lines + 1}: error" in out and f"bad.py:{lines + 2}: error" in out, out
