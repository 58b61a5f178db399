//! `[shear_cell]`: the push-plate cell of Su et al. 2020 (Fig. 1a-b): which wall is the
//! push-plate, the measures of Sect. 2.5 every run records, and whether the liquid is confined
//! to the membrane (Fig. 2 step 15).

use super::run::WallRef;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ShearCellSection {
    /// The push-plate: a segment wall (`a`, `b`) with a `velocity`, by name or index.
    pub plate: WallRef,
    /// Length over which the plate's displacement rate shears the sample: γ̇ = (du_y/dt) / L in
    /// the inertial number of Eq. 20 (Su Sect. 3.4: 10 mm).
    #[serde(default = "ten_mm")]
    pub shear_length: f64,
    /// With a liquid: nodes outside the membrane polygon or behind the plate are the "solid
    /// zone" of Fig. 2 step 15, rebuilt every LBM step (default true).
    #[serde(default = "yes")]
    pub confine_liquid: bool,
    /// What the liquid sees outside the membrane: `"at_rest"` (default), step 15 as written (a
    /// sink of liquid ahead of a rising membrane: docs/su2020.md, "This is an artefact"), or
    /// `"moving"`, a wall moving with the membrane whose reaction the membrane grains feel
    /// (needs heavy membrane grains, and not yet stable for every assembly).
    #[serde(default)]
    pub membrane_boundary: lbdem_coupling::MembraneBoundary,
    /// With `membrane_boundary = "moving"`: the weight ω of the membrane's newest velocity in
    /// what the liquid is shown, the rest kept from the step before (default ½; 1 keeps
    /// nothing). At ½ six random reduced cells with a membrane 2.7 times the liquid's density
    /// all ran, at 1 all six blew up (`lbdem_coupling::Confinement::set_relaxation`).
    #[serde(default = "half")]
    pub membrane_relaxation: f64,
    /// Seconds with the plate held still before it moves (default 0): the grains come to rest
    /// against the membrane with the run's own contact law and liquid, as Su et al. relax the
    /// assembly inside the membrane before deformation (Sect. 2.4). A_0 of Eq. 18 and the
    /// plate's displacement are measured from the end of it; `[run] time` counts after it.
    #[serde(default)]
    pub settle: f64,
    /// With `settle`: hold the plate on after it until every grain is slower than `speed`
    /// (m/s; Su Sect. 2.4: 1e-7), for at most `max_time` seconds in all; a run released at
    /// `max_time` with grains still moving says so after it ends. `settle` is then the
    /// shortest hold (the grains start at rest, so the criterion holds at the first step).
    #[serde(default)]
    pub settle_until_rest: Option<UntilRest>,
}

/// `[shear_cell] settle_until_rest`.
#[derive(Clone, Copy, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct UntilRest {
    /// Speed every grain must be below (m/s).
    pub speed: f64,
    /// Longest hold (s), `settle` included.
    pub max_time: f64,
}

fn half() -> f64 {
    0.5
}
fn ten_mm() -> f64 {
    0.01
}
fn yes() -> bool {
    true
}
