"""Type stubs of the compiled extension (Rust, pyo3). SI units: m, N, Pa, Pa/m, m².

The public, documented API is the package :mod:`contactscope`, which wraps these functions.
"""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str

PixelSize = Union[float, Tuple[float, float], Sequence[float]]
Path = Union[str, PathLike[str]]
Stack = Union[
    npt.NDArray[np.uint8],
    npt.NDArray[np.uint16],
    npt.NDArray[np.int16],
    npt.NDArray[np.float32],
    npt.NDArray[np.float64],
]

class InputError(ValueError): ...
class FileError(OSError): ...
class ConvergenceError(ValueError): ...
class InternalError(RuntimeError): ...

def set_num_threads(n: int) -> None: ...
def get_num_threads() -> int: ...

# Micrographs
class SeriesSpec(TypedDict):
    """The files of a series, as the command line's inputs, --manifest and selection flags."""

    inputs: List[str]
    manifest: Optional[str]
    series: Optional[int]
    channel: Optional[int]
    z: Optional[int]
    t: Optional[int]
    axes: Optional[Dict[str, int]]
    load_axis: Optional[str]
    forces: Optional[List[float]]

class SeriesResult(TypedDict):
    images: Stack
    forces_n: List[Optional[float]]
    paths: List[str]
    pages: List[int]
    pixel_size_m: Optional[Tuple[float, float]]
    pixel_size_source: Optional[str]
    warnings: List[str]

class ThresholdResult(TypedDict):
    threshold: float
    method: str
    contact_rule: str
    pixels: int
    images: int
    files: int
    warnings: List[str]

class AnalyzeResult(TypedDict):
    inputs: Dict[str, Any]
    threshold: Dict[str, Any]
    area_unit: str
    fits: Dict[str, Any]
    hertz: Optional[Dict[str, float]]
    warnings: List[str]
    rows: List[Dict[str, Any]]

def read_series(spec: SeriesSpec, pixel_size: Optional[PixelSize] = None) -> SeriesResult: ...
def otsu_threshold(images: Union[Stack, SeriesSpec]) -> ThresholdResult: ...
def measure(
    image: Stack, threshold: float, pixel_size: Optional[PixelSize] = None
) -> Dict[str, Any]: ...
def analyze(
    images: Union[Stack, SeriesSpec],
    forces: Optional[Sequence[float]] = None,
    pixel_size: Optional[PixelSize] = None,
    method: Union[str, float, None] = None,
    radius: Optional[float] = None,
    modulus: Optional[float] = None,
    masks: bool = False,
) -> AnalyzeResult: ...
Selection = Optional[Dict[str, int]]

class PsfBead(TypedDict):
    """One bead candidate: a row of beads.csv."""

    bead: int
    x_px: float
    y_px: float
    plane: int
    page: int
    x_m: float
    y_m: float
    peak: float
    background: Optional[float]
    centroid_x_px: Optional[float]
    centroid_y_px: Optional[float]
    sigma_m: Optional[float]
    fwhm_m: Optional[float]
    sigma_raw_m: Optional[float]
    sigma_x_m: Optional[float]
    sigma_y_m: Optional[float]
    ellipticity: Optional[float]
    fit_rms_rel: Optional[float]
    used: bool
    skip_reason: Optional[str]

class PsfSkipped(TypedDict):
    bead: int
    x_px: float
    y_px: float
    plane: int
    reason: str
    detail: str

class PsfDetection(TypedDict):
    background: float
    noise: float
    threshold: float
    sigma_guess_px: float

class PsfResult(TypedDict):
    """psf.json in SI units, with the rows of beads.csv."""

    input: str
    planes: int
    pixel_size_m: float
    pixel_size_source: str
    beads_found: int
    beads_used: int
    bead_diameter_m: Optional[float]
    bead_correction_applied: bool
    bead_correction: str
    summary_from: str
    method: Dict[str, Any]
    detection: PsfDetection
    saturation_level: Optional[float]
    skipped: List[PsfSkipped]
    sigma_m_mean: float
    sigma_m_sd: Optional[float]
    fwhm_m_mean: float
    fwhm_m_sd: Optional[float]
    sigma_raw_m_mean: float
    sigma_raw_m_sd: Optional[float]
    fwhm_raw_m_mean: float
    fwhm_raw_m_sd: Optional[float]
    sigma_x_2d_m_mean: float
    sigma_x_2d_m_sd: Optional[float]
    sigma_y_2d_m_mean: float
    sigma_y_2d_m_sd: Optional[float]
    beads: List[PsfBead]

def psf(
    beads: Union[Path, Stack],
    pixel_size: Optional[PixelSize] = None,
    bead_diameter: Optional[float] = None,
    saturation_level: Optional[float] = None,
    series: Optional[int] = None,
    channel: Optional[int] = None,
    z: Optional[int] = None,
    t: Optional[int] = None,
    axes: Selection = None,
) -> PsfResult: ...

class AutocorrImage(TypedDict):
    """One image of autocorr.json, with its curve."""

    image: str
    file: str
    page: int
    width_px: int
    height_px: int
    pixel_size_x_m: float
    pixel_size_y_m: float
    max_lag_m: float
    correlation_length_m_1e: Optional[float]
    first_zero_m: Optional[float]
    lag_m: npt.NDArray[np.float64]
    acf: npt.NDArray[np.float64]

class AutocorrResult(TypedDict):
    """autocorr.json in SI units."""

    method: Dict[str, str]
    images: List[AutocorrImage]
    warnings: List[str]

def autocorrelation(
    images: List[Union[Path, Stack]],
    pixel_size: Optional[PixelSize] = None,
    max_lag: Optional[float] = None,
    series: Optional[int] = None,
    channel: Optional[int] = None,
    z: Optional[int] = None,
    t: Optional[int] = None,
    axes: Selection = None,
) -> AutocorrResult: ...

class NewtonInputs(TypedDict):
    reflection: str
    fluorescence: str
    pixel_size_x_m: float
    pixel_size_y_m: float

class NewtonRingGap(TypedDict):
    order: int
    gap_m: float

class NewtonProfile(TypedDict):
    """One line profile (newton.json's profiles; newton_profiles.csv)."""

    profile: int
    angle_deg: float
    rings: int
    edge_radius_m: Optional[float]
    half_lines_used: int
    a_m: Optional[float]
    R_m: Optional[float]
    rms_residual_m: Optional[float]
    shifted_rms_residual_m: Optional[float]
    shifted_residual_ratio: Optional[float]
    detection_gap_m: Optional[float]
    used: bool
    skipped_reason: Optional[str]

class NewtonSkipped(TypedDict):
    profile: int
    angle_deg: float
    reason: str

class NewtonRing(TypedDict):
    """One ring maximum: a row of newton_rings.csv."""

    profile: int
    angle_deg: float
    side: str
    order: int
    r_m: float
    gap_m: float
    fit_gap_m: Optional[float]
    used: bool

class NewtonResult(TypedDict):
    """newton.json in SI units, with the rows of newton_rings.csv."""

    inputs: NewtonInputs
    detection_gap_m_mean: float
    detection_gap_m_sd: Optional[float]
    edge_radius_m: float
    edge_radius_m_sd: Optional[float]
    contact_radius_a_m_mean: float
    contact_radius_a_m_sd: Optional[float]
    sphere_radius_R_m_mean: float
    sphere_radius_R_m_sd: Optional[float]
    profiles_used: int
    profiles_total: int
    profiles_needed: int
    centre_x_px: float
    centre_y_px: float
    centre_x_m: float
    centre_y_m: float
    fluorescence_threshold: float
    fluorescence_contact_pixels: int
    wavelength_m: float
    medium_index: float
    phase: str
    ring_gaps_m: List[NewtonRingGap]
    method: Dict[str, Any]
    profiles: List[NewtonProfile]
    skipped_profiles: List[NewtonSkipped]
    rings: List[NewtonRing]

def newton(
    reflection: Union[Path, Stack],
    contact: Union[Path, Stack],
    pixel_size: Optional[PixelSize] = None,
    wavelength: Optional[float] = None,
    medium_index: Optional[float] = None,
    profiles: Optional[int] = None,
    phase: Optional[str] = None,
    contact_channel: Optional[int] = None,
    series: Optional[int] = None,
    channel: Optional[int] = None,
    z: Optional[int] = None,
    t: Optional[int] = None,
    axes: Selection = None,
) -> NewtonResult: ...
def blur_and_resample(
    map: npt.NDArray[np.float64], pixel_size: PixelSize, fwhm: float, image_pixel_size: PixelSize
) -> npt.NDArray[np.float64]: ...
def compare(
    micrographs: Stack,
    forces: Sequence[float],
    pixel_size: PixelSize,
    maps: npt.NDArray[np.float64],
    map_forces: Sequence[float],
    map_pixel_size: PixelSize,
    psf_fwhm: float,
    dihedral: bool = False,
    upsample: int = 20,
    force_tolerance: float = 0.01,
) -> List[Dict[str, Any]]: ...

# Height maps and contact mechanics
def read_topography(
    path: Path,
    pixel_size: Optional[PixelSize] = None,
    height_unit: Optional[float] = None,
    detrend: str = "plane",
    channel: Optional[str] = None,
    fill_invalid: Optional[str] = None,
) -> Dict[str, Any]: ...
def surface(
    nx: int,
    ny: int,
    pixel_size: float,
    hurst: float = 0.8,
    rms_height: Optional[float] = None,
    rms_slope: Optional[float] = None,
    rolloff: Optional[float] = None,
    cutoff: Optional[float] = None,
    seed: int = 0,
) -> npt.NDArray[np.float64]: ...
class SimulatedLoad(TypedDict):
    force_n: float
    area_m2: float
    contact_fraction: float
    mean_pressure_pa: Optional[float]
    max_pressure_pa: Optional[float]
    approach_m: float
    patches: int
    iterations: int
    residual: float
    plastic_volume_m3: float
    edge_contact: bool

class HeightFacts(TypedDict):
    path: str
    nx: int
    ny: int
    pixel_size_x_m: float
    pixel_size_y_m: float
    detrend: str
    channel: Optional[str]
    fill_invalid: Optional[str]
    h_rms_m: float
    h_prime_rms: float
    h_double_prime_rms_per_m: float
    sphere_radius_m: Optional[float]

class SimulateResult(TypedDict, total=False):
    topography: HeightFacts
    contact_modulus_pa: float
    model: Dict[str, Any]
    boundary: str
    solver: Dict[str, Any]
    loads: List[SimulatedLoad]
    power_law: Optional[Dict[str, Any]]
    warnings: List[str]
    # With maps=True: (loads, ny, nx) stacks.
    pressure: npt.NDArray[np.float64]
    gap: npt.NDArray[np.float64]
    plastic: npt.NDArray[np.float64]
    contact: npt.NDArray[np.bool_]

def simulate(
    heights: Union[Path, npt.NDArray[np.float64]],
    pixel_size: Optional[PixelSize],
    modulus: float,
    loads: Sequence[float],
    model: str = "elastic",
    hardness: Optional[float] = None,
    k: Optional[float] = None,
    initial_hardness: Optional[float] = None,
    alpha: Optional[float] = None,
    radius: Optional[float] = None,
    periodic: bool = False,
    tolerance: Optional[float] = None,
    max_iterations: Optional[int] = None,
    maps: bool = True,
    detrend: str = "plane",
    height_unit: Optional[float] = None,
    channel: Optional[str] = None,
    fill_invalid: Optional[str] = None,
) -> SimulateResult: ...
def ramp(
    heights: npt.NDArray[np.float64],
    pixel_size: PixelSize,
    modulus: float,
    family: str,
    parameter: Optional[float],
    loads: Sequence[float],
    radius: Optional[float] = None,
    tolerance: float = 1e-8,
    max_iterations: int = 5000,
    imaging_fwhm: Optional[float] = None,
    imaging_pixel_size: Optional[PixelSize] = None,
) -> Dict[str, Any]: ...
def misfit(forces: Sequence[float], areas: Sequence[float], simulated: Sequence[float]) -> float: ...
def fit_hardening(
    forces: Sequence[float],
    areas: Sequence[float],
    heights: npt.NDArray[np.float64],
    pixel_size: PixelSize,
    modulus: float,
    radius: Optional[float] = None,
    family: str = "hardening",
    range: Optional[Tuple[float, float]] = None,
    grid: int = 7,
    ln_tolerance: float = 0.01,
    tolerance: float = 1e-8,
    max_iterations: int = 5000,
    imaging_fwhm: Optional[float] = None,
    imaging_pixel_size: Optional[PixelSize] = None,
) -> Dict[str, Any]: ...

# Generators and a writer
def synth_series(
    width: int = 256,
    height: int = 256,
    pixel_size: float = 200e-9,
    forces: Optional[Sequence[float]] = None,
    seed: int = 2018,
) -> Dict[str, Any]: ...
def synth_beads(
    width: int = 128,
    height: int = 128,
    planes: int = 1,
    beads: int = 6,
    sigma_px: float = 1.91,
    seed: int = 7,
) -> npt.NDArray[np.uint16]: ...
def synth_newton(
    width: int = 256,
    height: int = 256,
    pixel_size: float = 200e-9,
    contact_radius: float = 12e-6,
    detection_gap: float = 9e-9,
    seed: int = 7,
) -> Dict[str, Any]: ...
def write_tiff(
    path: Path,
    stack: Union[npt.NDArray[np.uint16], npt.NDArray[np.float32]],
    pixel_size: Optional[PixelSize] = None,
) -> None: ...
