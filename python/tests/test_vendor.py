"""Vendor files through the Python readers (issue 14: "the Python reader once it exists"): the
real CZI and AFM samples beside the checkout (``../shared/data``; skipped when absent), checked
against the command line's ``info --json --stats`` and ``topography --json`` on the same files."""

import json

import numpy as np
import pytest

import contactscope as cs
from conftest import ROOT

REAL = ROOT.parent / "shared" / "data" / "real-formats"


def sample(relative):
    path = REAL / relative
    if not path.exists():
        pytest.skip(f"{path} not found (the shared test data sits beside the checkout)")
    return path


def test_czi_planes_along_t_match_cli_stats(cli):
    czi = sample("czi/CellDivision_T3_Z5_CH2_X240_Y170.czi")
    r = cs.read_image(czi, channel=1, z=2, load_axis="t")
    assert r.images.shape == (3, 170, 240)
    info = json.loads(cli("info", czi, "--json", "--stats"))
    planes = [p for p in info["series"][0]["planes"] if p["z"] == 2 and p["c"] == 1]
    assert [p["t"] for p in planes] == [0, 1, 2]
    for image, p in zip(r.images, planes):
        assert (image.min(), image.max(), image.sum()) == (p["min"], p["max"], p["sum"])
    px = info["series"][0]["pixel_size_um"]
    assert r.pixel_size_m == pytest.approx((px["x"] * 1e-6, px["y"] * 1e-6), rel=1e-12)
    # One plane by its selection equals the same plane of the load axis.
    one = cs.read_image(czi, channel=1, z=2, t=1).images
    np.testing.assert_array_equal(one[0], r.images[1])
    # The same file as a load series: integer samples kept, one image per time point.
    s = cs.read_series(czi, forces=[4e-3, 40e-3, 400e-3], channel=1, z=2, load_axis="t")
    assert s.images.dtype == np.uint16 and s.images.shape == (3, 170, 240)
    np.testing.assert_array_equal(s.images, r.images.astype(np.uint16))


def test_czi_selection_errors_are_input_errors():
    czi = sample("czi/CellDivision_T3_Z5_CH2_X240_Y170.czi")
    with pytest.raises(cs.InputError, match="CellDivision"):
        cs.read_image(czi, channel=7)
    with pytest.raises(cs.InputError, match="load_axis"):
        cs.read_image(czi, load_axis="w")


def test_vendor_height_maps_match_cli(cli):
    ibw = sample("ibw/spot_1-1000nm.ibw")
    t = cs.read_topography(ibw, channel="HeightTrace", detrend="none")
    summary = json.loads(cli("topography", ibw, "--json", "--channel", "HeightTrace"))
    assert t.heights.shape == (summary["ny"], summary["nx"])
    assert t.heights.std() * 1e6 == pytest.approx(summary["h_rms_as_stored_um"], rel=1e-6)
    assert t.pixel_size_m[0] * 1e6 == pytest.approx(summary["pixel_size_um"]["x"], rel=1e-12)
    # Python describes the file as `topography --json` does, in SI units.
    mine = t.summary
    for key in ("file", "format", "channel", "nx", "ny", "valid_points",
                "h_prime_rms_as_stored"):
        assert mine[key] == summary[key], key
    for key in ("height_min", "height_max", "height_mean", "h_rms_as_stored"):
        assert mine[f"{key}_m"] * 1e6 == pytest.approx(summary[f"{key}_um"], rel=1e-12), key
    assert mine["h_double_prime_rms_as_stored_per_m"] * 1e-6 == pytest.approx(
        summary["h_double_prime_rms_as_stored_per_um"], rel=1e-12)
    with pytest.raises(cs.InputError, match="channel"):
        cs.read_topography(ibw, channel="NoSuchChannel")


def test_invalid_points_refused_unless_filled(cli):
    opd = sample("opd/opd-1.opd")
    with pytest.raises(cs.InputError, match="invalid.*fill_invalid="):
        cs.read_topography(opd)
    t = cs.read_topography(opd, fill_invalid="mean", detrend="none")
    summary = json.loads(cli("topography", opd, "--json"))
    invalid = summary["nx"] * summary["ny"] - summary["valid_points"]
    assert invalid > 0 and str(invalid) in t.notes[0]
    assert np.isfinite(t.heights).all()
    # Filled with the mean of the valid heights: the mean is unchanged.
    assert t.heights.mean() * 1e6 == pytest.approx(summary["height_mean_um"], rel=1e-9)
    # The summary describes the file as stored (its invalid points), as the command line does.
    assert t.summary["valid_points"] == summary["valid_points"]
    assert summary["detrended"] is None and "invalid" in summary["note"]
    with pytest.raises(cs.InputError, match="fill_invalid"):
        cs.read_topography(opd, fill_invalid="zero")


def test_autocorrelation_of_a_czi_plane_matches_cli(cli, tmp_path):
    czi = sample("czi/CellDivision_T3_Z5_CH2_X240_Y170.czi")
    cli("autocorr", czi, "--channel", "1", "--z", "2", "--t", "1", "--out", tmp_path / "ac")
    theirs = json.loads((tmp_path / "ac" / "autocorr.json").read_text())["images"]
    mine = cs.autocorrelation(czi, channel=1, z=2, t=1).rows
    assert len(mine) == len(theirs) == 1
    m, t = mine[0], theirs[0]
    assert (m["image"], m["file"], m["page"]) == (t["image"], t["file"], t["page"])
    assert m["max_lag_m"] * 1e6 == pytest.approx(t["max_lag_um"], rel=1e-12)
    for key in ("correlation_length_um_1e", "first_zero_um"):
        si = key.replace("_um", "_m")
        if t[key] is None:
            assert m[si] is None
        else:
            assert m[si] * 1e6 == pytest.approx(t[key], rel=1e-12)
    # The same plane read as an array and given its pixel size: the same curve.
    plane = cs.read_image(czi, channel=1, z=2, t=1)
    again = cs.autocorrelation(plane.images[0], plane.pixel_size_m).rows[0]
    np.testing.assert_allclose(again["acf"], m["acf"], rtol=0, atol=1e-12)


def write_sxm(path, forward, backward, scan_range_m, scan_dir):
    """A Nanonis .sxm scan written from the format's description (header tags, DATA_INFO, the
    0x1A 0x04 marker, big-endian float32 images forward then backward), independently of the
    Rust encoder: a current saved forward only, then Z in both directions."""
    ny, nx = forward.shape
    header = (
        ":NANONIS_VERSION:\n2\n:SCANIT_TYPE:\n              FLOAT            MSBFIRST\n"
        f":SCAN_PIXELS:\n       {nx}       {ny}\n"
        f":SCAN_RANGE:\n           {scan_range_m[0]:E}           {scan_range_m[1]:E}\n"
        f":SCAN_DIR:\n{scan_dir}\n:DATA_INFO:\n"
        "\tChannel\tName\tUnit\tDirection\tCalibration\tOffset\n"
        "\t0\tCurrent\tA\tforward\t1.000E-10\t0.000E+0\n"
        "\t14\tZ\tm\tboth\t-3.484E-9\t0.000E+0\n\n:SCANIT_END:\n\n\n"
    )
    current = np.full(forward.shape, 1e-12)
    images = [current, forward, backward]
    body = b"".join(np.asarray(a, dtype=">f4").tobytes() for a in images)
    path.write_bytes(header.encode("latin-1") + b"\x1a\x04" + body)


def test_nanonis_sxm_reads_with_its_calibration_and_orientation(cli, tmp_path):
    ny, nx = 6, 8
    stored = (np.arange(ny * nx, dtype=np.float64).reshape(ny, nx) * 0.25e-9).astype(np.float32)
    stored[0, 0] = np.nan  # a point not scanned
    mirrored = stored[:, ::-1] + np.float32(1e-9)  # backward lines are scanned right to left
    path = tmp_path / "scan.sxm"
    write_sxm(path, stored, mirrored, (4e-9, 3e-9), "up")
    t = cs.read_topography(path, detrend="none", fill_invalid="nearest")
    assert t.pixel_size_m == pytest.approx((0.5e-9, 0.5e-9), rel=1e-12)
    assert t.heights.shape == (ny, nx)
    # A scan "up" stores its bottom line first: row 0 of the map is the last stored line.
    np.testing.assert_allclose(t.heights[0], stored[-1].astype(np.float64), rtol=1e-7)
    back = cs.read_topography(path, channel="Z (backward)", detrend="none",
                              fill_invalid="nearest")
    np.testing.assert_allclose(back.heights[0], stored[-1].astype(np.float64) + 1e-9, rtol=1e-6)
    summary = json.loads(cli("topography", path, "--json"))
    assert summary["channel"] == "Z (forward)"
    assert summary["channels"] == ["Current", "Z (forward)", "Z (backward)"]
    assert summary["valid_points"] == nx * ny - 1
    with pytest.raises(cs.InputError, match="'A', not a length"):
        cs.read_topography(path, channel="Current")


def test_topostats_file_reads_with_its_nm_calibration(cli):
    """The committed TopoStats-layout fixture (tests/data/topostats_fixture.py): heights in nm
    and pixel_to_nm_scaling become metres, as AFMReader's load_topostats gives them in nm."""
    path = ROOT / "fixtures" / "topostats" / "tiny.topostats"
    t = cs.read_topography(path, detrend="none")
    i, j = np.mgrid[0:6, 0:8]
    np.testing.assert_allclose(t.heights, (0.5 * i - 0.25 * j + 0.125 * i * j) * 1e-9,
                               rtol=0, atol=1e-22)
    assert t.pixel_size_m == pytest.approx((2.5e-9, 2.5e-9), rel=1e-12)
    summary = json.loads(cli("topography", path, "--json"))
    assert (summary["format"], summary["channels"]) == ("topostats", ["image", "image_original"])


def test_jpk_tiff_reads_its_default_calibration_slot(cli):
    """The committed JPK-layout fixture (tests/data/jpk_fixture.py): raw·(−1.5e−15) + 2.5e−6 m of
    its `calibrated` slot, lines flipped (stored bottom first), 4 nm pixels; the deflection page
    in newtons is refused."""
    path = ROOT / "fixtures" / "jpk" / "tiny.jpk"
    t = cs.read_topography(path, detrend="none")
    i, j = np.mgrid[0:4, 0:5]
    raw = 1000 * i + 10 * j
    np.testing.assert_allclose(t.heights, (raw * -1.5e-15 + 2.5e-6)[::-1], rtol=1e-12)
    assert t.pixel_size_m == pytest.approx((4e-9, 4e-9), rel=1e-12)
    summary = json.loads(cli("topography", path, "--json"))
    assert summary["channel"] == "height (retrace)"
    with pytest.raises(cs.InputError, match="'N', not a length"):
        cs.read_topography(path, channel="vDeflection")


def test_createc_image_reads_its_dac_counts_in_metres(cli):
    """The committed Createc image (fixtures/createc, ProbeFlow's sample): decoded here with zlib
    and NumPy from the header's own numbers — float32 planes after the DATA line, the first
    column dropped, the 9 lines scanned of 256 kept, counts × Dacto[A]z (nm) × GainZ/10."""
    import zlib
    path = ROOT / "fixtures" / "createc" / "A250407.141806.dat"
    raw = path.read_bytes()
    at = raw.index(b"\nDATA")
    header = dict(line.split("=", 1) for line in raw[:at].decode("latin-1").splitlines()
                  if "=" in line)
    assert header["Num.X / Num.X"] == "256" and header["Dacto[A]z"] == "0.00037"
    planes = np.frombuffer(zlib.decompress(raw[at + 5:]), "<f4")[:4 * 256 * 256]
    z_forward = planes.reshape(4, 256, 256)[0, :9, 1:].astype(np.float64) * 0.00037e-9
    t = cs.read_topography(path, detrend="none")
    np.testing.assert_allclose(t.heights, z_forward, rtol=1e-12)
    assert t.pixel_size_m == pytest.approx((998.468e-10 / 256,) * 2, rel=1e-12)
    summary = json.loads(cli("topography", path, "--json"))
    assert (summary["format"], summary["channel"], summary["nx"], summary["ny"]) == \
        ("createc", "Z (forward)", 255, 9)
    with pytest.raises(cs.InputError, match="'A', not a length"):
        cs.read_topography(path, channel="Current (forward)")


def test_sflz_files_read_as_surfalize_wrote_them(cli):
    """The committed surfalize files (tests/data/sflz_fixture.py, sflz_earlier_fixture.py): the
    formula's heights back, to the quantisation step of each file, with surfalize's unit and
    step, in both layouts."""
    ny, nx = 36, 48
    y, x = np.mgrid[0:ny, 0:nx].astype(np.float64)
    um = 0.8 + 0.01 * x - 0.02 * y + 0.35 * np.sin(x / 4.0) * np.cos(y / 5.0)
    spread = um.max() - um.min()
    # Within half a step where surfalize rounds (0.19), within a step where it truncates (0.17).
    for name, step in [("none_i2.sflz", 0.5 * spread / 65535), ("lzma_f8.sflz", 0.0),
                       ("zlib_u4.sflz", 0.5 * spread / (2**32 - 2)),
                       ("earlier_lzma_f8.sflz", 0.0),
                       ("earlier_zlib_u4.sflz", spread / (2**32 - 1))]:
        t = cs.read_topography(ROOT / "fixtures" / "sflz" / name, detrend="none",
                               fill_invalid="nearest")
        assert t.pixel_size_m == pytest.approx((0.625e-6, 0.5e-6), rel=1e-12)
        measured = np.ones_like(um, dtype=bool)
        if name in ("lzma_f8.sflz", "zlib_u4.sflz"):
            measured[3, 5] = False
            measured[20, 40:44] = False
        error = np.abs(t.heights[measured] - um[measured] * 1e-6)
        assert error.max() <= step * 1e-6 * (1 + 1e-6) + 1e-21, name
        summary = json.loads(cli("topography", ROOT / "fixtures" / "sflz" / name, "--json"))
        assert summary["format"] == "sflz"
        assert summary["valid_points"] == measured.sum()


def test_zon_files_read_as_surface_topography_reads_them(cli):
    """The committed Keyence ZON files (tests/data/zon_fixture.py; zstd members and stored
    ones) against SurfaceTopography's ZONReader: every measured height equal (its arrays are
    (x, y), ours rows = y), the same points unmeasured, the same pixel size; and against the
    fixture's own formula (counts of 10 nm)."""
    st = pytest.importorskip("SurfaceTopography")
    y, x = np.mgrid[0:14, 0:20]
    counts = (300 * (x - 9.5) ** 2 - 150 * (y - 6.5) ** 2 + 4000 * (x > 12) - 7).astype(np.int32)
    for name in ["tiny.zon", "tiny-plain.zon"]:
        path = ROOT / "fixtures" / "zon" / name
        theirs = st.open_topography(str(path)).topography()
        h = np.ma.masked_invalid(theirs.heights()).T
        ours = cs.read_topography(path, detrend="none", fill_invalid="nearest")
        measured = ~np.ma.getmaskarray(h)
        assert ours.heights.shape == h.shape == counts.shape
        np.testing.assert_array_equal(ours.heights[measured], np.asarray(h)[measured])
        np.testing.assert_allclose(ours.heights[measured], counts[measured] * 1e-8, rtol=1e-12)
        size = np.array(theirs.physical_sizes) / np.array(theirs.nb_grid_pts)
        assert ours.pixel_size_m == pytest.approx(tuple(size), rel=1e-12)
        summary = json.loads(cli("topography", path, "--json"))
        assert summary["format"] == "zon"
        assert summary["valid_points"] == measured.sum() == 272


def test_a_zygo_datx_file_is_refused_by_name(tmp_path):
    """An HDF5 file laid out as Zygo's DATX (a root MetaData table, Measurement/Surface) is
    refused naming the format, not read as plain datasets in an unknown unit."""
    h5py = pytest.importorskip("h5py")
    path = tmp_path / "scan.datx"
    with h5py.File(path, "w") as f:
        row = np.dtype([("Source", "S16"), ("Link", "S16"), ("Destination", "S16")])
        f.create_dataset("MetaData", data=np.array([(b"Root", b"Path", b"x")], dtype=row))
        f.create_dataset("Measurement/Surface", data=np.zeros((4, 5), np.float32))
    with pytest.raises(cs.InputError, match="Zygo DATX"):
        cs.read_topography(path, pixel_size=1e-6)


def test_a_tiny_map_is_levelled_as_asked_and_says_what_it_cannot_compute(tmp_path):
    """A 2 × 2 map has no interior point for the slope: its summary leaves the slope null with a
    note, and its heights are still levelled as asked (plane: they sum to zero)."""
    import struct
    header = (b"Gwyddion Simple Field 1.0\nXRes = 2\nYRes = 2\nXReal = 2e-6\nYReal = 2e-6\n"
              b"XYUnits = m\nZUnits = m\n")
    header += b"\0" * (4 - len(header) % 4)
    path = tmp_path / "tiny.gsf"
    path.write_bytes(header + struct.pack("<4f", 1e-9, 2e-9, 3e-9, 5e-9))
    t = cs.read_topography(path)
    assert t.summary["h_prime_rms_as_stored"] is None
    assert "needs at least 3 × 3 pixels" in t.summary["note"]
    assert t.pixel_size_m == pytest.approx((1e-6, 1e-6), rel=1e-12)
    assert abs(t.heights.sum()) < 1e-20
    stored = cs.read_topography(path, detrend="none")
    np.testing.assert_allclose(stored.heights.ravel(), [1e-9, 2e-9, 3e-9, 5e-9], rtol=1e-7)
