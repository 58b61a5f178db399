//! Validation cases built from the engines, shared by the tests, the benchmark and the
//! speed-versus-error study (no I/O: callers write what they need).

pub mod dkt;
pub mod incline;
pub mod resolution;
pub mod settling;

use crate::error::CouplingError;
use crate::units::CouplingUnits;
use lbdem_core::units::lattice::{LatticeInput, LatticeUnits, TimeSpec};
use lbdem_lbm::{Domain, Face};

/// A w × h box (SI) walled on all four sides, on a lattice of spacing `dx` at relaxation time
/// `tau`, with `ratio` DEM steps per LBM step.
pub(crate) struct ClosedBox {
    pub units: CouplingUnits,
    pub domain: Domain,
    pub nodes: usize,
    /// LBM time step (s).
    pub dt: f64,
}

/// Units (checked against the Mach limit for `u_max`) and domain of a [`ClosedBox`].
pub(crate) fn closed_box(
    [w, h]: [f64; 2],
    dx: f64,
    nu: f64,
    rho_f: f64,
    u_max: f64,
    tau: f64,
    ratio: u32,
) -> Result<ClosedBox, CouplingError> {
    let (nx, ny) = ((w / dx).round() as usize, (h / dx).round() as usize);
    let lattice = LatticeUnits::derive(&LatticeInput::new(dx, nu, rho_f, u_max, TimeSpec::Tau(tau)))?;
    let dt = lattice.dt;
    let units = CouplingUnits::new(lattice, [0.0, 0.0], dt / ratio as f64)?;
    let wall = Face::Wall { velocity: [0.0; 3] };
    let domain = Domain::new(
        [nx, ny, 1],
        [wall, wall, wall, wall, Face::Periodic, Face::Periodic],
    );
    Ok(ClosedBox {
        units,
        domain,
        nodes: nx * ny,
        dt,
    })
}
