//! lbdem-dem: discrete-element engine for rigid clumps of circles (2D), after Su et al. 2020
//! (Sects. 2.3-2.4, Table 1), Ness et al. 2017 (Eq. 6) and Leonardi et al. 2014 (Sect. 3).
//!
//! State is plain data ([`System`]: [`Bodies`], walls, bonds, [`Contacts`]); the [`Stepper`] is
//! scratch. Contact laws implement [`ContactLaw`] (each with its own range and history type) and
//! are registered for scenes in [`Law`]; callers add forces through a [`ForceHook`]. No file
//! I/O here.

pub mod assembly;
pub mod body;
pub mod cases;
pub mod contact;
pub mod domain;
pub mod error;
pub mod generate;
pub mod history;
mod kick_disks;
mod lanes;
pub mod neighbor;
mod on_arrays;
#[cfg(target_arch = "x86_64")]
mod on_avx2;
#[cfg(target_arch = "x86_64")]
mod on_avx512;
mod pair_batched;
pub mod polygon;
mod scratch;
pub mod shape;
pub mod spheres;
pub mod stepper;
pub mod system;
pub mod vector;
pub mod wall;

pub use body::Bodies;
pub use contact::{ContactLaw, Damping, History, Law, LawVisitor, SpringDashpots};
pub use domain::Domain;
pub use error::DemError;
pub use history::{Histories, HistoryData};
pub use neighbor::Contacts;
pub use shape::{Ball, ClumpShape, MassProps2};
pub use stepper::bond_dashpots::{BOND_DASHPOT_LIMIT, BondDashpotLimit};
pub use stepper::{ForceHook, StepParams, Stepper, WallContactStep};
pub use system::{Membrane, System};
pub use vector::{Vec2, Vec3, Vector};
pub use wall::{ServoLength, Wall, WallMotion, WallShape};
