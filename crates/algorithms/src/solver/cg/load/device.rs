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
    // SAFETY: the arguments match the kernel's signature; `to` holds dst.h·dst.w values and
    // `from` src.h·src.w.
    unsafe {
        gpu.launch(&gpu.kernels.embed)
            .arg(to)
            .arg(&a(dst.y0))
            .arg(&a(dst.x0))
            .arg(&a(dst.h))
            .arg(&a(dst.w))
            .arg(from)
            .arg(&a(src.y0))
            .arg(&a(src.x0))
            .arg(&a(src.h))
            .arg(&a(src.w))
            .launch(Gpu::elementwise(dst.len()))
    }
    .map_err(launch_error("moving the window"))?;
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
        // SAFETY: the arguments match the kernel's signature; every buffer holds n values.
        unsafe {
            self.gpu
                .launch(&self.gpu.kernels.gaps)
                .arg(&mut self.sums.partials)
                .arg(&self.s)
                .arg(&self.u)
                .arg(&self.p)
                .arg(&self.t)
                .arg(&n)
                .arg(&mode)
                .arg(&compliance)
                .arg(&self.bound)
                .arg(&delta)
                .launch(Gpu::reducing())
        }
        .map_err(launch_error("the residual pass"))?;
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
        // SAFETY: as in `gaps`.
        unsafe {
            self.gpu
                .launch(&self.gpu.kernels.residual_sq)
                .arg(&mut self.sums.partials)
                .arg(&self.s)
                .arg(&self.u)
                .arg(&self.p)
                .arg(&n)
                .arg(&mode)
                .arg(&compliance)
                .arg(&self.bound)
                .arg(&delta)
                .launch(Gpu::reducing())
        }
        .map_err(launch_error("the residual norm"))?;
        Ok(self.sums.fold(self.gpu, &[Fold::Sum])?[0])
    }

    fn direction(&mut self, delta: f64, beta: f64, mean: f64) -> Result<()> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        // SAFETY: as in `gaps`.
        unsafe {
            self.gpu
                .launch(&self.gpu.kernels.direction)
                .arg(&mut self.t)
                .arg(&self.s)
                .arg(&self.u)
                .arg(&self.p)
                .arg(&n)
                .arg(&mode)
                .arg(&compliance)
                .arg(&self.bound)
                .arg(&delta)
                .arg(&beta)
                .arg(&mean)
                .launch(Gpu::elementwise(n as usize))
        }
        .map_err(launch_error("the direction"))?;
        Ok(())
    }

    fn curvature(&mut self) -> Result<f64> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        // SAFETY: as in `gaps`.
        unsafe {
            self.gpu
                .launch(&self.gpu.kernels.curvature)
                .arg(&mut self.sums.partials)
                .arg(&self.r)
                .arg(&self.t)
                .arg(&self.p)
                .arg(&n)
                .arg(&mode)
                .arg(&compliance)
                .arg(&self.bound)
                .launch(Gpu::reducing())
        }
        .map_err(launch_error("the curvature"))?;
        Ok(self.sums.fold(self.gpu, &[Fold::Sum])?[0])
    }

    fn step(&mut self, delta: f64, tau: f64, width: usize) -> Result<Step> {
        let n = self.len();
        let width = width as i32;
        let Plastic { mode, compliance } = self.plastic;
        // SAFETY: as in `gaps`.
        unsafe {
            self.gpu
                .launch(&self.gpu.kernels.step)
                .arg(&mut self.sums.partials)
                .arg(&mut self.p)
                .arg(&mut self.previous)
                .arg(&self.s)
                .arg(&self.u)
                .arg(&self.t)
                .arg(&n)
                .arg(&width)
                .arg(&mode)
                .arg(&compliance)
                .arg(&self.bound)
                .arg(&delta)
                .arg(&tau)
                .launch(Gpu::reducing())
        }
        .map_err(launch_error("the step"))?;
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
        // SAFETY: as in `gaps`.
        unsafe {
            self.gpu
                .launch(&self.gpu.kernels.shift_sums)
                .arg(&mut self.sums.partials)
                .arg(&self.p)
                .arg(&n)
                .arg(&mode)
                .arg(&compliance)
                .arg(&self.bound)
                .arg(&mu)
                .launch(Gpu::reducing())
        }
        .map_err(launch_error("the load's shift"))?;
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
        // SAFETY: as in `gaps`.
        unsafe {
            self.gpu
                .launch(&self.gpu.kernels.apply_shift)
                .arg(&mut self.sums.partials)
                .arg(&mut self.p)
                .arg(&self.previous)
                .arg(&n)
                .arg(&mode)
                .arg(&compliance)
                .arg(&self.bound)
                .arg(&shift.inside_scale)
                .arg(&shift.inside_add)
                .arg(&shift.capped_scale)
                .launch(Gpu::reducing())
        }
        .map_err(launch_error("restoring the load"))?;
        let v = self.sums.fold(self.gpu, &[Fold::Sum; 2])?;
        Ok((v[0], v[1]))
    }

    fn change(&mut self) -> Result<(f64, f64)> {
        let n = self.len();
        // SAFETY: as in `gaps`.
        unsafe {
            self.gpu
                .launch(&self.gpu.kernels.change)
                .arg(&mut self.sums.partials)
                .arg(&self.p)
                .arg(&self.previous)
                .arg(&n)
                .launch(Gpu::reducing())
        }
        .map_err(launch_error("the pressure change"))?;
        let v = self.sums.fold(self.gpu, &[Fold::Sum; 2])?;
        Ok((v[0], v[1]))
    }

    fn start_sums(&mut self, lambda: f64) -> Result<(f64, f64)> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        // SAFETY: as in `gaps`.
        unsafe {
            self.gpu
                .launch(&self.gpu.kernels.start_sums)
                .arg(&mut self.sums.partials)
                .arg(&self.p)
                .arg(&n)
                .arg(&mode)
                .arg(&compliance)
                .arg(&self.bound)
                .arg(&lambda)
                .launch(Gpu::reducing())
        }
        .map_err(launch_error("the starting load"))?;
        let v = self.sums.fold(self.gpu, &[Fold::Sum; 2])?;
        Ok((v[0], v[1]))
    }

    fn scale(&mut self, lambda: f64) -> Result<()> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        // SAFETY: as in `gaps`.
        unsafe {
            self.gpu
                .launch(&self.gpu.kernels.scale)
                .arg(&mut self.p)
                .arg(&n)
                .arg(&mode)
                .arg(&compliance)
                .arg(&self.bound)
                .arg(&lambda)
                .launch(Gpu::elementwise(n as usize))
        }
        .map_err(launch_error("scaling the pressure"))?;
        Ok(())
    }

    fn fill(&mut self, value: f64) -> Result<()> {
        let n = self.len();
        let Plastic { mode, compliance } = self.plastic;
        // SAFETY: as in `gaps`.
        unsafe {
            self.gpu
                .launch(&self.gpu.kernels.fill)
                .arg(&mut self.p)
                .arg(&n)
                .arg(&mode)
                .arg(&compliance)
                .arg(&self.bound)
                .arg(&value)
                .launch(Gpu::elementwise(n as usize))
        }
        .map_err(launch_error("filling the pressure"))?;
        Ok(())
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
