"""Type stubs of the compiled extension (Rust, pyo3). SI units: m, N, Pa, Pa/m, m².

The public, documented API is the package :mod:`contactscope`, which wraps these functions.
"""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

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
def read_image(
    path: Path,
    channel: Optional[int] = None,
    pixel_size: Optional[PixelSize] = None,
    series: Optional[int] = None,
    z: Optional[int] = None,
    t: Optional[int] = None,
    axes: Optional[Dict[str, int]] = None,
    load_axis: Optional[str] = None,
) -> Dict[str, Any]: ...
def read_series(
    inputs: Sequence[Path],
    channel: Optional[int] = None,
    forces: Optional[Sequence[float]] = None,
    pixel_size: Optional[PixelSize] = None,
    manifest: bool = False,
    series: Optional[int] = None,
    z: Optional[int] = None,
    t: Optional[int] = None,
    axes: Optional[Dict[str, int]] = None,
    load_axis: Optional[str] = None,
) -> Dict[str, Any]: ...
def otsu_threshold(images: Stack) -> Dict[str, Any]: ...
def measure(
    image: Stack, threshold: float, pixel_size: Optional[PixelSize] = None
) -> Dict[str, Any]: ...
def analyze(
    images: Stack,
    forces: Optional[Sequence[float]] = None,
    pixel_size: Optional[PixelSize] = None,
    method: Union[str, float, None] = None,
) -> Dict[str, Any]: ...
def psf(
    beads: npt.NDArray[np.float64],
    pixel_size: PixelSize,
    bead_diameter: Optional[float] = None,
    saturation_level: Optional[float] = None,
) -> Dict[str, Any]: ...
def autocorrelation(
    image: npt.NDArray[np.float64], pixel_size: PixelSize, max_lag: Optional[float] = None
) -> Dict[str, Any]: ...
def newton(
    reflection: npt.NDArray[np.float64],
    contact: npt.NDArray[np.float64],
    pixel_size: PixelSize,
    wavelength: float = 488e-9,
    medium_index: float = 1.447,
    profiles: int = 20,
) -> Dict[str, Any]: ...
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
def simulate(
    heights: npt.NDArray[np.float64],
    pixel_size: PixelSize,
    modulus: float,
    loads: Sequence[float],
    model: str = "elastic",
    hardness: Optional[float] = None,
    k: Optional[float] = None,
    initial_hardness: float = 0.0,
    alpha: Optional[float] = None,
    radius: Optional[float] = None,
    periodic: bool = False,
    tolerance: float = 1e-8,
    max_iterations: int = 5000,
    maps: bool = True,
) -> Dict[str, Any]: ...
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
