"""A TIFF's planes read by the axes its metadata states, as tifffile reads them
(``series[0].axes``), over a matrix of axis orders and sizes; arrays on the wrong axis refused
or warned of."""

import pathlib

import numpy as np
import pytest

import contactscope as cs

tifffile = pytest.importorskip("tifffile")

SIZES = {"T": 3, "Z": 2, "C": 2, "Y": 12, "X": 10}


def _data(axes):
    """Every plane distinct: its values encode its position."""
    shape = tuple(SIZES[a] for a in axes)
    planes = int(np.prod(shape[:-2]))
    base = (np.arange(planes, dtype=np.uint16) * 100 + 200).reshape(shape[:-2] + (1, 1))
    ramp = np.arange(SIZES["Y"] * SIZES["X"], dtype=np.uint16).reshape(SIZES["Y"], SIZES["X"])
    return (base + ramp % 50).astype(np.uint16)


def _plane(data, axes, t, z, c):
    index = tuple({"T": t, "Z": z, "C": c}.get(a, slice(None)) for a in axes)
    return data[index]


OME_AXES = ["TCYX", "CTYX", "TZCYX", "ZTCYX", "CZTYX", "TZYX", "ZCYX"]
IMAGEJ_AXES = ["TZCYX", "TCYX", "ZCYX", "TZYX", "CYX", "TYX"]


@pytest.mark.parametrize("writer,axes", [("ome", a) for a in OME_AXES]
                         + [("imagej", a) for a in IMAGEJ_AXES])
def test_planes_match_tifffile(tmp_path, writer, axes):
    path = tmp_path / f"{writer}_{axes}.tif"
    data = _data(axes)
    if writer == "ome":
        tifffile.imwrite(path, data, ome=True, metadata={"axes": axes})
    else:
        tifffile.imwrite(path, data, imagej=True, metadata={"axes": axes})
    series = tifffile.TiffFile(path).series[0]
    assert series.axes == axes, series.axes
    info = cs.info(path)["series"][0]["axes"]
    for a in "TZC":
        assert info[a] == SIZES[a] if a in axes else info[a] == 1, (a, info)
    ts = range(SIZES["T"]) if "T" in axes else [0]
    zs = range(SIZES["Z"]) if "Z" in axes else [0]
    cs_ = range(SIZES["C"]) if "C" in axes else [0]
    for t in ts:
        for z in zs:
            for c in cs_:
                got = cs.read_series(path, channel=c if "C" in axes else None,
                                     z=z if "Z" in axes else None,
                                     t=t if "T" in axes else None)["images"]
                assert got.shape == (1, SIZES["Y"], SIZES["X"])
                np.testing.assert_array_equal(got[0], _plane(data, axes, t, z, c),
                                              err_msg=f"t {t} z {z} c {c}")
    # Along the time points, one focal plane and channel: the planes tifffile gives.
    if "T" in axes:
        got = cs.read_series(path, channel=1 if "C" in axes else None,
                             z=1 if "Z" in axes else None, load_axis="t")["images"]
        want = np.stack([_plane(data, axes, t, 1, 1) for t in ts])
        np.testing.assert_array_equal(got, want)


def test_a_channel_by_its_ome_name(tmp_path):
    path = tmp_path / "named.ome.tif"
    data = _data("TCYX")
    tifffile.imwrite(path, data, ome=True,
                     metadata={"axes": "TCYX", "Channel": {"Name": ["fluo", "refl"]}})
    got = cs.read_series(path, channel="refl")["images"]
    np.testing.assert_array_equal(got, data[:, 1])
    with pytest.raises(cs.InputError, match="'fluo'"):
        cs.read_series(path)


def test_each_image_of_a_multi_image_ome_tiff_is_tifffiles_series(tmp_path):
    """Images written one after another into one OME-TIFF (stage positions): series k is
    tifffile's ``series[k]``, with its own axes and pixel size; none is read unchosen."""
    path = tmp_path / "positions.ome.tif"
    first, second = _data("TCYX"), _data("ZYX")[:, :8, :6]
    with tifffile.TiffWriter(path, ome=True) as w:
        w.write(first, metadata={"axes": "TCYX", "Name": "left"})
        w.write(second, metadata={"axes": "ZYX", "Name": "right",
                                  "PhysicalSizeX": 0.1, "PhysicalSizeY": 0.1})
    with tifffile.TiffFile(path) as f:
        want = [s.asarray() for s in f.series]
        assert [s.axes for s in f.series] == ["TCYX", "ZYX"]
    info = cs.info(path)["series"]
    assert [s["name"] for s in info] == ["left", "right"]
    assert (info[1]["axes"]["Z"], info[1]["axes"]["Y"], info[1]["axes"]["X"]) == (2, 8, 6)
    assert info[1]["pixel_size_m"]["x"] == pytest.approx(1e-7)
    with pytest.raises(cs.InputError, match="'right'"):
        cs.read_series(path, channel=0, load_axis="t")
    got = cs.read_series(path, series=0, channel=1, load_axis="t")["images"]
    np.testing.assert_array_equal(got, want[0][:, 1])
    got = cs.read_series(path, series=1, load_axis="z")
    np.testing.assert_array_equal(got["images"], want[1])
    assert got["pixel_size_m"][0] == pytest.approx(1e-7)


def test_rgb_arrays_are_refused_and_loads_last_warned_of():
    rgb = np.zeros((64, 48, 3), np.uint16)
    with pytest.raises(cs.InputError, match="rgb_to_gray"):
        cs.otsu_threshold(rgb)
    gray = cs.rgb_to_gray(rgb)
    assert gray.shape == (64, 48)
    stack = np.zeros((5, 64, 64), np.uint16)
    stack[:, 20:40, 20:40] = 3000
    with pytest.warns(cs.ContactscopeWarning, match="np.moveaxis"):
        cs.otsu_threshold(np.moveaxis(stack, 0, -1))


SHARED = pathlib.Path(__file__).resolve().parents[2].parent / "shared" / "data"


def test_every_shared_tiff_has_tifffiles_axes():
    """The real and synthetic TIFFs beside the checkout: T, Z and C as tifffile's
    ``series[0]`` (its unlabelled page axes I and Q are our time points, its samples S our
    channels)."""
    files = sorted(SHARED.glob("real-tiff/**/*.tif*")) + \
        sorted(SHARED.glob("synthetic-tiff-formats/*.tif"))
    if not files:
        pytest.skip(f"{SHARED} not found (the shared test data sits beside the checkout)")
    compared = 0
    for path in files:
        if path.name == "m_packed12.tif":  # packed 12-bit: refused by design
            continue
        s = tifffile.TiffFile(path).series[0]
        want = {k: (s.shape[s.axes.index(k)] if k in s.axes else 1) for k in "TZC"}
        for unlabelled in "IQ":
            if unlabelled in s.axes:
                want["T"] = s.shape[s.axes.index(unlabelled)]
        if "S" in s.axes:
            want["C"] = s.shape[s.axes.index("S")]
        got = {k: v for k, v in cs.info(path)["series"][0]["axes"].items() if k in "TZC"}
        assert got == want, (path.name, s.axes, got)
        compared += 1
    assert compared > 20


def _ome_set_xml(names, sizes):
    """The OME-XML every file of a two-file set carries (OME-TIFF specification, multi-file
    datasets): DimensionOrder XYCZT, the first half of the time points in ``names[0]``."""
    t, c, y, x = sizes
    half = t // 2 * c
    uuids = [f"urn:uuid:00000000-0000-4000-8000-00000000000{k}" for k in (1, 2)]
    blocks = "".join(
        f'<TiffData FirstT="{k * (t // 2)}" IFD="0" PlaneCount="{half}">'
        f'<UUID FileName="{name}">{uuid}</UUID></TiffData>'
        for k, (name, uuid) in enumerate(zip(names, uuids))
    )
    channels = "".join(f'<Channel ID="Channel:0:{k}" SamplesPerPixel="1"/>' for k in range(c))
    return (
        '<?xml version="1.0" encoding="UTF-8"?>'
        '<OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06" '
        f'UUID="{uuids[0]}"><Image ID="Image:0"><Pixels ID="Pixels:0" DimensionOrder="XYCZT" '
        f'Type="uint16" SizeX="{x}" SizeY="{y}" SizeC="{c}" SizeZ="1" SizeT="{t}">'
        f"{channels}{blocks}</Pixels></Image></OME>"
    )


def test_a_multi_file_ome_set_reads_as_tifffile_reads_it(tmp_path):
    """A set of two files, time points split between them: read from either file, every
    channel's planes are tifffile's ``series[0]`` of the set."""
    t, c, y, x = 4, 2, SIZES["Y"], SIZES["X"]
    base = (np.arange(t * c, dtype=np.uint16) * 100 + 200).reshape(t, c, 1, 1)
    data = (base + np.arange(y * x, dtype=np.uint16).reshape(y, x) % 50).astype(np.uint16)
    names = ["set_0.ome.tif", "set_1.ome.tif"]
    xml = _ome_set_xml(names, data.shape)
    for k, name in enumerate(names):
        pages = data[k * (t // 2):(k + 1) * (t // 2)].reshape(-1, y, x)
        with tifffile.TiffWriter(tmp_path / name) as w:
            for j, page in enumerate(pages):
                w.write(page, description=xml if j == 0 else None, metadata=None)
    reference = tifffile.TiffFile(tmp_path / names[0]).series[0]
    assert reference.axes == "TCYX" and reference.shape == data.shape
    np.testing.assert_array_equal(reference.asarray(), data)
    for name in names:
        for channel in range(c):
            got = cs.read_series(tmp_path / name, channel=channel)["images"]
            np.testing.assert_array_equal(got, data[:, channel], err_msg=f"{name} c {channel}")


def test_a_set_whose_metadata_is_a_companion_file_reads_whole(tmp_path):
    """The set's OME-XML in ``set.companion.ome``, each TIFF's own XML only pointing to it
    (``BinaryOnly``, as Bio-Formats writes such a set): read from either TIFF or from the
    companion, every channel's planes are the planes written. (tifffile reads each TIFF of such
    a set alone, so the reference here is the array written.)"""
    t, c, y, x = 4, 2, SIZES["Y"], SIZES["X"]
    base = (np.arange(t * c, dtype=np.uint16) * 100 + 200).reshape(t, c, 1, 1)
    data = (base + np.arange(y * x, dtype=np.uint16).reshape(y, x) % 50).astype(np.uint16)
    names = ["set_0.ome.tif", "set_1.ome.tif"]
    xml = _ome_set_xml(names, data.shape)
    (tmp_path / "set.companion.ome").write_text(xml)
    uuid = "urn:uuid:00000000-0000-4000-8000-000000000001"
    pointer = (
        '<?xml version="1.0" encoding="UTF-8"?>'
        '<OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06" '
        'UUID="urn:uuid:00000000-0000-4000-8000-0000000000ff">'
        f'<BinaryOnly MetadataFile="set.companion.ome" UUID="{uuid}"/></OME>'
    )
    for k, name in enumerate(names):
        pages = data[k * (t // 2):(k + 1) * (t // 2)].reshape(-1, y, x)
        with tifffile.TiffWriter(tmp_path / name) as w:
            for j, page in enumerate(pages):
                w.write(page, description=pointer if j == 0 else None, metadata=None)
    for source in [*names, "set.companion.ome"]:
        assert cs.info(tmp_path / source)["series"][0]["axes"]["T"] == t, source
        for channel in range(c):
            got = cs.read_series(tmp_path / source, channel=channel)["images"]
            np.testing.assert_array_equal(got, data[:, channel], err_msg=f"{source} c {channel}")


def test_a_companion_naming_one_image_per_file_reads_each_image(tmp_path):
    """A companion file describing two images (stage positions), each stored in a TIFF of its
    own that only points to the companion: read from the companion or from either TIFF, series
    k is image k's planes, named as the companion names it."""
    ns = "http://www.openmicroscopy.org/Schemas/OME/2016-06"
    uuid = "urn:uuid:00000000-0000-4000-8000-000000000001"
    pointer = (f'<?xml version="1.0" encoding="UTF-8"?><OME xmlns="{ns}">'
               f'<BinaryOnly MetadataFile="set.companion.ome" UUID="{uuid}"/></OME>')
    names = ["posA.ome.tif", "posB.ome.tif"]
    written, images = [], ""
    for k, name in enumerate(names):
        data = _data("TYX")[:, :, k:]  # the two images differ in width too
        written.append(data)
        with tifffile.TiffWriter(tmp_path / name) as w:
            for j, page in enumerate(data):
                w.write(page, description=pointer if j == 0 else None, metadata=None)
        t, y, x = data.shape
        images += (
            f'<Image ID="Image:{k}" Name="{name[:4]}"><Pixels ID="Pixels:{k}" '
            f'DimensionOrder="XYCZT" Type="uint16" SizeX="{x}" SizeY="{y}" SizeC="1" SizeZ="1" '
            f'SizeT="{t}"><Channel ID="Channel:{k}:0" SamplesPerPixel="1"/>'
            f'<TiffData IFD="0" PlaneCount="{t}"><UUID FileName="{name}">'
            f"urn:uuid:00000000-0000-4000-8000-00000000001{k}</UUID></TiffData></Pixels></Image>")
    (tmp_path / "set.companion.ome").write_text(
        f'<?xml version="1.0" encoding="UTF-8"?><OME xmlns="{ns}" UUID="{uuid}">{images}</OME>')
    for source in ["set.companion.ome", *names]:
        info = cs.info(tmp_path / source)["series"]
        assert [s["name"] for s in info] == ["posA", "posB"], source
        for k in range(2):
            got = cs.read_series(tmp_path / source, series=k, load_axis="t")["images"]
            np.testing.assert_array_equal(got, written[k], err_msg=f"{source} series {k}")
        with pytest.raises(cs.InputError, match="'posB'"):
            cs.read_series(tmp_path / source, load_axis="t")
