"""contact.engineering interoperability: surface containers written by SurfaceTopography read
with the same grid, physical size and heights; ours read back by SurfaceTopography; and
`simulate --export contact-engineering` beside ContactMechanics on the same problem.

SurfaceTopography and ContactMechanics are installed by scripts/test-all; the tests skip
without them. The AFM files are SurfaceTopography's own examples (``../shared/data/real-afm``,
skipped when absent); a generated surface is used besides them.
"""

import csv
import gzip
import io
import json
import os
import pathlib
import warnings
import zipfile

import numpy as np
import pytest

import contactscope as cs

st = pytest.importorskip("SurfaceTopography")
from SurfaceTopography import Topography, open_topography, read_container  # noqa: E402
from SurfaceTopography.Container.IO import write_containers  # noqa: E402
from SurfaceTopography.Container.SurfaceContainer import (  # noqa: E402
    InMemorySurfaceContainer,
)
from SurfaceTopography.Generation import fourier_synthesis  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
AFM = ROOT.parent / "shared" / "data" / "real-afm"
FIXTURES = ROOT / "fixtures" / "surface-topography"
AFM_FILES = ["di-3.di", "spot_1-1000nm.ibw", "mi-1.mi", "nid-1.nid", "top-1.top"]
UNIT_M = {"m": 1.0, "mm": 1e-3, "µm": 1e-6, "um": 1e-6, "nm": 1e-9, "Å": 1e-10, "pm": 1e-12}

# The orientations our (rows = y) arrays may have relative to SurfaceTopography's (x, y).
ORIENTATIONS = {
    "transpose": lambda a: a.T,
    "transpose, rows reversed": lambda a: a.T[::-1],
    "transpose, columns reversed": lambda a: a.T[:, ::-1],
    "transpose, both reversed": lambda a: a.T[::-1, ::-1],
}


def quiet(f, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return f(*args, **kwargs)


def afm(name):
    path = AFM / name
    if not path.exists():
        pytest.skip(f"{path} not found (the shared test data sits beside the checkout)")
    return path


def orientation_of(path):
    """How our reader lays out this file's heights relative to SurfaceTopography's: found on
    the file read directly (both sides, no processing), then used for its container copies."""
    ours = cs.read_topography(path, detrend="none")["heights"]
    t = quiet(lambda: open_topography(str(path)).topography())
    theirs = quiet(t.heights) * UNIT_M[t.unit]
    scale = np.abs(ours).max()
    for name, f in ORIENTATIONS.items():
        t = f(theirs)
        if t.shape == ours.shape and np.abs(t - ours).max() <= 1e-12 * scale:
            return f
    pytest.fail(f"{path.name}: no orientation maps SurfaceTopography's heights onto ours")


def assert_same_topography(ours, theirs, orient, label):
    """Same grid, physical size and heights (1e-9 relative to the largest height)."""
    h = ours["heights"]
    t = orient(quiet(theirs.heights))
    assert h.shape == t.shape, label
    unit = UNIT_M[theirs.unit]
    size = np.array(theirs.physical_sizes) * unit
    px = ours["summary"]["pixel_size_m"]
    ny, nx = h.shape
    mine = np.array([px["x"] * nx, px["y"] * ny])
    # Our x is SurfaceTopography's first axis for every orientation above.
    assert np.allclose(mine, size, rtol=1e-9), (label, mine, size)
    t = t * unit
    scale = np.abs(t).max()
    worst = np.nanmax(np.abs(h - t))
    assert worst <= 1e-9 * scale, f"{label}: heights differ by {worst:.3e} m of {scale:.3e} m"
    return worst / scale


def test_containers_written_by_surface_topography_read_alike(tmp_path):
    paths = [afm(f) for f in AFM_FILES]
    generated = fourier_synthesis((96, 64), (9.6, 6.4), 0.8, rms_height=0.05, unit="µm",
                                  rng=np.random.default_rng(3), periodic=True,
                                  info={"name": "generated"})
    topographies = [quiet(lambda p=p: open_topography(str(p)).topography()) for p in paths]
    container = tmp_path / "st.zip"
    quiet(write_containers, [InMemorySurfaceContainer(topographies + [generated])], container)
    theirs = list(quiet(read_container, str(container))[0])
    worst = 0.0
    for k, t in enumerate(theirs):
        # The container holds SurfaceTopography's arrays as NetCDF heights(x, y), whatever the
        # original file's line order: a plain transpose of ours.
        ours = cs.read_topography(container, detrend="none", measurement=str(k))
        worst = max(worst, assert_same_topography(ours, t, ORIENTATIONS["transpose"],
                                                  f"measurement {k}"))
    print(f"SurfaceTopography-written container: largest height difference {worst:.2e} (rel)")


def test_topobank_containers_with_originals_apply_the_processing_alike(tmp_path):
    """A container as contact.engineering downloads it: the original files with their
    processing in the metadata (detrending, height scale, filling of undefined data)."""
    paths = [afm(f) for f in AFM_FILES[:4]]
    orients = [orientation_of(p) for p in paths]
    # A map with undefined points, stored (NetCDF with a mask) as an original file.
    rng = np.random.default_rng(9)
    h = np.cumsum(rng.normal(size=(48, 40)), axis=0) * 1e-9 + 2e-9 * np.arange(40)
    mask = np.zeros(h.shape, bool)
    mask[10:14, 5:9] = True
    mask[30, 20] = True
    holes = Topography(np.ma.masked_array(h, mask), (4.8e-6, 4.0e-6), unit="m")
    holes_nc = tmp_path / "holes.nc"
    quiet(holes.to_netcdf, str(holes_nc))
    plans = [
        ("di-3.di", {"detrend_mode": "height"}),
        ("spot_1-1000nm.ibw", {"detrend_mode": "curvature", "height_scale": 2.0}),
        ("mi-1.mi", {"detrend_mode": "center"}),
        ("nid-1.nid", {"detrend_mode": "height", "height_scale": 0.5}),
        ("holes.nc", {"detrend_mode": "curvature", "fill_undefined_data_mode": "harmonic"}),
    ]
    metas = []
    container = tmp_path / "tb.zip"
    with zipfile.ZipFile(container, "w") as z:
        for name, extra in plans:
            source = holes_nc if name == "holes.nc" else AFM / name
            z.write(source, f"originals/{name}")
            metas.append({"name": name, "datafile": {"original": f"originals/{name}"},
                          "size": [1.0, 1.0], "unit": "um", "is_periodic": False,
                          "data_source": 0, **extra})
        z.writestr("index.json", json.dumps({"versions": {}, "surfaces": [
            {"name": "lab", "topographies": metas}]}))
    # The same metadata as meta.yml only (older downloads): absent keys mean no step there.
    yml = tmp_path / "yml"
    with zipfile.ZipFile(container) as z:
        z.extractall(yml)
    (yml / "index.json").unlink()
    import yaml

    (yml / "meta.yml").write_text(yaml.safe_dump({"surfaces": [
        {"name": "lab", "topographies": metas}]}))
    theirs = list(quiet(read_container, str(container))[0])
    orients = orients + [ORIENTATIONS["transpose"]]  # NetCDF: heights(x, y)
    worst = 0.0
    for k, t in enumerate(theirs):
        for source in (container, yml):
            ours = cs.read_topography(source, detrend="none", measurement=metas[k]["name"])
            worst = max(worst, assert_same_topography(ours, t, orients[k],
                                                      f"{source.name}: {metas[k]['name']}"))
    print(f"originals with their processing: largest height difference {worst:.2e} (rel)")
    # Filled and detrended: no undefined point is left.
    ours = cs.read_topography(container, detrend="none", measurement="lab/holes.nc")
    assert np.isfinite(ours["heights"]).all()


def test_data_source_names_surface_topography_s_channel(tmp_path):
    """``data_source: k`` is channel k of SurfaceTopography's reader for the original file:
    every channel of the multi-channel examples, one container each, read as
    ``read_container`` reads it (the same heights to 1e-9), or refused naming the channel
    where ours is not a height map (a phase, a deflection in volts)."""
    read, refused, by_place = 0, 0, 0
    # di-2 (SurfaceTopography's fixture): two channels named Height, then a deflection.
    di2 = tmp_path / "di-2.di"
    di2.write_bytes(gzip.decompress((FIXTURES / "di-2.di.gz").read_bytes()))
    paths = [afm(n) for n in ["di-3.di", "spot_1-1000nm.ibw", "mi-1.mi", "nid-1.nid"]] + [di2]
    for path in paths:
        name = path.name
        orient = orientation_of(path)
        channels = [c.name for c in quiet(lambda: open_topography(str(path)).channels)]
        assert len(channels) > 1, name
        for k, channel in enumerate(channels):
            container = tmp_path / f"{name}-{k}.zip"
            meta = {"name": name, "datafile": {"original": f"originals/{name}"},
                    "size": [1.0, 1.0], "unit": "um", "is_periodic": False,
                    "data_source": k, "detrend_mode": "center"}
            with zipfile.ZipFile(container, "w") as z:
                z.write(path, f"originals/{name}")
                z.writestr("index.json", json.dumps({"versions": {}, "surfaces": [
                    {"name": "lab", "topographies": [meta]}]}))
            label = f"{name} data_source {k} ({channel})"
            try:
                ours = cs.read_topography(container, detrend="none", measurement="0")
            except cs.InputError as e:
                # Refused by our reader: the message names the channel it was asked for.
                assert channel.split(" (")[0] in str(e) or channel in str(e), (label, str(e))
                refused += 1
                continue
            (theirs,) = list(quiet(read_container, str(container))[0])
            assert_same_topography(ours, theirs, orient, label)
            read += 1
            if not name.endswith(".nid"):
                # Where SurfaceTopography numbers every channel, ``channel=k`` is its channel k.
                direct = cs.read_topography(path, detrend="none", channel=k)
                assert direct["summary"]["channel"] == ours["summary"]["channel"], label
                np.testing.assert_allclose(direct["heights"] - direct["heights"].mean(),
                                           ours["heights"], rtol=0, err_msg=label,
                                           atol=1e-12 * np.abs(ours["heights"]).max())
                by_place += 1
    print(f"data_source: {read} channels read as SurfaceTopography reads them ({by_place} "
          f"also as channel=k), {refused} refused as not height maps")
    assert read >= 10 and by_place >= 6, (read, by_place)


def test_a_container_downloaded_from_contact_engineering_reads_as_read_container(tmp_path):
    """SurfaceTopography's own `container-2.zip` (its test/file_format_examples, CC-BY-4.0
    data, 1.1 MB: not committed; run when CONTACTSCOPE_ST_EXAMPLES names that folder): a
    download of topobank 0.13 (`meta.yml` with `!!python/tuple` sizes), a Bruker AFM map with
    `height_scale` 0.112 and `detrend_mode: height` read with SurfaceTopography's grid, size and
    heights; its two line scans refused as line scans, naming the measurement's file."""
    folder = os.environ.get("CONTACTSCOPE_ST_EXAMPLES")
    if not folder:
        pytest.skip("set CONTACTSCOPE_ST_EXAMPLES to SurfaceTopography's test/file_format_examples")
    container = pathlib.Path(folder) / "container-2.zip"
    theirs = list(quiet(read_container, str(container))[0])
    maps = 0
    for k, t in enumerate(theirs):
        original = t.info["datafile"]["original"]
        if t.dim == 1:
            with pytest.raises(cs.InputError, match="line scan") as e:
                cs.read_topography(container, detrend="none", measurement=str(k))
            assert original in str(e.value)
            continue
        raw = tmp_path / original
        with zipfile.ZipFile(container) as z:
            raw.write_bytes(z.read(original))
        ours = cs.read_topography(container, detrend="none", measurement=str(k))
        assert_same_topography(ours, t, orientation_of(raw), original)
        maps += 1
    assert maps == 1 and len(theirs) == 3


def test_the_median_detrend_is_surface_topography_s(tmp_path):
    """``detrend_mode: median`` subtracts the height at which the bearing area of the
    piecewise-linear surface is one half (SurfaceTopography's median, found by bisection to
    1e-6 of the height range): a rough map, a periodic one and one with undefined points left
    undefined, each stored as an original NetCDF file (heights(x, y), the triangulation
    SurfaceTopography uses for them). The results differ by a constant, the two medians'
    difference, which must lie within the bisection's tolerance: 1e-6 of the height range."""
    rng = np.random.default_rng(21)
    rough = Topography(np.cumsum(rng.normal(size=(64, 48)), axis=0) * 1e-9
                       + np.cumsum(rng.normal(size=(64, 48)), axis=1) * 0.5e-9,
                       (6.4e-6, 4.8e-6), unit="m")
    periodic = fourier_synthesis((80, 56), (8e-6, 5.6e-6), 0.8, rms_height=20e-9, unit="m",
                                 rng=np.random.default_rng(4), periodic=True)
    h = np.cumsum(rng.normal(size=(40, 36)), axis=1) * 2e-9
    mask = np.zeros(h.shape, bool)
    mask[5:9, 10:20] = True
    mask[33, 2] = True
    holes = Topography(np.ma.masked_array(h, mask), (4e-6, 3.6e-6), unit="m")
    plans = [("rough.nc", rough, False, [6.4, 4.8]), ("periodic.nc", periodic, True, [8.0, 5.6]),
             ("holes.nc", holes, False, [4.0, 3.6])]
    metas = []
    container = tmp_path / "median.zip"
    with zipfile.ZipFile(container, "w") as z:
        for name, topography, is_periodic, size_um in plans:
            path = tmp_path / name
            quiet(topography.to_netcdf, str(path))
            z.write(path, f"originals/{name}")
            metas.append({"name": name, "datafile": {"original": f"originals/{name}"},
                          "size": size_um, "unit": "um", "is_periodic": is_periodic,
                          "data_source": 0, "detrend_mode": "median",
                          "fill_undefined_data_mode": "do-not-fill"})
        z.writestr("index.json", json.dumps({"versions": {}, "surfaces": [
            {"name": "lab", "topographies": metas}]}))
    theirs = list(quiet(read_container, str(container))[0])
    for meta, t in zip(metas, theirs):
        # The undefined points stay undefined through the detrending; filled afterwards (the
        # Python API refuses a map with holes), they are left out of the comparison.
        ours = cs.read_topography(container, detrend="none", measurement=meta["name"],
                                  fill_invalid="nearest")
        h = ours["heights"]
        ref = np.ma.filled(np.ma.masked_invalid(quiet(t.heights)), np.nan).T * UNIT_M[t.unit]
        assert h.shape == ref.shape, meta["name"]
        valid = ~np.isnan(ref)
        assert valid.sum() < ref.size or meta["name"] != "holes.nc"
        span = np.nanmax(ref) - np.nanmin(ref)
        offset = h[valid] - ref[valid]
        # One constant apart (the heights themselves agree to rounding) ...
        assert np.ptp(offset) <= 1e-12 * span, (meta["name"], np.ptp(offset))
        # ... and that constant within the bisection's tolerance.
        assert abs(offset.mean()) <= 1e-6 * span, (meta["name"], offset.mean() / span)
        print(f"median {meta['name']}: medians differ by {abs(offset.mean()) / span:.1e} of "
              "the height range")
        # Not the median of the points (that would be another constant).
        assert abs(np.median(h[valid])) > 1e-6 * span, meta["name"]


def test_our_containers_read_back_in_surface_topography(cli, tmp_path):
    out = tmp_path / "gen.zip"
    cli("surface", "--size", 64, "--pixel-size", "50nm", "--rms-height", "20nm", "--seed", 4,
        "--out", out)
    npy = tmp_path / "gen.npy"
    cli("surface", "--size", 64, "--pixel-size", "50nm", "--rms-height", "20nm", "--seed", 4,
        "--out", npy)
    # meta.yml says what index.json says, to a YAML 1.1 reader too (PyYAML takes `1e-6` for a
    # string: 64 pixels of 15.625 nm are exactly 1e-6 m).
    import yaml

    exact = tmp_path / "exact.zip"
    cli("surface", "--size", 64, "--pixel-size", "15.625nm", "--rms-height", "1nm", "--out",
        exact)
    with zipfile.ZipFile(exact) as z:
        index = json.loads(z.read("index.json"))
        # (A YAML 1.1 reader takes the unquoted measurement_date for a date: as a string it
        # is the same, and SurfaceTopography's schema takes either.)
        assert json.loads(json.dumps(yaml.safe_load(z.read("meta.yml")), default=str)) == index
    assert index["surfaces"][0]["topographies"][0]["size"] == [1e-6, 1e-6]
    # Our generated surface in a container SurfaceTopography writes: the same heights here.
    ours = np.load(npy)
    theirs = Topography(ours.T.copy(), (64 * 50e-9, 64 * 50e-9), unit="m", periodic=True,
                        info={"name": "ours"})
    st_zip = tmp_path / "st-of-ours.zip"
    quiet(write_containers, [InMemorySurfaceContainer([theirs])], st_zip)
    back = cs.read_topography(st_zip, detrend="none", measurement="0")
    assert np.array_equal(back["heights"], ours)
    assert np.allclose(back["summary"]["pixel_size_m"]["x"], 50e-9, rtol=1e-12)
    (t,) = list(quiet(read_container, str(out))[0])
    assert t.is_periodic and t.unit == "m"
    assert np.allclose(t.physical_sizes, (64 * 50e-9, 64 * 50e-9), rtol=1e-12)
    assert np.array_equal(t.heights().T, np.load(npy))
    # Deformed surfaces of a plastic run, one topography per load and map.
    cli("simulate", "--topography", npy, "--pixel-size", "50nm", "--modulus", "10GPa",
        "--model", "hardness", "--hardness", "300MPa", "--forces", "0.02mN,0.05mN",
        "--periodic", "--maps", "all", "--export", "surface-container", "--out", tmp_path / "sim")
    deformed = list(quiet(read_container, str(tmp_path / "sim" / "deformed_surfaces.zip"))[0])
    names = [d.info["name"] for d in deformed]
    assert names == ["load_001 deformed", "load_001 plastic", "load_002 deformed",
                     "load_002 plastic"]
    import tifffile

    plastic_um = tifffile.imread(tmp_path / "sim" / "load_002_plastic_um.tif")
    assert np.abs(deformed[3].heights().T * 1e6 - plastic_um).max() < 1e-6 * plastic_um.max()
    assert deformed[3].heights().max() > 0, "the hardness model left plastic flow"
    # And they read back here the same.
    ours = cs.read_topography(tmp_path / "sim" / "deformed_surfaces.zip", detrend="none",
                              measurement="load_002 plastic")
    assert np.array_equal(ours["heights"], deformed[3].heights().T)


# ---- contact mechanics beside ContactMechanics ------------------------------------------

PRESSURES = [0.002, 0.01, 0.05]  # p/E*


def contact_mechanics_plot(t, kind):
    """The contact.engineering calculation with explicit pressures (topobank-contact's
    `_contact_at_given_load`): E* = 1, Polonsky–Keer, pentol from the rms height; the rows and
    maps its download holds."""
    cm = pytest.importorskip("ContactMechanics")
    from ContactMechanics.Systems import NonSmoothContactSystem

    half_space = (cm.PeriodicFFTElasticHalfSpace if kind == "periodic"
                  else cm.FreeFFTElasticHalfSpace)(t.nb_grid_pts, 1.0, t.physical_sizes)
    system = NonSmoothContactSystem(half_space, t)
    a0 = np.prod(t.physical_sizes)
    rms = t.rms_height_from_area()
    pentol = max(rms / (10 * np.mean(t.nb_grid_pts)), 1e-12)
    nx, ny = t.nb_grid_pts
    rows = []
    for p in PRESSURES:
        opt = quiet(system.minimize_proxy, external_force=p * a0, pentol=pentol, maxiter=1000)
        force = opt.jac[:nx, :ny]
        displacement = opt.x[:nx, :ny]
        rows.append({
            "pressure": force.sum() / a0,
            "fraction": (force > 0).sum() / (nx * ny),
            "gap": (displacement.mean() - t.heights().mean() - opt.offset) / rms,
            "converged": bool(opt.success),
            "contact": force > 0,
        })
    return rows


def read_export(zip_path, name):
    with zipfile.ZipFile(zip_path) as z:
        names = z.namelist()
        table = z.read(f"{name}/plot.csv").decode()
        info = z.read(f"{name}/info.txt").decode()
        import scipy.io

        steps = {}
        for n in names:
            if n.endswith(".nc"):
                f = scipy.io.netcdf_file(io.BytesIO(z.read(n)), "r", mmap=False)
                steps[n.split("/")[-1]] = f
    return names, table, info, steps


def test_contact_engineering_export_matches_contact_mechanics(cli, tmp_path):
    t = fourier_synthesis((128, 128), (12.8e-6, 12.8e-6), 0.8, rms_height=50e-9,
                          short_cutoff=800e-9, rng=np.random.default_rng(5), periodic=True,
                          unit="m")
    periodic = Topography(t.heights(), t.physical_sizes, periodic=True, unit="m",
                          info={"name": "periodic"})
    free = Topography(t.heights(), t.physical_sizes, periodic=False, unit="m",
                      info={"name": "free"})
    container = tmp_path / "cm.zip"
    quiet(write_containers, [InMemorySurfaceContainer([periodic, free])], container)
    a0 = np.prod(t.physical_sizes)
    modulus = 1e9  # any E*: the normalised results do not depend on it
    forces = ",".join(f"{float(p * a0 * modulus)!r}N" for p in PRESSURES)
    report = []
    for name, kind in [("periodic", "periodic"), ("free", "nonperiodic")]:
        out = tmp_path / f"sim-{name}"
        cli("simulate", "--topography", container, "--measurement", name, "--detrend", "none",
            "--modulus", "1GPa", "--model", "elastic", "--forces", forces, "--maps", "none",
            "--export", "contact-engineering", "--out", out)
        names, table, info, steps = read_export(out / "contact_mechanics.zip", name)
        assert names[0] == "README.txt" and f"{name}/plot.csv" in names
        lines = table.splitlines()
        assert lines[0] == (",Normalized pressure p/E*,Fractional contact area A/A0,"
                            "Normalized mean gap u/h_rms,converged,filename")
        rows = list(csv.reader(lines[1:]))
        assert [r[0] for r in rows] == ["0", "1", "2"]
        assert all(r[4] == "True" for r in rows)
        assert "Input SHA-256" in info and info.startswith("# topography: ")
        theirs = contact_mechanics_plot(t, kind)
        for row, ref in zip(rows, theirs):
            pressure, fraction, gap = map(float, row[1:4])
            nc = steps[row[5]]
            # The file's variables and attributes, as contact.engineering's.
            assert set(nc.variables) == {"pressure", "contacting_points", "gap", "displacement"}
            for v in nc.variables.values():
                assert v.dimensions == ("x", "y") and v.data.shape == (128, 128)
            assert nc.variables["contacting_points"].data.dtype == np.int8
            attrs = nc._attributes
            assert attrs["type"].decode() == kind
            assert np.isclose(attrs["mean_pressure"], pressure, rtol=1e-12)
            assert np.isclose(attrs["total_contact_area"], fraction, rtol=1e-12)
            contact = nc.variables["contacting_points"].data.astype(bool)
            assert contact.mean() == fraction
            assert np.isclose(nc.variables["pressure"].data.mean(), pressure, rtol=1e-6)
            # Beside ContactMechanics: the same pressure, contact area and mean gap.
            differing = int((contact != ref["contact"]).sum())
            report.append((kind, ref["pressure"], fraction, ref["fraction"], gap, ref["gap"],
                           differing))
            assert np.isclose(pressure, ref["pressure"], rtol=1e-6)
            assert abs(fraction - ref["fraction"]) <= 5e-4, (kind, fraction, ref["fraction"])
            assert differing <= 10, (kind, differing)
            assert abs(gap - ref["gap"]) <= 1e-3 * max(ref["gap"], 0.01), (kind, gap, ref["gap"])
    print("\nboundary  p/E*  A/A0 ours  A/A0 ContactMechanics  u/h_rms ours  u/h_rms CM  "
          "pixels differing")
    for r in report:
        print("  ".join(f"{v:.8g}" if isinstance(v, float) else str(v) for v in r))


def test_container_choices_and_refusals(cli, tmp_path):
    t = fourier_synthesis((32, 32), (3.2e-6, 3.2e-6), 0.8, rms_height=10e-9, unit="m",
                          rng=np.random.default_rng(1))
    container = tmp_path / "two.zip"
    quiet(write_containers, [InMemorySurfaceContainer([t, t])], container)
    with pytest.raises(cs.InputError, match="2 measurements.*measurement="):
        cs.read_topography(container)
    with pytest.raises(cs.InputError, match="no measurement 5"):
        cs.read_topography(container, measurement="5")
    # An index as an int chooses as its digits do; other types are refused naming the keyword.
    np.testing.assert_array_equal(cs.read_topography(container, measurement=1)["heights"],
                                  cs.read_topography(container, measurement="1")["heights"])
    with pytest.raises(cs.InputError, match="no measurement 5"):
        cs.read_topography(container, measurement=np.int64(5))
    with pytest.raises(TypeError, match="measurement=.*index"):
        cs.read_topography(container, measurement=1.0)
    with pytest.raises(cs.InputError, match="not a contact.engineering surface container"):
        cs.read_topography(afm("mi-1.mi"), measurement="0")
    whole = json.loads(cli("topography", container, "--detrend", "none", "--json"))
    assert [m["index"] for m in whole["measurements"]] == [0, 1]
    one = whole["measurements"][0]["detrended"]["h_rms_nm"]
    assert np.isclose(whole["combined"]["h_rms_nm"], one, rtol=1e-12)
    assert np.isclose(one * 1e-9, quiet(t.rms_height_from_area), rtol=1e-9)


def test_mad_detrends_are_refused_because_surface_topography_s_depend_on_the_unit(tmp_path):
    """``mad-tilt`` is refused, and this is why: SurfaceTopography's Nelder–Mead tolerances
    are absolute in the height unit, so one map stored in m keeps its least-squares tilt and
    in nm gets another (docs/formats.md). Should SurfaceTopography's result stop depending on
    the unit, this test fails and the mode can be applied."""
    rng = np.random.default_rng(21)
    h = (np.cumsum(rng.normal(size=(64, 48)), axis=0) * 1e-9
         + np.cumsum(rng.normal(size=(64, 48)), axis=1) * 0.5e-9 + 3e-9 * np.arange(48))
    detrended = {}
    for unit, scale in (("m", 1.0), ("nm", 1e9)):
        t = Topography(h * scale, (6.4e-6 * scale, 4.8e-6 * scale), unit=unit)
        detrended[unit] = quiet(t.detrend("mad-tilt").heights) / scale
    span = np.ptp(detrended["m"])
    moved = np.ptp(detrended["m"] - detrended["nm"]) / span
    assert moved > 1e-3, moved
    print(f"SurfaceTopography mad-tilt, m against nm: {moved:.1e} of the height range")
    t = Topography(h, (6.4e-6, 4.8e-6), unit="m")
    container = tmp_path / "mad.zip"
    quiet(t.to_netcdf, str(tmp_path / "mad.nc"))
    with zipfile.ZipFile(container, "w") as z:
        z.write(tmp_path / "mad.nc", "originals/mad.nc")
        z.writestr("index.json", json.dumps({"versions": {}, "surfaces": [{"name": "lab",
                   "topographies": [{"name": "mad.nc", "datafile": {"original": "originals/mad.nc"},
                                     "size": [6.4, 4.8], "unit": "um", "is_periodic": False,
                                     "data_source": 0, "detrend_mode": "mad-tilt"}]}]}))
    with pytest.raises(cs.InputError, match="mad-tilt.*height unit.*'height'"):
        cs.read_topography(container, detrend="none", measurement="0")


def test_python_writes_the_same_export_as_the_command_line(cli, tmp_path):
    t = fourier_synthesis((48, 48), (4.8e-6, 4.8e-6), 0.8, rms_height=30e-9,
                          rng=np.random.default_rng(7), periodic=True, unit="m",
                          info={"name": "twin"})
    container = tmp_path / "twin.zip"
    quiet(write_containers, [InMemorySurfaceContainer([t])], container)
    forces = [1e-5, 4e-5]
    cli("simulate", "--topography", container, "--detrend", "none", "--modulus", "2GPa",
        "--model", "hardness", "--hardness", "100MPa", "--forces", "0.01mN,0.04mN", "--maps",
        "none", "--export", "contact-engineering", "--out", tmp_path / "cli")
    out = tmp_path / "py.zip"
    result = quiet(cs.simulate, container, None, 2e9, forces, "hardness", hardness=1e8,
                   detrend="none", maps="none", measurement="0", contact_engineering=out)
    assert result["boundary"].startswith("periodic"), "the container marks it periodic"
    with zipfile.ZipFile(out) as a, zipfile.ZipFile(tmp_path / "cli" / "contact_mechanics.zip") as b:
        assert a.namelist() == b.namelist()
        assert a.read("twin/plot.csv") == b.read("twin/plot.csv")
        import scipy.io

        nc = scipy.io.netcdf_file(io.BytesIO(a.read("twin/result-step-1.nc")), "r", mmap=False)
        assert np.isclose(nc._attributes["hardness"], 1e8 / 2e9)
        assert nc.variables["pressure"].data.max() <= 1e8 / 2e9 * (1 + 1e-9)
    with pytest.raises(cs.InputError, match="Greenwood"):
        quiet(cs.simulate, container, None, 2e9, forces, "gt", radius=290e-6, detrend="none",
              contact_engineering=tmp_path / "gt.zip")
    assert not (tmp_path / "gt.zip").exists()


def test_the_export_has_the_layout_topobank_contact_writes(cli, tmp_path):
    """The reference: the files written the way topobank-contact's worker and download write
    them (an xarray Dataset of the four fields with its attributes, `to_netcdf` in
    NETCDF3_64BIT; the plot table through pandas' `to_csv`) from ContactMechanics' results on
    the same topography; ours must have the same columns, variables, dimensions, types and
    attributes (`_FillValue` aside: every value of ours is defined)."""
    xr = pytest.importorskip("xarray")
    pd = pytest.importorskip("pandas")
    import scipy.io

    t = fourier_synthesis((64, 64), (6.4e-6, 6.4e-6), 0.8, rms_height=40e-9,
                          rng=np.random.default_rng(2), periodic=True, unit="m",
                          info={"name": "ref"})
    container = tmp_path / "ref.zip"
    quiet(write_containers, [InMemorySurfaceContainer([t])], container)
    rows = contact_mechanics_plot(t, "periodic")
    reference = tmp_path / "reference"
    reference.mkdir()
    nx, ny = t.nb_grid_pts
    for k, r in enumerate(rows):
        field = np.zeros((nx, ny))
        ds = xr.Dataset({"pressure": (("x", "y"), field),
                         "contacting_points": (("x", "y"), r["contact"]),
                         "gap": (("x", "y"), field),
                         "displacement": (("x", "y"), field)})
        ds.attrs["mean_pressure"] = r["pressure"]
        ds.attrs["total_contact_area"] = r["fraction"]
        ds.attrs["type"] = "periodic"
        ds.to_netcdf(reference / f"result-step-{k}.nc", format="NETCDF3_64BIT")
    table = pd.DataFrame({
        "Normalized pressure p/E*": [r["pressure"] for r in rows],
        "Fractional contact area A/A0": [r["fraction"] for r in rows],
        "Normalized mean gap u/h_rms": [r["gap"] for r in rows],
        "converged": [r["converged"] for r in rows],
        "filename": [f"result-step-{k}.nc" for k in range(len(rows))],
    }).to_csv()
    a0 = np.prod(t.physical_sizes)
    forces = ",".join(f"{float(p * a0 * 1e9)!r}N" for p in PRESSURES)
    cli("simulate", "--topography", container, "--detrend", "none", "--modulus", "1GPa",
        "--model", "elastic", "--forces", forces, "--maps", "none", "--export",
        "contact-engineering", "--out", tmp_path / "ours")
    names, ours_table, _, steps = read_export(tmp_path / "ours" / "contact_mechanics.zip", "ref")
    assert ours_table.splitlines()[0] == table.splitlines()[0]
    theirs_df = pd.read_csv(io.StringIO(table), index_col=0)
    ours_df = pd.read_csv(io.StringIO(ours_table), index_col=0)
    assert list(ours_df.columns) == list(theirs_df.columns)
    assert list(ours_df.dtypes) == list(theirs_df.dtypes)
    for k in range(len(rows)):
        ref = scipy.io.netcdf_file(reference / f"result-step-{k}.nc", "r", mmap=False)
        ours = steps[f"result-step-{k}.nc"]
        assert ref.version_byte == ours.version_byte == 2
        assert set(ours.variables) == set(ref.variables)
        assert set(ref._attributes) <= set(ours._attributes)
        for name, v in ref.variables.items():
            mine = ours.variables[name]
            assert mine.dimensions == v.dimensions, name
            assert mine.data.dtype.kind == v.data.dtype.kind, name
            assert mine.data.dtype.itemsize == v.data.dtype.itemsize, name
            wanted = {a for a in v._attributes if a != "_FillValue"}
            assert wanted <= set(mine._attributes), (name, wanted, mine._attributes)
            for a in wanted:
                assert mine._attributes[a] == v._attributes[a], (name, a)
