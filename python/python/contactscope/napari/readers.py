"""napari readers for what contactscope reads, through its Rust core (no second file parser).

Micrographs: TIFF (ImageJ hyperstacks, OME-TIFF and plain multi-page files), Zeiss CZI, Nikon
ND2 and Leica LIF, each read with :func:`contactscope.info` (series, axes, voxel size) and
:func:`contactscope.read_image` (planes in their stored sample type); a folder of TIFFs opens as
one stack in natural order (:func:`contactscope.read_series`, as the command line reads a load
series). One image layer per series and channel, with the T, Z and extra axes (e.g. an Airyscan
``H`` or a LIF ``lambda_emission``) that have more than one plane, the scale in µm from the
file's pixel size (1 where the file does not state it) and the file's name and series name.

Height maps: AFM and profilometer files (Igor ibw, Nanosurf nid, PicoView mi, Gwyddion gwy,
X3P, SDF, Wyko opd, Sensofar plu, Digital Surf sur and mnt, FRT, GSF, WSxM top/stp, Nanoscope
di/spm/001, Nanonis sxm, TopoStats, JPK TIFF and HDF5, surfalize sflz, Keyence zon, Createc and Zygo MetroPro dat
(recognised by their first bytes: .dat is a common name), Alicona al3d, TrueMap tmd, NanoFocus nms, Image Metrology bcr/bcrf, Vision64 opdx,
NetCDF nc, HDF5 h5, Park TIFF) through :func:`contactscope.read_topography`, as the command line's ``topography``
reads them (plane-levelled, its default): one image layer of heights in µm, scale in µm.

A file contactscope cannot read gives napari's ordinary "no reader" path (``get_*_reader``
returns ``None``) with contactscope's one-line message as an error notification; no Rust
message reaches the user as a traceback.
"""

from __future__ import annotations

import itertools
import os
import warnings
from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np

import contactscope as cs

from ._common import ERRORS, META, guarded, layer_meta, notify_error, one_line, stem, um

LayerData = Tuple[Any, Dict[str, Any], str]
# What napari hands a reader: one path, or a list of them.
PathOrPaths = Union[str, List[str], Tuple[str, ...]]
Reader = Callable[[PathOrPaths], Optional[List[LayerData]]]

# `.ome`: an OME-TIFF set's companion file (`NAME.companion.ome`), which opens the set.
MICROGRAPH_EXTENSIONS = (".tif", ".tiff", ".czi", ".nd2", ".lif", ".zarr", ".ome")
TIFF_EXTENSIONS = (".tif", ".tiff")
TOPOGRAPHY_EXTENSIONS = (".ibw", ".nid", ".mi", ".gwy", ".x3p", ".sdf", ".opd", ".plu", ".sur",
                         ".frt", ".gsf", ".top", ".stp", ".di", ".spm", ".001", ".al3d", ".tmd",
                         ".nms", ".bcr", ".bcrf", ".mnt", ".opdx", ".nc", ".h5", ".sxm", ".topostats", ".jpk",
                         ".jpk-qi-image", ".sflz", ".h5-jpk", ".zon")


CHANNEL_COLOURS = ("green", "magenta", "cyan", "yellow", "red", "blue", "gray")


def _ext(path: str) -> str:
    return os.path.splitext(os.fspath(path))[1].lower()


def _is_zarr_store(path: str) -> bool:
    """A folder holding Zarr metadata at its root (an OME-Zarr image, plate or bioformats2raw
    output): one micrograph file, not a folder of them."""
    return os.path.isdir(path) and any(
        os.path.isfile(os.path.join(path, n)) for n in ("zarr.json", ".zgroup", ".zattrs"))


def _micrographs_in(folder: str) -> List[str]:
    return [n for n in os.listdir(folder)
            if _ext(n) in MICROGRAPH_EXTENSIONS
            and (_ext(n) != ".zarr" or _is_zarr_store(os.path.join(folder, n)))]


def get_micrograph_reader(path: PathOrPaths) -> Optional[Reader]:
    """The reader of a micrograph file, a folder of micrographs or a list of micrograph files;
    ``None`` (napari's "no reader") for anything else or a file contactscope cannot open."""
    if isinstance(path, (list, tuple)):
        paths = [os.fspath(p) for p in path]
        if not paths or any(_ext(p) not in MICROGRAPH_EXTENSIONS for p in paths):
            return None
        return read_stack
    path = os.fspath(path).rstrip("/\\") or os.fspath(path)
    if os.path.isdir(path) and not _is_zarr_store(path):
        return read_stack if _micrographs_in(path) else None
    if _ext(path) not in MICROGRAPH_EXTENSIONS and not _is_zarr_store(path):
        return None
    try:
        cs.info(path)
    except ERRORS as e:
        if _ext(path) in TIFF_EXTENSIONS:
            # A height map stored as TIFF (Park Systems) is no micrograph: try it as one.
            return read_topography_layers
        notify_error(f"contactscope cannot read {os.path.basename(path)}: {one_line(e)}")
        return None
    return read_micrographs


def get_topography_reader(path: PathOrPaths) -> Optional[Reader]:
    """The reader of an AFM or profilometer height map; ``None`` for anything else."""
    if isinstance(path, (list, tuple)):
        return None
    path = os.fspath(path)
    if os.path.isdir(path):
        return None
    if _ext(path) == ".dat":
        return read_topography_layers if _height_map_dat(path) else None
    if _ext(path) not in TOPOGRAPHY_EXTENSIONS:
        return None
    return read_topography_layers


# The first bytes of the `.dat` files that hold height maps: Zygo MetroPro (three header
# formats) and Createc images. Other `.dat` files are left to other readers.
DAT_HEIGHT_MAP_MAGIC = (b"\x88\x1b\x03\x6f", b"\x88\x1b\x03\x70", b"\x88\x1b\x03\x71",
                        b"[Paramco32]")


def _height_map_dat(path: str) -> bool:
    try:
        with open(path, "rb") as f:
            head = f.read(16)
    except OSError:
        return False
    return head.startswith(DAT_HEIGHT_MAP_MAGIC)


def read_micrographs(path: PathOrPaths) -> Optional[List[LayerData]]:
    """Every series of a micrograph file as image layers (one per channel)."""
    if isinstance(path, (list, tuple)):
        return [layer for p in path for layer in (read_micrographs(p) or [])]
    return guarded(f"reading {os.path.basename(path)}", lambda: micrograph_layers(path))


def read_stack(path: PathOrPaths) -> Optional[List[LayerData]]:
    """A folder of micrographs (or a list of files) as one stack, in natural order."""
    return guarded(f"reading {stem(path) if isinstance(path, str) else 'the files'}",
                   lambda: stack_layers(path))


def read_topography_layers(path: PathOrPaths) -> Optional[List[LayerData]]:
    """A height map as an image layer of heights in µm."""
    if isinstance(path, (list, tuple)):
        return [layer for p in path for layer in (read_topography_layers(p) or [])]
    return guarded(f"reading {os.path.basename(path)}", lambda: topography_layers(path))


def _planes_of_channel(path: str, fmt: str, series: int, channel: int,
                       sizes: Dict[str, int], extras: Dict[str, int],
                       shape: Tuple[int, int]) -> np.ndarray:
    """One channel of one series as (T, Z, extra axes…, Y, X)."""
    nt, nz = sizes["T"], sizes["Z"]
    # Every format, TIFF too, by the axes `info` gives (a TIFF's OME-XML or ImageJ axes).
    stacks = []
    for combo in itertools.product(range(nz), *[range(n) for n in extras.values()]):
        z, rest = combo[0], dict(zip(extras, combo[1:]))
        axes = rest or None
        if nt > 1:
            image = cs.read_image(path, series=series, channel=channel, z=z, axes=axes,
                                  load_axis="t")
        else:
            image = cs.read_image(path, series=series, channel=channel, z=z, axes=axes, t=0)
        stacks.append(image.images)
    data = np.stack(stacks, axis=1)  # (T, Z × extras, Y, X)
    return data.reshape(nt, nz, *extras.values(), *shape)


def micrograph_layers(path: str) -> List[LayerData]:
    """Layer data of a micrograph file: per series, one image layer per channel."""
    described = cs.info(path)
    fmt = described["format"]
    many = len(described["series"]) > 1
    layers: List[LayerData] = []
    for s in described["series"]:
        axes = dict(s["axes"])
        shape = (axes.pop("Y"), axes.pop("X"))
        sizes = {"T": axes.pop("T", 1), "Z": axes.pop("Z", 1)}
        channels = axes.pop("C", 1)
        extras = axes  # axes beyond T, Z, C, Y, X, by name, in the file's order
        data = np.stack([_planes_of_channel(path, fmt, s["index"], c, sizes, extras, shape)
                         for c in range(channels)])  # (C, T, Z, extras…, Y, X)
        px = s.get("pixel_size_m") or {}
        x_um, y_um, z_um = um(px.get("x")), um(px.get("y")), um(px.get("z"))
        labels = ["T", "Z", *extras]
        steps = [1.0, z_um or 1.0, *[1.0] * len(extras)]
        keep = [i for i, n in enumerate(data.shape[1:1 + len(labels)]) if n > 1]
        drop = tuple(1 + i for i in range(len(labels)) if i not in keep)
        data = data.squeeze(axis=drop) if drop else data
        labels = [labels[i] for i in keep] + ["y", "x"]
        scale = [steps[i] for i in keep] + [y_um or 1.0, x_um or 1.0]
        base = stem(path)
        if many:
            base += f" [{s['index']}{': ' + s['name'] if s.get('name') else ''}]"
        names = [f"{base} C{c}" if channels > 1 else base for c in range(channels)]
        meta = layer_meta(path=os.fspath(path), format=fmt, series=s["index"], axes=labels,
                          series_count=len(described["series"]), channels=channels,
                          pixel_size_m=None if x_um is None else (px["x"], px["y"]),
                          pixel_size_source=s.get("pixel_size_source"),
                          z_step_m=px.get("z"), dtype=s.get("dtype"))
        units = ["pixel" if x_um is None or a in ("T", *extras) or (a == "Z" and z_um is None)
                 else "µm" for a in labels]
        for c in range(channels):
            kwargs = {"name": names[c], "scale": scale, "axis_labels": labels, "units": units,
                      "metadata": {META: {**meta[META], "channel": c}}}
            if channels > 1:
                # Channels overlaid in colour, as a confocal viewer shows them.
                kwargs["colormap"] = CHANNEL_COLOURS[c % len(CHANNEL_COLOURS)]
                kwargs["blending"] = "additive"
            layers.append((data[c], kwargs, "image"))
    return layers


def stack_layers(path: PathOrPaths) -> List[LayerData]:
    """A folder of micrographs (or a list of files) as one (images, Y, X) stack."""
    inputs = [os.fspath(p) for p in path] if isinstance(path, (list, tuple)) else [os.fspath(path)]
    with warnings.catch_warnings():
        # Warnings about areas (no pixel size, no forces) concern an analysis, not a view;
        # the layer keeps them in its metadata.
        warnings.simplefilter("ignore", cs.ContactscopeWarning)
        series = cs.read_series(inputs)
    px = series["pixel_size_m"]
    name = stem(inputs[0]) if len(inputs) == 1 else f"{stem(inputs[0])} … ({len(inputs)} files)"
    scale = [1.0, 1.0, 1.0] if px is None else [1.0, px[1] * 1e6, px[0] * 1e6]
    units = ["pixel"] * 3 if px is None else ["pixel", "µm", "µm"]
    meta = layer_meta(path=inputs[0] if len(inputs) == 1 else None, inputs=inputs,
                      format="series", paths=list(series["paths"]), pages=list(series["pages"]),
                      forces_n=list(series["forces_n"]), pixel_size_m=px,
                      pixel_size_source=series["pixel_size_source"], axes=["image", "y", "x"],
                      warnings=list(series["warnings"]))
    return [(series["images"], {"name": name, "scale": scale, "units": units,
                                 "axis_labels": ["image", "y", "x"], "metadata": meta}, "image")]


def topography_layers(path: str) -> List[LayerData]:
    """A height map: heights in µm (plane-levelled, as the command line's default), scale µm."""
    try:
        t = cs.read_topography(path)
    except cs.InputError as e:
        if "invalid (not measured)" not in str(e):
            raise
        # Unmeasured points: shown filled with the nearest valid height (the name says so).
        t = cs.read_topography(path, fill_invalid="nearest")
    summary = t["summary"]
    px, py = t["pixel_size_m"]
    heights_um = np.asarray(t["heights"]) * 1e6
    meta = layer_meta(path=os.fspath(path), format=summary.get("format"),
                      channel=summary.get("channel"), pixel_size_m=(px, py),
                      height_unit="µm", detrend="plane", notes=list(t["notes"]),
                      h_rms_m=summary["detrended"]["h_rms_m"])
    channel = summary.get("channel")
    name = f"{stem(path)} {channel} (µm)" if channel else f"{stem(path)} height (µm)"
    invalid = summary["nx"] * summary["ny"] - summary["valid_points"]
    if invalid:
        name += f" [{invalid} unmeasured points filled]"
    return [(heights_um, {"name": name, "scale": [py * 1e6, px * 1e6], "units": ["µm", "µm"],
                          "axis_labels": ["y", "x"], "colormap": "viridis", "metadata": meta},
             "image")]
