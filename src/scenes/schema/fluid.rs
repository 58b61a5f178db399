//! Sections of the liquid: `[fluid]` (material), `[lattice]` (discretisation), `[boundaries]`
//! (the box faces), `[forcing]` (a body acceleration of the liquid), `[[obstacles]]` and
//! `[mask]` (fixed or moving solids of a fluid-only scene). The same types serve fluid and
//! coupled scenes; the defaults live in `lbdem_core::units::lattice` (Mach) and here.

use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// `[fluid]`: the liquid's material.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FluidSection {
    /// kg/m³.
    pub density: f64,
    /// Kinematic viscosity ν (m²/s); or give `dynamic_viscosity` μ (Pa s).
    #[serde(default)]
    pub viscosity: Option<f64>,
    #[serde(default)]
    pub dynamic_viscosity: Option<f64>,
    /// Largest liquid speed expected (m/s), for the Mach check (Su Eq. 16).
    pub u_max: f64,
    /// The liquid's velocity and pressure at the start, from a fluid table (a run's
    /// `fields/fluid_*.csv`/`.parquet`, or one written by hand with columns `i, j, k, ux, uy,
    /// uz` in m/s and `pressure` in Pa): every liquid node once. Default: at rest.
    #[serde(default)]
    pub initial: Option<PathBuf>,
}

impl FluidSection {
    /// The kinematic viscosity, from whichever of the two keys is given.
    pub fn kinematic_viscosity(&self) -> Result<f64, String> {
        match (self.viscosity, self.dynamic_viscosity) {
            (Some(nu), None) => Ok(nu),
            (None, Some(mu)) => Ok(mu / self.density),
            _ => Err(
                "[fluid]: give exactly one of viscosity (kinematic, m²/s) or dynamic_viscosity (Pa s)".into(),
            ),
        }
    }
}

/// `[lattice]`: the lattice-Boltzmann discretisation.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LatticeSection {
    /// "D2Q9" or "D3Q19"; by default the one of the domain's dimension.
    #[serde(default)]
    pub stencil: Option<String>,
    /// "f64" (default) or "f32" population storage.
    #[serde(default = "f64s")]
    pub precision: String,
    /// "bgk" or "trt" (default).
    #[serde(default = "trt")]
    pub collision: String,
    /// TRT magic parameter Λ (default 3/16: halfway bounce-back walls exactly where they are
    /// drawn at every τ, for the cost of 1/4 and in the same stability band; chosen by the atlas,
    /// docs/atlas.md "Defaults from evidence").
    #[serde(default = "three_sixteenths")]
    pub magic: f64,
    /// Node spacing (m).
    pub dx: f64,
    /// Time step (s); give this or `tau`. Coupled scenes: a whole multiple of `[dem] dt`.
    #[serde(default)]
    pub dt: Option<f64>,
    #[serde(default)]
    pub tau: Option<f64>,
    #[serde(default = "mach_warn")]
    pub mach_warn: f64,
    #[serde(default = "mach_max")]
    pub mach_max: f64,
    /// "auto" (default), "aa" (in place) or "two-array" (needed for Zou-He faces).
    #[serde(default = "auto")]
    pub kernel: String,
}

fn f64s() -> String {
    "f64".into()
}
fn trt() -> String {
    "trt".into()
}
fn three_sixteenths() -> f64 {
    0.1875
}
fn auto() -> String {
    "auto".into()
}
fn mach_warn() -> f64 {
    lbdem_core::units::lattice::MACH_WARN
}
fn mach_max() -> f64 {
    lbdem_core::units::lattice::MACH_MAX
}

/// `[boundaries]`: faces of non-periodic axes; an omitted one is a wall at rest. Faces of the
/// axes `[domain] periodic` names are periodic and may not be given.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BoundariesSection {
    pub x_min: Option<FaceSection>,
    pub x_max: Option<FaceSection>,
    pub y_min: Option<FaceSection>,
    pub y_max: Option<FaceSection>,
    pub z_min: Option<FaceSection>,
    pub z_max: Option<FaceSection>,
}

/// One face.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum FaceSection {
    /// Halfway bounce-back wall, optionally sliding (m/s).
    Wall {
        #[serde(default)]
        velocity: Vec<f64>,
    },
    /// Zou-He velocity inlet/outlet (m/s).
    Velocity { velocity: Vec<f64> },
    /// Zou-He pressure (gauge Pa).
    Pressure { pressure: f64 },
}

/// `[forcing]`: body acceleration (m/s²) on the liquid, e.g. a pressure gradient / density.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ForcingSection {
    #[serde(default)]
    pub acceleration: Vec<f64>,
}

/// One entry of `[[obstacles]]`: a circle (2D) or sphere (3D) in rigid motion.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSection {
    /// "circle" (2D) or "sphere" (3D).
    pub shape: String,
    pub centre: Vec<f64>,
    pub radius: f64,
    #[serde(default)]
    pub velocity: Vec<f64>,
    /// rad/s: a number in 2D (about z), a vector in 3D.
    #[serde(default)]
    pub omega: Option<toml::Value>,
    #[serde(default)]
    pub name: Option<String>,
}

/// `[mask]`: an image with one pixel per node (2D): dark (< 128) = solid; row 0 is the top.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MaskSection {
    pub image: PathBuf,
    #[serde(default = "mask_name")]
    pub name: String,
}

fn mask_name() -> String {
    "mask".into()
}
