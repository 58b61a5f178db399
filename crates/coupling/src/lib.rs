//! LBM-DEM coupling by partially saturated cells (Noble & Torczynski 1998; Su et al.
//! 2020 Eqs. 9-14), and the moving-boundary bounce-back alternative (Leonardi et al. 2014
//! Eqs. 19-21) for comparison on the same cases.
//!
//! - geometry: the exact overlap of lattice cells with circles ([`overlap`]) and the per-cell
//!   solid fraction of clumped grains with the hydrodynamic radius r_hd ([`solid_fraction`]),
//!   kept from step to step and recomputed for the grains that moved ([`remap`]);
//! - the weighting B of Eq. 10 ([`weighting`]);
//! - the PSM lattice: collision of Eqs. 9 and 11, force and moment of Eq. 14 ([`psm`]);
//! - the liquid confined to a deforming sample, the moving "solid zone" ([`confine`]);
//! - the sub-cycling driver that holds the hydrodynamic load over the DEM steps ([`driver`]);
//! - 3D grains in a free-surface liquid by moving bounce-back ([`surface_grains`]).

// Kernels index several parallel arrays (velocities, weights, populations) by direction: an index
// loop says that more plainly than zipped iterators.
#![allow(clippy::needless_range_loop)]

pub mod bounce;
pub mod cases;
pub mod confine;
pub mod driver;
pub mod error;
pub mod hydro;
pub mod overlap;
pub mod psm;
pub mod remap;
pub mod solid_fraction;
pub mod surface_grains;
pub mod weighting;

/// The units of a coupled run live in `lbdem_core::units::coupled` (the one units module);
/// re-exported here so that `lbdem_coupling::units::CouplingUnits` keeps working.
pub use lbdem_core::units::coupled as units;

pub use bounce::{BounceFluid, BounceState};
pub use confine::{Confinement, MembraneBoundary};
pub use driver::{Coupled, CoupledState, INTERIOR_LIQUID_MIN_RATIO};
pub use error::CouplingError;
pub use hydro::{Hydro, HydroState, Method};
pub use psm::{GrainMotion, LIQUID, Load, PsmFluid, PsmSettings, PsmState, ZoneExchange, ZoneMass};
