//! The CUDA device: context, the kernels compiled by NVRTC, the elastic operators (transfer
//! functions and cuFFT plans, cached per grid) and the deterministic reductions.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use cudarc::cufft::sys::{cufftType, double2};
use cudarc::cufft::CudaFft;
use cudarc::driver::{
    CudaContext, CudaFunction, CudaModule, CudaSlice, CudaStream, LaunchArgs, LaunchConfig,
    PinnedHostSlice, PushKernelArg,
};
use cudarc::nvrtc::{compile_ptx_with_opts, CompileOptions};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::solver::halfspace::{Boundary, ElasticOperator};

/// Blocks of every reducing kernel: fixed, so that the sums do not depend on the device.
pub(crate) const BLOCKS: u32 = 512;
/// Threads per block (`THREADS` in kernels.cu).
const THREADS: u32 = 256;
/// Most blocks of an element-wise kernel (they loop over the grid).
const MAX_BLOCKS: usize = 8192;
/// Most operators kept planned (a ramp at 2048² uses the whole grid's and 2–4 windows'; one at
/// 4096² holds about 1.6 GB of transfer function, buffers and cuFFT work area).
const MAX_OPERATORS: usize = 8;

const SOURCE: &str = include_str!("kernels.cu");

/// A CUDA error as the library's [`Error::Device`].
pub(crate) fn device_error(what: &str, error: impl std::fmt::Debug) -> Error {
    Error::Device {
        reason: format!("{what}: {error:?}"),
    }
}

macro_rules! kernels {
    ($($name:ident),* $(,)?) => {
        /// The compiled kernels of kernels.cu.
        pub(crate) struct Kernels {
            $(pub(crate) $name: CudaFunction,)*
        }

        impl Kernels {
            fn load(module: &Arc<CudaModule>) -> Result<Kernels> {
                Ok(Kernels {
                    $($name: module
                        .load_function(stringify!($name))
                        .map_err(|e| device_error(concat!("loading kernel ", stringify!($name)), e))?,)*
                })
            }
        }
    };
}

kernels!(
    love_kernel,
    real_part,
    periodic_transfer,
    pad,
    multiply,
    crop,
    embed,
    gaps,
    residual_sq,
    direction,
    curvature,
    step,
    shift_sums,
    apply_shift,
    change,
    start_sums,
    affine,
);

/// An NVIDIA GPU opened for the solver.
pub struct Gpu {
    name: String,
    pub(crate) stream: Arc<CudaStream>,
    pub(crate) kernels: Kernels,
    operators: Mutex<Vec<Arc<DeviceOperator>>>,
    /// The most device memory seen in use while a solve held its fields, bytes.
    peak_used: AtomicUsize,
    /// Page-locked host memory that the fields pass through on their way to and from the
    /// device (copies from pageable memory ran at 1.6 GB/s on an H200 machine).
    staging: Mutex<Option<PinnedHostSlice<f64>>>,
    _ctx: Arc<CudaContext>,
}

impl std::fmt::Debug for Gpu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gpu").field("name", &self.name).finish()
    }
}

impl Gpu {
    /// Open GPU `ordinal` (0 for the first): load the CUDA driver, NVRTC and cuFFT, create a
    /// context and compile the kernels. A clear [`Error::Device`] when any of them is missing.
    pub fn open(ordinal: usize) -> Result<Gpu> {
        let missing = |what: &str, hint: &str| Error::Device {
            reason: format!("{what} was not found ({hint})"),
        };
        // SAFETY: each only tries to load the library by name.
        unsafe {
            if !cudarc::driver::sys::is_culib_present() {
                return Err(missing(
                    "the NVIDIA CUDA driver (libcuda)",
                    "no NVIDIA driver is installed on this machine",
                ));
            }
            if !cudarc::nvrtc::sys::is_culib_present() {
                return Err(missing(
                    "the CUDA runtime compiler NVRTC (libnvrtc)",
                    "install the CUDA toolkit or the nvidia-cuda-nvrtc package and add its \
                     lib folder to LD_LIBRARY_PATH",
                ));
            }
            if !cudarc::cufft::sys::is_culib_present() {
                return Err(missing(
                    "cuFFT (libcufft)",
                    "install the CUDA toolkit or the nvidia-cufft package and add its lib \
                     folder to LD_LIBRARY_PATH",
                ));
            }
        }
        let count =
            CudaContext::device_count().map_err(|e| device_error("no usable CUDA device", e))?;
        if count <= ordinal as i32 {
            return Err(Error::Device {
                reason: format!("no CUDA device {ordinal} (the driver sees {count})"),
            });
        }
        let ctx = CudaContext::new(ordinal).map_err(|e| device_error("opening the GPU", e))?;
        // One stream: the safe API's cross-stream event tracking is not needed.
        // SAFETY: every buffer is used on `stream` only.
        unsafe { ctx.disable_event_tracking() };
        let name = ctx
            .name()
            .map_err(|e| device_error("reading the GPU's name", e))?;
        let ptx = compile_ptx_with_opts(
            SOURCE,
            CompileOptions {
                name: Some("kernels.cu".into()),
                ..Default::default()
            },
        )
        .map_err(|e| device_error("compiling the solver's kernels with NVRTC", e))?;
        let module = ctx
            .load_module(ptx)
            .map_err(|e| device_error("loading the solver's kernels", e))?;
        let kernels = Kernels::load(&module)?;
        let stream = ctx.default_stream();
        Ok(Gpu {
            name,
            stream,
            kernels,
            operators: Mutex::new(Vec::new()),
            peak_used: AtomicUsize::new(0),
            staging: Mutex::new(None),
            _ctx: ctx,
        })
    }

    /// The device's name ("NVIDIA H100 80GB HBM3").
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Free and total device memory, bytes.
    pub fn memory(&self) -> Result<(usize, usize)> {
        self.stream
            .context()
            .mem_get_info()
            .map_err(|e| device_error("reading the GPU's memory", e))
    }

    /// The most device memory in use (by every process) seen while a solve held its fields,
    /// bytes: what a solve needs, plus what else runs on the device.
    pub fn peak_memory_used(&self) -> usize {
        self.peak_used.load(Ordering::Relaxed)
    }

    /// Note the device memory in use now (see [`Gpu::peak_memory_used`]).
    pub(crate) fn note_memory(&self) {
        if let Ok((free, total)) = self.memory() {
            self.peak_used
                .fetch_max(total.saturating_sub(free), Ordering::Relaxed);
        }
    }

    /// u = G∗p on the GPU for a pressure on an `h × w` window of `op`'s grid (zero outside it),
    /// as [`ElasticOperator::apply_window`] computes it on the host.
    pub fn displacement(
        &self,
        op: &ElasticOperator,
        pressure: &[f64],
        h: usize,
        w: usize,
    ) -> Result<Vec<f64>> {
        if pressure.len() != h * w || h > op.ny() || w > op.nx() {
            return Err(Error::SizeMismatch {
                what: "GPU operator: pressure values for the window",
                expected: h * w,
                got: pressure.len(),
            });
        }
        let device_op = self.window_operator(op, h, w)?;
        let p = self.upload(pressure)?;
        let mut u = self.zeros(h * w)?;
        self.apply(&device_op, &p, h, w, &mut u)?;
        self.download(&u, h * w)
    }

    /// A zeroed device buffer of `n` values.
    pub(crate) fn zeros(&self, n: usize) -> Result<CudaSlice<f64>> {
        self.stream
            .alloc_zeros::<f64>(n.max(1))
            .map_err(|e| device_error(&format!("allocating {} MB on the GPU", (n * 8) >> 20), e))
    }

    /// A device copy of a device buffer.
    pub(crate) fn duplicate(&self, buffer: &CudaSlice<f64>) -> Result<CudaSlice<f64>> {
        let mut copy = self.zeros(buffer.len())?;
        self.stream
            .memcpy_dtod(buffer, &mut copy)
            .map_err(|e| device_error("copying on the GPU", e))?;
        Ok(copy)
    }

    /// A device copy of `values`.
    pub(crate) fn upload(&self, values: &[f64]) -> Result<CudaSlice<f64>> {
        let mut buffer = self.zeros(values.len())?;
        self.upload_into(values, &mut buffer)?;
        Ok(buffer)
    }

    /// Copy `values` into the start of `buffer` (through the page-locked staging memory).
    pub(crate) fn upload_into(&self, values: &[f64], buffer: &mut CudaSlice<f64>) -> Result<()> {
        let n = values.len();
        if n == 0 {
            return Ok(());
        }
        let mut staging = self.staging(n)?;
        let pinned = staging.as_mut().expect("staging memory");
        let host = pinned
            .as_mut_slice()
            .map_err(|e| device_error("staging memory", e))?;
        parallel_copy(values, &mut host[..n]);
        let mut view = buffer.slice_mut(0..n);
        self.stream
            .memcpy_htod(&host[..n], &mut view)
            .map_err(|e| device_error("copying to the GPU", e))?;
        self.sync()
    }

    /// The first `n` values of `buffer`, on the host (through the page-locked staging memory).
    pub(crate) fn download(&self, buffer: &CudaSlice<f64>, n: usize) -> Result<Vec<f64>> {
        if n == 0 {
            return Ok(Vec::new());
        }
        let mut staging = self.staging(n)?;
        let pinned = staging.as_mut().expect("staging memory");
        let host = pinned
            .as_mut_slice()
            .map_err(|e| device_error("staging memory", e))?;
        self.stream
            .memcpy_dtoh(&buffer.slice(0..n), &mut host[..n])
            .map_err(|e| device_error("copying from the GPU", e))?;
        self.sync()?;
        let mut out = vec![0.0; n];
        parallel_copy(&host[..n], &mut out);
        Ok(out)
    }

    /// The staging memory, grown to at least `n` values.
    fn staging(&self, n: usize) -> Result<std::sync::MutexGuard<'_, Option<PinnedHostSlice<f64>>>> {
        let mut staging = self.staging.lock().expect("staging lock");
        if staging.as_ref().is_none_or(|s| s.len() < n) {
            *staging = None;
            // SAFETY: plain page-locked memory (flags 0: cached, readable by the host).
            let pinned = unsafe { self.stream.context().alloc_pinned_with_flags::<f64>(n, 0) }
                .map_err(|e| device_error("allocating page-locked host memory", e))?;
            *staging = Some(pinned);
        }
        Ok(staging)
    }

    /// Wait for the stream; reports errors of earlier launches.
    pub(crate) fn sync(&self) -> Result<()> {
        self.stream
            .synchronize()
            .map_err(|e| device_error("running the solver's kernels", e))
    }

    /// A launch of `kernel` on the GPU's stream; add its arguments in order.
    pub(crate) fn launch<'a>(&'a self, kernel: &'a CudaFunction) -> LaunchArgs<'a> {
        self.stream.launch_builder(kernel)
    }

    /// The configuration of an element-wise kernel over `n` elements.
    pub(crate) fn elementwise(n: usize) -> LaunchConfig {
        let blocks = n.div_ceil(THREADS as usize).clamp(1, MAX_BLOCKS) as u32;
        LaunchConfig {
            grid_dim: (blocks, 1, 1),
            block_dim: (THREADS, 1, 1),
            shared_mem_bytes: 0,
        }
    }

    /// The configuration of a reducing kernel (fixed grid).
    pub(crate) fn reducing() -> LaunchConfig {
        LaunchConfig {
            grid_dim: (BLOCKS, 1, 1),
            block_dim: (THREADS, 1, 1),
            shared_mem_bytes: 0,
        }
    }

    /// The operator for fields on an `h × w` window of `op`'s grid, as
    /// [`ElasticOperator::window`] chooses it on the host but on powers of two: the whole
    /// operator, or a smaller free one. Planned once per grid and cached.
    pub(crate) fn window_operator(
        &self,
        op: &ElasticOperator,
        h: usize,
        w: usize,
    ) -> Result<Arc<DeviceOperator>> {
        let (ny, nx) = (op.ny(), op.nx());
        // Powers of two: cuFFT plans them fastest, and fewer sizes mean fewer plans (a plan
        // for a new size costs more than a whole solve).
        let (wy, wx) = (h.next_power_of_two(), w.next_power_of_two());
        let grid = if op.boundary() == Boundary::Periodic || (wy >= ny && wx >= nx) {
            (ny, nx)
        } else {
            (wy.min(ny), wx.min(nx))
        };
        let (dx, dy) = op.pixel_size();
        let key = OperatorKey {
            grid,
            dx: dx.to_bits(),
            dy: dy.to_bits(),
            e_star: op.modulus().to_bits(),
            periodic: op.boundary() == Boundary::Periodic,
        };
        let mut cache = self.operators.lock().expect("operator cache lock");
        if let Some(found) = cache.iter().find(|o| o.key == key) {
            return Ok(Arc::clone(found));
        }
        // The cache lives as long as the process (`shared`): with many grids (a Python session
        // looping over maps) drop the oldest operator no solve holds before adding one.
        if cache.len() >= MAX_OPERATORS {
            if let Some(idle) = cache.iter().position(|o| Arc::strong_count(o) == 1) {
                cache.remove(idle);
            }
        }
        let made = Arc::new(DeviceOperator::new(self, key, dx, dy, op.modulus())?);
        cache.push(Arc::clone(&made));
        Ok(made)
    }

    /// dst (h × w) = G∗src for src (h × w) on a window of `op` (pressure outside it zero).
    pub(crate) fn apply(
        &self,
        op: &DeviceOperator,
        src: &CudaSlice<f64>,
        h: usize,
        w: usize,
        dst: &mut CudaSlice<f64>,
    ) -> Result<()> {
        let (fy, fx) = (op.fy, op.fx);
        let mut work = op.work.lock().expect("operator buffers lock");
        let OperatorWork {
            forward,
            inverse,
            real,
            spectrum,
        } = &mut *work;
        let (fy32, fx32, h32, w32) = (fy as i32, fx as i32, h as i32, w as i32);
        let k = &self.kernels;
        let launched = (|| {
            // SAFETY: the arguments match the kernels' signatures; every index is bounded by
            // the sizes passed with the buffers.
            unsafe {
                self.launch(&k.pad)
                    .arg(&mut *real)
                    .arg(&fy32)
                    .arg(&fx32)
                    .arg(src)
                    .arg(&h32)
                    .arg(&w32)
                    .launch(Gpu::elementwise(fy * fx))?;
            }
            Ok::<_, cudarc::driver::DriverError>(())
        })();
        launched.map_err(|e| device_error("padding", e))?;
        forward
            .exec_d2z(&*real, &mut *spectrum)
            .map_err(|e| device_error("cuFFT forward transform", e))?;
        let n_spec = op.spectrum_len() as i64;
        // SAFETY: as above.
        unsafe {
            self.launch(&k.multiply)
                .arg(&mut *spectrum)
                .arg(&op.transfer)
                .arg(&n_spec)
                .launch(Gpu::elementwise(op.spectrum_len()))
        }
        .map_err(|e| device_error("multiplying by the transfer function", e))?;
        inverse
            .exec_z2d(&mut *spectrum, &mut *real)
            .map_err(|e| device_error("cuFFT inverse transform", e))?;
        // SAFETY: as above.
        unsafe {
            self.launch(&k.crop)
                .arg(dst)
                .arg(&h32)
                .arg(&w32)
                .arg(&*real)
                .arg(&fx32)
                .launch(Gpu::elementwise(h * w))
        }
        .map_err(|e| device_error("cropping", e))?;
        Ok(())
    }
}

/// `to.copy_from_slice(from)` in parallel chunks (the page faults of a fresh vector dominate).
fn parallel_copy(from: &[f64], to: &mut [f64]) {
    const CHUNK: usize = 1 << 16;
    to.par_chunks_mut(CHUNK)
        .zip(from.par_chunks(CHUNK))
        .for_each(|(t, f)| t.copy_from_slice(f));
}

/// What identifies a planned operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct OperatorKey {
    /// The operator's grid (rows, columns) before padding.
    grid: (usize, usize),
    dx: u64,
    dy: u64,
    e_star: u64,
    periodic: bool,
}

/// An elastic operator on the device: its transfer function on the fy × (fx/2 + 1) half
/// spectrum (normalisation included) and the cuFFT plans and buffers of one application.
pub(crate) struct DeviceOperator {
    key: OperatorKey,
    fy: usize,
    fx: usize,
    transfer: CudaSlice<f64>,
    work: Mutex<OperatorWork>,
}

struct OperatorWork {
    forward: CudaFft,
    inverse: CudaFft,
    real: CudaSlice<f64>,
    spectrum: CudaSlice<double2>,
}

impl DeviceOperator {
    fn new(gpu: &Gpu, key: OperatorKey, dx: f64, dy: f64, e_star: f64) -> Result<Self> {
        let (ny, nx) = key.grid;
        let (fy, fx) = if key.periodic {
            (ny, nx)
        } else {
            (2 * ny, 2 * nx)
        };
        let half = fy * (fx / 2 + 1);
        let plan = |kind| {
            CudaFft::plan_2d(fy as i32, fx as i32, kind, Arc::clone(&gpu.stream))
                .map_err(|e| device_error(&format!("planning a {fy} × {fx} cuFFT transform"), e))
        };
        let forward = plan(cufftType::CUFFT_D2Z)?;
        let inverse = plan(cufftType::CUFFT_Z2D)?;
        let mut real = gpu.zeros(fy * fx)?;
        let mut spectrum = gpu
            .stream
            .alloc_zeros::<double2>(half)
            .map_err(|e| device_error("allocating a spectrum on the GPU", e))?;
        let mut transfer = gpu.zeros(half)?;
        let scale = 1.0 / (fy * fx) as f64;
        let (fy32, fx32) = (fy as i32, fx as i32);
        let k = &gpu.kernels;
        if key.periodic {
            let (lx, ly) = (nx as f64 * dx, ny as f64 * dy);
            // SAFETY: the arguments match the kernel's signature.
            unsafe {
                gpu.launch(&k.periodic_transfer)
                    .arg(&mut transfer)
                    .arg(&fy32)
                    .arg(&fx32)
                    .arg(&lx)
                    .arg(&ly)
                    .arg(&e_star)
                    .arg(&scale)
                    .launch(Gpu::elementwise(half))
            }
            .map_err(|e| device_error("the periodic transfer function", e))?;
        } else {
            // SAFETY: the arguments match the kernels' signatures.
            unsafe {
                gpu.launch(&k.love_kernel)
                    .arg(&mut real)
                    .arg(&fy32)
                    .arg(&fx32)
                    .arg(&dx)
                    .arg(&dy)
                    .arg(&e_star)
                    .launch(Gpu::elementwise(fy * fx))
            }
            .map_err(|e| device_error("the free-boundary kernel", e))?;
            forward
                .exec_d2z(&real, &mut spectrum)
                .map_err(|e| device_error("cuFFT transform of the kernel", e))?;
            let n = half as i64;
            // SAFETY: as above.
            unsafe {
                gpu.launch(&k.real_part)
                    .arg(&mut transfer)
                    .arg(&spectrum)
                    .arg(&n)
                    .arg(&scale)
                    .launch(Gpu::elementwise(half))
            }
            .map_err(|e| device_error("the free-boundary transfer function", e))?;
        }
        gpu.sync()?;
        Ok(DeviceOperator {
            key,
            fy,
            fx,
            transfer,
            work: Mutex::new(OperatorWork {
                forward,
                inverse,
                real,
                spectrum,
            }),
        })
    }

    fn spectrum_len(&self) -> usize {
        self.fy * (self.fx / 2 + 1)
    }
}

/// The plasticity as the kernels take it: mode 0 elastic, 1 penetration hardness (the bound
/// is the cap), 2 hardening (the bound is p_Y of the previous load; compliance 1/k).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Plastic {
    pub mode: i32,
    pub compliance: f64,
}

/// How a reduction slot combines.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Fold {
    Sum,
    Min,
    Max,
}

/// The block partials of the reducing kernels and their fold on the host, in block order.
pub(crate) struct Reduction {
    pub partials: CudaSlice<f64>,
    host: Vec<f64>,
}

/// Most partials per block (the step pass has 15).
const SLOTS: usize = 16;

impl Reduction {
    pub fn new(gpu: &Gpu) -> Result<Self> {
        Ok(Reduction {
            partials: gpu.zeros(BLOCKS as usize * SLOTS)?,
            host: vec![0.0; BLOCKS as usize * SLOTS],
        })
    }

    /// Fold the partials of a kernel that wrote `folds.len()` slots per block.
    pub fn fold(&mut self, gpu: &Gpu, folds: &[Fold]) -> Result<Vec<f64>> {
        let k = folds.len();
        let n = BLOCKS as usize * k;
        gpu.stream
            .memcpy_dtoh(&self.partials.slice(0..n), &mut self.host[..n])
            .map_err(|e| device_error("copying sums from the GPU", e))?;
        gpu.sync()?;
        let mut out: Vec<f64> = folds
            .iter()
            .map(|f| match f {
                Fold::Sum => 0.0,
                Fold::Min => f64::INFINITY,
                Fold::Max => f64::NEG_INFINITY,
            })
            .collect();
        for block in self.host[..n].chunks_exact(k) {
            for ((acc, v), f) in out.iter_mut().zip(block).zip(folds) {
                *acc = match f {
                    Fold::Sum => *acc + v,
                    Fold::Min => acc.min(*v),
                    Fold::Max => acc.max(*v),
                };
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kernels_compile_with_nvrtc() {
        // Needs NVRTC only (no GPU): run with its lib folder on LD_LIBRARY_PATH.
        // SAFETY: only tries to load the library.
        if !unsafe { cudarc::nvrtc::sys::is_culib_present() } {
            assert!(
                std::env::var_os("CONTACTSCOPE_REQUIRE_NVRTC").is_none(),
                "NVRTC (libnvrtc) not found on LD_LIBRARY_PATH"
            );
            eprintln!("skipped: NVRTC (libnvrtc) not found on the library path");
            return;
        }
        let compiled = compile_ptx_with_opts(
            SOURCE,
            CompileOptions {
                name: Some("kernels.cu".into()),
                ..Default::default()
            },
        );
        assert!(compiled.is_ok(), "{compiled:?}");
    }
}
