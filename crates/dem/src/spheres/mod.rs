//! 3D spheres: a discrete-element engine for solid spheres and rigid clumps of spheres (issue 19
//! item 1; Leonardi et al. 2014 Sect. 3 and Ness et al. 2017 need 3D grains).
//!
//! Built as the 2D engine is: the state is plain data ([`SphereSystem`]: spheres, plane walls,
//! the Verlet list with its contact histories, the clock; serialisable, checked when read, a
//! checkpoint resumes bit for bit), the [`SphereStepper`] is scratch and generic over the
//! contact law ([`SphereLaw`]: its range beyond contact, its history, its stable step), callers
//! add forces through a [`SphereForceHook`]. No file I/O.
//!
//! - `domain.rs`: the box, periodic on any axis (minimum image), Lees-Edwards shear;
//! - `edit.rs`: removing spheres (the open outlet), histories remapped;
//! - `cells.rs`: linked-cell broad phase building a sorted Verlet list with a skin, reaching the
//!   law's range;
//! - `law/`: the contact-law seam and the laws ([`HertzMindlinSpring`]; Ness et al. 2017's
//!   [`LinearSpring`] and [`Lubrication`], combined by [`Lubricated`]);
//! - `clump.rs`: rigid clumps (mass properties of the union of spheres, principal axes, the
//!   body-frame free rotation);
//! - `hook.rs`: user forces;
//! - `validate.rs`: the consistency check of a state (checkpoints are user input);
//! - `stepper.rs`: velocity Verlet; the pair laws in parallel, their sums serial (the bits do
//!   not depend on the thread count);
//! - `stress.rs`: the per-contact forces of the last evaluation and the dipole stress sum.
//!
//! Validated against Chung & Ooi (2011) benchmarks 1-4 (`crates/dem/tests/chung_ooi.rs`,
//! `docs/dem3d.md`); clumps in `crates/dem/tests/clumps.rs`. Not yet here:
//! per-sphere materials.

pub mod cells;
pub mod clump;
pub mod domain;
pub mod edit;
pub mod error;
pub mod extruder;
pub(crate) mod hm_batched;
pub mod hook;
pub(crate) mod kick_batched;
pub mod law;
pub mod stepper;
pub mod stress;
pub mod system;
pub mod validate;

pub use clump::{BodyFrame, ClumpTemplate, Clumps};
pub use domain::{Domain3, LeesEdwards};
pub use error::SphereError;
pub use hook::SphereForceHook;
pub use law::{
    Elastic, HertzMindlinSpring, Interaction, LinearSpring, Lubricated, Lubrication, Response, SphereLaw,
    Surface, TimeStepLimit,
};
pub use stepper::{SphereStepParams, SphereStepper, max_time_step};
pub use stress::{ContactForce, Partner, SphereDipole, dipole_stress, sphere_dipoles};
pub use system::{FREE, PlaneWall, SphereContacts, SphereSystem, Spheres};
