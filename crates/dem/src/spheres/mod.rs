//! 3D spheres: a discrete-element engine for solid spheres and rigid clumps of spheres with
//! Hertz-Mindlin contacts (issue 19 item 1, first slice; Leonardi et al. 2014 Sect. 3 and Ness
//! et al. 2017 need 3D grains).
//!
//! Built as the 2D engine is: the state is plain data ([`SphereSystem`]: spheres, plane walls,
//! the Verlet list with its contact histories, the clock; serialisable, a checkpoint resumes bit
//! for bit), the [`SphereStepper`] is scratch, the contact law ([`HertzMindlin`], `law.rs`) is a
//! small pure kernel with its equations in its docs. No file I/O.
//!
//! - `domain.rs`: the box, periodic on any axis (minimum image);
//! - `cells.rs`: linked-cell broad phase building a sorted Verlet list with a skin;
//! - `law.rs`: Hertz normal force, Mindlin tangential spring with history, Coulomb cap,
//!   restitution damping (Tsuji; LIGGGHTS `hertz tangential history`);
//! - `clump.rs`: rigid clumps (mass properties of the union of spheres, principal axes, the
//!   body-frame free rotation);
//! - `stepper.rs`: velocity Verlet, serial (results are independent of the rayon thread count
//!   because nothing here runs in parallel yet).
//!
//! Validated against Chung & Ooi (2011) benchmarks 1-4 (`crates/dem/tests/chung_ooi.rs`,
//! `docs/dem3d.md`); clumps in `crates/dem/tests/clumps.rs`. Not yet here: lubrication,
//! parallel passes, per-sphere materials.

pub mod cells;
pub mod clump;
pub mod domain;
pub mod error;
pub mod law;
pub mod stepper;
pub mod system;

pub use clump::{ClumpTemplate, Clumps};
pub use domain::Domain3;
pub use error::SphereError;
pub use law::{Elastic, HertzMindlin, Surface};
pub use stepper::{SphereStepParams, SphereStepper};
pub use system::{FREE, PlaneWall, SphereContacts, SphereSystem, Spheres};
