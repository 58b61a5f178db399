//! The one failure diagnosis of every lattice (two-array and AA kernels, the PSM lattice of
//! `lbdem-coupling`): the first node that left the accepted range ([`Limits`]) becomes an
//! [`LbmError::Unstable`] naming the step, the node, its state and the likely cause with the fix.

use crate::LbmError;
use crate::kernel::Limits;
use crate::lattice::CS2;

/// The first node outside the limits: where, when, its state and its relaxation time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BadNode {
    /// The step that produced the state (completed steps after it).
    pub step: u64,
    /// Node coordinates (z = 0 in 2D).
    pub node: [usize; 3],
    pub rho: f64,
    /// Velocity (z = 0 in 2D).
    pub u: [f64; 3],
    /// Relaxation time τ⁺ at the node (the local one with per-node rates).
    pub tau: f64,
}

impl BadNode {
    /// The error of a run stopped at this node.
    pub fn into_error(self, limits: &Limits) -> LbmError {
        LbmError::Unstable {
            step: self.step,
            node: self.node,
            rho: self.rho,
            u: self.u,
            cause: likely_cause(self.tau, self.rho, self.u, limits),
        }
    }
}

/// The likely cause of a node leaving the limits, with the fix: τ near ½ (under-resolved
/// viscosity, Su Eq. 15), a local Mach number beyond the limit (Su Eq. 16), or a density out of
/// range (compressibility).
pub fn likely_cause(tau: f64, rho: f64, u: [f64; 3], lim: &Limits) -> String {
    let speed = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let finite = rho.is_finite() && speed.is_finite();
    let mach = speed / CS2.sqrt();
    if !finite && tau < 0.55 {
        format!(
            "relaxation time tau = {tau:.4} is close to 0.5 (under-resolved viscosity); raise tau \
             (larger viscosity or time step relative to dx^2) or use TRT"
        )
    } else if speed >= lim.u_max || (!finite && mach > lbdem_core::units::lattice::MACH_MAX) {
        format!(
            "local Mach number |u|/c_s = {mach:.3} beyond the limit {:.3}: lower the velocity in \
             lattice units (smaller time step or coarser dx)",
            lim.u_max / CS2.sqrt()
        )
    } else if finite {
        format!(
            "density {rho:.4} outside [{}, {}]: compressibility error from a too large pressure \
             drop or velocity; lower the driving (force, pressure, velocity) in lattice units",
            lim.rho_min, lim.rho_max
        )
    } else {
        format!(
            "non-finite value with tau = {tau:.4}: the run went unstable (most often tau near 0.5 \
             or Mach too high); raise tau, refine the lattice or lower the velocity"
        )
    }
}
