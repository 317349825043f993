//! Contact mechanics: the solver against analytic results and the reference algorithm,
//! `simulate`, generated and read surfaces, `fit-hardening`, friction and squeeze tests.

mod fit;
mod friction_hertz;
mod gpu;
mod simulate;
mod simulate_cli;
mod solver;
mod solver_reference;
mod surface;
