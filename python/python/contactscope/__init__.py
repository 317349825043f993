"""contactscope: real-contact-area microscopy (Weber et al., Nat. Commun. 9, 888 (2018)).

numpy arrays in, numpy arrays out; the work is done by the Rust library with the GIL released.

Units are SI everywhere: lengths and heights in metres (200 nm = 2e-7), forces in newtons
(4 mN = 4e-3), pressures, moduli and hardness in pascals, the hardening coefficient k in Pa/m
(4 MPa/nm = 4e15 Pa/m), areas in m². Dictionary keys and column names carry their unit
(``area_m2``, ``force_n``).

Errors: bad input raises :class:`InputError` (a ``ValueError``), a file that cannot be read raises
:class:`FileError` (an ``OSError``), a solver at its iteration limit :class:`ConvergenceError`
(a ``ValueError``); each carries the library's message.

Distributed sweeps and fits on Dask: :mod:`contactscope.distributed`.
"""

from __future__ import annotations

import os
import warnings as _warnings
from typing import TYPE_CHECKING, Any, Dict, Iterable, Mapping, Optional, Sequence, Union

import numpy as np

from . import _contactscope as _cs
from ._args import command_line as _command_line
from ._args import f64 as _f64
from ._args import number as _number
from ._args import numbers_of as _numbers
from ._args import optional_number as _opt_number
from ._args import optional_numbers as _opt_numbers
from ._args import spec as _spec
from ._contactscope import (  # noqa: F401  (re-exported)
    ConvergenceError,
    FileError,
    InputError,
    InternalError,
    get_num_threads,
    set_num_threads,
)

if TYPE_CHECKING:
    from ._contactscope import SeriesSpec

__version__ = _cs.__version__
#: The git commit this build came from (``None`` when built outside a checkout, e.g. from the sdist).
__source_revision__ = _cs.__source_revision__

PathLike = Union[str, "os.PathLike[str]"]
PixelSize = Union[float, "tuple[float, float]"]

__all__ = [
    "ContactscopeWarning",
    "ConvergenceError",
    "FileError",
    "InputError",
    "InternalError",
    "FitResults",
    "Results",
    "Series",
    "analyze",
    "autocorrelation",
    "blur_and_resample",
    "compare",
    "fit_hardening",
    "friction",
    "get_num_threads",
    "hertz",
    "info",
    "measure",
    "misfit",
    "newton",
    "otsu_threshold",
    "parse_forces",
    "parse_pixel_size",
    "psf",
    "ramp",
    "read_image",
    "read_series",
    "read_topography",
    "set_num_threads",
    "simulate",
    "surface",
    "surface_with_stats",
]


class ContactscopeWarning(UserWarning):
    """A warning of a contactscope job (the command line prints the same text on stderr); the
    result keeps every warning in its ``warnings`` list."""


class Results(dict):
    """A result: the job's outcome as a dict (SI units, keys naming their unit) whose keys are
    also attributes; ``rows`` (one dict per image or load: the outcome's table) become a table
    with :meth:`to_pandas`."""

    #: The key of the per-item table (``"loads"`` for :func:`simulate`).
    _table = "rows"

    def __init__(self, *args: Any, table: Optional[str] = None, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if table is not None:
            self._table = table

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    @property
    def rows(self) -> list:
        """The per-image or per-load table: a list of dicts."""
        return self[self._table]

    def to_pandas(self):
        """The per-image or per-load rows as a ``pandas.DataFrame`` (needs pandas)."""
        try:
            import pandas as pd
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("to_pandas() needs pandas: pip install pandas") from e
        return pd.DataFrame(list(self.rows))


def _warn(result: Mapping[str, Any]) -> None:
    """Each of the job's warnings as a :class:`ContactscopeWarning` (they stay on the result)."""
    for text in result.get("warnings") or ():
        _warnings.warn(text, ContactscopeWarning, stacklevel=3)


class Series(Results):
    """A load series read from files: ``images`` (n, rows, columns) in the files' stored sample
    type (uint8, uint16, int16 or float32, as tifffile returns them), ``forces_n`` (N, ``None``
    where unknown), ``paths``, ``pages``, ``pixel_size_m`` ((x, y) in m or ``None``),
    ``pixel_size_source`` and ``warnings``. :func:`analyze` and :func:`otsu_threshold` given a
    Series read its files as the command line does (same thresholds, areas and file names)."""

    def __init__(self, *args: Any, spec: Optional[SeriesSpec] = None,
                 pixel_size: Optional[PixelSize] = None, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._spec = spec
        self._pixel_size = pixel_size

    def to_pandas(self):
        import pandas as pd

        return pd.DataFrame(
            {"path": self["paths"], "page": self["pages"], "force_n": self["forces_n"]}
        )


_STACK_TYPES = (np.uint8, np.uint16, np.int16, np.float32, np.float64)


def _stack(images: Any) -> np.ndarray:
    """One image (2-D), a stack (3-D) or a list of equal 2-D images as a C-ordered 3-D array of
    a type the library keeps as is (uint8, uint16, int16, float32, float64)."""
    if isinstance(images, Series):
        images = images["images"]
    if isinstance(images, (list, tuple)):
        images = np.stack([np.asarray(i) for i in images])
    a = np.asarray(images)
    if a.ndim == 2:
        a = a[np.newaxis]
    if a.ndim != 3:
        raise InputError(f"images must be a 2-D image or a 3-D stack; got {a.ndim} dimensions")
    _check_axes(a)
    if a.dtype.type not in _STACK_TYPES:
        if np.issubdtype(a.dtype, np.integer) and a.size and a.min() >= 0 and a.max() <= 65535:
            a = a.astype(np.uint16)
        else:
            a = a.astype(np.float64)
    return np.ascontiguousarray(a)


def _check_axes(a: np.ndarray) -> None:
    """A stack is (loads, rows, columns): an RGB(A) image (last axis 3 or 4, the others larger)
    is refused, and a last axis far shorter than the others (the loads last?) is warned of."""
    n, rows, cols = a.shape
    if cols in (3, 4) and n > 4 and rows > 4:
        kind = "RGB" if cols == 3 else "RGBA"
        raise InputError(
            f"images of shape {a.shape} look like one {kind} image (a last axis of {cols}), not "
            f"a stack of {n} images of {rows}×{cols} pixels: pass one channel "
            f"(images[..., 1] for green) or cs.rgb_to_gray(images); a stack is "
            f"(load, rows, columns)")
    if cols * 8 <= min(n, rows) and cols <= 64:
        _warnings.warn(
            f"the stack's last axis ({cols}) is far shorter than its others ({n}, {rows}): a "
            f"stack is (load, rows, columns); if the loads are the last axis, pass "
            f"np.moveaxis(images, -1, 0)", ContactscopeWarning, stacklevel=4)


def rgb_to_gray(image: Any) -> np.ndarray:
    """An RGB or RGBA image (rows, columns, 3 or 4) as one grey image (float64): the luma of
    ITU-R BT.601, 0.299 R + 0.587 G + 0.114 B; the alpha channel is dropped. For a
    fluorescence image stored as RGB, one channel (``image[..., 1]`` for green) is usually
    the better choice: the others hold no signal."""
    a = np.asarray(image)
    if a.ndim < 3 or a.shape[-1] not in (3, 4):
        raise InputError(f"rgb_to_gray needs (..., 3) or (..., 4) values; got shape {a.shape}")
    rgb = a[..., :3].astype(np.float64)
    return rgb @ np.array([0.299, 0.587, 0.114])


def read_image(path: PathLike, channel: Union[int, str, None] = None,
               pixel_size: Optional[PixelSize] = None, *, series: Optional[int] = None,
               z: Optional[int] = None, t: Optional[int] = None,
               axes: Optional[Dict[str, int]] = None,
               load_axis: Optional[str] = None) -> Results:
    """Images of a TIFF, Zeiss CZI, Nikon ND2 or Leica LIF file (found by content), in the
    file's stored sample type (uint8, uint16, int16 or float32, as tifffile returns them).

    A TIFF has the axes its OME-XML or ImageJ description states (plain pages are time
    points); a file gives the plane that ``series``, ``channel``, ``z``, ``t`` and ``axes`` (extra
    axes by name, e.g. ``{"H": 3}`` for an Airyscan phase) select, or every plane along
    ``load_axis`` ("t", "z" or "series") — as the command line's selection flags: an axis
    longer than 1 must be chosen (the error lists every such axis at once), and ``channel`` is
    an index or the channel's name as :func:`info` lists it ("AF488"). Returns ``images``
    (images, rows, columns), ``pixel_size_m`` ((x, y) in m from the
    file's metadata or ``pixel_size``, m; ``None`` if unknown), ``pixel_size_source``,
    ``path`` and ``warnings``.
    """
    spec = _spec(path, None, channel, series, z, t, axes, load_axis)
    r = _cs.read_series(spec, pixel_size)
    return Results({"images": r["images"], "pixel_size_m": r["pixel_size_m"],
                    "pixel_size_source": r["pixel_size_source"], "path": os.fspath(path),
                    "warnings": r["warnings"]})


def read_series(paths_or_manifest: Union[PathLike, Sequence[PathLike]],
                forces: Optional[Sequence[float]] = None, channel: Union[int, str, None] = None,
                pixel_size: Optional[PixelSize] = None, *, series: Optional[int] = None,
                z: Optional[int] = None, t: Optional[int] = None,
                axes: Optional[Dict[str, int]] = None,
                load_axis: Optional[str] = None) -> Series:
    """A load series: TIFF, CZI, ND2, LIF or OME-Zarr files and folders (natural order) or one manifest
    CSV (``.csv``: columns ``file``, ``page``, ``force_mN``… as for the command line).

    ``forces`` (N), one per image, when the files do not come with a manifest; ``pixel_size``
    (m, or (x, y)) overrides the files' metadata. A vendor file contributes the plane its
    selection (``series``, ``channel``, ``z``, ``t``, ``axes``) names, or one image per plane
    along ``load_axis`` ("t", "z" or "series"). Returns a :class:`Series`.
    """
    spec = _spec(paths_or_manifest, forces, channel, series, z, t, axes, load_axis)
    result = Series(_cs.read_series(spec, pixel_size), spec=spec, pixel_size=pixel_size)
    _warn(result)
    return result


def _images(images: Any) -> Any:
    """A :class:`Series` as its file spec (read again as the command line reads it), anything
    else as a stack in its stored sample type."""
    if isinstance(images, Series) and images._spec is not None:
        return images._spec
    a = _stack(images)
    if np.issubdtype(a.dtype, np.floating) and a.size:
        finite = a[np.isfinite(a)]
        if finite.size and finite.min() != finite.max() and finite.min() >= 0 \
                and finite.max() <= 65535 and (np.mod(finite, 1) == 0).all():
            _warnings.warn(
                "the images are floats holding integer values: a threshold bins floats in "
                "4096 bins over their range, integers one bin per level; pass them in their "
                "stored integer type (e.g. images.astype(np.uint16)) for the exact integer "
                "threshold the command line computes on integer files",
                ContactscopeWarning, stacklevel=3)
    return a


def otsu_threshold(images: Any) -> float:
    """One exact Otsu (1979) threshold over the pooled histogram of all images (the paper's
    global rule; the command line's ``threshold``), in the images' intensity units; contact is
    value > threshold. Integer images (uint8, uint16, int16) get one histogram bin per level,
    float images 4096 bins over their range, as the command line bins integer and float
    files."""
    result = _cs.otsu_threshold(_images(images))
    _warn(result)
    return result["threshold"]


def measure(image: Any, threshold: float, pixel_size: Optional[PixelSize] = None) -> Results:
    """Contact (value > ``threshold``) of one 2-D image: ``contact_pixels``, ``area_m2`` (with
    ``pixel_size`` in m), intensities, 8-connected ``patches`` and the boolean ``mask``."""
    threshold = _number(threshold, "threshold", "intensity units")
    return Results(_cs.measure(_stack(image), threshold, pixel_size))


def analyze(series: Any, forces: Optional[Sequence[float]] = None,
            pixel_size: Optional[PixelSize] = None,
            method: Union[str, float, None] = None, *, radius: Optional[float] = None,
            modulus: Optional[float] = None, masks: bool = False,
            out: Optional[PathLike] = None, overlays: bool = False, save_masks: bool = False,
            command_line: Optional[Sequence[str]] = None,
            progress: Optional[Any] = None,
            pixel_size_uncertainty: float = 0.0,
            psf_fwhm: Optional[float] = None,
            zarr_out: Optional[PathLike] = None) -> Results:
    """The paper's series analysis, the command line's ``analyze``: one global Otsu threshold
    over all images, then each image measured. ``series``: a :class:`Series` (its files are read
    as the command line reads them, with its forces and pixel size unless given here) or
    images (2-D, 3-D stack or list, in their stored sample type). ``forces`` in N,
    ``pixel_size`` in m; ``method``: "otsu" (default), "per-image" or a fixed threshold; the
    Hertz reference columns with ``radius`` (m) and ``modulus`` (Pa); ``masks``: also return the
    contact masks (images, rows, columns) as ``masks``. ``pixel_size_uncertainty``: the pixel
    size's relative uncertainty as bounds (0.01 for ±1 %, the command line's
    ``--pixel-size-uncertainty``); it widens ``area_m2_lo``/``_hi`` and the fit intervals.
    ``psf_fwhm``: the PSF's FWHM in m (``--psf-fwhm``), for the corrected areas
    (``area_corrected_m2``) and their 95 % intervals on the true area (``area_m2_lo``/``_hi``);
    without it a 1 µm FWHM is taken (``area_interval["psf_source"]`` says so).

    Returns the outcome the command line writes as ``summary.json`` and ``areas.csv``, in SI
    units: ``rows`` (per image: ``image``, ``page``, ``force_n``, ``threshold``,
    ``contact_pixels``, ``area_m2`` (``area_px`` without a pixel size), ``mean_intensity``,
    ``patches``, ``mean_pressure_pa``, ``equivalent_radius_m``, …), ``threshold`` (``value``,
    ``method``, ``histogram_pixels``, …), ``fits`` (``power_law``, ``proportional``),
    ``inputs``, ``area_unit`` and ``warnings`` (also issued as :class:`ContactscopeWarning`);
    ``to_pandas()`` gives the table.

    ``out``: also write the folder the command line's ``analyze --out`` writes, by the same
    writer (``areas.csv``, ``summary.json``, ``area_vs_load.png``/``.svg``; ``overlays`` and
    ``save_masks`` as ``--overlays`` and ``--save-masks``), all or nothing; ``summary.json``
    records ``command_line`` (a list of words, e.g. the equivalent command; by default the
    interpreter and this call) and ``written`` lists the files. ``progress(pass, done, total)``
    is called as the images are read
    (``"histogram"``) and measured (``"measure"``), from the threads doing the work.

    ``zarr_out`` (with ``out``): also write the contact masks as the NGFF label image
    ``labels/contact`` and the table as ``tables/contact_areas/table.parquet`` into an OME-Zarr
    store, the command line's ``--zarr-out``: the one store analysed (its images untouched) or
    a new store holding the analysed planes too.
    """
    if isinstance(series, Series) and pixel_size is None:
        pixel_size = series._pixel_size
    forces = _opt_numbers(forces, "forces", "N")
    result = Results(_cs.analyze(_images(series), forces, pixel_size, method, radius, modulus,
                                 masks, None if out is None else os.fspath(out),
                                 _command_line(command_line, "analyze", out), bool(overlays),
                                 bool(save_masks), progress,
                                 _number(pixel_size_uncertainty, "pixel_size_uncertainty",
                                         "fraction (0.01 for ±1 %)"),
                                 None if psf_fwhm is None
                                 else _number(psf_fwhm, "psf_fwhm", "m (4.5e-7 for 450 nm)"),
                                 None if zarr_out is None else os.fspath(zarr_out)),
                      table="rows")
    _warn(result)
    return result


def _image(image: Any) -> Any:
    """A file (path) as its path, anything else as a stack in its stored sample type."""
    if isinstance(image, (str, os.PathLike)):
        return os.fspath(image)
    return _stack(image)


def psf(beads: Any, pixel_size: Optional[PixelSize] = None,
        bead_diameter: Optional[float] = None, saturation_level: Optional[float] = None, *,
        series: Optional[int] = None, channel: Union[int, str, None] = None,
        z: Optional[int] = None, t: Optional[int] = None,
        axes: Optional[Dict[str, int]] = None) -> Results:
    """The point-spread function from sub-resolution beads, the command line's ``psf``.

    ``beads``: a bead image or z stack as a file (TIFF: every page of ``channel``; CZI, ND2,
    LIF: every z plane of the selection ``series``, ``channel``, ``t``, ``axes``, or the one
    plane ``z`` names) or as an array (2-D image or 3-D stack) in its stored sample type (uint8,
    uint16, int16, float32, float64). ``pixel_size`` (m) overrides the file's metadata and is
    needed for arrays; ``bead_diameter`` (m) turns on the finite-bead correction σ² − a²/5.
    Beads with two or more window pixels at the detector's saturation level are skipped; the
    level follows from the sample type as on the command line (uint8 255, uint16 4095 when the
    data do not exceed it — 12-bit data — else 65535, int16 32767, floats: no check) unless
    ``saturation_level`` gives it.

    Returns the outcome the command line writes as ``psf.json`` and ``beads.csv``, in SI units:
    ``sigma_m_mean``, ``sigma_m_sd``, ``fwhm_m_mean``, ``fwhm_m_sd`` (bead-corrected when asked),
    ``sigma_raw_m_mean``…, ``fwhm_raw_m_mean``…, ``sigma_x_2d_m_mean``…, ``beads_used``,
    ``beads_found``, ``pixel_size_m``, ``saturation_level``, ``skipped``, ``detection``,
    ``method`` and ``beads`` (per candidate: ``x_px``, ``y_px``, ``plane``, ``sigma_m``,
    ``fwhm_m``, ``used``, ``skip_reason``, …; also :attr:`Results.rows`).
    """
    return Results(_cs.psf(_image(beads), pixel_size, bead_diameter, saturation_level, series,
                           channel, z, t, axes), table="beads")


def autocorrelation(images: Any, pixel_size: Optional[PixelSize] = None,
                    max_lag: Optional[float] = None, *, series: Optional[int] = None,
                    channel: Union[int, str, None] = None, z: Optional[int] = None,
                    t: Optional[int] = None, axes: Optional[Dict[str, int]] = None) -> Results:
    """Radially averaged intensity autocorrelation C(r), the command line's ``autocorr``.

    ``images``: one file or a list of files (every page of a multi-page TIFF is one image; a
    CZI, ND2, LIF or OME-Zarr file gives the plane its selection ``series``, ``channel``, ``z``, ``t``,
    ``axes`` names), or an array (a 2-D image or a 3-D stack, each plane one image) with its
    ``pixel_size`` (m). Lags go up to ``max_lag`` m (default, and at most, half the shorter
    side of each image).

    Returns the outcome the command line writes as ``autocorr.json``, in SI units: ``images``
    (per image: ``image``, ``file``, ``page``, ``pixel_size_x_m``, ``max_lag_m``,
    ``correlation_length_m_1e`` (first lag with C ≤ 1/e, m), ``first_zero_m`` (m), and the
    curve as arrays ``lag_m`` (m) and ``acf``; also :attr:`Results.rows`), ``method`` and
    ``warnings`` (also issued as :class:`ContactscopeWarning`).
    """
    if isinstance(images, (list, tuple)) \
            and all(isinstance(i, (str, os.PathLike)) for i in images):
        items = [os.fspath(i) for i in images]
    else:
        items = [_image(images)]
    result = Results(_cs.autocorrelation(items, pixel_size, max_lag, series, channel, z, t,
                                         axes), table="images")
    _warn(result)
    return result


def newton(reflection: Any, contact: Any, pixel_size: Optional[PixelSize] = None,
           wavelength: Optional[float] = None, medium_index: Optional[float] = None,
           profiles: Optional[int] = None, phase: Optional[str] = None, *,
           contact_channel: Optional[int] = None, series: Optional[int] = None,
           channel: Union[int, str, None] = None, z: Optional[int] = None, t: Optional[int] = None,
           axes: Optional[Dict[str, int]] = None) -> Results:
    """The detection gap from Newton rings around the fluorescent contact, the command line's
    ``newton``.

    ``reflection`` (the rings) and ``contact`` (the fluorescence image of the same field): files
    (a single-page TIFF or the plane of a CZI, ND2, LIF or OME-Zarr file that ``series``, ``channel``,
    ``z``, ``t``, ``axes`` select; ``contact_channel`` when the contact image is another
    channel of the same file) or 2-D arrays in their stored sample type with their
    ``pixel_size`` (m). Defaults as on the command line: ``wavelength`` 488e-9 m,
    ``medium_index`` 1.447 (formamide), ``profiles`` 20 lines through the centre, ``phase``
    "half" (maxima at (m + ½)λ/(2n); "zero" for a sphere of lower index than the medium).

    Returns the outcome the command line writes as ``newton.json`` and ``newton_rings.csv``, in
    SI units: ``detection_gap_m_mean``, ``detection_gap_m_sd``, ``edge_radius_m``,
    ``edge_radius_m_sd``, ``contact_radius_a_m_mean``/``_sd``, ``sphere_radius_R_m_mean``/``_sd``,
    ``profiles_used``, ``profiles_total``, ``centre_x_px``, ``centre_y_px``,
    ``fluorescence_threshold``, ``ring_gaps_m``, ``inputs``, ``method``, ``profiles`` (per
    line profile: ``angle_deg``, ``rings``, ``edge_radius_m``, ``a_m``, ``R_m``,
    ``rms_residual_m``, ``detection_gap_m``, ``used``, ``skipped_reason``, …; also
    :attr:`Results.rows`), ``skipped_profiles`` and ``rings`` (every ring maximum: ``profile``,
    ``side``, ``order``, ``r_m``, ``gap_m``, ``fit_gap_m``, ``used``).
    """
    return Results(_cs.newton(_image(reflection), _image(contact), pixel_size, wavelength,
                              medium_index, profiles, phase, contact_channel, series, channel,
                              z, t, axes), table="profiles")


def blur_and_resample(map: Any, pixel_size: PixelSize, fwhm: float,
                      image_pixel_size: PixelSize) -> np.ndarray:
    """A map (e.g. a simulated contact map, 1 = contact; pixel size in m) as the microscope sees
    it: Gaussian PSF blur of FWHM ``fwhm`` (m), then integrated over image pixels of
    ``image_pixel_size`` (m). A binary map's image sums to its area in image pixels."""
    return _cs.blur_and_resample(_f64(map, 2, "map"), pixel_size, _number(fwhm, "fwhm", "m"),
                                 image_pixel_size)


def compare(micrographs: Any, forces: Optional[Sequence[float]], pixel_size: Optional[PixelSize],
            maps: Any, map_forces: Optional[Sequence[float]] = None,
            map_pixel_size: Optional[PixelSize] = None, psf_fwhm: float = 450e-9, *,
            dihedral: Optional[bool] = None, upsample: Optional[int] = None,
            force_tolerance: Optional[float] = None, images: bool = False,
            out: Optional[PathLike] = None,
            command_line: Optional[Sequence[str]] = None) -> Results:
    """Simulated contact maps against micrographs, load by load: the command line's ``compare``
    with its defaults and checks. ``micrographs``: a :class:`Series` (its files and forces) or
    images in their stored sample type with ``forces`` (N) and ``pixel_size`` (m). ``maps``: a
    folder written by ``simulate`` (its maps, forces and pixel size), or contact maps (loads,
    ny, nx; 1 = contact) with ``map_forces`` (N) and ``map_pixel_size`` (m). Each map is blurred
    with the PSF (``psf_fwhm``, m), registered (``dihedral`` also tries mirror images and
    rotations; sub-pixel 1/``upsample``) and scored where its force matches a micrograph's
    within ``force_tolerance`` (default 0.01).

    Returns the outcome the command line writes as ``compare.json`` (SI units): ``loads`` (per
    matched load: ``force_n``, ``dice``, ``jaccard``, ``experiment_area_m2``,
    ``simulated_area_m2``, ``shift_x_px``, ``shift_x_m``, ``correlation_peak``,
    ``refinement``, ``edge_distance_m``, …; also :attr:`Results.rows`),
    ``series_registration`` (the one transform and shift of the whole series, each load
    refined within ``window_px`` of it), ``dice_mean``, the thresholds and ``warnings``.

    ``images``: also the registered pairs the scores are computed on (the panels the command
    line draws), each a (matched loads, rows, columns) stack on the micrograph's grid:
    ``micrographs`` (grey levels), ``simulated_images`` (each map blurred with the PSF, resampled
    to the micrograph's pixels, registered and put on the micrograph's grey scale; NaN outside
    the simulated region), ``experiment_contact`` and ``simulated_contact`` (bool: contact as
    the Dice counts it, inside the compared region).

    ``out``: also write the command line's ``compare --out`` folder there, by its own writer
    (``compare.csv``, ``compare.json`` recording ``command_line``, one ``panel_NNN.png`` per
    load), all files or none; ``written`` lists them.
    """
    if isinstance(micrographs, Series) and pixel_size is None:
        pixel_size = micrographs._pixel_size
    forces = _opt_numbers(forces, "forces", "N")
    if isinstance(maps, (str, os.PathLike)):
        maps = os.fspath(maps)
    else:
        maps = _f64(maps, 3, "maps")
    map_forces = _opt_numbers(map_forces, "map_forces", "N")
    result = Results(_cs.compare(_images(micrographs), forces, pixel_size, maps, map_forces,
                                 map_pixel_size, _number(psf_fwhm, "psf_fwhm", "m"), dihedral,
                                 upsample, force_tolerance, bool(images),
                                 None if out is None else os.fspath(out),
                                 _command_line(command_line, "compare", out)),
                     table="loads")
    _warn(result)
    return result


def read_topography(path: PathLike, pixel_size: Optional[PixelSize] = None,
                    height_unit: Optional[float] = None, detrend: str = "plane", *,
                    channel: Union[int, str, None] = None,
                    fill_invalid: Optional[str] = None,
                    measurement: Union[int, str, None] = None) -> Results:
    """A height map from any format contactscope reads (npy, TIFF, GSF, text matrices with or
    without a Gwyddion or h=/w= header, x y z grids, gzip text, WSxM, Nanoscope, Nanonis sxm, TopoStats, JPK TIFF and HDF5, Igor ibw,
    Nanosurf nid, PicoView mi, Park TIFF, Gwyddion, X3P, SDF, Wyko opd, Sensofar plu, Digital
    Surf sur and mnt, surfalize sflz, Keyence zon, Createc dat, FRT, Alicona al3d, TrueMap tmd, NanoFocus nms, Image Metrology bcr/bcrf,
    Zygo MetroPro dat, NetCDF, HDF5 … recognised by content; ``docs/formats.md``), read as the
    command line's ``topography`` reads it (the same checks and messages).

    ``pixel_size`` (m, or (x, y)) overrides the file's; ``height_unit``: metres per stored unit
    for files without one. ``channel`` names the channel of a multi-channel file (default: its
    height channel). A map with invalid (unmeasured) points raises :class:`InputError` unless
    ``fill_invalid`` is "mean", "nearest" or "harmonic"; ``notes`` then says how many points
    were filled. A contact.engineering surface container (ZIP or folder) is read with its own
    processing (size, unit, height scale, filling, detrending, as SurfaceTopography's
    ``read_container``); ``measurement`` chooses one by index (``0`` or "0") or name ("name"
    or "surface/name"), needed when it holds several.

    Returns ``heights`` (rows = y, m; filled as asked, then detrended by ``detrend``: "none",
    "mean" or "plane", the command line's default), ``pixel_size_m`` ((x, y), m), ``notes`` and
    ``summary``: the command line's ``topography --json`` in SI units, describing the file as
    stored (``file``, ``format``, ``channel``, ``channels`` (every channel of the file), ``nx``,
    ``ny``, ``pixel_size_m`` {``x``, ``y``},
    ``valid_points``, ``height_min_m``, ``height_max_m``, ``height_mean_m``,
    ``h_rms_as_stored_m``, ``h_prime_rms_as_stored``, ``h_double_prime_rms_as_stored_per_m``)
    and after detrending (``detrended``: ``detrend``,
    ``pixel_size_x_m``, ``pixel_size_y_m``, ``h_rms_m``, ``h_prime_rms``,
    ``h_double_prime_rms_per_m``).
    """
    result = Results(_cs.read_topography(os.fspath(path), pixel_size, height_unit, detrend,
                                         channel, fill_invalid, measurement))
    # The command line's warnings (a pixel size that replaced the file's, points filled).
    for text in result.get("notes") or ():
        _warnings.warn(text, ContactscopeWarning, stacklevel=2)
    d = result["summary"]["detrended"]
    if d is not None:
        result["pixel_size_m"] = (d["pixel_size_x_m"], d["pixel_size_y_m"])
    else:
        # A map too small for the roughness statistics: the file's own grid (as read).
        p = result["summary"]["pixel_size_m"]
        result["pixel_size_m"] = (p["x"], p["y"])
    return result


def surface(nx: int, ny: int, pixel_size: float, hurst: Optional[float] = None,
            rms_height: Optional[float] = None, rms_slope: Optional[float] = None,
            rolloff: Optional[float] = None, cutoff: Optional[float] = None,
            seed: Optional[int] = None) -> np.ndarray:
    """A seeded self-affine random surface, as the command line's ``surface`` makes it (the
    same defaults and range checks): heights (ny, nx) in m on ``pixel_size`` m pixels, Hurst
    exponent ``hurst`` (default 0.8), scaled to ``rms_height`` (m) or ``rms_slope`` (give
    exactly one); optional roll-off and short-wavelength cutoff wavelengths (m); ``seed``
    (default 7, as the command line). :func:`surface_with_stats` also returns its roughness
    statistics."""
    return surface_with_stats(nx, ny, pixel_size, hurst, rms_height, rms_slope, rolloff,
                              cutoff, seed)["heights"]


def surface_with_stats(nx: int, ny: int, pixel_size: float, hurst: Optional[float] = None,
                       rms_height: Optional[float] = None, rms_slope: Optional[float] = None,
                       rolloff: Optional[float] = None, cutoff: Optional[float] = None,
                       seed: Optional[int] = None) -> Results:
    """:func:`surface` with the finite-difference roughness statistics the command line's
    ``surface`` prints: ``heights`` (ny, nx; m), ``nx``, ``ny``, ``pixel_size_m``, ``h_rms_m``
    (m), ``h_prime_rms`` (central differences) and ``h_double_prime_rms_per_m`` (5-point
    Laplacian, 1/m)."""
    return Results(_cs.surface(nx, ny, pixel_size, hurst, rms_height, rms_slope, rolloff,
                               cutoff, None if seed is None else int(seed)))


def simulate(heights: Any, pixel_size: Optional[PixelSize], modulus: float,
             loads: Iterable[float], model: str = "elastic", *, hardness: Optional[float] = None,
             k: Optional[float] = None, initial_hardness: Optional[float] = None,
             alpha: Optional[float] = None, radius: Optional[float] = None,
             periodic: bool = False, tolerance: Optional[float] = None,
             max_iterations: Optional[int] = None, maps: Union[str, bool] = "all",
             detrend: str = "plane",
             height_unit: Optional[float] = None, channel: Union[int, str, None] = None,
             fill_invalid: Optional[str] = None, device: str = "cpu",
             measurement: Union[int, str, None] = None,
             contact_engineering: Optional[PathLike] = None) -> Results:
    """A load ramp on a rough body pressed on a flat of contact modulus E* ``modulus`` (Pa) at
    normal forces ``loads`` (N, in order; the plastic state carries from load to load): the
    command line's ``simulate``, with the same defaults, checks and warnings.

    ``heights``: a height-map file of any format the command line reads (``pixel_size``,
    ``height_unit``, ``channel`` and ``fill_invalid`` as its flags), or an array of heights in m
    (rows = y, positive towards the flat) with its ``pixel_size`` (m). The map is detrended by
    ``detrend`` ("plane" by default, as the command line; "mean" or "none"). A sphere of
    ``radius`` m is added when given.

    Models: "elastic"; "hardness" (p ≤ ``hardness`` Pa; ``alpha`` for the volume-conserving
    update); "hardening" (p_Y = ``initial_hardness`` + ``k``·h_pl, k in Pa/m); "gt"
    (Greenwood–Tripp bearing area, needs ``radius``). Solver limits: ``tolerance`` (default
    1e-8) and ``max_iterations`` per load (default 5000). ``device``: "cpu", "cuda" (an NVIDIA
    GPU, in a package built with the ``cuda`` feature; an error when none is usable) or "auto"
    (a GPU when one is usable); ``solver["device"]`` says which ran.

    Returns the outcome the command line writes as ``summary.json``, in SI units: ``loads``
    (per load: ``force_n``, ``area_m2``, ``mean_pressure_pa``, ``approach_m``, ``patches``,
    ``plastic_volume_m3``, ``edge_contact``, …; also :attr:`Results.rows`), ``topography``,
    ``model``, ``power_law``, ``maps`` and ``warnings`` (also issued as
    :class:`ContactscopeWarning`), and the per-load stacks ``maps`` asks for, each (loads, ny,
    nx): with ``"all"`` (the default) ``pressure`` (Pa), ``gap`` (m), ``contact`` (bool) and
    ``plastic`` (m); with ``"contact"`` ``contact`` only; with ``"none"`` none (``True`` and
    ``False`` mean ``"all"`` and ``"none"``). The command line's ``--maps`` takes the same choice.

    ``measurement`` chooses the measurement of a contact.engineering surface container by
    index or name, as :func:`read_topography` does (a measurement marked periodic is solved
    with periodic boundaries). ``contact_engineering``: a
    ``.zip`` path to write contact.engineering's contact-mechanics download to (``plot.csv``,
    ``result-step-N.nc``, ``info.txt``; the command line's ``--export contact-engineering``,
    ``docs/outputs.md``), written once every load is solved.
    """
    if not isinstance(heights, (str, os.PathLike)):
        heights = _f64(heights, 2, "heights")
    result = Results(_cs.simulate(heights, pixel_size, _number(modulus, "modulus", "Pa"),
                                  _numbers(loads, "loads", "N"),
                                  model, hardness, k, initial_hardness, alpha, radius, periodic,
                                  tolerance, max_iterations, maps, detrend, height_unit,
                                  channel, fill_invalid, device, measurement,
                                  None if contact_engineering is None
                                  else os.fspath(contact_engineering)), table="loads")
    _warn(result)
    return result


def _heights(heights: Any) -> Any:
    """A height-map path as it is, anything else as a 2-D float64 array."""
    if isinstance(heights, (str, os.PathLike)):
        return os.fspath(heights)
    return _f64(heights, 2, "heights")


def ramp(heights: Any, pixel_size: Optional[PixelSize], modulus: float, family: str,
         parameter: Optional[float], loads: Sequence[float], radius: Optional[float] = None,
         tolerance: Optional[float] = None, max_iterations: Optional[int] = None,
         imaging_fwhm: Optional[float] = None,
         imaging_pixel_size: Optional[PixelSize] = None, *, detrend: str = "plane",
         periodic: bool = False, device: str = "cpu") -> Results:
    """One model evaluation of a fit (the unit of a Dask task): contact areas ``areas_m2`` (m²)
    of one load ramp (``loads`` in N, increasing) for ``family`` ("elastic", "gt", "hardness"
    with p_Y in Pa, "hardening" with k in Pa/m), on the body :func:`fit_hardening` builds from
    the same arguments and counted as it counts them; ``device`` as :func:`simulate`."""
    return Results(_cs.ramp(_heights(heights), pixel_size, _number(modulus, "modulus", "Pa"),
                            family, parameter, _numbers(loads, "loads", "N"), radius, tolerance,
                            max_iterations, imaging_fwhm, imaging_pixel_size, detrend, periodic,
                            device))


def misfit(forces: Sequence[float], areas: Sequence[float], simulated: Sequence[float]) -> float:
    """RMS over the measured loads of ln(A_sim/A_exp) (forces in N, areas in m²)."""
    return _cs.misfit(_numbers(forces, "forces", "N"), _numbers(areas, "areas", "m²"),
                      _numbers(simulated, "simulated", "m²"))


class FitResults(Results):
    """The outcome of :func:`fit_hardening` (``fit.json`` in SI units): ``models`` (per model:
    ``model``, ``misfit_rms_ln_area``, ``areas_m2``, ``k_pa_per_m`` or ``hardness_pa`` with
    ``_se``, ``at_range_edge``, the search ``trace``), ``best_model``, ``measured``,
    ``roughness``, ``warnings``. The attributes below describe the best model."""

    _table = "models"

    @property
    def best(self) -> Dict[str, Any]:
        """The model with the lowest misfit."""
        return min(self["models"], key=lambda m: m["misfit_rms_ln_area"])

    @property
    def family(self) -> str:
        return self.best["model"]

    @property
    def parameter(self) -> Optional[float]:
        """k (Pa/m) or p_Y (Pa) of the best model; ``None`` for elastic and GT."""
        b = self.best
        return b.get("k_pa_per_m", b.get("hardness_pa"))

    @property
    def parameter_se(self) -> Optional[float]:
        b = self.best
        return b.get("k_pa_per_m_se", b.get("hardness_pa_se"))

    @property
    def parameter_ci95(self) -> Optional["tuple[float, float]"]:
        """The 95 % interval (lo, hi) of k (Pa/m) or p_Y (Pa) of the best model, from the
        measured areas' intervals and the scatter about the fit; ``None`` where it cannot be
        estimated."""
        b = self.best
        ci = b.get("k_pa_per_m_ci95", b.get("hardness_pa_ci95"))
        return None if ci is None else (ci[0], ci[1])

    @property
    def misfit(self) -> float:
        return self.best["misfit_rms_ln_area"]

    @property
    def areas_m2(self) -> np.ndarray:
        return np.asarray(self.best["areas_m2"])

    @property
    def trace(self) -> list:
        return self.best.get("trace", [])

    @property
    def at_range_edge(self) -> bool:
        return self.best["at_range_edge"]


def fit_hardening(forces: Any, areas: Optional[Sequence[float]], heights: Any,
                  pixel_size: Optional[PixelSize], modulus: float,
                  radius: Optional[float] = None, family: Union[str, Sequence[str]] = "hardening",
                  range: Optional["tuple[float, float]"] = None, grid: Optional[int] = None,
                  ln_tolerance: Optional[float] = None, tolerance: Optional[float] = None,
                  max_iterations: Optional[int] = None, imaging_fwhm: Optional[float] = None,
                  imaging_pixel_size: Optional[PixelSize] = None, client: Any = None, *,
                  detrend: str = "plane", periodic: bool = False,
                  height_unit: Optional[float] = None, channel: Union[int, str, None] = None,
                  fill_invalid: Optional[str] = None, device: str = "cpu",
                  area_intervals: Optional[Any] = None) -> FitResults:
    """Fit contact models to a measured area–load curve: the command line's ``fit-hardening``,
    with its defaults, checks and warnings. The curve: ``forces`` (N) and ``areas`` (m²), with
    each area's interval as ``area_intervals`` = (lower ends, upper ends) in m² when known (the
    ``area_m2_lo``, ``area_m2_hi`` of :func:`analyze`), or ``forces`` an ``areas.csv`` written by
    ``analyze`` (``areas`` None; its intervals are read from it). The rough sphere:
    ``heights`` (a height-map file, or an array in m with ``pixel_size`` in m; detrended by
    ``detrend``), sphere ``radius`` (m), E* ``modulus`` (Pa). ``family``: one model or a list
    ("elastic", "gt", "hardness", "hardening"); "hardening" fits k (Pa/m; default range
    1e14–1e17), "hardness" p_Y (Pa; 1e7–1e10) by a log grid (``grid``, default 7) then Brent's
    method to ``ln_tolerance`` (default 0.01); "elastic" and "gt" are evaluated once.
    ``imaging_fwhm`` and ``imaging_pixel_size`` count simulated areas as imaged. A height-map
    file is read as the command line reads ``--topography`` (``height_unit``, ``channel``,
    ``fill_invalid``). ``device`` as :func:`simulate` (``device`` in ``fit.json`` says which ran).

    Returns a :class:`FitResults` (``parameter``, ``parameter_se``, ``parameter_ci95`` (the 95 %
    interval), ``misfit``, ``areas_m2``, ``trace`` of the best model; the whole ``fit.json`` in SI
    units). With a
    ``dask.distributed`` ``client``, the model evaluations run as Dask tasks
    (:func:`contactscope.distributed.fit_hardening`).
    """
    families = [family] if isinstance(family, str) else list(family)
    if client is not None:
        from . import distributed

        if len(families) != 1 or isinstance(forces, (str, os.PathLike)) or areas is None:
            raise InputError("a distributed fit takes one family and forces and areas")
        return distributed.fit_hardening(forces, areas, heights, pixel_size, modulus,
                                         radius=radius, family=families[0], range=range,
                                         grid=grid, ln_tolerance=ln_tolerance,
                                         tolerance=tolerance, max_iterations=max_iterations,
                                         imaging_fwhm=imaging_fwhm,
                                         imaging_pixel_size=imaging_pixel_size, client=client,
                                         device=device)
    if isinstance(forces, (str, os.PathLike)):
        if areas is not None or area_intervals is not None:
            raise InputError("give forces and areas, or an areas.csv alone")
        measured: Any = os.fspath(forces)
    else:
        if areas is None:
            raise InputError("areas (m²) are needed with forces (N)")
        measured = (_numbers(forces, "forces", "N"), _numbers(areas, "areas", "m²"))
        if area_intervals is not None:
            if not (isinstance(area_intervals, (tuple, list)) and len(area_intervals) == 2):
                raise InputError("area_intervals= must be (lower ends, upper ends) in m²; got "
                                 f"{type(area_intervals).__name__}")
            measured = measured + (_numbers(area_intervals[0], "area_intervals", "m²"),
                                   _numbers(area_intervals[1], "area_intervals", "m²"))
    result = FitResults(_cs.fit_hardening(measured, _heights(heights), pixel_size,
                                          _number(modulus, "modulus", "Pa"), radius, families,
                                          range, grid, ln_tolerance, tolerance, max_iterations,
                                          imaging_fwhm, imaging_pixel_size, detrend, periodic,
                                          height_unit, channel, fill_invalid, device))
    _warn(result)
    return result


def friction(traces: Union[PathLike, Sequence[PathLike]], normal_force: Optional[float] = None,
             rotation_radius: Optional[float] = None, areas: Optional[PathLike] = None,
             force_tolerance: Optional[float] = None, images: bool = False) -> Results:
    """Static and kinetic friction from rheometer traces, the command line's ``friction`` on the
    same files (the same defaults, checks, warnings and numbers).

    ``traces``: one CSV per trace (columns ``time_s`` | ``displacement_um`` | ``angle_rad``,
    ``friction_mN`` | ``friction_N`` | ``torque_mNm`` | ``torque_Nm``, optional
    ``normal_force_mN`` | ``normal_force_N``). ``normal_force`` (N) for traces without a
    normal-force column; ``rotation_radius`` (m) turns torque into force; ``areas``: an
    ``areas.csv`` of :func:`analyze` or the command line (``force_mN``, ``area_um2``) for
    F_s = τ·A, each trace matched to the row with the nearest force within ``force_tolerance``
    (a fraction, default 0.02).

    Returns the outcome the command line writes as ``summary.json``, in SI units: ``traces``
    (per trace: ``file``, ``normal_force_n``, ``static_friction_n``, ``kinetic_friction_n``,
    ``slip_at`` with ``slip_at_unit`` ("m", "rad" or "s"), ``mu_static``, ``mu_kinetic``,
    ``noise_n``, ``area_m2``, …; also :attr:`Results.rows`), ``tau_pa``, ``tau_se_pa``, ``r2``,
    ``static_shear_fit``, ``kinetic_shear_fit``, ``mu_static_vs_load``, ``inputs``, ``method``
    and ``warnings`` (also issued as :class:`ContactscopeWarning`).
    """
    if isinstance(traces, (str, os.PathLike)):
        traces = [traces]
    result = Results(_cs.friction([os.fspath(t) for t in traces],
                                  _opt_number(normal_force, "normal_force", "N"),
                                  _opt_number(rotation_radius, "rotation_radius", "m"),
                                  None if areas is None else os.fspath(areas),
                                  _opt_number(force_tolerance, "force_tolerance", "N")),
                     table="traces")
    _warn(result)
    return result


def hertz(squeeze: PathLike, radius: float, loads: Optional[Sequence[float]] = None) -> Results:
    """The contact modulus E* from a squeeze test of a sphere of ``radius`` (m) between two
    plates, the command line's ``hertz`` on the same file: P = (4/3) E* R^(1/2) δ^(3/2) with
    δ = displacement/2, least squares through the origin (and with a free contact point).

    ``squeeze``: a CSV with ``force_mN`` (or ``force_N``) and ``displacement_um`` (total plate
    displacement 2δ); ``loads`` (N) where the Hertz contact is predicted (default: the measured
    forces).

    Returns the outcome the command line writes as ``hertz.json``, in SI units:
    ``contact_modulus_pa``, ``contact_modulus_se_pa``, ``r2``, ``points_used``,
    ``max_abs_residual_n``, ``offset_fit`` (``contact_modulus_pa``, …,
    ``contact_offset_displacement_m``), ``radius_m``, ``predicted`` (per load: ``force_n``,
    ``contact_radius_m``, ``contact_area_m2``; also :attr:`Results.rows`), ``method``, and
    ``points``: the fitted points as ``hertz_fit.csv`` has them (``force_n``,
    ``displacement_m``, ``delta_m``, ``fitted_force_n``, ``residual_n``); ``warnings`` (a
    modulus outside any solid's range, naming the likely unit; also issued as
    :class:`ContactscopeWarning`).
    """
    loads = _opt_numbers(loads, "loads", "N")
    radius = _number(radius, "radius", "m")
    result = Results(_cs.hertz(os.fspath(squeeze), radius, loads), table="predicted")
    _warn(result)
    return result


def parse_forces(text: str) -> list:
    """Forces as the command line's ``--forces`` reads them, in N: a list with a unit
    (``"4,10,20,40mN"``; a 0 is a reference frame) or a log-spaced range (``"4mN..400mN:12"``).
    Raises :class:`InputError` with the command line's message for anything else."""
    return _cs.parse_forces(str(text))


def parse_pixel_size(text: str) -> tuple:
    """A pixel size as the command line's ``--pixel-size`` reads it: (x, y) in m from
    ``"200nm"``, ``"0.2um"`` or ``"200x210nm"`` (x × y). Raises :class:`InputError` with the
    command line's message for anything else."""
    return tuple(_cs.parse_pixel_size(str(text)))


def info(path: PathLike, stats: bool = False) -> Results:
    """What a TIFF, Zeiss CZI, Nikon ND2 or Leica LIF file holds, as the command line's
    ``info --json`` describes it, in SI units: ``file``, ``format`` and ``series`` (per series:
    ``index``, ``name``, ``axes`` (``T``, ``Z``, ``C``, ``Y``, ``X`` and extra axes by name),
    ``dtype``, ``pixel_size_m`` {``x``, ``y``, ``z``} (m, ``None`` where the file does not
    state it), ``pixel_size_source`` and, with ``stats``, ``planes``: every plane's index with
    its ``min``, ``max``, ``mean`` and ``sum``)."""
    return Results(_cs.info(os.fspath(path), bool(stats)), table="series")


# Seeded generators with known truth, and a TIFF writer (inputs for examples and tests).

def synth_series(width: Optional[int] = None, height: Optional[int] = None,
                 pixel_size: Optional[float] = None, forces: Optional[Sequence[float]] = None,
                 seed: Optional[int] = None) -> Results:
    """A synthetic confocal load series (12-bit values in uint16) with known truth, as the
    command line's ``synth-series`` makes it (the same defaults and checks): ``images``
    (loads, rows, columns), ``forces_n`` (N), ``true_area_m2`` (m²), ``true_contact_pixels``
    and the true masks ``truth``; pixel size in m. Defaults: the bundled fixture (256 × 256
    pixels of 200 nm, 8 loads 4–100 mN, seed 2018)."""
    forces = _opt_numbers(forces, "forces", "N")
    return Results(_cs.synth_series(width, height, pixel_size, forces, seed))


def synth_beads(width: int = 128, height: int = 128, planes: int = 1, beads: int = 6,
                sigma_px: float = 1.91, seed: int = 7) -> np.ndarray:
    """A synthetic bead image or z stack (12-bit values in uint16), spots of σ = ``sigma_px``
    pixels: (planes, rows, columns)."""
    return _cs.synth_beads(width, height, planes, beads, sigma_px, seed)


def synth_newton(width: int = 256, height: int = 256, pixel_size: float = 200e-9,
                 contact_radius: float = 12e-6, detection_gap: float = 9e-9,
                 seed: int = 7) -> Results:
    """A synthetic Newton-ring ``reflection`` image and ``fluorescence`` image of one contact
    (uint16), with the true ``detection_gap_m``, ``contact_radius_m``, ``sphere_radius_m`` (m)."""
    return Results(_cs.synth_newton(width, height, pixel_size, contact_radius, detection_gap,
                                    seed))


def write_tiff(path: PathLike, stack: Any, pixel_size: Optional[PixelSize] = None) -> None:
    """Write an image or stack (uint16 or float32; other types as float32) as a multi-page TIFF
    with the pixel size (m) in its metadata when given."""
    a = np.asarray(stack)
    if a.ndim == 2:
        a = a[np.newaxis]
    if a.dtype != np.uint16:
        a = a.astype(np.float32)
    _cs.write_tiff(os.fspath(path), np.ascontiguousarray(a), pixel_size)


__all__ += ["synth_series", "synth_beads", "synth_newton", "write_tiff", "rgb_to_gray"]

from .archive import BatchResult, batch  # noqa: E402  (uses the names above)

__all__ += ["batch", "BatchResult"]
