//! Errors of the sphere engine: each names the parameter, its value, the limit and the fix.

use thiserror::Error;

#[derive(Debug, Error, PartialEq)]
pub enum SphereError {
    #[error("{name} = {value} is invalid: {why}")]
    BadParameter {
        name: &'static str,
        value: f64,
        why: &'static str,
    },
    #[error(
        "time step dt = {dt:e} s is above the Rayleigh time step {rayleigh:e} s of the smallest sphere \
         (t_R = pi r sqrt(rho/G) / (0.1631 nu + 0.8766)); Hertzian contacts are unstable beyond it — \
         take dt at most 0.2 t_R = {:e} s",
        0.2 * rayleigh
    )]
    TimeStepTooLarge { dt: f64, rayleigh: f64 },
    #[error("time step dt = {dt:e} s must be a positive, finite number of seconds")]
    BadTimeStep { dt: f64 },
    #[error(
        "periodic axis {axis}: the box length {length:e} m is below twice the pair cutoff {cutoff:e} m \
         (largest diameter + skin), so the minimum image is not unique; widen the box or shrink the skin"
    )]
    PeriodicBoxTooSmall { axis: usize, length: f64, cutoff: f64 },
    #[error(
        "the cell list would need {cells} cells (box / cutoff); the box is too large for the sphere size — \
         give a smaller box or larger spheres"
    )]
    TooManyCells { cells: usize },
    #[error(
        "sphere {sphere}: non-finite state at step {step} (position, velocity or spin is NaN/inf); \
         a non-finite initial state or a blown-up run — check the initial state, then lower dt"
    )]
    NonFinite { sphere: usize, step: u64 },
}
