//! `[extruder]` and `[suspension]`: the square-entry die extruder of Ness et al. (2017), Fig. 1,
//! and its paste (Table 1), in SI. A scene with `[extruder]` builds its own box and grains (3D
//! spheres of `lbdem_dem::spheres`), so it takes no `[domain]`, `[particles]`, `[contact]` or
//! `[dem]` (those are the 2D engine's); docs/ness2017.md.

use anyhow::{Result, bail};
use lbdem_dem::spheres::extruder::{Drive, ExtruderSpec, Geometry, Paste, SteadyRule};
use lbdem_dem::spheres::{LinearSpring, Lubricated, Lubrication, SphereLaw, TimeStepLimit};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

fn jitter() -> f64 {
    0.25
}
fn one() -> u64 {
    1
}
fn half() -> f64 {
    0.5
}
fn ten() -> u64 {
    10
}
fn attempts() -> u32 {
    200
}
fn tolerance() -> f64 {
    0.1
}
fn min_removed() -> u64 {
    100
}

/// `[extruder]`: geometry (m), wall realisation, drive (N), steady-state rule (s).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ExtruderSection {
    /// Barrel width (Ness: 100 d).
    pub barrel_width: f64,
    /// Ram face to the die entry (Ness: the square entry at x = 300 d).
    pub barrel_length: f64,
    /// Die width (Ness: 20 d).
    pub die_width: f64,
    /// Die length (not in the text of the paper; docs/ness2017.md).
    pub die_length: f64,
    /// Depth, periodic in z (Ness: 5 d); with `monolayer`, the layer's thickness for volume
    /// fractions and stresses.
    pub depth: f64,
    /// One layer of grains in the plane z = depth/2 instead of the periodic slab: the extruder
    /// as 2D disks with the spheres' laws (default false; docs/ness2017.md, "The monolayer").
    #[serde(default)]
    pub monolayer: bool,
    /// Inlet box length from the ram face (Ness's dashed box; about 10 d).
    pub inlet_length: f64,
    /// Wall-grain diameter (default: half the smaller paste diameter, Ness's 0.5 d).
    #[serde(default)]
    pub wall_diameter: Option<f64>,
    /// Largest wall-grain spacing (default: the wall-grain diameter, touching).
    #[serde(default)]
    pub wall_spacing: Option<f64>,
    /// Jitter of the wall grains, a fraction of the spacing (default 0.25).
    #[serde(default = "jitter")]
    pub wall_jitter: f64,
    /// The wall realisation (Ness: five per case).
    #[serde(default = "one")]
    pub wall_seed: u64,
    /// Grains are removed this far past the die's end (m; default 0).
    #[serde(default)]
    pub outlet_gap: f64,
    /// Body force on each grain in the inlet box, along +x (N).
    pub body_force: f64,
    /// Volume fraction kept in the inlet box (default 0.5, Ness).
    #[serde(default = "half")]
    pub phi_inlet: f64,
    /// Steps between insertion passes (default 10).
    #[serde(default = "ten")]
    pub insert_every: u64,
    /// Failed random positions in a row that end a pass (default 200).
    #[serde(default = "attempts")]
    pub insert_attempts: u32,
    /// Seed of the insertion positions (default 1).
    #[serde(default = "one")]
    pub seed: u64,
    /// Fill the channel at this volume fraction before the run (default 0: start empty, Ness).
    #[serde(default)]
    pub prefill_phi: f64,
    /// Trailing window of the mass balance (s).
    pub steady_window: f64,
    /// Largest |r_in − r_out|/max(r_in, r_out) over the window (default 0.1).
    #[serde(default = "tolerance")]
    pub steady_tolerance: f64,
    /// Fewest grains removed over the window for a verdict (default 100).
    #[serde(default = "min_removed")]
    pub steady_min_removed: u64,
    /// End the run once the mass balance holds (default false: run the full length).
    #[serde(default)]
    pub stop_when_steady: bool,
}

fn h_min() -> f64 {
    0.001
}
fn h_max() -> f64 {
    0.05
}
fn fraction() -> f64 {
    0.2
}

/// `[suspension]`: the paste (Ness et al. 2017, Sect. "Contact model" and Table 1), SI.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SuspensionSection {
    /// The two diameters, 1:1 by number (Ness: d and 1.5 d), m.
    pub diameters: [f64; 2],
    /// Grain density = liquid density (density-matched), kg/m³.
    pub density: f64,
    /// Liquid viscosity η_f (Pa s).
    pub viscosity: f64,
    /// Normal stiffness k_n (N/m); k_t = (2/7) k_n.
    pub k_n: f64,
    /// Particle-particle friction μ_p.
    pub mu_p: f64,
    /// Particle-wall friction μ_w.
    pub mu_w: f64,
    /// h_min / d_ij (Ness Eq. 5: 0.001).
    #[serde(default = "h_min")]
    pub h_min: f64,
    /// h_max / d_ij (Ness: 0.05).
    #[serde(default = "h_max")]
    pub h_max: f64,
    /// Fraction of each stability bound accepted (default 0.2).
    #[serde(default = "fraction")]
    pub stability_fraction: f64,
    /// Time step (s); default: the largest the law accepts.
    #[serde(default)]
    pub dt: Option<f64>,
    /// Verlet skin (m); default 0.1 × the smaller diameter.
    #[serde(default)]
    pub skin: Option<f64>,
}

/// Ness's law: lubrication (Eqs. 3-5) plus the linear spring with friction (Eq. 6).
pub type NessLaw = Lubricated<LinearSpring>;

impl SuspensionSection {
    pub fn law(&self) -> NessLaw {
        let mut contact = LinearSpring::ness(self.k_n, self.mu_p, self.mu_w);
        contact.stability_fraction = self.stability_fraction;
        Lubricated {
            lubrication: Lubrication {
                viscosity: self.viscosity,
                h_min: self.h_min,
                h_max: self.h_max,
                stability_fraction: self.stability_fraction,
            },
            contact,
        }
    }

    /// The smallest step limit of the law over the two paste sizes.
    pub fn limit(&self) -> TimeStepLimit {
        let law = self.law();
        let lim = |d: f64| law.max_time_step(0.5 * d, self.density * PI / 6.0 * d * d * d);
        let [a, b] = self.diameters.map(lim);
        if a.dt <= b.dt { a } else { b }
    }

    /// The time step: `dt` if given and accepted, else the limit; refused above the limit.
    pub fn time_step(&self) -> Result<f64> {
        self.law()
            .check()
            .map_err(|e| anyhow::anyhow!("[suspension]: {e}"))?;
        let lim = self.limit();
        match self.dt {
            None => Ok(lim.dt),
            Some(dt) if dt > 0.0 && dt <= lim.dt => Ok(dt),
            Some(dt) if dt > 0.0 => bail!(
                "[suspension] dt = {dt:e} s is above the time-step limit {:e} s of the paste's law ({}); \
                 take dt at most {:e} s, or leave dt out to use the limit",
                lim.dt,
                lim.bound,
                lim.dt
            ),
            Some(dt) => bail!("[suspension] dt = {dt:e}: give a positive time step in s"),
        }
    }

    /// The skin: `skin` or 0.1 × the smaller diameter.
    pub fn skin(&self) -> f64 {
        self.skin
            .unwrap_or(0.1 * self.diameters[0].min(self.diameters[1]))
    }
}

impl ExtruderSection {
    /// The driver's parameters with the paste of `s`.
    pub fn spec(&self, s: &SuspensionSection) -> ExtruderSpec {
        let d_min = s.diameters[0].min(s.diameters[1]);
        let wall_diameter = self.wall_diameter.unwrap_or(0.5 * d_min);
        ExtruderSpec {
            geometry: Geometry {
                barrel_width: self.barrel_width,
                barrel_length: self.barrel_length,
                die_width: self.die_width,
                die_length: self.die_length,
                depth: self.depth,
                inlet_length: self.inlet_length,
                wall_diameter,
                wall_spacing: self.wall_spacing.unwrap_or(wall_diameter),
                wall_jitter: self.wall_jitter,
                wall_seed: self.wall_seed,
                outlet_gap: self.outlet_gap,
                monolayer: self.monolayer,
            },
            paste: Paste {
                diameters: s.diameters,
                density: s.density,
            },
            drive: Drive {
                body_force: self.body_force,
                phi_inlet: self.phi_inlet,
                insert_every: self.insert_every,
                insert_attempts: self.insert_attempts,
                seed: self.seed,
                prefill_phi: self.prefill_phi,
            },
            steady: SteadyRule {
                window: self.steady_window,
                tolerance: self.steady_tolerance,
                min_removed: self.steady_min_removed,
            },
        }
    }
}

/// Refuse an extruder scene that cannot run, before anything is built: the geometry, the drive,
/// the law and the time step, each error naming the key, its value and the fix.
pub fn check(e: &ExtruderSection, s: &SuspensionSection) -> Result<()> {
    e.spec(s)
        .check()
        .map_err(|err| anyhow::anyhow!("[extruder]: {err}"))?;
    s.time_step()?;
    if !(s.skin() >= 0.0 && s.skin().is_finite()) {
        bail!("[suspension] skin = {}: give a length ≥ 0 in m (0.1 d)", s.skin());
    }
    Ok(())
}
