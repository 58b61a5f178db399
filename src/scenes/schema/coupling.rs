//! `[coupling]`: how the liquid and the grains see each other (Su et al. 2020 Sect. 2.3).

use lbdem_coupling::Method;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CouplingSection {
    /// "psm" (partially saturated cells, default) or "bounce-back".
    #[serde(default)]
    pub method: Method,
    /// Hydrodynamic radius factor for the LBM step only (Su Sect. 2.3: 0.8).
    #[serde(default = "r_hd")]
    pub r_hd: f64,
    /// Sample depth (m) that the particle density is per (kg/m² = ρ_S × depth).
    #[serde(default = "one")]
    pub depth: f64,
    /// Membrane grains do not feel the liquid.
    #[serde(default)]
    pub dry_membrane: bool,
    /// PSM only: give the grains back the inertia of the liquid PSM carries inside them
    /// (Uhlmann 2005); refused unless every grain is at least 1.2 times denser than the liquid.
    #[serde(default)]
    pub interior_liquid_correction: bool,
    /// `false` turns the liquid off and runs the grains alone (Su et al. 2020 Fig. 11, right
    /// column: "LBM turned off, skipping steps 9-17"), keeping the scene's other sections.
    #[serde(default = "yes")]
    pub liquid: bool,
    /// PSM only: a grain's solid fraction is computed again once it moved more than this many
    /// lattice cells since it was last mapped (0: whenever it moved, Su Fig. 2 step 10). A speed
    /// switch for quasi-static runs (issue 13 item 7; docs/su2020.md, "Speed").
    #[serde(default)]
    pub remap_tolerance: f64,
}

impl Default for CouplingSection {
    fn default() -> Self {
        Self {
            method: Method::Psm,
            r_hd: r_hd(),
            depth: 1.0,
            dry_membrane: false,
            interior_liquid_correction: false,
            liquid: true,
            remap_tolerance: 0.0,
        }
    }
}

fn r_hd() -> f64 {
    0.8
}
fn yes() -> bool {
    true
}
fn one() -> f64 {
    1.0
}
