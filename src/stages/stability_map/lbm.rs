//! The LBM map: the decaying Taylor-Green vortex (`lbdem_lbm::cases::taylor_green`) over a grid
//! of τ and lattice Mach number Ma = u0/c_s, for each collision. Every point is run, refused or
//! not (a τ ≤ ½ forced past the engine's check), and classed by its ν error; the set-up check's
//! verdict is recorded beside it.

use super::{Class, Verdict};
use anyhow::{Result, anyhow};
use lbdem_core::units::lattice::CS2;
use lbdem_lbm::Collision;
use lbdem_lbm::cases::taylor_green::{self, Spec};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The collision operators a scene can choose.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Operator {
    #[serde(rename = "bgk")]
    Bgk,
    /// TRT with Λ = 1/4 (the stable choice).
    #[serde(rename = "trt-1/4")]
    TrtQuarter,
    /// TRT with Λ = 3/16 (walls exactly halfway).
    #[serde(rename = "trt-3/16")]
    TrtThreeSixteenths,
}

impl Operator {
    pub fn collision(self, tau: f64) -> Collision {
        match self {
            Operator::Bgk => Collision::Bgk { tau },
            Operator::TrtQuarter => Collision::Trt { tau, magic: 0.25 },
            Operator::TrtThreeSixteenths => Collision::Trt {
                tau,
                magic: 3.0 / 16.0,
            },
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Operator::Bgk => "bgk",
            Operator::TrtQuarter => "trt-1/4",
            Operator::TrtThreeSixteenths => "trt-3/16",
        }
    }
}

/// One run of the map.
#[derive(Clone, Debug, Serialize)]
pub struct Point {
    pub operator: Operator,
    pub tau: f64,
    pub mach: f64,
    pub verdict: Verdict,
    pub class: Class,
    /// Relative ν error; NaN when the run blew up.
    pub nu_error: f64,
    /// Steps run (to the stop when it blew up).
    pub steps: u64,
}

/// Run every (operator, τ, Ma) on the current rayon pool; points come back in grid order
/// (operator, then τ, then Ma) whatever the thread count.
pub fn map(ops: &[Operator], taus: &[f64], machs: &[f64], size: usize, accuracy: f64) -> Result<Vec<Point>> {
    let grid: Vec<(Operator, f64, f64)> = ops
        .iter()
        .flat_map(|&o| {
            taus.iter()
                .flat_map(move |&t| machs.iter().map(move |&m| (o, t, m)))
        })
        .collect();
    grid.par_iter()
        .map(|&(operator, tau, mach)| {
            let collision = operator.collision(tau);
            let u0 = mach * CS2.sqrt();
            let verdict = Verdict::from(taylor_green::setup_verdict(collision, u0));
            let spec = Spec {
                size,
                force_past_refusal: true,
                ..Spec::new(collision, u0)
            };
            let r = taylor_green::run(&spec).map_err(|e| {
                anyhow!(
                    "stability-map: {} at tau = {tau}, Ma = {mach}: {e}",
                    operator.name()
                )
            })?;
            let class = match r.nu_error {
                None => Class::BlownUp,
                Some(e) if e < accuracy => Class::Accurate,
                Some(_) => Class::Inaccurate,
            };
            Ok(Point {
                operator,
                tau,
                mach,
                verdict,
                class,
                nu_error: r.nu_error.unwrap_or(f64::NAN),
                steps: r.steps,
            })
        })
        .collect()
}
