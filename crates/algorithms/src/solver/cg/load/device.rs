//! The fields of a load-controlled solve on a GPU ([`crate::solver::gpu`]): every field lives on
//! the device for the whole solve, each pass is one kernel (solver/gpu/kernels.cu, the same
//! arithmetic as the host passes of [`super::passes`]) and returns its scalars.

use std::sync::Arc;

use cudarc::driver::{CudaSlice, PushKernelArg};

use crate::error::Result;
use crate::solver::cg::{Plasticity, Problem};
use crate::solver::gpu::{device_error, DeviceOperator, Fold, Gpu, Plastic, Reduction};

use super::fields::{Fields, Gaps, Shift, ShiftSums, Step};
use super::window::Window;

/// Launch kernel `$kernel` of kernels.cu with `$config` and the arguments in order; a launch
/// error names `$pass`.
macro_rules! launch {
    ($gpu:expr, $kernel:ident, $config:expr, $pass:literal, [$($arg:expr),* $(,)?]) => {{
        let gpu: &Gpu = $gpu;
        // SAFETY: every call below passes the arguments of the kernel's signature in
        // kernels.cu, in order and of its types (i64 for `long long`, i32 for `int`), and
        // buffers holding at least the `n` values (or window sizes) passed with them.
        unsafe { gpu.launch(&gpu.kernels.$kernel)$(.arg($arg))*.launch($config) }
            .map(|_| ())
            .map_err(launch_error($pass))
    }};
}

/// The fields on the device. Each buffer holds the whole grid; the window's `h × w` values sit
/// at its start.
pub(super) struct DeviceFields<'a> {
    gpu: &'a Gpu,
    problem: &'a Problem<'a>,
    plasticity: Plasticity<'a>,
    plastic: Plastic,
    whole_s: CudaSlice<f64>,
    whole_bound: CudaSlice<f64>,
    s: CudaSlice<f64>,
    bound: CudaSlice<f64>,
    p: CudaSlice<f64>,
    previous: CudaSlice<f64>,
    u: CudaSlice<f64>,
    t: CudaSlice<f64>,
    r: CudaSlice<f64>,
    spare: CudaSlice<f64>,
    /// The window's rows and columns.
    shape: (usize, usize),
    op: Arc<DeviceOperator>,
    sums: Reduction,
}

/// A kernel launch's error, named by its pass.
fn launch_error(pass: &'static str) -> impl Fn(cudarc::driver::DriverError) -> crate::error::Error {
    move |e| device_error(pass, e)
}

impl<'a> DeviceFields<'a> {
    /// The fields on the whole grid with starting pressure `p`.
    pub fn new(
        gpu: &'a Gpu,
        problem: &'a Problem<'a>,
        plasticity: Plasticity<'a>,
        p: &[f64],
    ) -> Result<Self> {
        let operator = problem.operator;
        let (ny, nx) = (operator.ny(), operator.nx());
        let n = ny * nx;
        let (plastic, bound) = match plasticity {
            Plasticity::Elastic => (
                Plastic {
                    mode: 0,
                    compliance: 0.0,
                },
                None,
            ),
            Plasticity::Cap(cap) => (
                Plastic {
                    mode: 1,
                    compliance: 0.0,
                },
                Some(cap),
            ),
            Plasticity::Hardening {
                yield_pressure,
                compliance,
            } => (
                Plastic {
                    mode: 2,
                    compliance,
                },
                Some(yield_pressure),
            ),
        };
        let whole_s = gpu.upload(problem.separation)?;
        let s = gpu.duplicate(&whole_s)?;
        let whole_bound = match bound {
            Some(b) => gpu.upload(b)?,
            None => gpu.zeros(1)?,
        };
        let bound = gpu.duplicate(&whole_bound)?;
        let fields = DeviceFields {
            gpu,
            problem,
            plasticity,
            plastic,
            whole_s,
            whole_bound,
            s,
            bound,
            p: gpu.upload(p)?,
            previous: gpu.zeros(n)?,
            u: gpu.zeros(n)?,
            t: gpu.zeros(n)?,
            r: gpu.zeros(n)?,
            spare: gpu.zeros(n)?,
            shape: (ny, nx),
            op: gpu.window_operator(operator, ny, nx)?,
            sums: Reduction::new(gpu)?,
        };
        gpu.note_memory();
        Ok(fields)
    }

    /// p ← min(a·p + b, cap).
    fn affine(&mut self, a: f64, b: f64) -> Result<()> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        launch!(
            self.gpu,
            affine,
            Gpu::elementwise(n as usize),
            "setting the pressure",
            [&mut self.p, &n, &mode, &compliance, &self.bound, &a, &b]
        )
    }

    fn len(&self) -> i64 {
        (self.shape.0 * self.shape.1) as i64
    }

    fn n(&self) -> usize {
        self.shape.0 * self.shape.1
    }
}

/// Copy the part of `from` (on window `src`) that lies in `dst` into `to` (on `dst`).
fn embed(
    gpu: &Gpu,
    to: &mut CudaSlice<f64>,
    dst: &Window,
    from: &CudaSlice<f64>,
    src: &Window,
) -> Result<()> {
    let a = |v: usize| v as i32;
    launch!(
        gpu,
        embed,
        Gpu::elementwise(dst.len()),
        "moving the window",
        [
            to,
            &a(dst.y0),
            &a(dst.x0),
            &a(dst.h),
            &a(dst.w),
            from,
            &a(src.y0),
            &a(src.x0),
            &a(src.h),
            &a(src.w)
        ]
    )?;
    Ok(())
}

impl Fields for DeviceFields<'_> {
    fn apply_pressure(&mut self, window: &Window) -> Result<()> {
        self.gpu
            .apply(&self.op, &self.p, window.h, window.w, &mut self.u)?;
        Ok(())
    }

    fn apply_direction(&mut self, window: &Window) -> Result<()> {
        self.gpu
            .apply(&self.op, &self.t, window.h, window.w, &mut self.r)?;
        Ok(())
    }

    fn gaps(&mut self, delta: f64) -> Result<Gaps> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        launch!(
            self.gpu,
            gaps,
            Gpu::reducing(),
            "the residual pass",
            [
                &mut self.sums.partials,
                &self.s,
                &self.u,
                &self.p,
                &self.t,
                &n,
                &mode,
                &compliance,
                &self.bound,
                &delta
            ]
        )?;
        use Fold::{Max, Min, Sum};
        let v = self.sums.fold(
            self.gpu,
            &[Sum, Sum, Sum, Sum, Sum, Min, Max, Min, Max, Sum],
        )?;
        Ok(Gaps {
            count: v[0] as usize,
            sum: v[1],
            sum_sq: v[2],
            sum_gt: v[3],
            sum_t: v[4],
            free_min: v[5],
            free_max: v[6],
            zero_min: v[7],
            capped_max: v[8],
            energy: v[9],
        })
    }

    fn residual_sq(&mut self, delta: f64) -> Result<f64> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        launch!(
            self.gpu,
            residual_sq,
            Gpu::reducing(),
            "the residual norm",
            [
                &mut self.sums.partials,
                &self.s,
                &self.u,
                &self.p,
                &n,
                &mode,
                &compliance,
                &self.bound,
                &delta
            ]
        )?;
        Ok(self.sums.fold(self.gpu, &[Fold::Sum])?[0])
    }

    fn direction(&mut self, delta: f64, beta: f64, mean: f64) -> Result<()> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        launch!(
            self.gpu,
            direction,
            Gpu::elementwise(n as usize),
            "the direction",
            [
                &mut self.t,
                &self.s,
                &self.u,
                &self.p,
                &n,
                &mode,
                &compliance,
                &self.bound,
                &delta,
                &beta,
                &mean
            ]
        )?;
        Ok(())
    }

    fn curvature(&mut self) -> Result<f64> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        launch!(
            self.gpu,
            curvature,
            Gpu::reducing(),
            "the curvature",
            [
                &mut self.sums.partials,
                &self.r,
                &self.t,
                &self.p,
                &n,
                &mode,
                &compliance,
                &self.bound
            ]
        )?;
        Ok(self.sums.fold(self.gpu, &[Fold::Sum])?[0])
    }

    fn step(&mut self, delta: f64, tau: f64, width: usize) -> Result<Step> {
        let n = self.len();
        let width = width as i32;
        let Plastic { mode, compliance } = self.plastic;
        launch!(
            self.gpu,
            step,
            Gpu::reducing(),
            "the step",
            [
                &mut self.sums.partials,
                &mut self.p,
                &mut self.previous,
                &self.s,
                &self.u,
                &self.t,
                &n,
                &width,
                &mode,
                &compliance,
                &self.bound,
                &delta,
                &tau
            ]
        )?;
        use Fold::{Max, Min, Sum};
        let v = self.sums.fold(
            self.gpu,
            &[
                Sum, Sum, Sum, Min, Min, Sum, Sum, Sum, Sum, Sum, Sum, Min, Max, Min, Max,
            ],
        )?;
        let index = |x: f64, none: usize| if x.is_finite() { x as usize } else { none };
        Ok(Step {
            total: v[0],
            inside: v[1] as usize,
            capped: v[2] as usize,
            min_inside: v[3],
            headroom: v[4],
            inside_total: v[5],
            capped_total: v[6],
            engaged: v[7] as usize,
            released: v[8] as usize,
            clamped: v[9] as usize,
            flipped: v[10] as usize,
            rows: (index(v[11], usize::MAX), index(v[12], 0)),
            cols: (index(v[13], usize::MAX), index(v[14], 0)),
        })
    }

    fn shift_sums(&mut self, mu: f64) -> Result<ShiftSums> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        launch!(
            self.gpu,
            shift_sums,
            Gpu::reducing(),
            "the load's shift",
            [
                &mut self.sums.partials,
                &self.p,
                &n,
                &mode,
                &compliance,
                &self.bound,
                &mu
            ]
        )?;
        let v = self.sums.fold(self.gpu, &[Fold::Sum; 4])?;
        Ok(ShiftSums {
            value: v[0],
            inside: v[1] as usize,
            others: v[2],
            capacity: v[3],
        })
    }

    fn apply_shift(&mut self, shift: Shift) -> Result<(f64, f64)> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        launch!(
            self.gpu,
            apply_shift,
            Gpu::reducing(),
            "restoring the load",
            [
                &mut self.sums.partials,
                &mut self.p,
                &self.previous,
                &n,
                &mode,
                &compliance,
                &self.bound,
                &shift.inside_scale,
                &shift.inside_add,
                &shift.capped_scale
            ]
        )?;
        let v = self.sums.fold(self.gpu, &[Fold::Sum; 2])?;
        Ok((v[0], v[1]))
    }

    fn change(&mut self) -> Result<(f64, f64)> {
        let n = self.len();
        launch!(
            self.gpu,
            change,
            Gpu::reducing(),
            "the pressure change",
            [&mut self.sums.partials, &self.p, &self.previous, &n]
        )?;
        let v = self.sums.fold(self.gpu, &[Fold::Sum; 2])?;
        Ok((v[0], v[1]))
    }

    fn start_sums(&mut self, lambda: f64) -> Result<(f64, f64)> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        launch!(
            self.gpu,
            start_sums,
            Gpu::reducing(),
            "the starting load",
            [
                &mut self.sums.partials,
                &self.p,
                &n,
                &mode,
                &compliance,
                &self.bound,
                &lambda
            ]
        )?;
        let v = self.sums.fold(self.gpu, &[Fold::Sum; 2])?;
        Ok((v[0], v[1]))
    }

    fn scale(&mut self, lambda: f64) -> Result<()> {
        self.affine(lambda, 0.0)
    }

    fn fill(&mut self, value: f64) -> Result<()> {
        self.affine(0.0, value)
    }

    fn gaps_and_caps(&mut self) -> Result<Vec<(f64, f64)>> {
        let n = self.n();
        let s = self.gpu.download(&self.s, n)?;
        let u = self.gpu.download(&self.u, n)?;
        let p = self.gpu.download(&self.p, n)?;
        let bound = if self.plastic.mode == 0 {
            Vec::new()
        } else {
            self.gpu.download(&self.bound, n)?
        };
        let window = match self.plasticity {
            Plasticity::Elastic => Plasticity::Elastic,
            Plasticity::Cap(_) => Plasticity::Cap(&bound),
            Plasticity::Hardening { compliance, .. } => Plasticity::Hardening {
                yield_pressure: &bound,
                compliance,
            },
        };
        Ok((0..n)
            .map(|i| (s[i] + u[i] + window.spring(i, p[i]), window.cap(i)))
            .collect())
    }

    fn rewindow(&mut self, current: &Window, next: &Window, whole: &Window) -> Result<()> {
        embed(self.gpu, &mut self.spare, next, &self.p, current)?;
        std::mem::swap(&mut self.p, &mut self.spare);
        embed(self.gpu, &mut self.s, next, &self.whole_s, whole)?;
        if self.plastic.mode != 0 {
            embed(self.gpu, &mut self.bound, next, &self.whole_bound, whole)?;
        }
        let n = next.len();
        self.gpu
            .stream
            .memcpy_dtod(&self.p.slice(0..n), &mut self.previous.slice_mut(0..n))
            .map_err(launch_error("moving the window"))?;
        for field in [&mut self.u, &mut self.t, &mut self.r] {
            self.gpu
                .stream
                .memset_zeros(field)
                .map_err(launch_error("moving the window"))?;
        }
        self.shape = (next.h, next.w);
        self.op = self
            .gpu
            .window_operator(self.problem.operator, next.h, next.w)?;
        Ok(())
    }

    fn solution(&mut self, window: &Window, whole: &Window) -> Result<(Vec<f64>, Vec<f64>)> {
        let operator = self.problem.operator;
        let (ny, nx) = (operator.ny(), operator.nx());
        let op = self.gpu.window_operator(operator, ny, nx)?;
        // The whole-grid pressure goes to the spare buffer and its displacement to r, which the
        // next window (if any) overwrites and zeroes.
        embed(self.gpu, &mut self.spare, whole, &self.p, window)?;
        self.gpu.apply(&op, &self.spare, ny, nx, &mut self.r)?;
        Ok((
            self.gpu.download(&self.spare, ny * nx)?,
            self.gpu.download(&self.r, ny * nx)?,
        ))
    }
}
