"""OME-Zarr stores as labs make them — written by ome-zarr-py, ngff-zarr and bioio, NGFF 0.4
(Zarr v2) and 0.5 (Zarr v3) — from the shared confocal files (CZI, ND2, LIF, OME-TIFF) and a
generated load series: each analyses with the same threshold, areas and pixel size as its source
file (issue 45). The masks written back (``analyze --zarr-out``) validate against the NGFF models
(ome-zarr-models), open in ome-zarr-py's reader as a label image, and the table reads back in
pandas and DuckDB equal to ``areas.csv``.

The writers are optional test dependencies (``scripts/test-all`` installs them); a missing one
skips its cases with a message."""

import csv
import json
import math

import numpy as np
import pytest

import contactscope as cs
from conftest import ROOT

REAL = ROOT.parent / "shared" / "data"

# (name, source file below ../shared/data, selection flags, read_image arguments)
SOURCES = [
    ("czi", "real-formats/czi/CellDivision_T3_Z5_CH2_X240_Y170.czi",
     ["--channel", "1", "--z", "2", "--load-axis", "t"], dict(channel=1, z=2, load_axis="t")),
    ("nd2", "real-formats/nd2/cluster.nd2",
     ["--channel", "0", "--z", "4", "--load-axis", "t"], dict(channel=0, z=4, load_axis="t")),
    ("lif", "real-formats/lif/LeicaLASX_wavelength-sweep_example.lif",
     ["--series", "0", "--axis", "lambda_emission=10"],
     dict(series=0, axes={"lambda_emission": 10})),
    ("ome-tiff", "real-tiff/aicsimageio/s_1_t_1_c_1_z_1.ome.tiff", [], {}),
]


def _source(relative):
    path = REAL / relative
    if not path.exists():
        pytest.skip(f"{path} not found (the shared test data sits beside the checkout)")
    return path


def _write_ome_zarr_py(path, data, pixel_um, version):
    zarr = pytest.importorskip("zarr")
    pytest.importorskip("ome_zarr")
    from ome_zarr.format import FormatV04, FormatV05
    from ome_zarr.io import parse_url
    from ome_zarr.writer import write_image
    fmt = FormatV04() if version == "0.4" else FormatV05()
    store = parse_url(str(path), mode="w", fmt=fmt).store
    root = zarr.group(store=store, zarr_format=2 if version == "0.4" else 3)
    write_image(data, root, axes="tyx", fmt=fmt, scale_factors=(2,),
                scale={"y": pixel_um[1], "x": pixel_um[0]},
                axes_units={"y": "micrometer", "x": "micrometer"})


def _write_ngff_zarr(path, data, pixel_um, version):
    nz = pytest.importorskip("ngff_zarr")
    image = nz.to_ngff_image(data, dims=["t", "y", "x"],
                             scale={"t": 1.0, "y": pixel_um[1], "x": pixel_um[0]},
                             axes_units={"y": "micrometer", "x": "micrometer"})
    nz.to_ngff_zarr(str(path), nz.to_multiscales(image, scale_factors=[2]), version=version)


def _write_bioio(path, data, pixel_um, version):
    pytest.importorskip("bioio_ome_zarr")
    from bioio_ome_zarr.writers import OMEZarrWriter
    shape = data.shape
    half = (shape[0], max(1, shape[1] // 2), max(1, shape[2] // 2))
    w = OMEZarrWriter(str(path), level_shapes=[shape, half], dtype=data.dtype,
                      zarr_format=2 if version == "0.4" else 3,
                      axes_names=["t", "y", "x"], axes_types=["time", "space", "space"],
                      axes_units=[None, "micrometer", "micrometer"],
                      physical_pixel_size=[1.0, pixel_um[1], pixel_um[0]])
    w.write_full_volume(data)


WRITERS = {"ome-zarr-py": _write_ome_zarr_py, "ngff-zarr": _write_ngff_zarr,
           "bioio": _write_bioio}


def _areas(out):
    with open(out / "areas.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return rows


def _same_numbers(a, b):
    """Rows equal column by column, but for the file name (numbers to 1e-9 relative: the pixel
    size passes through the store's JSON)."""
    assert len(a) == len(b)
    for ra, rb in zip(a, b):
        assert ra.keys() == rb.keys()
        for k in ra:
            if k == "image":
                continue
            x, y = ra[k], rb[k]
            try:
                fx, fy = float(x), float(y)
            except ValueError:
                assert x == y, k
                continue
            assert (math.isnan(fx) and math.isnan(fy)) or fx == pytest.approx(fy, rel=1e-9), k


def _pixel_um(summary_path):
    s = json.loads(summary_path.read_text())
    return s["inputs"]["pixel_size_used"]


@pytest.mark.parametrize("version", ["0.4", "0.5"])
@pytest.mark.parametrize("writer", sorted(WRITERS))
@pytest.mark.parametrize("name,relative,flags,select", SOURCES, ids=[s[0] for s in SOURCES])
def test_stores_analyse_as_their_source(cli, tmp_path, name, relative, flags, select, writer,
                                        version):
    src = _source(relative)
    r = cs.read_image(src, **select)
    n = r.images.shape[0]
    # The planes in their stored sample type (uint8, uint16), as a converter would copy them.
    data = np.asarray(cs.read_series(src, forces=[1e-3] * n, **select).images)
    forces = "4mN..400mN:%d" % n if n > 1 else "100mN"
    cli("analyze", src, *flags, "--forces", forces, "--out", tmp_path / "src")
    store = tmp_path / f"{name}.ome.zarr"
    pixel_um = tuple(p * 1e6 for p in r.pixel_size_m)
    WRITERS[writer](store, data, pixel_um, version)
    cli("analyze", store, "--load-axis", "t", "--forces", forces, "--out", tmp_path / "zarr")
    _same_numbers(_areas(tmp_path / "zarr"), _areas(tmp_path / "src"))
    a, b = _pixel_um(tmp_path / "zarr" / "summary.json"), _pixel_um(tmp_path / "src" / "summary.json")
    assert a["x_um"] == pytest.approx(b["x_um"], rel=1e-12)
    assert a["y_um"] == pytest.approx(b["y_um"], rel=1e-12)
    # Python reads the same planes from the store.
    back = cs.read_series(store, load_axis="t", forces=[1e-3] * n)
    np.testing.assert_array_equal(np.asarray(back.images), data)


def test_generated_series_masks_back_into_the_store(cli, tmp_path):
    pytest.importorskip("ome_zarr")
    pd = pytest.importorskip("pandas")
    duckdb = pytest.importorskip("duckdb")
    models = pytest.importorskip("ome_zarr_models")
    import zarr
    from ome_zarr.io import parse_url
    from ome_zarr.reader import Reader
    from ome_zarr_models.v05.image import Image
    from ome_zarr_models.v05.image_label import ImageLabel
    s = cs.synth_series(256, 224, 200e-9, [4e-3, 8e-3, 16e-3, 32e-3], seed=45)
    store = tmp_path / "generated.ome.zarr"
    _write_ome_zarr_py(store, np.asarray(s.images), (0.2, 0.2), "0.5")
    out = tmp_path / "out"
    cli("analyze", store, "--load-axis", "t", "--forces", "4mN,8mN,16mN,32mN", "--out", out,
        "--zarr-out", store)
    rows = _areas(out)
    g = zarr.open_group(str(store), mode="r")
    Image.from_zarr(g)
    label = ImageLabel.from_zarr(g["labels/contact"])
    assert label.attributes.ome.image_label.colors[0].label_value == 1
    masks = np.asarray(g["labels/contact"][label.attributes.ome.multiscales[0].datasets[0].path])
    assert masks.shape == np.asarray(s.images).shape
    assert masks.sum(axis=(1, 2)).tolist() == [int(r["contact_pixels"]) for r in rows]
    # ome-zarr-py's reader finds the image and its contact labels at the image's scale.
    nodes = list(Reader(parse_url(str(store)))())
    labels = [n for n in nodes if str(n.zarr.path).endswith("labels/contact")]
    assert labels and labels[0].data[0].shape == masks.shape
    scale = g["labels/contact"].attrs["ome"]["multiscales"][0]["datasets"][0][
        "coordinateTransformations"][0]["scale"]
    assert scale[1:] == pytest.approx([0.2, 0.2])
    # The table: pandas and DuckDB read areas.csv's columns and values.
    parquet = store / "tables" / "contact_areas" / "table.parquet"
    table = pd.read_parquet(parquet)
    expected = pd.read_csv(out / "areas.csv")
    assert list(table.columns) == list(expected.columns)
    for c in expected.columns:
        if c == "image":
            continue
        np.testing.assert_allclose(table[c].astype(float), expected[c].astype(float), rtol=1e-12)
    n = duckdb.connect().execute(
        f"select count(*), sum(contact_pixels) from '{parquet}'").fetchall()[0]
    assert n == (len(rows), sum(int(r["contact_pixels"]) for r in rows))
    attrs = g["tables/contact_areas"].attrs
    assert attrs["backend"] == "parquet" and attrs["region"]["path"] == "../labels/contact"
    del models


def test_a_plate_is_one_series_per_field_in_the_batch(cli, tmp_path):
    """An HCS plate written by ome-zarr-py: `batch` takes each field of each well as a series
    (the well and field as columns), each analysed as the same planes alone would be."""
    zarr = pytest.importorskip("zarr")
    pytest.importorskip("ome_zarr")
    from ome_zarr.format import FormatV04
    from ome_zarr.io import parse_url
    from ome_zarr.writer import write_image, write_plate_metadata, write_well_metadata
    s = cs.synth_series(128, 128, 200e-9, [2e-3, 4e-3, 8e-3], seed=7)
    data = np.asarray(s.images)
    fmt = FormatV04()
    archive = tmp_path / "archive"
    store = parse_url(str(archive / "plate1.ome.zarr"), mode="w", fmt=fmt).store
    root = zarr.group(store=store, zarr_format=2)
    write_plate_metadata(root, ["A", "B"], ["1", "2"], ["A/1", "B/2"], fmt=fmt)
    for row, col in (("A", "1"), ("B", "2")):
        well = root.require_group(row).require_group(col)
        write_well_metadata(well, [{"path": "0"}, {"path": "1"}], fmt=fmt)
        for field in range(2):
            # Field 1 holds the loads in reverse order.
            write_image(data if field == 0 else data[::-1], well.require_group(str(field)),
                        axes="tyx", fmt=fmt, scale_factors=(), scale={"y": 0.2, "x": 0.2},
                        axes_units={"y": "micrometer", "x": "micrometer"})
    cs.write_tiff(tmp_path / "alone.tif", data, 200e-9)
    cli("analyze", tmp_path / "alone.tif", "--forces", "2mN,4mN,8mN", "--out", tmp_path / "alone")
    alone = [r["contact_pixels"] for r in _areas(tmp_path / "alone")]
    out = tmp_path / "res"
    cli("batch", archive, "--load-axis", "t", "--forces", "2mN,4mN,8mN", "--out", out)
    with open(out / "series.csv", newline="") as f:
        series = list(csv.DictReader(f))
    assert [(r["series_id"], r["plate_well"], r["plate_field"], r["status"]) for r in series] == [
        ("plate1-A-1-0", "A/1", "0", "ok"), ("plate1-A-1-1", "A/1", "1", "ok"),
        ("plate1-B-2-0", "B/2", "0", "ok"), ("plate1-B-2-1", "B/2", "1", "ok")]
    with open(out / "images.csv", newline="") as f:
        images = list(csv.DictReader(f))
    for sid in ("plate1-A-1-0", "plate1-B-2-0"):
        assert [r["contact_pixels"] for r in images if r["series_id"] == sid] == alone
    assert [r["contact_pixels"] for r in images if r["series_id"] == "plate1-A-1-1"] == alone[::-1]


def test_python_analyze_writes_the_same_store_as_the_command_line(cli, tmp_path, series_tif):
    """``analyze(..., out=, zarr_out=)`` is ``analyze --out --zarr-out``; without ``out`` it is
    refused (nothing is written)."""
    path, _ = series_tif
    series = cs.read_series(path, forces=[2e-3, 4e-3, 8e-3])
    with pytest.raises(cs.InputError, match="zarr_out"):
        cs.analyze(series, zarr_out=tmp_path / "alone.ome.zarr")
    assert not (tmp_path / "alone.ome.zarr").exists()
    r = cs.analyze(series, out=tmp_path / "py", zarr_out=tmp_path / "py.ome.zarr")
    cli("analyze", path, "--forces", "2mN,4mN,8mN", "--out", tmp_path / "cli",
        "--zarr-out", tmp_path / "cli.ome.zarr")
    assert str(tmp_path / "py.ome.zarr") in [str(p) for p in r["written"]]
    for name in ("zarr.json", "labels/contact/zarr.json"):
        a = json.loads((tmp_path / "py.ome.zarr" / name).read_text())
        b = json.loads((tmp_path / "cli.ome.zarr" / name).read_text())
        assert a == b, name
    py = cs.read_series(tmp_path / "py.ome.zarr" / "labels" / "contact", load_axis="t",
                        forces=[1e-3] * 3).images
    cli_masks = cs.read_series(tmp_path / "cli.ome.zarr" / "labels" / "contact", load_axis="t",
                               forces=[1e-3] * 3).images
    np.testing.assert_array_equal(np.asarray(py), np.asarray(cli_masks))


@pytest.mark.parametrize("version", ["0.4", "0.5"])
def test_a_path_to_one_level_reads_that_level(cli, tmp_path, series_tif, version):
    """``image.ome.zarr/1`` reads the second resolution level: its planes (as zarr-python reads
    them), its scale as the pixel size; the masks are not written into a level."""
    zarr = pytest.importorskip("zarr")
    tif, _ = series_tif
    data = np.asarray(cs.read_image(tif).images)
    store = tmp_path / "ramp.ome.zarr"
    _write_ome_zarr_py(store, data, (0.2, 0.2), version)
    attrs = json.loads((store / (".zattrs" if version == "0.4" else "zarr.json")).read_text())
    ms = (attrs if version == "0.4" else attrs["attributes"]["ome"])["multiscales"][0]
    level = ms["datasets"][1]
    scale = level["coordinateTransformations"][0]["scale"]
    lower = np.asarray(zarr.open_array(str(store / level["path"]), mode="r"))
    assert lower.shape[1] < data.shape[1]
    reference = tmp_path / "level1.tif"
    cs.write_tiff(reference, lower, scale[-1] * 1e-6)
    forces = "2mN,4mN,8mN"
    cli("analyze", reference, "--forces", forces, "--out", tmp_path / "tif")
    cli("analyze", store / level["path"], "--load-axis", "t", "--forces", forces,
        "--out", tmp_path / "level")
    _same_numbers(_areas(tmp_path / "level"), _areas(tmp_path / "tif"))
    px = _pixel_um(tmp_path / "level" / "summary.json")
    assert px["x_um"] == pytest.approx(scale[-1], rel=1e-12)
    np.testing.assert_array_equal(
        np.asarray(cs.read_image(store / level["path"], load_axis="t").images), lower)
    with pytest.raises(AssertionError, match="resolution level"):
        cli("analyze", store / level["path"], "--load-axis", "t", "--forces", forces,
            "--out", tmp_path / "z", "--zarr-out", store / level["path"])
