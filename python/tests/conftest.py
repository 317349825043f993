"""Shared fixtures: the release binary of the command line (to check the API against it) and
small seeded inputs written as TIFF files both sides read."""

import os
import pathlib
import shutil
import subprocess

import pytest

import contactscope as cs

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _binary():
    given = os.environ.get("CONTACTSCOPE_BIN")
    if given:
        return pathlib.Path(given)
    built = ROOT / "target" / "release" / "contactscope"
    if built.exists():
        return built
    found = shutil.which("contactscope")
    return pathlib.Path(found) if found else None


@pytest.fixture(scope="session")
def cli():
    """Run the command line; returns its stdout. Tests that compare with it are skipped when no
    binary is found, unless CONTACTSCOPE_REQUIRE_CLI=1 (CI), where that is a failure."""
    binary = _binary()
    if binary is None or not binary.exists():
        if os.environ.get("CONTACTSCOPE_REQUIRE_CLI") == "1":
            pytest.fail("the contactscope binary is needed: cargo build --release")
        pytest.skip("no contactscope binary (cargo build --release, or set CONTACTSCOPE_BIN)")

    def run(*args, cwd=None):
        done = subprocess.run([str(binary), *map(str, args)], cwd=cwd, capture_output=True,
                              text=True, timeout=300)
        # 4: the outputs are written but no load is valid (the small synthetic fields here cut
        # their contacts at the border); the comparisons with Python hold all the same.
        assert done.returncode in (0, 4), f"contactscope {' '.join(map(str, args))}: {done.stderr}"
        return done.stdout

    return run


FORCES = [2e-3, 4e-3, 8e-3]


@pytest.fixture(scope="session")
def series_tif(tmp_path_factory):
    """A seeded synthetic load series (160² px of 200 nm, 2/4/8 mN) as one TIFF, with its truth:
    a field wide enough that no contact is cut off by its border."""
    d = tmp_path_factory.mktemp("series")
    s = cs.synth_series(160, 160, 200e-9, FORCES, seed=11)
    path = d / "series.tif"
    cs.write_tiff(path, s.images, 200e-9)
    return path, s


@pytest.fixture(scope="session")
def surface_npy(tmp_path_factory, cli):
    """A self-affine height map written by the command line (.npy, metres)."""
    d = tmp_path_factory.mktemp("surface")
    path = d / "s.npy"
    cli("surface", "--size", 128, "--pixel-size", "100nm", "--rms-height", "50nm", "--seed", 3,
        "--out", path)
    return path


@pytest.fixture(scope="session")
def hardening_sim(tmp_path_factory, cli):
    """A `simulate` folder on the grid of `series_tif` (96² px of 200 nm, hardening k = 4
    MPa/nm, 2/4/8 mN), written by the command line: what `compare` tests compare with."""
    d = tmp_path_factory.mktemp("simulation")
    sim, topo = d / "sim", d / "t.npy"
    cli("surface", "--size", 96, "--pixel-size", "200nm", "--rms-height", "100nm", "--seed", 5,
        "--out", topo)
    cli("simulate", "--topography", topo, "--pixel-size", "200nm", "--radius", "290um",
        "--modulus", "2GPa", "--model", "hardening", "--hardening", "4MPa/nm",
        "--forces", "2,4,8mN", "--out", sim, "-q")
    return sim
