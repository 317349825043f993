"""Type stubs of the compiled extension (Rust, pyo3). SI units: m, N, Pa, Pa/m, m².

The public, documented API is the package :mod:`contactscope`, which wraps these functions.
"""

from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, TypedDict, Union, final

import numpy as np
import numpy.typing as npt

__version__: str
__source_revision__: Optional[str]

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
    channel: Union[int, str, None]
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
    area_interval: Dict[str, Any]
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
    out: Optional[Path] = None,
    command_line: Optional[Sequence[str]] = None,
    overlays: bool = False,
    save_masks: bool = False,
    progress: Optional[Callable[[str, int, int], Any]] = None,
    pixel_size_uncertainty: float = 0.0,
    psf_fwhm: Optional[float] = None,
    zarr_out: Optional[Path] = None,
) -> AnalyzeResult: ...
def parse_forces(text: str) -> List[float]: ...
def parse_pixel_size(text: str) -> Tuple[float, float]: ...
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
    channel: Union[int, str, None] = None,
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
    images: Sequence[Union[Path, Stack]],
    pixel_size: Optional[PixelSize] = None,
    max_lag: Optional[float] = None,
    series: Optional[int] = None,
    channel: Union[int, str, None] = None,
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
    channel: Union[int, str, None] = None,
    z: Optional[int] = None,
    t: Optional[int] = None,
    axes: Selection = None,
) -> NewtonResult: ...
def blur_and_resample(
    map: npt.NDArray[np.float64], pixel_size: PixelSize, fwhm: float, image_pixel_size: PixelSize
) -> npt.NDArray[np.float64]: ...
class CompareSeriesRegistration(TypedDict):
    """One transform and shift for the whole series (each load refined within ``window_px``)."""

    transform: str
    shift_x_px: float
    shift_y_px: float
    shift_x_m: float
    shift_y_m: float
    correlation_peak: float
    window_px: int

class CompareResult(TypedDict):
    simulation: str
    psf_fwhm_m: float
    experiment_threshold: float
    simulated_threshold: float
    dihedral_search: bool
    upsample: int
    force_tolerance_fraction: float
    loads_matched: int
    dice_mean: float
    jaccard_mean: float
    series_registration: CompareSeriesRegistration
    method: Dict[str, str]
    loads: List[Dict[str, Any]]
    warnings: List[str]

def compare(
    micrographs: Union[Stack, SeriesSpec],
    forces: Optional[Sequence[float]],
    pixel_size: Optional[PixelSize],
    maps: Union[Path, npt.NDArray[np.float64]],
    map_forces: Optional[Sequence[float]],
    map_pixel_size: Optional[PixelSize],
    psf_fwhm: float,
    dihedral: Optional[bool] = None,
    upsample: Optional[int] = None,
    force_tolerance: Optional[float] = None,
    images: bool = False,
    out: Optional[Path] = None,
    command_line: Optional[Sequence[str]] = None,
) -> CompareResult: ...

# Height maps and contact mechanics
class TopographyPixelSize(TypedDict):
    x: float
    y: float

class TopographyDetrended(TypedDict):
    detrend: str
    pixel_size_x_m: float
    pixel_size_y_m: float
    h_rms_m: float
    h_prime_rms: float
    h_double_prime_rms_per_m: float

class TopographySummary(TypedDict, total=False):
    """``topography --json`` in SI units (``note`` only when ``detrended`` is ``None``)."""

    file: str
    format: str
    channel: str
    channels: List[str]
    nx: int
    ny: int
    pixel_size_m: TopographyPixelSize
    valid_points: int
    height_min_m: float
    height_max_m: float
    height_mean_m: float
    h_rms_as_stored_m: float
    h_prime_rms_as_stored: Optional[float]
    h_double_prime_rms_as_stored_per_m: Optional[float]
    detrended: Optional[TopographyDetrended]
    note: str

class TopographyResult(TypedDict):
    summary: TopographySummary
    notes: List[str]
    heights: npt.NDArray[np.float64]
    pixel_size_m: Tuple[float, float]

def read_topography(
    path: Path,
    pixel_size: Optional[PixelSize] = None,
    height_unit: Optional[float] = None,
    detrend: str = "plane",
    channel: Union[int, str, None] = None,
    fill_invalid: Optional[str] = None,
    measurement: Union[int, str, None] = None,
) -> TopographyResult: ...

class SurfaceResult(TypedDict):
    nx: int
    ny: int
    pixel_size_m: float
    h_rms_m: float
    h_prime_rms: float
    h_double_prime_rms_per_m: float
    heights: npt.NDArray[np.float64]

def surface(
    nx: int,
    ny: int,
    pixel_size: float,
    hurst: Optional[float] = None,
    rms_height: Optional[float] = None,
    rms_slope: Optional[float] = None,
    rolloff: Optional[float] = None,
    cutoff: Optional[float] = None,
    seed: Optional[int] = None,
) -> SurfaceResult: ...
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
    measurement: Optional[str]
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
    maps: str
    warnings: List[str]
    # (loads, ny, nx) stacks: all four with maps="all", contact only with maps="contact".
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
    maps: Union[str, bool] = "all",
    detrend: str = "plane",
    height_unit: Optional[float] = None,
    channel: Union[int, str, None] = None,
    fill_invalid: Optional[str] = None,
    device: str = "cpu",
    measurement: Union[int, str, None] = None,
    contact_engineering: Optional[Path] = None,
) -> SimulateResult: ...
class RampResult(TypedDict):
    areas_m2: npt.NDArray[np.float64]
    edge_contact: bool

def ramp(
    heights: Union[Path, npt.NDArray[np.float64]],
    pixel_size: Optional[PixelSize],
    modulus: float,
    family: str,
    parameter: Optional[float],
    loads: Sequence[float],
    radius: Optional[float] = None,
    tolerance: Optional[float] = None,
    max_iterations: Optional[int] = None,
    imaging_fwhm: Optional[float] = None,
    imaging_pixel_size: Optional[PixelSize] = None,
    detrend: str = "plane",
    periodic: bool = False,
    device: str = "cpu",
) -> RampResult: ...
def misfit(forces: Sequence[float], areas: Sequence[float], simulated: Sequence[float]) -> float: ...

class FitResult(TypedDict):
    experiment: str
    topography: str
    topography_channel: Optional[str]
    fill_invalid: Optional[str]
    radius_m: Optional[float]
    contact_modulus_pa: float
    roughness: Dict[str, float]
    measured: Dict[str, List[float]]
    simulated_areas: Dict[str, Any]
    method: str
    device: str
    models: List[Dict[str, Any]]
    best_model: Optional[str]
    sweep_rows: int
    warnings: List[str]

def fit_hardening(
    measured: Union[Path, Tuple[Sequence[float], Sequence[float]]],
    heights: Union[Path, npt.NDArray[np.float64]],
    pixel_size: Optional[PixelSize],
    modulus: float,
    radius: Optional[float] = None,
    families: Optional[Sequence[str]] = None,
    range: Optional[Tuple[float, float]] = None,
    grid: Optional[int] = None,
    ln_tolerance: Optional[float] = None,
    tolerance: Optional[float] = None,
    max_iterations: Optional[int] = None,
    imaging_fwhm: Optional[float] = None,
    imaging_pixel_size: Optional[PixelSize] = None,
    detrend: str = "plane",
    periodic: bool = False,
    height_unit: Optional[float] = None,
    channel: Union[int, str, None] = None,
    fill_invalid: Optional[str] = None,
    device: str = "cpu",
) -> FitResult: ...

# Mechanics tests (CSV files)
class FrictionTrace(TypedDict):
    file: str
    normal_force_n: float
    static_friction_n: float
    kinetic_friction_n: float
    slip_at: float
    slip_at_unit: str
    slip_sample: int
    slip_criterion: str
    mu_static: float
    mu_kinetic: float
    noise_n: float
    drop_threshold_n: float
    area_m2: Optional[float]

class ShearFit(TypedDict):
    tau_pa: float
    tau_se_pa: Optional[float]
    r2: Optional[float]
    points: int

class MuTrend(TypedDict):
    exponent: float
    exponent_se: Optional[float]
    relative_spread: float
    varies: Optional[bool]

class FrictionInputs(TypedDict):
    traces: List[str]
    areas: Optional[str]
    normal_force_n: Optional[float]
    rotation_radius_m: Optional[float]
    force_tolerance_fraction: float

class FrictionResult(TypedDict):
    inputs: FrictionInputs
    method: Dict[str, Any]
    tau_pa: Optional[float]
    tau_se_pa: Optional[float]
    r2: Optional[float]
    static_shear_fit: Optional[ShearFit]
    kinetic_shear_fit: Optional[ShearFit]
    mu_static_vs_load: Optional[MuTrend]
    traces: List[FrictionTrace]
    warnings: List[str]

def friction(
    traces: Sequence[Path],
    normal_force: Optional[float] = None,
    rotation_radius: Optional[float] = None,
    areas: Optional[Path] = None,
    force_tolerance: Optional[float] = None,
) -> FrictionResult: ...

class HertzPrediction(TypedDict):
    force_n: float
    contact_radius_m: float
    contact_area_m2: float

class HertzPoint(TypedDict):
    force_n: float
    displacement_m: float
    delta_m: float
    fitted_force_n: float
    residual_n: float

class HertzOffsetFit(TypedDict):
    contact_modulus_pa: float
    contact_modulus_se_pa: float
    r2: float
    contact_offset_displacement_m: float

class HertzResult(TypedDict):
    input: str
    radius_m: float
    method: Dict[str, str]
    points_used: int
    contact_modulus_pa: float
    contact_modulus_se_pa: float
    r2: float
    max_abs_residual_n: float
    offset_fit: Optional[HertzOffsetFit]
    predicted: List[HertzPrediction]
    points: List[HertzPoint]
    warnings: List[str]

def hertz(squeeze: Path, radius: float, loads: Optional[Sequence[float]] = None) -> HertzResult: ...

# File descriptions
class VoxelSize(TypedDict):
    x: Optional[float]
    y: Optional[float]
    z: Optional[float]

class InfoChannel(TypedDict):
    """One channel: its name (what ``channel=`` matches) and wavelengths (m)."""

    name: Optional[str]
    emission_m: Optional[float]
    excitation_m: Optional[float]

class InfoSeries(TypedDict, total=False):
    """One series (``planes`` only with ``stats=True``; ``axes_from`` for a TIFF: where its
    axes come from, ``ome``, ``imagej`` or ``pages``)."""

    index: int
    name: str
    axes: Dict[str, int]
    dtype: str
    channels: List[InfoChannel]
    pixel_size_m: VoxelSize
    pixel_size_source: Optional[str]
    axes_from: str
    planes: List[Dict[str, Any]]

class InfoResult(TypedDict):
    file: str
    format: str
    series: List[InfoSeries]

def info(path: Path, stats: bool = False) -> InfoResult: ...

# Generators and a writer
class SynthSeriesResult(TypedDict):
    forces_n: List[float]
    true_area_m2: List[float]
    true_contact_pixels: List[int]
    truth: npt.NDArray[np.bool_]
    images: npt.NDArray[np.uint16]

def synth_series(
    width: Optional[int] = None,
    height: Optional[int] = None,
    pixel_size: Optional[float] = None,
    forces: Optional[Sequence[float]] = None,
    seed: Optional[int] = None,
) -> SynthSeriesResult: ...
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
def write_folder(out: Path, files: Sequence[Tuple[str, bytes]]) -> List[Path]: ...

# The batch (contactscope.batch, contactscope.distributed.batch): a table as its columns, each
# (name, kind: "float" | "int" | "text" | "bool", values with None for nulls).
TableColumns = List[Tuple[str, str, List[Any]]]

class BatchOutcome(TypedDict):
    series: int
    ok: int
    failed: int
    analysed: int
    reused: int
    image_rows: int
    written: List[str]
    tables_seconds: float
    warnings: List[str]
    failures: List[List[str]]
    bytes_hashed: int
    images_table: TableColumns
    series_table: TableColumns

@final
class BatchPlan:
    def run(
        self, progress: Optional[Callable[[str, int, int], None]] = None
    ) -> BatchOutcome: ...
    def tasks(self) -> List[str]: ...
    def counts(self) -> Tuple[int, int]: ...
    def finish(self, records: Sequence[str]) -> BatchOutcome: ...

def batch_plan(
    kind: str, source: str, out: Path, base: Optional[Path] = None,
    patterns: Sequence[str] = ..., tiff_folders: bool = False,
    options: Dict[str, str] = ..., overlays: bool = False, save_masks: bool = False,
    memory_mib: int = 128, device: str = "cpu", rerun: str = "changed",
    color_by: Optional[str] = None, command_line: Sequence[str] = ...,
) -> BatchPlan: ...

def batch_series(task: str) -> str: ...
def check_out_folder(out: Path) -> None: ...
