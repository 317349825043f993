//! The solver on an NVIDIA GPU (cargo feature `cuda`): the load-controlled Polonsky–Keer
//! iteration of [`crate::solver::cg::load`] with its fields resident on the device, the elastic
//! operator as cuFFT transforms (float64; free boundaries zero-padded on the same window ladder
//! as the host, periodic ones on the grid) and the fused passes as kernels with deterministic
//! reductions. Only scalars cross to the host per iteration.
//!
//! The CUDA driver, NVRTC (which compiles the kernels of `kernels.cu` when a [`Gpu`] is opened)
//! and cuFFT are loaded at run time, so a build with the feature runs on machines without them
//! and says so in one line ([`Gpu::open`]); a build without the feature has the same API and
//! refuses every GPU. Pass a [`Gpu`] to the solver with [`SolverOptions::gpu`].
//!
//! [`SolverOptions::gpu`]: crate::solver::cg::SolverOptions::gpu

#[cfg(feature = "cuda")]
mod device;

#[cfg(feature = "cuda")]
pub use device::Gpu;
#[cfg(feature = "cuda")]
pub(crate) use device::{device_error, DeviceOperator, Fold, Plastic, Reduction};

/// Which processor a command's solver runs on, as the user asks for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum DeviceChoice {
    /// The CPU (the default).
    #[default]
    Cpu,
    /// The first CUDA GPU; an error when none is usable.
    Cuda,
    /// The first CUDA GPU when one is usable, else the CPU.
    Auto,
}

impl DeviceChoice {
    /// The names, for messages and option parsers.
    pub const NAMES: [&'static str; 3] = ["cpu", "cuda", "auto"];

    /// The choice named `name` (`cpu`, `cuda` or `auto`).
    pub fn parse(name: &str) -> Option<DeviceChoice> {
        match name.trim().to_ascii_lowercase().as_str() {
            "cpu" => Some(DeviceChoice::Cpu),
            "cuda" => Some(DeviceChoice::Cuda),
            "auto" => Some(DeviceChoice::Auto),
            _ => None,
        }
    }

    /// The GPU this choice asks for ([`shared`]): `None` for the CPU (also for `auto` when no
    /// GPU is usable), an error for `cuda` when none is.
    pub fn open(self) -> crate::error::Result<Option<&'static Gpu>> {
        match self {
            DeviceChoice::Cpu => Ok(None),
            DeviceChoice::Cuda => shared().map(Some),
            DeviceChoice::Auto => Ok(shared().ok()),
        }
    }
}

/// The process's GPU (the first CUDA device), opened on first use and kept: its compiled
/// kernels, cuFFT plans and operator spectra are reused by every later solve, ramp and command
/// of the process. An error (not kept: a later call tries again) when none is usable.
pub fn shared() -> crate::error::Result<&'static Gpu> {
    static SHARED: std::sync::OnceLock<Gpu> = std::sync::OnceLock::new();
    if let Some(gpu) = SHARED.get() {
        return Ok(gpu);
    }
    let opened = Gpu::open(0)?;
    Ok(SHARED.get_or_init(|| opened))
}

/// A GPU; in a build without the feature `cuda` none can be opened.
#[cfg(not(feature = "cuda"))]
#[derive(Debug)]
pub struct Gpu {
    never: std::convert::Infallible,
}

#[cfg(not(feature = "cuda"))]
impl Gpu {
    /// Always an error: this build has no CUDA support.
    pub fn open(_ordinal: usize) -> crate::error::Result<Gpu> {
        Err(crate::error::Error::Device {
            reason: "this build of contactscope has no CUDA support (build it with \
                     `--features cuda`)"
                .into(),
        })
    }

    /// The device's name.
    pub fn name(&self) -> &str {
        match self.never {}
    }

    /// Free and total device memory, bytes.
    pub fn memory(&self) -> crate::error::Result<(usize, usize)> {
        match self.never {}
    }

    /// The most device memory seen in use while a solve held its fields, bytes.
    pub fn peak_memory_used(&self) -> usize {
        match self.never {}
    }

    /// u = G∗p on the GPU for a pressure on an `h × w` window of `op`'s grid.
    pub fn displacement(
        &self,
        _op: &crate::solver::halfspace::ElasticOperator,
        _pressure: &[f64],
        _h: usize,
        _w: usize,
    ) -> crate::error::Result<Vec<f64>> {
        match self.never {}
    }

    pub(crate) fn unreachable(&self) -> ! {
        match self.never {}
    }
}

/// A one-line description of where a solve runs: "cpu" or "cuda: <device name>".
pub fn describe(gpu: Option<&Gpu>) -> String {
    match gpu {
        None => "cpu".into(),
        Some(gpu) => format!("cuda: {}", gpu.name()),
    }
}
