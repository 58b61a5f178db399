//! The square-entry die extruder of Ness et al. (2017) (Fig. 1 and Sect. "Geometry and boundary
//! conditions"; issue 19 item 3): frozen wall grains along the barrel, the die entry and the die
//! ([`geometry`]), a bidisperse 1:1 paste inserted in an inlet box behind the barrel to keep
//! φ ≈ 0.5 there and pushed along +x by a body force on every grain in the box ([`inlet`]),
//! grains removed past the open outlet ([`outlet`]), and the steady state found from the mass
//! balance ([`balance`]). [`driver`] puts them round one step of the sphere engine. Plain data
//! and functions over a [`crate::spheres::SphereSystem`]: no files, no scene format; every
//! length is in m, so a reduced extruder (narrower barrel and die, shorter) is the same code
//! with other numbers.

pub mod balance;
pub mod driver;
pub mod error;
pub mod geometry;
pub mod grid;
pub mod inlet;
pub mod outlet;

pub use balance::{Balance, SteadyRule};
pub use driver::{ExtruderState, Measures};
pub use error::ExtruderError;
pub use geometry::{Geometry, JAMMING_2D, JAMMING_3D, Segment, monolayer_thickness};
pub use inlet::{Drive, Paste};

use serde::{Deserialize, Serialize};

/// Everything that defines an extruder run besides the contact law and the step.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExtruderSpec {
    pub geometry: Geometry,
    pub paste: Paste,
    pub drive: Drive,
    pub steady: SteadyRule,
}

impl ExtruderSpec {
    /// Refuse what cannot run, naming the parameter (before anything is built).
    pub fn check(&self) -> Result<(), ExtruderError> {
        self.paste.check()?;
        let [d_min, d_max] = self.paste.range();
        self.geometry.check(d_min, d_max)?;
        self.drive.check()?;
        self.steady.check()
    }
}
