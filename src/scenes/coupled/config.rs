//! The coupled-scene file format (TOML, SI units): a dry scene's particles, box, walls, contact
//! law and DEM step, plus the liquid, the lattice and the coupling. Every key is documented in
//! docs/coupling.md.

use crate::scenes::dry::config::{BondsCfg, DomainCfg, MembraneCfg, ParticlesCfg, WallCfg};
use lbdem_coupling::Method;
use lbdem_dem::{Law, StepParams};
use serde::Deserialize;

/// The dry-scene tables are repeated here rather than `#[serde(flatten)]`ed from `DryScene`:
/// serde cannot combine `flatten` with `deny_unknown_fields`, and a misspelt key must be refused.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoupledScene {
    #[allow(dead_code)]
    pub scene: toml::Value,
    pub particles: ParticlesCfg,
    pub domain: DomainCfg,
    #[serde(default)]
    pub walls: Vec<WallCfg>,
    pub contact: Law,
    #[serde(default)]
    pub wall_contact: Option<Law>,
    #[serde(default)]
    pub bonds: Option<BondsCfg>,
    #[serde(default)]
    pub membrane: Option<MembraneCfg>,
    /// DEM step: `dt` is the DEM time step Δt (Su et al. 2020 Table 1).
    pub step: StepParams,
    pub fluid: FluidCfg,
    pub lattice: LatticeCfg,
    #[serde(default)]
    pub coupling: CouplingCfg,
    pub run: RunCfg,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidCfg {
    /// Liquid density ρ_L (kg/m³).
    pub density: f64,
    /// Kinematic viscosity ν (m²/s); or give `dynamic_viscosity` μ_L (Pa s) instead.
    #[serde(default)]
    pub viscosity: Option<f64>,
    #[serde(default)]
    pub dynamic_viscosity: Option<f64>,
    /// Largest liquid speed expected (m/s), for the Mach check (Su Eq. 16).
    pub u_max: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LatticeCfg {
    /// Node spacing (m); Su et al. use 40 µm.
    pub dx: f64,
    /// LBM time step δt (s); must be a whole multiple of the DEM step (Su Table 3).
    pub dt: f64,
    #[serde(default = "f64_name")]
    pub precision: String,
    #[serde(default = "mach_warn")]
    pub mach_warn: f64,
    #[serde(default = "mach_max")]
    pub mach_max: f64,
    /// rayon threads, 0 = all.
    #[serde(default)]
    pub threads: usize,
}

fn f64_name() -> String {
    "f64".into()
}
fn mach_warn() -> f64 {
    0.1
}
fn mach_max() -> f64 {
    0.3
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CouplingCfg {
    #[serde(default)]
    pub method: Method,
    /// Hydrodynamic radius factor for the LBM step only (Su Sect. 2.3: 0.8).
    #[serde(default = "r_hd")]
    pub r_hd: f64,
    /// Sample depth (m) that the particle density is per (kg/m² = ρ_S × depth).
    #[serde(default = "one")]
    pub depth: f64,
    /// Membrane grains (tag 1) do not feel the liquid.
    #[serde(default)]
    pub dry_membrane: bool,
    /// PSM only: relax the liquid with two rates (TRT) of this magic parameter (1/4 is usual)
    /// instead of BGK; needed near τ = ½ (Reynolds numbers of hundreds).
    #[serde(default)]
    pub trt_magic: Option<f64>,
    /// PSM only: give the grains back the inertia of the liquid PSM carries inside them
    /// (Uhlmann 2005); refused unless every grain is at least 1.2 times denser than the liquid.
    #[serde(default)]
    pub interior_liquid_correction: bool,
}

impl Default for CouplingCfg {
    fn default() -> Self {
        Self {
            method: Method::Psm,
            r_hd: r_hd(),
            depth: 1.0,
            dry_membrane: false,
            trt_magic: None,
            interior_liquid_correction: false,
        }
    }
}

fn r_hd() -> f64 {
    0.8
}
fn one() -> f64 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunCfg {
    /// LBM steps (each with `dt_lbm / dt_dem` DEM sub-steps).
    pub steps: u64,
    #[serde(default = "ten")]
    pub output_every: u64,
    /// VTK fields and particles every this many LBM steps (0 = only at the end).
    #[serde(default)]
    pub snapshot_every: u64,
    /// Pressure-change threshold (Pa) for the "area below" statistic (Su Sect. 2.5, Eq. 19).
    #[serde(default = "threshold")]
    pub pressure_threshold: f64,
}

fn ten() -> u64 {
    10
}
fn threshold() -> f64 {
    -1000.0
}
