//! lbdem-lbm: the lattice-Boltzmann engine (issue 3).
//!
//! D2Q9 and D3Q19 lattices behind one trait of constants ([`lattice`]), BGK and TRT collision
//! with Guo forcing ([`collision`]), a fused stream-collide kernel over structure-of-arrays storage
//! in f32 or f64 ([`kernel`]), halfway bounce-back on stationary and moving walls with the
//! momentum-exchange force and torque, Zou-He velocity and pressure faces, periodic faces, and a
//! stepper that stops at the first node leaving the accepted range with a diagnosis ([`stepper`]),
//! Bingham plastic rheology by a local relaxation time in the same kernels ([`bingham`]), and a
//! free surface by mass tracking ([`free_surface`]).
//! Pure computation: no file I/O; units are converted in `lbdem_core::units::lattice`.

// Kernels index several parallel arrays (velocities, weights, populations) by direction: an index
// loop says that more plainly than zipped iterators.
#![allow(clippy::needless_range_loop)]

pub mod bingham;
pub mod cases;
pub mod collision;
pub mod compiled;
pub mod diagnosis;
pub mod domain;
pub mod free_surface;
pub mod kernel;
pub mod kernel_aa;
pub mod lattice;
pub mod layout;
pub mod plan;
pub mod real;
pub mod roofline;
pub mod stepper;
pub mod stepper_aa;
pub mod storage;
pub mod zouhe;

pub use bingham::{Bingham, BinghamRates};
pub use collision::{Collider, Collision, LocalRates, NodeRates};
pub use diagnosis::BadNode;
pub use domain::{Domain, Face, Motion};
pub use free_surface::{FreeSurface, FreeSurfaceParams, FreeSurfaceStepper};
pub use kernel::Limits;
pub use lattice::{D2Q9, D3Q19, Lattice};
pub use real::Real;
pub use stepper::{Fluid, ForceTorque, Macro, Settings, Stepper};
pub use stepper_aa::{Partition, StepperAa};
pub use storage::{Precision, ShiftedF16, ShiftedF32, Storage, UnknownPrecision};

/// Errors of the LBM engine; each names the parameter, its value, the limit and the fix.
#[derive(Debug, thiserror::Error)]
pub enum LbmError {
    #[error(
        "relaxation time tau = {tau} must be > 0.5 (zero or negative viscosity, Su et al. 2020 Eq. 15); \
         increase the viscosity or the time step, or refine dx"
    )]
    Tau { tau: f64 },
    #[error(
        "local relaxation time tau = {tau} at node {node} must be > 0.5 and finite (Su et al. 2020 \
         Eq. 15); clamp the local viscosity (e.g. the Bingham cap) so that tau stays above 0.5, and \
         give solid or inactive nodes any valid tau"
    )]
    LocalTau { node: usize, tau: f64 },
    #[error(
        "per-node relaxation times: {got} values for a lattice of {nodes} nodes; give one tau per node \
         in node order (x + nx (y + ny z))"
    )]
    LocalTauLength { got: usize, nodes: usize },
    #[error("Bingham parameter {name} = {value}: {fix}")]
    Bingham {
        name: &'static str,
        value: f64,
        fix: String,
    },
    #[error("TRT magic parameter = {magic} must be > 0; use 0.25 (stability) or 3/16 (exact walls)")]
    Magic { magic: f64 },
    #[error("free surface: {0}")]
    FreeSurface(String),
    #[error("unsupported set-up: {0}")]
    Unsupported(String),
    #[error(
        "run unstable at step {step}, node {node:?}: density {rho:.6}, velocity {u:?}; likely cause: {cause}"
    )]
    Unstable {
        step: u64,
        node: [usize; 3],
        rho: f64,
        u: [f64; 3],
        cause: String,
    },
}
