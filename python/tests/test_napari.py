"""The napari plugin (``contactscope[napari]``): the npe2 manifest, the readers on generated and
real files, the load-series widget against the command line's ``analyze`` folder, the compare
widget against ``compare``'s scores, the sample, errors without tracebacks, and the screenshots
of the docs.

Skipped, with the reason, where napari is not installed (``pip install "contactscope[napari]"``)
or there is no display (run under a virtual X server: ``xvfb-run -a python -m pytest …``; with
``QT_QPA_PLATFORM=offscreen`` alone napari cannot add a layer, for want of an OpenGL context).
``CONTACTSCOPE_DOCS_IMAGES=<folder>`` also writes the screenshots of ``docs/napari.md`` there.
"""

import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import contactscope as cs
from conftest import FORCES, ROOT

try:
    import napari  # noqa: F401

    HAVE_NAPARI = True
except ImportError:
    HAVE_NAPARI = False

REAL = ROOT.parent / "shared" / "data"
needs_napari = pytest.mark.skipif(
    not HAVE_NAPARI, reason="napari is not installed: pip install 'contactscope[napari]' "
    "(the napari plugin's tests are skipped)")
needs_display = pytest.mark.skipif(
    not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")),
    reason="no display for napari's viewer: run the tests under xvfb-run -a")


def real(relative):
    path = REAL / relative
    if not path.exists():
        pytest.skip(f"{path} not found (the shared test data sits beside the checkout)")
    return path


def test_core_package_imports_without_napari():
    # Importing contactscope (and its plugin package) never imports napari or Qt.
    code = ("import sys, contactscope, contactscope.napari; "
            "print(sorted(m for m in ('napari', 'qtpy', 'PyQt5') if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True)
    assert done.stdout.strip() == "[]"


# The manifest -----------------------------------------------------------------------------

@needs_napari
def test_manifest_is_valid_and_registered():
    from npe2 import PluginManifest

    path = pathlib.Path(cs.__file__).with_name("napari") / "napari.yaml"
    from_file = PluginManifest.from_file(path)
    # Registered through the `napari.manifest` entry point of the installed distribution.
    installed = PluginManifest.from_distribution("contactscope")
    assert installed.name == from_file.name == "contactscope"
    c = installed.contributions
    assert {r.command for r in c.readers} == {"contactscope.get_micrograph_reader",
                                               "contactscope.get_topography_reader"}
    assert "*.czi" in next(r for r in c.readers if "micrograph" in r.command).filename_patterns
    assert {w.command for w in c.widgets} == {"contactscope.load_series_widget",
                                               "contactscope.compare_widget"}
    assert [s.key for s in c.sample_data] == ["synthetic_series"]
    # Every command resolves to an object of the package.
    for command in c.commands:
        module, name = command.python_name.split(":")
        assert callable(getattr(__import__(module, fromlist=[name]), name)), command.id
    done = subprocess.run([sys.executable, "-m", "npe2", "validate", "contactscope"],
                          capture_output=True, text=True)
    assert done.returncode == 0 and "valid" in done.stdout, done.stdout + done.stderr


# Readers on generated files ---------------------------------------------------------------

@needs_napari
def test_tiff_reader_scale_and_values(series_tif):
    from contactscope.napari import readers

    path, s = series_tif
    reader = readers.get_micrograph_reader(str(path))
    assert reader is not None
    [(data, kwargs, kind)] = reader(str(path))
    assert kind == "image"
    np.testing.assert_array_equal(data, s.images)
    assert kwargs["scale"] == pytest.approx([1.0, 0.2, 0.2])  # 200 nm pixels, in µm
    assert kwargs["name"] == "series"
    assert kwargs["metadata"]["contactscope"]["path"] == str(path)


@needs_napari
def test_an_ome_companion_file_opens_its_set(tmp_path):
    """A multi-file OME-TIFF set whose XML is in ``set.companion.ome`` (each TIFF's own XML
    only points to it): the companion opens the whole set, in the set's plane order."""
    import tifffile

    from contactscope.napari import readers

    s = cs.synth_series(64, 60, 250e-9, [1e-3, 1.5e-3, 2e-3, 3e-3], seed=5)
    names = ["set_0.ome.tif", "set_1.ome.tif"]
    ns = "http://www.openmicroscopy.org/Schemas/OME/2016-06"
    uuid = "urn:uuid:00000000-0000-4000-8000-000000000001"
    blocks = "".join(
        f'<TiffData FirstT="{2 * k}" IFD="0" PlaneCount="2"><UUID FileName="{n}">'
        f"urn:uuid:00000000-0000-4000-8000-00000000001{k}</UUID></TiffData>"
        for k, n in enumerate(names)
    )
    (tmp_path / "set.companion.ome").write_text(
        f'<?xml version="1.0" encoding="UTF-8"?><OME xmlns="{ns}" UUID="{uuid}">'
        '<Image ID="Image:0"><Pixels ID="Pixels:0" DimensionOrder="XYCZT" Type="uint16" '
        'SizeX="64" SizeY="60" SizeC="1" SizeZ="1" SizeT="4" PhysicalSizeX="0.25" '
        'PhysicalSizeXUnit="µm" PhysicalSizeY="0.25" PhysicalSizeYUnit="µm">'
        f'<Channel ID="Channel:0:0" SamplesPerPixel="1"/>{blocks}</Pixels></Image></OME>'
    )
    pointer = (f'<?xml version="1.0" encoding="UTF-8"?><OME xmlns="{ns}">'
               f'<BinaryOnly MetadataFile="set.companion.ome" UUID="{uuid}"/></OME>')
    for k, name in enumerate(names):
        with tifffile.TiffWriter(tmp_path / name) as w:
            for j, page in enumerate(s.images[2 * k:2 * k + 2]):
                w.write(page, description=pointer if j == 0 else None, metadata=None)
    companion = str(tmp_path / "set.companion.ome")
    reader = readers.get_micrograph_reader(companion)
    assert reader is not None
    [(data, kwargs, kind)] = reader(companion)
    assert kind == "image"
    np.testing.assert_array_equal(data, s.images)
    assert kwargs["scale"][-2:] == pytest.approx([0.25, 0.25])


@needs_napari
def test_each_image_of_a_multi_image_ome_tiff_is_a_layer(tmp_path):
    """Two stage positions in one OME-TIFF: one layer each, named by the image, with its own
    pixel size (not eight pages of one stack)."""
    import tifffile

    from contactscope.napari import readers

    s = cs.synth_series(64, 60, 250e-9, [1e-3, 1.5e-3, 2e-3, 3e-3], seed=6)
    path = tmp_path / "positions.ome.tif"
    with tifffile.TiffWriter(path, ome=True) as w:
        w.write(s.images[:2], metadata={"axes": "TYX", "Name": "left", "PhysicalSizeX": 0.25,
                                        "PhysicalSizeY": 0.25})
        w.write(s.images[2:], metadata={"axes": "TYX", "Name": "right", "PhysicalSizeX": 0.1,
                                        "PhysicalSizeY": 0.1})
    layers = readers.get_micrograph_reader(str(path))(str(path))
    assert [kwargs["name"] for _, kwargs, _ in layers] == [
        "positions.ome [0: left]", "positions.ome [1: right]"]
    np.testing.assert_array_equal(layers[0][0], s.images[:2])
    np.testing.assert_array_equal(layers[1][0], s.images[2:])
    assert layers[1][1]["scale"][-2:] == pytest.approx([0.1, 0.1])


def _store_with_masks(series_tif, tmp_path, cli):
    """A new OME-Zarr store written by `analyze --zarr-out` from the series TIFF."""
    path, _ = series_tif
    store = tmp_path / "series.ome.zarr"
    cli("analyze", path, "--forces", "2mN,4mN,8mN", "--out", tmp_path / "out", "--zarr-out", store)
    return store


@needs_napari
def test_ome_zarr_store_reader_scale_and_values(series_tif, tmp_path, cli):
    from contactscope.napari import readers

    store = _store_with_masks(series_tif, tmp_path, cli)
    reader = readers.get_micrograph_reader(str(store))
    assert reader is not None
    [(data, kwargs, kind)] = reader(str(store))
    assert kind == "image"
    np.testing.assert_array_equal(data.reshape(series_tif[1].images.shape), series_tif[1].images)
    assert kwargs["scale"][-2:] == pytest.approx([0.2, 0.2])


@needs_napari
def test_folder_reader_natural_order(tmp_path):
    from contactscope.napari import readers

    s = cs.synth_series(64, 60, 250e-9, [1e-3, 2e-3, 3e-3], seed=4)
    folder = tmp_path / "loads"
    folder.mkdir()
    for name, image in zip(["f2.tif", "f10.tif", "f1.tif"], s.images[[1, 2, 0]]):
        cs.write_tiff(folder / name, image, 250e-9)
    reader = readers.get_micrograph_reader(str(folder))
    [(data, kwargs, _)] = reader(str(folder))
    # Natural order (f1, f2, f10), as the command line reads a folder.
    np.testing.assert_array_equal(data, s.images)
    assert kwargs["scale"] == pytest.approx([1.0, 0.25, 0.25])
    assert [pathlib.Path(p).name for p in kwargs["metadata"]["contactscope"]["paths"]] == \
        ["f1.tif", "f2.tif", "f10.tif"]


@needs_napari
def test_bad_files_give_no_reader_and_one_line(tmp_path, monkeypatch):
    from contactscope.napari import _common, readers

    shown = []
    monkeypatch.setattr(_common, "notify_error", shown.append)
    monkeypatch.setattr(readers, "notify_error", shown.append)
    bad = tmp_path / "broken.czi"
    bad.write_bytes(b"not a czi file" * 8)
    assert readers.get_micrograph_reader(str(bad)) is None
    assert len(shown) == 1 and "broken.czi" in shown[0] and "\n" not in shown[0]
    # A height map that is no height map: the reader returns None, one line, no traceback.
    fake = tmp_path / "fake.ibw"
    fake.write_bytes(b"\x00" * 64)
    reader = readers.get_topography_reader(str(fake))
    assert reader is not None and reader(str(fake)) is None
    assert len(shown) == 2 and "fake.ibw" in shown[1] and "\n" not in shown[1]
    assert "Traceback" not in "".join(shown) and "panicked" not in "".join(shown)
    # Files of other kinds are not ours at all.
    assert readers.get_micrograph_reader(str(tmp_path / "notes.txt")) is None
    assert readers.get_topography_reader(str(bad)) is None


@needs_napari
def test_dat_files_by_their_first_bytes_and_sflz(tmp_path):
    """A `.dat` is a height map only when it starts as a Createc or MetroPro image does; the
    committed Createc and surfalize fixtures open as heights in µm."""
    from contactscope.napari import readers

    createc = ROOT / "fixtures" / "createc" / "A250407.141806.dat"
    [(data, kwargs, _)] = readers.get_topography_reader(str(createc))(str(createc))
    t = cs.read_topography(createc)
    assert data.shape == (9, 255)
    np.testing.assert_allclose(data, t.heights * 1e6)
    assert kwargs["scale"] == pytest.approx([t.pixel_size_m[1] * 1e6, t.pixel_size_m[0] * 1e6])
    other = tmp_path / "spectrum.dat"
    other.write_text("Experiment\tbias spectroscopy\n1 2 3\n")
    assert readers.get_topography_reader(str(other)) is None
    sflz = ROOT / "fixtures" / "sflz" / "none_i2.sflz"
    [(data, _, _)] = readers.get_topography_reader(str(sflz))(str(sflz))
    np.testing.assert_allclose(data, cs.read_topography(sflz).heights * 1e6)
    assert data.shape == (36, 48)


# Readers on the real files beside the checkout ---------------------------------------------

@needs_napari
def test_real_czi_channels_axes_scale():
    from contactscope.napari import readers

    czi = real("real-formats/czi/CellDivision_T3_Z5_CH2_X240_Y170.czi")
    layers = readers.get_micrograph_reader(str(czi))(str(czi))
    assert [k["name"] for _, k, _ in layers] == ["CellDivision_T3_Z5_CH2_X240_Y170 C0",
                                                 "CellDivision_T3_Z5_CH2_X240_Y170 C1"]
    px = cs.info(czi)["series"][0]["pixel_size_m"]
    for c, (data, kwargs, _) in enumerate(layers):
        assert data.shape == (3, 5, 170, 240) and data.dtype == np.uint16
        assert kwargs["axis_labels"] == ["T", "Z", "y", "x"]
        assert kwargs["scale"] == pytest.approx([1.0, px["z"] * 1e6, px["y"] * 1e6,
                                                 px["x"] * 1e6])
        # One plane equals the library's reading of the same selection.
        np.testing.assert_array_equal(data[1, 2], cs.read_image(czi, channel=c, z=2, t=1)
                                      .images[0])


@needs_napari
def test_real_nd2_lif_and_tiff_hyperstack():
    from contactscope.napari import readers

    nd2 = real("real-formats/nd2/cluster.nd2")
    layers = readers.get_micrograph_reader(str(nd2))(str(nd2))
    assert len(layers) == 2 and layers[0][0].shape == (3, 10, 31, 38)
    assert layers[0][1]["scale"][1] == pytest.approx(0.5)  # z step 500 nm
    lif = real("real-formats/lif/LeicaLASX_wavelength-sweep_example.lif")
    layers = readers.get_micrograph_reader(str(lif))(str(lif))
    assert [d.shape for d, _, _ in layers] == [(20, 64, 64), (15, 64, 64), (2, 11, 10, 64, 64)]
    assert layers[2][1]["axis_labels"] == ["T", "Z", "lambda_emission", "y", "x"]
    assert "x_y_lambdaEmi" in layers[0][1]["name"]
    tif = real("real-tiff/neubias/xyzc_16bit__dna_conf_wf.tif")
    layers = readers.get_micrograph_reader(str(tif))(str(tif))
    assert [d.shape for d, _, _ in layers] == [(45, 130, 133)] * 2
    np.testing.assert_array_equal(layers[1][0], cs.read_image(tif, channel=1, load_axis="z").images)


@needs_napari
def test_real_height_maps_in_micrometres():
    from contactscope.napari import readers

    ibw = real("real-formats/ibw/spot_1-1000nm.ibw")
    [(data, kwargs, _)] = readers.get_topography_reader(str(ibw))(str(ibw))
    t = cs.read_topography(ibw)
    np.testing.assert_allclose(data, t.heights * 1e6)
    assert kwargs["scale"] == pytest.approx([t.pixel_size_m[1] * 1e6, t.pixel_size_m[0] * 1e6])
    assert kwargs["units"] == ["µm", "µm"]
    # A Park Systems TIFF is a height map: the TIFF reader hands it on.
    park = real("real-formats/park-tiff/example_ps.tiff")
    [(data, kwargs, _)] = readers.get_micrograph_reader(str(park))(str(park))
    assert "µm" in kwargs["name"] and data.shape == (512, 512)
    assert kwargs["metadata"]["contactscope"]["format"] == "park-tiff"


# In the viewer ------------------------------------------------------------------------------

@pytest.fixture
def viewer():
    v = napari.Viewer(show=False)
    v.window.resize(1280, 820)
    yield v
    v.close()


def _docs_image(image, name):
    """Write a screenshot for docs/napari.md when CONTACTSCOPE_DOCS_IMAGES names a folder."""
    folder = os.environ.get("CONTACTSCOPE_DOCS_IMAGES")
    if folder:
        from PIL import Image

        # 256 colours keep a screenshot of the viewer small (< 300 kB) and legible.
        Image.fromarray(image[..., :3]).quantize(256).save(pathlib.Path(folder) / name,
                                                           optimize=True)


def _wait(widget):
    """Let the viewer's event loop run until the widget's worker has finished (the widget
    enables its button again when the worker's `finished` signal arrives)."""
    from qtpy.QtWidgets import QApplication

    for _ in range(1_000_000):
        if widget.run_button.isEnabled():
            return
        QApplication.processEvents()
    pytest.fail("the worker did not finish")


@needs_napari
@needs_display
def test_open_czi_in_viewer_with_scale(viewer):
    czi = real("real-formats/czi/CellDivision_T3_Z5_CH2_X240_Y170.czi")
    # No plugin named, as `napari file.czi` opens it (plugin=None: napari picks the one
    # compatible reader; viewer.open's own default would be napari's built-in reader).
    layers = viewer.open(str(czi), plugin=None)
    assert len(layers) == 2
    px = cs.info(czi)["series"][0]["pixel_size_m"]
    assert layers[0].scale[-1] == pytest.approx(px["x"] * 1e6)
    assert str(layers[0].units[-1]) == "micrometer"
    viewer.dims.set_point(0, 1)
    viewer.dims.set_point(1, 2)
    viewer.reset_view()
    image = viewer.screenshot(canvas_only=False)
    assert image[..., :3].std() > 1  # the micrograph is drawn, not a blank canvas
    _docs_image(image, "napari-czi.png")


@needs_napari
@needs_display
def test_napari_ome_zarr_opens_our_store_with_the_contact_labels(viewer, series_tif, tmp_path,
                                                                  cli):
    pytest.importorskip("napari_ome_zarr")
    store = _store_with_masks(series_tif, tmp_path, cli)
    layers = viewer.open(str(store), plugin="napari-ome-zarr")
    kinds = {type(layer).__name__: layer for layer in layers}
    assert set(kinds) == {"Image", "Labels"}, kinds
    image, labels = kinds["Image"], kinds["Labels"]
    # The labels lie on the image: same shape, same scale (0.2 µm pixels).
    assert labels.data[0].shape == image.data[0].shape if labels.multiscale else True
    assert list(labels.scale[-2:]) == pytest.approx([0.2, 0.2])
    assert list(image.scale[-2:]) == pytest.approx([0.2, 0.2])
    masks = np.asarray(labels.data[0] if labels.multiscale else labels.data)
    rows = (tmp_path / "out" / "areas.csv").read_text().splitlines()
    header = rows[0].split(",")
    pixels = [int(r.split(",")[header.index("contact_pixels")]) for r in rows[1:]]
    assert masks.reshape(len(pixels), -1).sum(axis=1).tolist() == pixels
    # napari-ome-zarr adds the labels it finds beside an image hidden; shown, the contact is
    # drawn in the label's colour (magenta) over the micrograph.
    labels.visible = True
    viewer.dims.set_point(0, 2)
    viewer.reset_view()
    shot = viewer.screenshot(canvas_only=False)
    _docs_image(shot, "napari-ome-zarr-labels.png")
    magenta = (shot[..., 0] > 150) & (shot[..., 1] < 120) & (shot[..., 2] > 150)
    assert magenta.sum() > 1000


@needs_napari
@needs_display
def test_series_widget_exports_the_cli_folder(viewer, series_tif, tmp_path, cli):
    from contactscope.napari.series_widget import LoadSeriesWidget

    path, s = series_tif
    w = LoadSeriesWidget(viewer)
    viewer.window.add_dock_widget(w)
    w.paths.setText(str(path))
    w.forces.setText("2,4,8mN")
    assert w.start() is not None  # the viewer's way: a worker thread
    _wait(w)
    assert w.outcome is not None, w.status.text()
    result = w.outcome["result"]
    # Layers: the masks and their edges over the micrographs, as the Rust analysis gave them.
    masks = viewer.layers["contact mask"].data
    np.testing.assert_array_equal(masks, cs.analyze(cs.read_series(path, forces=FORCES),
                                                    masks=True).masks)
    assert viewer.layers["contact edges"].contour == 1
    assert w.table.rowCount() == 3
    assert float(w.table.item(2, 2).text()) == pytest.approx(result.rows[2]["area_m2"] * 1e12,
                                                              abs=0.005)
    # The corrected area and its 95 % interval on the true area beside it, as the analysis
    # gave them.
    corrected = float(w.table.item(2, 3).text())
    assert corrected == pytest.approx(result.rows[2]["area_corrected_m2"] * 1e12, abs=0.005)
    lo, hi = (float(v) for v in w.table.item(2, 4).text().split("…"))
    assert lo == pytest.approx(result.rows[2]["area_m2_lo"] * 1e12, abs=0.005)
    assert hi == pytest.approx(result.rows[2]["area_m2_hi"] * 1e12, abs=0.005)
    assert lo <= corrected <= hi
    mine, theirs = tmp_path / "widget", tmp_path / "cli"
    written = w.export_now(str(mine))["written"]
    assert {pathlib.Path(p).name for p in written} >= {"areas.csv", "summary.json",
                                                       "area_vs_load.png", "area_vs_load.svg"}
    cli("analyze", str(path), "--forces", "2,4,8mN", "--out", str(theirs))
    # areas.csv byte for byte; summary.json equal but for the program's name.
    assert (mine / "areas.csv").read_bytes() == (theirs / "areas.csv").read_bytes()
    a = json.loads((mine / "summary.json").read_text())
    b = json.loads((theirs / "summary.json").read_text())
    # The recorded command is the command line's equivalent (its own --out folder).
    assert a.pop("command_line")[1:] == \
        [str(w) for w in ("analyze", path, "--forces", "2,4,8mN", "--out", mine)]
    assert b.pop("command_line")[1:-1] == ["analyze", str(path), "--forces", "2,4,8mN", "--out"]
    assert a == b
    assert (mine / "area_vs_load.svg").read_bytes() == (theirs / "area_vs_load.svg").read_bytes()


@needs_napari
@needs_display
@pytest.mark.parametrize("threshold", ["per-image", "1500"])
def test_series_widget_threshold_and_pixel_size_as_the_cli(viewer, series_tif, tmp_path, cli,
                                                           threshold):
    """The widget's threshold and pixel-size fields are the command line's --threshold and
    --pixel-size: the same areas.csv byte for byte, the same command recorded."""
    from contactscope.napari.series_widget import LoadSeriesWidget

    path, _ = series_tif
    w = LoadSeriesWidget(viewer)
    w.paths.setText(str(path))
    w.forces.setText("2,4,8mN")
    w.threshold.setText(threshold)
    w.pixel_size.setText("250nm")
    result = w.run_now()["result"]
    assert result["threshold"]["method"] != "otsu-global"
    # 250 nm pixels: each area is its contact pixels × 0.0625 µm².
    for r in result.rows:
        assert r["area_m2"] == pytest.approx(r["contact_pixels"] * 0.0625e-12, rel=1e-12)
    assert viewer.layers["contact mask"].scale[-1] == pytest.approx(0.25)
    mine, theirs = tmp_path / "widget", tmp_path / "cli"
    w.export_now(str(mine))
    cli("analyze", str(path), "--forces", "2,4,8mN", "--threshold", threshold, "--pixel-size",
        "250nm", "--out", str(theirs))
    assert (mine / "areas.csv").read_bytes() == (theirs / "areas.csv").read_bytes()
    a = json.loads((mine / "summary.json").read_text())
    b = json.loads((theirs / "summary.json").read_text())
    assert a.pop("command_line")[1:-1] == b.pop("command_line")[1:-1]
    # Where the pixel size came from, each in its own front-end's words.
    assert a["inputs"]["pixel_size_used"].pop("source") == "given (pixel_size=)"
    assert b["inputs"]["pixel_size_used"].pop("source") == "command line (--pixel-size)"
    assert a == b


@needs_napari
@needs_display
def test_series_widget_refuses_a_bad_threshold_or_pixel_size(viewer, series_tif, monkeypatch):
    from contactscope.napari import series_widget
    from contactscope.napari.series_widget import LoadSeriesWidget

    shown = []
    monkeypatch.setattr(series_widget, "notify_error", shown.append)
    path, _ = series_tif
    w = LoadSeriesWidget(viewer)
    w.paths.setText(str(path))
    w.forces.setText("2,4,8mN")
    w.threshold.setText("bright")
    assert w.start() is None
    assert "bright" in shown[-1] and "\n" not in shown[-1]
    w.threshold.setText("")
    w.pixel_size.setText("200")  # no unit
    assert w.start() is None
    assert "200" in shown[-1] and "\n" not in shown[-1]


@needs_napari
@needs_display
def test_series_widget_manifest_matches_cli(viewer, series_tif, tmp_path, cli):
    from contactscope.napari.series_widget import LoadSeriesWidget

    path, _ = series_tif
    manifest = tmp_path / "m.csv"
    manifest.write_text("file,page,force_mN\n" + "".join(
        f"{path},{i},{f * 1e3:g}\n" for i, f in enumerate(FORCES)), encoding="utf-8")
    w = LoadSeriesWidget(viewer)
    w.paths.setText(str(manifest))
    w.run_now()
    w.export_now(str(tmp_path / "widget"))
    cli("analyze", "--manifest", str(manifest), "--out", str(tmp_path / "cli"))
    assert (tmp_path / "widget" / "areas.csv").read_bytes() == \
        (tmp_path / "cli" / "areas.csv").read_bytes()


@needs_napari
@needs_display
def test_three_clicks_from_a_czi(viewer, tmp_path, cli):
    # Open the file, pick its layer in the dock widget (channel and load axis t come from the
    # layer; the Z plane from the widget's own z box, never the viewer's slider), type the
    # forces, Analyze.
    from contactscope.napari.series_widget import LoadSeriesWidget

    czi = real("real-formats/czi/CellDivision_T3_Z5_CH2_X240_Y170.czi")
    viewer.open(str(czi), plugin="contactscope")
    viewer.dims.set_point(1, 2 * 0.32)  # the Z slider on plane 2 (z step 0.32 µm)
    w = LoadSeriesWidget(viewer)
    viewer.window.add_dock_widget(w, name="Load series (contact area)")
    w.source.setCurrentText("CellDivision_T3_Z5_CH2_X240_Y170 C1")
    assert w.load_axis.currentText() == "t"
    # The slider stands on plane 2; the widget says it analyses plane 0 until told otherwise.
    assert (w.selection["channel"].value(), w.selection["z"].value()) == (1, 0)
    assert "z plane 0 of 5" in w.status.text() and "slider" in w.status.text()
    w.selection["z"].setValue(2)
    viewer.dims.set_point(1, 4 * 0.32)  # moving the slider changes nothing
    assert w.selection["z"].value() == 2
    assert w.selection["series"].value() == -1  # one series: no --series, as on the CLI
    w.forces.setText("4,40,400mN")
    w.run_now()
    # The masks in the file's axes (T, Z, y, x), on the Z plane analysed.
    mask = viewer.layers["contact mask"]
    assert mask.data.shape == (3, 1, 170, 240)
    assert mask.translate[1] == pytest.approx(2 * 0.32)
    assert "contact micrographs" not in viewer.layers
    assert w.table.rowCount() == 3
    words = json.loads(w.export_now(str(tmp_path / "w2")) and
                       (tmp_path / "w2" / "summary.json").read_text())["command_line"]
    assert words == ["contactscope", "analyze", str(czi), "--forces", "4,40,400mN",
                     "--channel", "1", "--z", "2", "--load-axis", "t", "--out",
                     str(tmp_path / "w2")]
    cli("analyze", str(czi), "--forces", "4,40,400mN", "--channel", "1", "--z", "2",
        "--load-axis", "t", "--out", str(tmp_path / "c2"))
    assert (tmp_path / "w2" / "areas.csv").read_bytes() == \
        (tmp_path / "c2" / "areas.csv").read_bytes()
    viewer.dims.set_point(0, 2)
    viewer.reset_view()
    _docs_image(viewer.screenshot(canvas_only=False), "napari-czi-series.png")


@needs_napari
@needs_display
def test_sample_and_widget_on_a_layer(viewer):
    from contactscope.napari.series_widget import LoadSeriesWidget

    layers = viewer.open_sample("contactscope", "synthetic_series")
    assert [layer.name for layer in layers] == ["synthetic series (4–100 mN)", "true contact"]
    s = cs.synth_series()
    np.testing.assert_array_equal(layers[0].data, s.images)
    assert layers[0].metadata["contactscope"]["forces_n"] == pytest.approx(s.forces_n)
    w = LoadSeriesWidget(viewer)
    viewer.window.add_dock_widget(w, name="Load series (contact area)")
    w.source.setCurrentText(layers[0].name)
    outcome = w.run_now()  # forces and pixel size from the layer
    ref = cs.analyze(s.images, s.forces_n, 200e-9, masks=True)
    assert [r["area_m2"] for r in outcome["result"]["rows"]] == [r["area_m2"] for r in ref.rows]
    np.testing.assert_array_equal(viewer.layers["contact edges"].data, ref.masks)
    assert "contact micrographs" not in viewer.layers  # drawn over the sample's own layer
    viewer.dims.set_point(0, 7)
    viewer.reset_view()
    image = viewer.screenshot(canvas_only=False)
    assert image.shape[0] > 400 and image[..., :3].std() > 1
    _docs_image(image, "napari-series.png")


@needs_napari
@needs_display
def test_compare_widget_layers_and_dice(viewer, series_tif, tmp_path, cli, hardening_sim):
    from contactscope.napari.compare_widget import CompareWidget

    path, _ = series_tif
    sim = hardening_sim
    w = CompareWidget(viewer)
    viewer.window.add_dock_widget(w)
    w.simulation.setText(str(sim))
    w.paths.setText(str(path))
    w.forces.setText("2,4,8mN")
    assert w.start() is not None
    _wait(w)
    assert w.outcome is not None, w.status.text()
    result = w.outcome["result"]
    # The scores are the command line's; the layers are what they were computed on.
    cli("compare", "--micrographs", path, "--forces", "2,4,8mN", "--simulation", sim,
        "--psf-fwhm", "450nm", "--out", tmp_path / "cmp")
    theirs = json.loads((tmp_path / "cmp" / "compare.json").read_text())
    assert [r["dice"] for r in result["loads"]] == pytest.approx(
        [r["dice"] for r in theirs["loads"]], abs=1e-12)
    exp = viewer.layers["experiment contact edges"].data.astype(bool)
    simulated = viewer.layers["sim: contact edges"].data.astype(bool)
    for i, r in enumerate(result["loads"]):
        dice = 2 * (exp[i] & simulated[i]).sum() / (exp[i].sum() + simulated[i].sum())
        assert dice == pytest.approx(r["dice"], abs=1e-12)
        assert w.table.item(i, 0).text() == "sim"
        assert float(w.table.item(i, 3).text()) == pytest.approx(r["dice"], abs=5e-4)
    assert viewer.layers["sim: imaged"].data.shape == (3, 160, 160)  # the micrographs' grid
    canvas = getattr(viewer, "canvas", None)
    assert (getattr(canvas, "grid", None) or viewer.grid).enabled


@needs_napari
@needs_display
def test_compare_widget_on_the_demo_experiment(viewer, tmp_path, cli, monkeypatch):
    # The demo's experiment (micrographs imaged from a hardening simulation, k = 4 MPa/nm)
    # against two models side by side, as the paper's Fig. 2: the same hardening model matches
    # the micrographs (the demo reports Dice 0.97), the elastic one less well.
    from contactscope.napari.compare_widget import CompareWidget

    monkeypatch.chdir(tmp_path)  # relative paths, as a person types them
    cli("demo", "--small", "--out", "demo", "-q")
    common = ["--topography", "demo/data/topography.npy", "--pixel-size", "80nm", "--radius",
              "50um", "--modulus", "3.7GPa", "--forces", "0.05,0.1,0.2,0.35mN", "-q"]
    cli("simulate", *common, "--model", "elastic", "--out", "elastic")
    cli("simulate", *common, "--model", "hardening", "--hardening", "4MPa/nm", "--out",
        "hardening")
    w = CompareWidget(viewer)
    viewer.window.add_dock_widget(w, name="Compare with simulation")
    w.simulation.setText("elastic;hardening")
    w.paths.setText("demo/data/micrographs/manifest.csv")
    results = dict(w.run_now()["results"])
    assert list(results) == ["elastic", "hardening"]
    for name, result in results.items():
        assert result["loads_matched"] == 4
        cli("compare", "--micrographs", "demo/data/micrographs/manifest.csv", "--simulation",
            name, "--psf-fwhm", "450nm", "--out", f"cmp-{name}")
        theirs = json.loads((tmp_path / f"cmp-{name}" / "compare.json").read_text())
        assert result["dice_mean"] == pytest.approx(theirs["dice_mean"], abs=1e-12)
        assert viewer.layers[f"{name}: imaged"].data.shape[0] == 4
    assert results["hardening"]["dice_mean"] > 0.9
    assert results["hardening"]["dice_mean"] > results["elastic"]["dice_mean"]
    assert w.table.rowCount() == 8
    assert [w.table.item(i, 0).text() for i in (0, 4)] == ["elastic", "hardening"]
    # A second comparison replaces this widget's layers, not others'.
    w.simulation.setText("hardening")
    w.run_now()
    assert "elastic: imaged" not in viewer.layers and "hardening: imaged" in viewer.layers
    w.simulation.setText("elastic;hardening")
    w.run_now()
    # Export: the command line's compare folder per model, by its own writer.
    folders = w.export_now(str(tmp_path / "exported"))
    assert [pathlib.Path(f).name for f in folders] == ["compare-elastic", "compare-hardening"]
    for name, folder in zip(results, map(pathlib.Path, folders)):
        theirs = tmp_path / f"cmp-{name}"
        assert (folder / "compare.csv").read_bytes() == (theirs / "compare.csv").read_bytes()
        a = json.loads((folder / "compare.json").read_text())
        b = json.loads((theirs / "compare.json").read_text())
        assert a.pop("command_line")[1:-1] == b.pop("command_line")[1:-1]
        assert a == b
        assert sorted(p.name for p in folder.glob("panel_*.png")) == \
            sorted(p.name for p in theirs.glob("panel_*.png")) != []
    viewer.dims.set_point(0, 3)
    viewer.reset_view()
    _docs_image(viewer.screenshot(canvas_only=False), "napari-compare.png")


@needs_napari
@needs_display
def test_widget_errors_are_one_line(viewer, tmp_path, monkeypatch):
    from contactscope.napari import series_widget
    from contactscope.napari.series_widget import LoadSeriesWidget

    shown = []
    monkeypatch.setattr(series_widget, "notify_error", shown.append)
    w = LoadSeriesWidget(viewer)
    w.paths.setText(str(tmp_path / "missing.tif"))
    w.forces.setText("4,10,oops")
    assert w.start() is None  # the forces are refused before any work
    assert "oops" in shown[-1] and "\n" not in shown[-1]
    w.forces.setText("4mN")
    assert w.start() is not None
    _wait(w)
    assert "missing.tif" in shown[-1] and "\n" not in shown[-1]
    assert w.status.text().startswith("error: ")
