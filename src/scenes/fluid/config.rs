//! The `fluid` scene file, in SI units (see docs/lbm.md for every key).

use serde::Deserialize;
use std::path::PathBuf;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidScene {
    /// `kind` and `name`, read by `scenes::run_scene`.
    #[allow(dead_code)]
    pub scene: toml::Value,
    pub lattice: LatticeCfg,
    pub domain: DomainCfg,
    pub fluid: FluidCfg,
    #[serde(default)]
    pub boundaries: BoundariesCfg,
    #[serde(default)]
    pub forcing: ForcingCfg,
    #[serde(default)]
    pub obstacles: Vec<ObstacleCfg>,
    #[serde(default)]
    pub mask: Option<MaskCfg>,
    pub stop: StopCfg,
    #[serde(default)]
    pub output: OutputCfg,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LatticeCfg {
    /// "D2Q9" or "D3Q19".
    #[serde(default = "d2q9")]
    pub stencil: String,
    /// "f64" (default) or "f32".
    #[serde(default = "f64s")]
    pub precision: String,
    /// "bgk" or "trt" (default).
    #[serde(default = "trt")]
    pub collision: String,
    /// TRT magic parameter Λ (default 1/4).
    #[serde(default = "quarter")]
    pub magic: f64,
    /// Lattice spacing (m).
    pub dx: f64,
    /// Time step (s); give this or `tau`.
    pub dt: Option<f64>,
    pub tau: Option<f64>,
    #[serde(default = "mach_warn")]
    pub mach_warn: f64,
    #[serde(default = "mach_max")]
    pub mach_max: f64,
    /// "aa" (in-place, default when no face is Zou-He) or "two-array" (needed for Zou-He faces).
    #[serde(default = "auto")]
    pub kernel: String,
    /// Rayon threads (0 = all cores).
    #[serde(default)]
    pub threads: usize,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DomainCfg {
    /// Box size (m): [x, y] or [x, y, z].
    pub size: Vec<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidCfg {
    /// kg/m³.
    pub density: f64,
    /// Kinematic viscosity m²/s.
    pub viscosity: f64,
    /// Largest velocity expected (m/s), for the Mach check.
    pub u_max: f64,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundariesCfg {
    pub x_min: Option<FaceCfg>,
    pub x_max: Option<FaceCfg>,
    pub y_min: Option<FaceCfg>,
    pub y_max: Option<FaceCfg>,
    pub z_min: Option<FaceCfg>,
    pub z_max: Option<FaceCfg>,
}

/// A face; omitted faces are periodic.
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum FaceCfg {
    Periodic,
    /// Halfway bounce-back wall, optionally sliding (m/s).
    Wall {
        #[serde(default)]
        velocity: Vec<f64>,
    },
    /// Zou-He velocity inlet/outlet (m/s).
    Velocity {
        velocity: Vec<f64>,
    },
    /// Zou-He pressure (gauge Pa).
    Pressure {
        pressure: f64,
    },
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForcingCfg {
    /// Body acceleration (m/s²) on the fluid, e.g. gravity or a pressure gradient / density.
    #[serde(default)]
    pub acceleration: Vec<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleCfg {
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

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaskCfg {
    /// Image with one pixel per node (2D): dark (< 128) = solid. Row 0 is the top (y max).
    pub image: PathBuf,
    #[serde(default = "mask_name")]
    pub name: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StopCfg {
    /// Simulated time (s).
    pub time: Option<f64>,
    pub steps: Option<u64>,
    /// Stop early when the mean velocity changes by less than this fraction between samples.
    pub steady_tol: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputCfg {
    /// Number of time-series samples over the run.
    #[serde(default = "samples")]
    pub samples: u64,
    /// Number of field snapshots (VTK) over the run, the last one always written.
    #[serde(default = "snapshots")]
    pub snapshots: u64,
}

impl Default for OutputCfg {
    fn default() -> Self {
        Self {
            samples: samples(),
            snapshots: snapshots(),
        }
    }
}

fn d2q9() -> String {
    "D2Q9".into()
}
fn f64s() -> String {
    "f64".into()
}
fn auto() -> String {
    "auto".into()
}
fn trt() -> String {
    "trt".into()
}
fn quarter() -> f64 {
    0.25
}
fn mach_warn() -> f64 {
    0.1
}
fn mach_max() -> f64 {
    0.3
}
fn mask_name() -> String {
    "mask".into()
}
fn samples() -> u64 {
    200
}
fn snapshots() -> u64 {
    5
}
