//! Stage `interior-liquid-map` (issue 16, item 2: "PSM at near-neutral buoyancy"): where a PSM
//! grain stops settling right as its density approaches the liquid's, with and without the
//! interior-liquid correction (`Coupled::with_interior_liquid_correction`, Uhlmann 2005 Eq. 15),
//! found by running it there. The settling disk of `lbdem_coupling::cases::settling` (Faxén's
//! drag between two walls, Re ≈ 0.06) is run over a grid of grain/liquid density ratios ρ_S/ρ_L
//! and τ; (ρ_S − ρ_L) g is held at the case's value, so every point has the same terminal velocity
//! and only the grain's inertia changes (a grain lighter than the liquid rises at the same speed).
//! Each run is classed by its terminal velocity against Faxén: accurate (error below `accuracy`),
//! inaccurate, or blown up (stopped by the engine's limits). What the run-time checks of a coupled
//! scene say of the same grain ([`verdict`]) is recorded beside each point.

use super::{Class, Grid, Verdict, map_output, operator_maps};
use crate::contract::{Stage, StageContext, StageOutput};
use crate::report::table::RowTable;
use anyhow::{Result, anyhow, bail};
use lbdem_core::units::coupled::{PSM_DENSITY_RATIO_MIN, PSM_DENSITY_RATIO_WARN};
use lbdem_coupling::cases::settling::{self, SettlingSpec};
use lbdem_coupling::{CouplingError, INTERIOR_LIQUID_MIN_RATIO};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// Grain/liquid density ratios ρ_S/ρ_L (≠ 1: a neutral grain does not move).
    #[serde(default = "ratios")]
    pub ratios: Vec<f64>,
    /// Relaxation times (> ½).
    #[serde(default = "taus")]
    pub taus: Vec<f64>,
    /// Lattice cells per diameter.
    #[serde(default = "cells")]
    pub cells_per_diameter: usize,
    /// Terminal-velocity error against Faxén below which a run is accurate. The case's own error,
    /// whatever the density: 0.29 % at τ = 0.6, 5.1 % at τ = 1 (PSM's τ-dependent drag).
    #[serde(default = "accuracy")]
    pub accuracy: f64,
    /// Simulated time in viscous times W²/ν (the validation's 0.6).
    #[serde(default = "duration")]
    pub duration: f64,
    /// rayon threads, 0 = all (the map does not depend on it).
    #[serde(default)]
    pub threads: usize,
}

fn ratios() -> Vec<f64> {
    vec![
        0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.93, 0.99, 1.01, 1.1, 1.2, 1.5, 2.0,
    ]
}
fn taus() -> Vec<f64> {
    vec![0.6, 0.8, 1.0]
}
fn cells() -> usize {
    10
}
fn accuracy() -> f64 {
    0.06
}
fn duration() -> f64 {
    0.6
}

/// With or without the interior-liquid correction: one map each.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Correction {
    Off,
    On,
}

impl Correction {
    fn name(self) -> &'static str {
        match self {
            Correction::Off => "off",
            Correction::On => "on",
        }
    }
}

impl super::MapKey for Correction {
    fn name(self) -> String {
        Correction::name(self).into()
    }
}

/// What the run-time checks of a coupled PSM scene say of a wet grain of density ratio `ratio`,
/// with or without the correction: the light-grain check (refused under
/// `PSM_DENSITY_RATIO_MIN`, warned under `PSM_DENSITY_RATIO_WARN`), then the correction's own
/// refusal under `INTERIOR_LIQUID_MIN_RATIO`.
pub fn verdict(ratio: f64, correction: Correction) -> Verdict {
    if ratio < PSM_DENSITY_RATIO_MIN || (correction == Correction::On && ratio < INTERIOR_LIQUID_MIN_RATIO) {
        Verdict::Refused
    } else if ratio < PSM_DENSITY_RATIO_WARN {
        Verdict::Warned
    } else {
        Verdict::Accepted
    }
}

/// One run of the map.
#[derive(Clone, Debug, Serialize)]
pub struct Point {
    pub correction: Correction,
    pub ratio: f64,
    pub tau: f64,
    pub verdict: Verdict,
    pub class: Class,
    /// (U − U_Faxén)/U_Faxén (signed: U is the rise speed of a light grain); NaN when blown up.
    pub error: f64,
    /// LBM steps run: to the end, or to the stop when blown up.
    pub steps: u64,
}

/// The settling case at density ratio `ratio`, (ρ_S − ρ_L) g held at the case's default.
fn spec(ratio: f64, tau: f64, correction: Correction, p: &Params) -> SettlingSpec {
    let d = SettlingSpec::default();
    let buoyant = (d.rho_p - d.rho_f) * d.g;
    SettlingSpec {
        rho_p: d.rho_f * ratio,
        g: buoyant / (d.rho_f * (ratio - 1.0).abs()),
        tau,
        cells_per_diameter: p.cells_per_diameter,
        duration: p.duration,
        interior_liquid_correction: correction == Correction::On,
        force_past_refusal: true,
        ..d
    }
}

/// Every (correction, τ, ratio) on the current rayon pool, in that order whatever the thread
/// count.
pub fn map(p: &Params) -> Result<Vec<Point>> {
    let grid: Vec<(Correction, f64, f64)> = [Correction::Off, Correction::On]
        .into_iter()
        .flat_map(|c| {
            p.taus
                .iter()
                .flat_map(move |&t| p.ratios.iter().map(move |&r| (c, t, r)))
        })
        .collect();
    grid.par_iter()
        .map(|&(correction, tau, ratio)| {
            let (class, error, steps) = match settling::run::<f64>(&spec(ratio, tau, correction, p)) {
                Ok(r) if r.velocity.is_finite() => {
                    let class = if r.error.abs() < p.accuracy {
                        Class::Accurate
                    } else {
                        Class::Inaccurate
                    };
                    (class, r.error, r.lbm_steps)
                }
                Ok(r) => (Class::BlownUp, f64::NAN, r.lbm_steps),
                Err(CouplingError::Lbm(lbdem_lbm::LbmError::Unstable { step, .. })) => {
                    (Class::BlownUp, f64::NAN, step)
                }
                Err(e) => {
                    return Err(anyhow!(
                        "interior-liquid-map: correction {} at rho_S/rho_L = {ratio}, tau = {tau}: {e}",
                        correction.name()
                    ));
                }
            };
            Ok(Point {
                correction,
                ratio,
                tau,
                verdict: verdict(ratio, correction),
                class,
                error,
                steps,
            })
        })
        .collect()
}

fn check(p: &Params) -> Result<()> {
    if p.ratios.is_empty() || p.taus.is_empty() {
        bail!("interior-liquid-map: ratios and taus must each list at least one value");
    }
    if let Some(r) = p
        .ratios
        .iter()
        .find(|r| !(r.is_finite() && **r > 0.0 && (**r - 1.0).abs() > 1e-6))
    {
        bail!(
            "interior-liquid-map: ratios contains {r}; give grain/liquid density ratios > 0 other than 1 \
             (a neutral grain does not move), e.g. 0.9 or 1.1"
        );
    }
    if let Some(t) = p.taus.iter().find(|t| !(t.is_finite() && **t > 0.5)) {
        bail!("interior-liquid-map: taus contains {t}; give finite relaxation times > 0.5, e.g. 0.6");
    }
    if p.cells_per_diameter < 4 {
        bail!(
            "interior-liquid-map: cells_per_diameter = {} cannot resolve the disk; use 10",
            p.cells_per_diameter
        );
    }
    if !(p.accuracy > 0.0 && p.accuracy < 1.0) {
        bail!(
            "interior-liquid-map: accuracy = {} must be a relative velocity error in (0, 1), e.g. 0.06",
            p.accuracy
        );
    }
    if !(p.duration > 0.0 && p.duration.is_finite()) {
        bail!(
            "interior-liquid-map: duration = {} must be a positive number of viscous times, e.g. 0.6",
            p.duration
        );
    }
    Ok(())
}

pub struct InteriorLiquidMap;

impl Stage for InteriorLiquidMap {
    const KIND: &'static str = "interior-liquid-map";
    const ABOUT: &'static str = "Where a PSM grain near the liquid's density fails: settling disk over rho_S/rho_L and tau, \
         with and without the interior-liquid correction, against the run-time check";
    type Params = Params;

    fn inputs(_: &Params, _: &StageContext) -> Vec<PathBuf> {
        Vec::new()
    }

    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        check(p)?;
        let pool = rayon::ThreadPoolBuilder::new().num_threads(p.threads).build()?;
        let points = pool.install(|| map(p))?;
        let csv = "interior_liquid_map.csv";
        write_points(&ctx.out_dir.join(csv), &points)?;
        let grid = Grid {
            xs: &p.ratios,
            ys: &p.taus,
            x_label: "grain / liquid density ratio rho_S / rho_L",
            y_label: "relaxation time tau",
        };
        let (figures, files) = operator_maps(
            &ctx.out_dir,
            "interior_liquid_map",
            &[Correction::Off, Correction::On],
            &points,
            |q| (q.correction, q.ratio, q.tau, q.class, q.verdict),
            &grid,
            |c| format!("Settling disk, PSM, interior-liquid correction {}", c.name()),
            |c| {
                format!(
                    "PSM disk ({} cells per diameter) settling between two walls (Faxen drag, Re 0.06), the \
                     interior-liquid correction {}, at each density ratio and tau with (rho_S - rho_L) g \
                     held, run whatever the run-time check says. Colour: accurate (terminal velocity within \
                     {} % of Faxen), inaccurate, blown up (stopped by the engine). Mark: none if the scene \
                     checks accept, a ring if they warn (rho_S/rho_L under {PSM_DENSITY_RATIO_WARN}), a cross \
                     if they refuse (under {PSM_DENSITY_RATIO_MIN}; with the correction, under {}).",
                    p.cells_per_diameter,
                    c.name(),
                    p.accuracy * 100.0,
                    INTERIOR_LIQUID_MIN_RATIO
                )
            },
        )?;
        Ok(map_output(
            csv,
            "Every run of the interior-liquid map: correction, density ratio, tau, run-time \
                          verdict, class, terminal-velocity error, steps",
            &points,
            |q| (q.verdict, q.class),
            figures,
            files,
        ))
    }
}

fn write_points(path: &std::path::Path, points: &[Point]) -> Result<()> {
    RowTable::new(points)
        .str("correction", |q| q.correction.name())
        .f64("ratio", |q| q.ratio)
        .f64("tau", |q| q.tau)
        .str("verdict", |q| q.verdict.name())
        .str("class", |q| q.class.name())
        .f64("error", |q| q.error)
        .u64("steps", |q| q.steps)
        .write(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 16 item 2 (PSM at near-neutral buoyancy): the map on a 20-point grid at 6 cells per
    /// diameter (the default map is at 10; docs/stability.md has both and 4). Every figure in
    /// the comments is from `lbdem interior-liquid-map` with these parameters (2026-11-30).
    #[test]
    fn the_interior_liquid_map_finds_where_light_grains_blow_up() {
        let p = Params {
            ratios: vec![0.3, 0.5, 0.7, 0.9, 1.1],
            taus: vec![0.6, 1.0],
            cells_per_diameter: 6,
            accuracy: accuracy(),
            duration: duration(),
            threads: 0,
        };
        let pts = map(&p).unwrap();
        assert_eq!(pts.len(), 20);
        let at = |c: Correction, tau: f64, ratio: f64| {
            pts.iter()
                .find(|q| q.correction == c && q.tau == tau && q.ratio == ratio)
                .unwrap()
        };
        for q in &pts {
            let what = format!("{q:?}");
            // The scene checks accept ρ_S/ρ_L ≥ 0.85 without the correction: none blew up
            // (0.9 and 1.1 ran at both τ; their error is the resolution's, 2.0 % at τ 0.6 and
            // 13.4 % at τ 1, the same at both ratios to 0.1 %).
            if q.verdict == Verdict::Accepted {
                assert_ne!(q.class, Class::BlownUp, "{what}");
            }
            // Without the correction every grain at 0.7 or lighter blew up (LBM steps 10-2807),
            // the refused 0.3 and the warned 0.5 and 0.7 alike: the refusal at 0.5 was found on
            // the confined shear cell, where 0.56 ran; in open liquid the edge is higher, hence
            // the warning up to 0.85.
            if q.correction == Correction::Off {
                assert_eq!(q.class == Class::BlownUp, q.ratio <= 0.7, "{what}");
            }
        }
        // The correction moves the edge down, and its refusal below 1.2 is conservative: with it
        // 0.7 ran at both τ (accurately at τ 0.6, 2.0 %), 0.5 and lighter blew up (steps 56-843).
        for tau in [0.6, 1.0] {
            assert_ne!(at(Correction::On, tau, 0.7).class, Class::BlownUp);
            assert_eq!(at(Correction::On, tau, 0.7).verdict, Verdict::Refused);
            assert_eq!(at(Correction::On, tau, 0.5).class, Class::BlownUp);
        }
        assert_eq!(at(Correction::On, 0.6, 0.7).class, Class::Accurate);
        // Light grains rise at the same speed as heavy ones sink: the buoyant weight is held.
        let (light, heavy) = (at(Correction::Off, 0.6, 0.9), at(Correction::Off, 0.6, 1.1));
        // Measured: 2.5e-5 apart (1.979 % and 1.977 %).
        assert!((light.error - heavy.error).abs() < 5e-5, "{light:?} {heavy:?}");
    }

    #[test]
    fn bad_params_are_refused_with_the_fix() {
        let p: Params = toml::from_str("ratios = [1.0]").unwrap();
        let e = check(&p).unwrap_err().to_string();
        assert!(e.contains("ratios") && e.contains("0.9"), "{e}");
        let p: Params = toml::from_str("taus = [0.5]").unwrap();
        assert!(check(&p).unwrap_err().to_string().contains("taus"));
        let p: Params = toml::from_str("cells_per_diameter = 2").unwrap();
        assert!(check(&p).unwrap_err().to_string().contains("cells_per_diameter"));
        assert!(toml::from_str::<Params>("ratio = [0.9]").is_err());
    }
}
