//! Load sweeps with the paper's contact models (Weber et al. 2018, Methods): purely elastic,
//! penetration hardness (bounded pressure, plastic displacement from the overlap, Eq. 4, or its
//! volume-conserving form, Eq. 5), and linear contact hardening p_Y = p_Y0 + k·h_pl.
//!
//! Decisions on the open choices of docs/methods.md §10, recorded here and in `docs/solver.md`:
//! * **Eq. 4** (α = 1) is exact in one pass for a constant hardness: the overlap on capped pixels
//!   becomes plastic displacement and the pressure does not change (§3.1, validation B8).
//! * **Eq. 5** is implemented in its exactly volume-conserving form (§3.1): each yielding pixel's
//!   overlap o is removed and a quarter of it deposited on each of its four neighbours,
//!   Δh_pl = α(o − ¼Σ_neighbours o); the load solve and the deposit alternate until no overlap is
//!   left. α defaults to 0.5.
//! * **Hardening** uses the implicit "series compliance" step (§3.4): consistent to round-off,
//!   needs no seed when p_Y0 = 0, and path independent for monotone loading. Negative h_pl cannot
//!   arise (Eq. 5 is not offered with hardening), so p_Y = p_Y0 + k·h_pl needs no clamp.
//! * **Load control with a cap** is one constrained-CG run with the approach as the load's
//!   Lagrange multiplier ([`super::cg::load`]); the root-find on the approach of §2.3(a) is kept as
//!   the reference ([`super::cg::Method::Reference`]).
//! * The plastic state h_pl carries from each load to the next, like the experiment's ramp.
//! * Contact = pixels with p > 0. Contact on the border of a free-boundary map means the map is
//!   too small: it is reported per load (`edge_contact`), not ignored.
//! * **The gap** of a [`LoadStep`] is the gap between the deformed surfaces after the load's
//!   plastic update, g = s + h_pl − δ + u, for every model: ≥ 0, and 0 on the contact to the
//!   solver's tolerance (Eq. 5: to its overlap tolerance). The overlap that flowed is in
//!   `plastic_m`. (The hardness model used to report the gap before the update, negative on
//!   yielding pixels, and hardening the gap after it.)

use crate::error::{Error, Result};
use crate::measure::patches::count_patches;
use crate::surface::Topography;
use rayon::prelude::*;

use super::cg::{solve_load_with, Plasticity, Problem, Solution, SolverOptions};
use super::halfspace::{Boundary, ElasticOperator};

/// The contact model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Model {
    /// Linear elastic, hard-wall contact.
    Elastic,
    /// Penetration hardness: 0 ≤ p ≤ `hardness_pa`; overlap becomes plastic displacement.
    Hardness {
        /// p_Y in Pa.
        hardness_pa: f64,
        /// Use the volume-conserving increment (Eq. 5) with this relaxation factor α ∈ (0, 1].
        volume_conserving: Option<f64>,
    },
    /// Linear contact hardening p_Y = p_Y0 + k·h_pl.
    Hardening {
        /// k in Pa per metre (4 MPa/nm = 4e15 Pa/m).
        modulus_pa_per_m: f64,
        /// p_Y0 in Pa (the paper's model has 0).
        initial_pa: f64,
    },
}

impl Model {
    /// Name used in outputs.
    pub fn name(&self) -> &'static str {
        match self {
            Model::Elastic => "elastic",
            Model::Hardness { .. } => "hardness",
            Model::Hardening { .. } => "hardening",
        }
    }
}

/// Everything a sweep needs besides the loads.
#[derive(Debug, Clone)]
pub struct Setup<'a> {
    /// The rigid rough body (heights positive towards the flat).
    pub topography: &'a Topography,
    /// Contact modulus E*, Pa.
    pub e_star_pa: f64,
    /// Free (isolated contact) or periodic boundaries.
    pub boundary: Boundary,
    /// The model.
    pub model: Model,
    /// CG limits.
    pub options: SolverOptions<'a>,
}

/// The result at one load.
#[derive(Debug, Clone)]
pub struct LoadStep {
    /// Imposed normal force, N.
    pub force_n: f64,
    /// The contact solution (pressure Pa, approach m, and the gap in m after this load's plastic
    /// update: see the module docs).
    pub solution: Solution,
    /// Plastic displacement after this load, m (material removed, ≥ 0 where it flowed).
    pub plastic_m: Vec<f64>,
    /// Contact area, m².
    pub area_m2: f64,
    /// Contact pixels / all pixels.
    pub contact_fraction: f64,
    /// Force / contact area, Pa.
    pub mean_pressure_pa: f64,
    /// Largest pixel pressure, Pa.
    pub max_pressure_pa: f64,
    /// 8-connected contact patches.
    pub patches: u64,
    /// Outer (plastic) iterations for Eq. 5; 1 otherwise.
    pub plastic_iterations: usize,
    /// Contact touches the border of a free-boundary map.
    pub edge_contact: bool,
}

/// Undeformed separation s = max(h) − h (first touch at s = 0).
pub fn separation(topography: &Topography) -> Vec<f64> {
    let top = topography
        .heights
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    topography.heights.iter().map(|h| top - h).collect()
}

/// Run the loads in order, carrying the plastic state from each to the next, and keep every
/// step (all fields of every load: at 2048² about 130 MB per load; [`sweep_each`] keeps none).
pub fn sweep(
    setup: &Setup,
    loads_n: &[f64],
    progress: &dyn Fn(usize, &LoadStep),
) -> Result<Vec<LoadStep>> {
    let mut steps = Vec::with_capacity(loads_n.len());
    sweep_each(setup, loads_n, &mut |i, step| {
        progress(i, &step);
        steps.push(step);
        Ok(())
    })?;
    Ok(steps)
}

/// Run the loads in order, carrying the plastic state from each to the next, and hand each
/// step to `consume` as soon as it is solved; memory does not grow with the number of loads.
/// An error from `consume` stops the ramp and is returned.
pub fn sweep_each(
    setup: &Setup,
    loads_n: &[f64],
    consume: &mut dyn FnMut(usize, LoadStep) -> Result<()>,
) -> Result<()> {
    check_setup(setup)?;
    let topo = setup.topography;
    let (ny, nx) = (topo.ny(), topo.nx());
    if let Model::Hardness { hardness_pa, .. } = setup.model {
        // Refused before any load is solved: a fit probing a low hardness learns at once that
        // the ramp is infeasible.
        let capacity = hardness_pa * (nx * ny) as f64 * topo.dx_m * topo.dy_m;
        let heaviest = loads_n.iter().copied().fold(0.0, f64::max);
        if heaviest >= capacity {
            return Err(Error::ExceedsCapacity {
                load_n: heaviest,
                capacity_n: capacity,
            });
        }
    }
    let operator = ElasticOperator::new(
        ny,
        nx,
        topo.dx_m,
        topo.dy_m,
        setup.e_star_pa,
        setup.boundary,
    );
    let base = separation(topo);
    let mut plastic = vec![0.0; nx * ny];
    for (i, &force) in loads_n.iter().enumerate() {
        let (solution, outer) = solve_step(setup, &operator, &base, &mut plastic, force)?;
        consume(i, describe(setup, force, solution, plastic.clone(), outer))?;
    }
    Ok(())
}

fn check_setup(setup: &Setup) -> Result<()> {
    // Every array of the solver holds at most one f64 per point of its FFT grid: the map itself
    // when periodic, the map padded to twice its size along each axis on a free boundary
    // (Hockney's zero padding). Checked before any is allocated.
    let (nx, ny) = (setup.topography.nx(), setup.topography.ny());
    let (gx, gy, what) = match setup.boundary {
        Boundary::Free => (
            nx.saturating_mul(2),
            ny.saturating_mul(2),
            format!("the solver's grid (a free boundary pads the {nx}×{ny} map to twice its size)"),
        ),
        Boundary::Periodic => (nx, ny, format!("the solver's grid ({nx}×{ny}, periodic)")),
    };
    crate::limits::Limits::DEFAULT
        .plane_bytes(gx, gy, 8)
        .map_err(|source| Error::Limit { what, source })?;
    let positive = |v: f64| v.is_finite() && v > 0.0;
    if !positive(setup.e_star_pa) {
        return Err(Error::not_positive(
            "contact modulus",
            setup.e_star_pa,
            "Pa",
        ));
    }
    match setup.model {
        Model::Hardness {
            hardness_pa,
            volume_conserving,
        } => {
            if !positive(hardness_pa) {
                return Err(Error::not_positive("hardness", hardness_pa, "Pa"));
            }
            if let Some(alpha) = volume_conserving {
                if !(alpha > 0.0 && alpha <= 1.0) {
                    return Err(Error::Value {
                        what: "relaxation factor α",
                        value: alpha,
                        unit: "",
                        requirement: "must lie in (0, 1]",
                    });
                }
            }
        }
        Model::Hardening {
            modulus_pa_per_m,
            initial_pa,
        } => {
            if !(positive(modulus_pa_per_m) && initial_pa >= 0.0 && initial_pa.is_finite()) {
                return Err(Error::InvalidArgument(
                    "hardening needs k > 0 and p_Y0 ≥ 0".into(),
                ));
            }
        }
        Model::Elastic => {}
    }
    Ok(())
}

fn solve_step(
    setup: &Setup,
    operator: &ElasticOperator,
    base: &[f64],
    plastic: &mut [f64],
    force: f64,
) -> Result<(Solution, usize)> {
    let topo = setup.topography;
    let pixel_area = topo.dx_m * topo.dy_m;
    let geometry = deformed(base, plastic);
    let problem = Problem {
        operator,
        separation: &geometry,
        pixel_area,
    };
    match setup.model {
        Model::Elastic => Ok((
            solve_load_with(&problem, force, Plasticity::Elastic, None, &setup.options)?,
            1,
        )),
        Model::Hardness {
            hardness_pa,
            volume_conserving: None,
        } => {
            let cap = vec![hardness_pa; geometry.len()];
            let mut sol =
                solve_load_with(&problem, force, Plasticity::Cap(&cap), None, &setup.options)?;
            let overlap = capped_overlap(&sol, hardness_pa);
            for ((h, g), o) in plastic.iter_mut().zip(&mut sol.gap).zip(overlap) {
                // The overlap flows: the gap after the update is 0 where it was negative.
                *h += o;
                *g += o;
            }
            Ok((sol, 1))
        }
        Model::Hardness {
            hardness_pa,
            volume_conserving: Some(alpha),
        } => conserving_step(setup, operator, base, plastic, force, hardness_pa, alpha),
        Model::Hardening {
            modulus_pa_per_m,
            initial_pa,
        } => {
            let yield_pressure: Vec<f64> = plastic
                .par_iter()
                .map(|h| initial_pa + modulus_pa_per_m * h)
                .collect();
            let plasticity = Plasticity::Hardening {
                yield_pressure: &yield_pressure,
                compliance: 1.0 / modulus_pa_per_m,
            };
            let sol = solve_load_with(&problem, force, plasticity, None, &setup.options)?;
            plastic
                .par_iter_mut()
                .zip(&sol.pressure)
                .zip(&yield_pressure)
                .for_each(|((h, p), y)| *h += (p - y).max(0.0) / modulus_pa_per_m);
            Ok((sol, 1))
        }
    }
}

/// The separation of the plastically deformed body, s + h_pl.
fn deformed(base: &[f64], plastic: &[f64]) -> Vec<f64> {
    base.par_iter().zip(plastic).map(|(s, h)| s + h).collect()
}

/// Overlap o = max(0, −g) on pixels at the cap (Eq. 4's increment), zero elsewhere.
fn capped_overlap(sol: &Solution, cap: f64) -> Vec<f64> {
    sol.pressure
        .iter()
        .zip(&sol.gap)
        .map(|(p, g)| if *p >= cap { (-g).max(0.0) } else { 0.0 })
        .collect()
}

/// Eq. 5 stops when the largest overlap is this fraction of the first one.
pub const CONSERVING_TOLERANCE: f64 = 1e-6;
/// Most load solves per load step for Eq. 5.
pub const CONSERVING_MAX_OUTER: usize = 100;

/// Eq. 5 in its conserving form, iterated to its limit.
///
/// Applying Eq. 5 repeatedly while the elastic state is fixed moves overlap between capped
/// pixels (whose pressure stays at p_Y whatever the geometry) until it lands on pixels below the
/// cap. That limit is a Dirichlet problem on the capped set C: find x (the volume removed from
/// each capped pixel) with (I − ¼A)_CC x = o_C, A the 4-neighbour adjacency. The result is
/// Δh = o on C (Eq. 4's increment there) and Δh = −¼(A x) on the neighbours outside C, and
/// Σ Δh = 0. Each outer iteration solves it directly (sparse CG), then re-solves the contact,
/// which only changes where the deposit created new contact; α damps the outer iteration.
fn conserving_step(
    setup: &Setup,
    operator: &ElasticOperator,
    base: &[f64],
    plastic: &mut [f64],
    force: f64,
    hardness: f64,
    alpha: f64,
) -> Result<(Solution, usize)> {
    let topo = setup.topography;
    let grid = Grid {
        nx: topo.nx(),
        ny: topo.ny(),
        periodic: setup.boundary == Boundary::Periodic,
    };
    let pixel_area = topo.dx_m * topo.dy_m;
    let cap = vec![hardness; base.len()];
    let mut first_overlap = None;
    let mut worst = f64::NAN;
    for outer in 1..=CONSERVING_MAX_OUTER {
        let geometry = deformed(base, plastic);
        let problem = Problem {
            operator,
            separation: &geometry,
            pixel_area,
        };
        let sol = solve_load_with(&problem, force, Plasticity::Cap(&cap), None, &setup.options)?;
        let overlap = capped_overlap(&sol, hardness);
        worst = overlap.iter().copied().fold(0.0, f64::max);
        let reference = *first_overlap.get_or_insert(worst);
        if worst <= CONSERVING_TOLERANCE * reference {
            return Ok((sol, outer));
        }
        let capped: Vec<bool> = sol.pressure.iter().map(|p| *p >= hardness).collect();
        for (h, d) in plastic
            .iter_mut()
            .zip(redistribute(&overlap, &capped, grid)?)
        {
            *h += alpha * d;
        }
    }
    Err(Error::NotConverged {
        what: "volume-conserving plastic relaxation (Eq. 5)".into(),
        iterations: CONSERVING_MAX_OUTER,
        residual: worst / first_overlap.unwrap_or(1.0),
        tolerance: CONSERVING_TOLERANCE,
    })
}

/// Grid shape and wrapping for neighbour lookups.
#[derive(Debug, Clone, Copy)]
struct Grid {
    nx: usize,
    ny: usize,
    periodic: bool,
}

impl Grid {
    /// The four neighbours of pixel i; on a free map a neighbour beyond the border is the pixel
    /// itself (its deposit stays put), which keeps Σ Δh = 0.
    fn neighbours(&self, i: usize) -> [usize; 4] {
        let (x, y) = ((i % self.nx) as i64, (i / self.nx) as i64);
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)].map(|(mut a, mut b)| {
            if self.periodic {
                a = a.rem_euclid(nx);
                b = b.rem_euclid(ny);
            } else if a < 0 || b < 0 || a >= nx || b >= ny {
                (a, b) = (x, y);
            }
            (b * nx + a) as usize
        })
    }
}

/// The converged Eq. 5 increment for overlap `o` on the `capped` set (see [`conserving_step`]).
fn redistribute(overlap: &[f64], capped: &[bool], grid: Grid) -> Result<Vec<f64>> {
    let set: Vec<usize> = (0..overlap.len()).filter(|&i| capped[i]).collect();
    if set.len() == overlap.len() {
        return Err(Error::InvalidArgument(
            "every pixel is at the hardness: the volume-conserving increment has nowhere to put material; use a larger map".into(),
        ));
    }
    let position: std::collections::HashMap<usize, usize> =
        set.iter().enumerate().map(|(k, &i)| (i, k)).collect();
    let apply = |x: &[f64], y: &mut [f64]| {
        for (k, &i) in set.iter().enumerate() {
            let inside: f64 = grid
                .neighbours(i)
                .iter()
                .filter_map(|n| position.get(n).map(|&m| x[m]))
                .sum();
            y[k] = x[k] - inside / 4.0;
        }
    };
    let rhs: Vec<f64> = set.iter().map(|&i| overlap[i]).collect();
    let x = sparse_cg(&apply, &rhs)?;
    let mut delta = vec![0.0; overlap.len()];
    for (k, &i) in set.iter().enumerate() {
        delta[i] += overlap[i];
        for n in grid.neighbours(i) {
            if !capped[n] || n == i {
                delta[n] -= x[k] / 4.0;
            }
        }
    }
    Ok(delta)
}

/// One application of Eq. 5 in its conserving form: each pixel's overlap is removed and a quarter
/// of it deposited on each of its four neighbours, Δh = o − ¼Σ_neighbours o, so Σ Δh = 0.
pub fn conserving_increment(overlap: &[f64], nx: usize, ny: usize, periodic: bool) -> Vec<f64> {
    let grid = Grid { nx, ny, periodic };
    let mut delta = overlap.to_vec();
    for (i, &o) in overlap.iter().enumerate().filter(|(_, o)| **o != 0.0) {
        for n in grid.neighbours(i) {
            delta[n] -= o / 4.0;
        }
    }
    delta
}

/// Conjugate gradients for a small symmetric positive definite operator.
fn sparse_cg(apply: &dyn Fn(&[f64], &mut [f64]), rhs: &[f64]) -> Result<Vec<f64>> {
    let n = rhs.len();
    let (mut x, mut r, mut q) = (vec![0.0; n], rhs.to_vec(), vec![0.0; n]);
    let mut d = r.clone();
    let norm0: f64 = rhs.iter().map(|v| v * v).sum::<f64>().sqrt();
    let mut rr: f64 = r.iter().map(|v| v * v).sum();
    for _ in 0..(10 * n + 100) {
        if rr.sqrt() <= 1e-13 * norm0 || norm0 == 0.0 {
            return Ok(x);
        }
        apply(&d, &mut q);
        let step = rr / d.iter().zip(&q).map(|(a, b)| a * b).sum::<f64>();
        for k in 0..n {
            x[k] += step * d[k];
            r[k] -= step * q[k];
        }
        let rr_new: f64 = r.iter().map(|v| v * v).sum();
        for k in 0..n {
            d[k] = r[k] + rr_new / rr * d[k];
        }
        rr = rr_new;
    }
    Err(Error::NotConverged {
        what: "volume redistribution (Eq. 5 limit)".into(),
        iterations: 10 * n + 100,
        residual: rr.sqrt() / norm0,
        tolerance: 1e-13,
    })
}

fn describe(
    setup: &Setup,
    force: f64,
    solution: Solution,
    plastic: Vec<f64>,
    outer: usize,
) -> LoadStep {
    let topo = setup.topography;
    let (nx, ny) = (topo.nx(), topo.ny());
    let mask: Vec<u8> = solution
        .pressure
        .par_iter()
        .map(|p| u8::from(*p > 0.0))
        .collect();
    let contact = mask.par_iter().filter(|m| **m == 1).count();
    let area = contact as f64 * topo.dx_m * topo.dy_m;
    let on_border = |i: usize| {
        let (x, y) = (i % nx, i / nx);
        x == 0 || y == 0 || x == nx - 1 || y == ny - 1
    };
    let edge_contact =
        setup.boundary == Boundary::Free && (0..nx * ny).any(|i| mask[i] == 1 && on_border(i));
    LoadStep {
        force_n: force,
        area_m2: area,
        contact_fraction: contact as f64 / (nx * ny) as f64,
        mean_pressure_pa: if area > 0.0 { force / area } else { f64::NAN },
        max_pressure_pa: solution
            .pressure
            .par_iter()
            .copied()
            .reduce(|| 0.0, f64::max),
        patches: count_patches(&mask, nx).0,
        plastic_iterations: outer,
        edge_contact,
        solution,
        plastic_m: plastic,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grid_beyond_the_limits_is_refused_before_the_solver_allocates() {
        // 40,000 × 2 points: a free boundary pads the x side to 80,000 > 65,536; periodic fits.
        let heights = ndarray::Array2::zeros((2, 40_000));
        let topo = Topography::new(heights, 1e-7, 1e-7).unwrap();
        let setup = |boundary| Setup {
            topography: &topo,
            e_star_pa: 1e9,
            boundary,
            model: Model::Elastic,
            options: SolverOptions::default(),
        };
        let e = check_setup(&setup(Boundary::Free)).unwrap_err().to_string();
        assert!(
            e.contains("the solver's grid (a free boundary pads the 40000×2 map"),
            "{e}"
        );
        assert!(check_setup(&setup(Boundary::Periodic)).is_ok());
    }

    #[test]
    fn conserving_increment_sums_to_zero() {
        // docs/validation.md B21: Σ Δh_pl = 0 to round-off; the literal printed form would give −1 for
        // a lone yielding pixel with g = −1.
        let (nx, ny) = (7, 5);
        let mut overlap = vec![0.0; nx * ny];
        overlap[2 * nx + 3] = 1.0;
        overlap[0] = 0.25;
        overlap[nx * ny - 1] = 0.5;
        for periodic in [true, false] {
            let d = conserving_increment(&overlap, nx, ny, periodic);
            assert!(d.iter().sum::<f64>().abs() < 1e-15, "periodic {periodic}");
            assert_eq!(d[2 * nx + 3], 1.0);
            assert_eq!(d[2 * nx + 2], -0.25);
        }
    }

    #[test]
    fn redistribution_is_the_limit_of_repeated_eq5() {
        // With the elastic state fixed, overlap deposited on capped pixels is removed again by
        // the next application; the direct solve must equal that limit.
        let (nx, ny) = (9, 8);
        let grid = Grid {
            nx,
            ny,
            periodic: false,
        };
        let capped: Vec<bool> = (0..nx * ny)
            .map(|i| (2..6).contains(&(i % nx)) && (2..5).contains(&(i / nx)))
            .collect();
        let overlap: Vec<f64> = (0..nx * ny)
            .map(|i| if capped[i] { 1.0 + (i % 3) as f64 } else { 0.0 })
            .collect();
        let direct = redistribute(&overlap, &capped, grid).unwrap();
        let (mut total, mut o) = (vec![0.0; nx * ny], overlap.clone());
        for _ in 0..3000 {
            let d = conserving_increment(&o, nx, ny, false);
            for i in 0..nx * ny {
                total[i] += d[i];
                o[i] = if capped[i] { o[i] - d[i] } else { 0.0 };
            }
        }
        for i in 0..nx * ny {
            assert!(
                (total[i] - direct[i]).abs() < 1e-9,
                "pixel {i}: {} vs {}",
                total[i],
                direct[i]
            );
            if capped[i] {
                assert!(
                    (direct[i] - overlap[i]).abs() < 1e-12,
                    "capped pixels lose exactly o"
                );
            }
        }
        assert!(direct.iter().sum::<f64>().abs() < 1e-12);
    }
}
