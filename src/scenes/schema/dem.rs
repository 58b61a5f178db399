//! Sections of the grains: `[particles]`, `[contact]`/`[wall_contact]` (the laws of
//! `lbdem_dem::Law`), `[[walls]]`, `[bonds]`, `[membrane]`, `[dem]` (the DEM time step) and
//! `[compress]` (isotropic compression before the run, Su et al. 2020 Sect. 2.4).

use lbdem_dem::contact::BondParams;
use lbdem_dem::generate::Compression;
use lbdem_dem::{StepParams, Vec2};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// `[particles]`: the grains, from the digitise stage's circle file or generated.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ParticlesSection {
    /// Density (kg/m² per unit thickness, i.e. ρ_s × 1 m; ρ_s × depth in coupled scenes).
    pub density: f64,
    /// Circles from the digitise stage: CSV with grain_id,x,y,r (+ JSON header beside it).
    #[serde(default)]
    pub csv: Option<PathBuf>,
    #[serde(default)]
    pub generate: Option<GenerateSection>,
    /// An assembly written by `lbdem assemble` (Su et al. 2020 Sect. 2.4), checked against the
    /// grain set the scene expects.
    #[serde(default)]
    pub assembly: Option<AssemblySection>,
    /// A finished run's `snapshots/` directory (or one particle snapshot): the grains start
    /// where that run ended, whatever `csv`, `assembly` or `generate` say (Su's Float: the
    /// second 10 % area cut continues from the first run, `--set particles.continue_from=...`).
    #[serde(default)]
    pub continue_from: Option<PathBuf>,
    /// Every grain's area times this factor before the run, about its centroid (Su et al. 2020
    /// Sect. 2.4, Float: 0.9, "the area of each two-circle grain was reduced by 10 %").
    #[serde(default = "one")]
    pub area_factor: f64,
    /// Initial velocity of every grain (m/s), `[vx, vy]`; default at rest (an impact test
    /// launches its grains with it instead of with a moving wall).
    #[serde(default)]
    pub velocity: Option<[f64; 2]>,
    /// Initial angular velocity of every grain (rad/s, counter-clockwise); default 0.
    #[serde(default)]
    pub omega: Option<f64>,
}

/// `[particles] assembly = { file = "...", grains = N, d = [d_min, d, d_max] }`: the assembly
/// file and the grain set it must hold (Su Table 2: N^DEM and d_min:d:d_max), so a case cannot
/// start from another case's grains.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct AssemblySection {
    pub file: PathBuf,
    pub grains: usize,
    #[serde(default)]
    pub d: Option<[f64; 3]>,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GenerateSection {
    pub count: usize,
    /// Templates: each a list of circles [x, y, r] (m) and a weight.
    pub templates: Vec<TemplateSection>,
    pub lo: [f64; 2],
    pub hi: [f64; 2],
    #[serde(default)]
    pub seed: u64,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TemplateSection {
    pub circles: Vec<[f64; 3]>,
    #[serde(default = "one")]
    pub weight: f64,
}

fn one() -> f64 {
    1.0
}

/// One entry of `[[walls]]`: `box = [x0, y0, x1, y1]` (four planes), a plane (`p`, `n`) or a
/// segment (`a`, `b`), with an optional prescribed velocity (m/s), e.g. the push-plate.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WallSection {
    /// A name to refer to the wall by (stop conditions, triggers); plane and segment walls only.
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default, rename = "box")]
    pub box_: Option<[f64; 4]>,
    #[serde(default)]
    pub p: Option<[f64; 2]>,
    #[serde(default)]
    pub n: Option<[f64; 2]>,
    #[serde(default)]
    pub a: Option<[f64; 2]>,
    #[serde(default)]
    pub b: Option<[f64; 2]>,
    #[serde(default)]
    pub velocity: Option<[f64; 2]>,
}

/// `[bonds]`: parallel bonds between membrane circles closer than r_i + r_j + gap.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BondsSection {
    pub params: BondParams,
    pub gap: f64,
}

/// `[membrane]`: grains within `shell` of the assembly's outline become membrane grains, pushed
/// back with `force` when they move outward by more than `threshold` (Su Sect. 2.4).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MembraneSection {
    pub shell: f64,
    pub threshold: f64,
    pub force: f64,
    /// F_N rises linearly over this distance beyond the threshold (m; 0, the default, is the
    /// paper's step, which keeps a grain resting at the threshold vibrating: `lbdem_dem::Membrane`).
    #[serde(default)]
    pub ramp: f64,
    /// Factor on the membrane grains' masses and inertias (default 1): the membrane is the
    /// model's confinement, not material of the sample. Until 2026-11-29 a membrane that shows
    /// the liquid its velocity (`[shear_cell] membrane_boundary = "moving"`) needed grains 2.5
    /// times the liquid's density; it now needs damped bonds instead (`[bonds] params.damping`,
    /// docs/su2020.md, "The membrane's bonds must be damped"). Over runs past u_y = 2 d̄ at
    /// Table 1's masses it needs both: membranes up to 1.35 times the liquid's density rang
    /// or blew up, 1.80 and 2.7 times did not, and one under 1.8 is warned before the run
    /// (`MOVING_MEMBRANE_DENSITY_RATIO_WARN`; docs/stability.md, "Damped membrane bonds").
    #[serde(default = "one")]
    pub mass_scale: f64,
}

/// `[dem]`: the DEM time step and what acts on every grain.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DemSection {
    /// DEM time step Δt (s); refused above the critical step.
    pub dt: f64,
    /// Verlet-list skin (m).
    pub skin: f64,
    /// Gravity (m/s²), [x, y].
    #[serde(default)]
    pub gravity: [f64; 2],
    /// Factor on gravity: 1 for dry grains, 1 − ρ_L/ρ_S for buoyant grains (Su Sect. 2.4).
    #[serde(default = "one")]
    pub gravity_factor: f64,
    /// Viscous damping rate γ (1/s): F −= γ m v, T −= γ I ω.
    #[serde(default)]
    pub viscous_damping: f64,
    /// Local (non-viscous, Cundall) damping α: F_k −= α |F_k| sign(v_k).
    #[serde(default)]
    pub local_damping: f64,
    /// Mass scaling: every grain's mass and inertia times this factor (default 1), so the
    /// critical step grows by its square root. For quasi-static runs only: the inertial
    /// number (Su Eq. 20) the series reports is the scaled run's, √factor times the real one.
    #[serde(default = "one")]
    pub mass_scale: f64,
    /// Mass scaling that follows the run (`[dem.mass_scale_control]`): `mass_scale` and `dt`
    /// are then the largest scale and its step, and the run takes the largest scale that keeps
    /// the scaled inertial number under a target. Coupled shear-cell scenes only.
    #[serde(default)]
    pub mass_scale_control: Option<MassScaleControl>,
}

/// `[dem.mass_scale_control]`: the mass scale follows the inertial number (Su Eq. 20) of the
/// run (issue 13 item 7; `scenes::models::mass_control`). The scale moves on a ladder of whole
/// DEM-LBM ratios r, the scale at r being `mass_scale` × (r_0/r)² (r_0 the scene's ratio), so
/// every rung keeps the scene's margin to the critical step.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MassScaleControl {
    /// Keep the scaled inertial number under this (Su Sect. 3.4: quasi-static below 0.002).
    pub inertial_number: f64,
    /// The smallest mass scale the ladder goes down to (default 1: the grains' own masses).
    #[serde(default = "one")]
    pub smallest: f64,
    /// LBM steps between two decisions (default 20).
    #[serde(default = "twenty")]
    pub every: u64,
    /// The scale while the plate is held (`[shear_cell] settle`): `"top"` (default), the
    /// scene's `mass_scale`, or `"smallest"`, the bottom of the ladder, so the sample rebounds
    /// against the membrane at its own masses: a heavy sample's rebound is slower, and its phase
    /// when the plate starts moved ε_vol^DEM beyond the mass scaling's tolerance on the 84 %PK
    /// case. Not the default: on Simulation I it moved ε_vol^DEM further from Table 1's masses,
    /// as the ladder then lifts the masses tenfold at once on a sample still in motion
    /// (docs/su2020.md, "Simulation I's switches checked on Simulation I itself").
    #[serde(default, skip_serializing_if = "HeldScale::is_top")]
    pub held: HeldScale,
}

/// `[dem.mass_scale_control] held`: which rung the ladder stands on while the plate is held.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum HeldScale {
    /// The scene's `[dem] mass_scale` (the top of the ladder).
    #[default]
    Top,
    /// The ladder's smallest scale (`smallest`).
    Smallest,
}

impl HeldScale {
    fn is_top(&self) -> bool {
        *self == Self::Top
    }
}

fn twenty() -> u64 {
    20
}

impl DemSection {
    pub fn step_params(&self) -> StepParams {
        StepParams {
            dt: self.dt,
            gravity: Vec2::new(self.gravity[0], self.gravity[1]),
            gravity_factor: self.gravity_factor,
            viscous_damping: self.viscous_damping,
            local_damping: self.local_damping,
            skin: self.skin,
        }
    }
}

/// `[compress]`: isotropic compression by four servo walls to a 2D stress before the run,
/// then optionally a radius scaling to a target packing fraction (Su Sect. 2.4).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CompressSection {
    pub target_stress: f64,
    #[serde(default = "alpha")]
    pub alpha: f64,
    pub v_max: f64,
    #[serde(default = "tol")]
    pub tolerance: f64,
    pub v_threshold: f64,
    pub max_steps: u64,
    #[serde(default)]
    pub target_packing: Option<f64>,
}

fn alpha() -> f64 {
    0.1
}
fn tol() -> f64 {
    0.05
}

impl CompressSection {
    pub fn to_kernel(&self) -> Compression {
        Compression {
            target_stress: self.target_stress,
            alpha: self.alpha,
            v_max: self.v_max,
            tolerance: self.tolerance,
            v_threshold: self.v_threshold,
            max_steps: self.max_steps,
        }
    }
}
