//! The steady state from the mass balance (Ness et al. 2017: "It is verified that a steady
//! state has been reached by checking that the mass balance is satisfied such that the total
//! number of particles present inside the extruder is approximately constant with time. As the
//! particle number is not fixed, the outlet flow minus the inlet flow fluctuates with time
//! around zero"). Over a trailing window of `window` seconds the insertion and removal rates
//! are r_in = ΔN_in/Δt and r_out = ΔN_out/Δt; the flow is steady when at least `min_removed`
//! grains left in the window and |r_in − r_out| ≤ `tolerance` · max(r_in, r_out). The counts
//! are whole grains, so the relative noise over a window is about 1/√(grains removed in it):
//! `min_removed` should be at least 1/tolerance² (100 for 0.1).

use super::error::ExtruderError;
use serde::{Deserialize, Serialize};

/// When the run counts as steady.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteadyRule {
    /// Trailing window (s).
    pub window: f64,
    /// Largest |r_in − r_out| / max(r_in, r_out).
    pub tolerance: f64,
    /// Fewest grains removed in the window for a verdict.
    pub min_removed: u64,
}

impl SteadyRule {
    pub fn check(&self) -> Result<(), ExtruderError> {
        if !(self.window > 0.0 && self.window.is_finite()) {
            return Err(ExtruderError::Parameter {
                name: "steady_window",
                value: self.window,
                why: "it must be a positive time (s)".into(),
                fix: "give the time a grain takes through the die, or longer".into(),
            });
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(ExtruderError::Parameter {
                name: "steady_tolerance",
                value: self.tolerance,
                why: "it is a relative rate difference in (0, 1)".into(),
                fix: "give 0.1".into(),
            });
        }
        Ok(())
    }
}

/// Samples of the cumulative counts over the trailing window, and the verdict.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Balance {
    /// (time, inserted, removed) every window/50, oldest first; the first at or before the
    /// window's start.
    pub samples: Vec<(f64, u64, u64)>,
    /// The counts now.
    pub latest: Option<(f64, u64, u64)>,
    /// Since when the rule has held without a break (s), if it holds now.
    pub steady_since: Option<f64>,
    /// The first time it held (s).
    pub first_steady: Option<f64>,
}

/// Rates and imbalance over the window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rates {
    pub r_in: f64,
    pub r_out: f64,
    pub removed: u64,
    /// |r_in − r_out| / max(r_in, r_out).
    pub imbalance: f64,
}

impl Balance {
    /// Record the counts at time `t` and update the verdict.
    pub fn record(&mut self, rule: &SteadyRule, t: f64, inserted: u64, removed: u64) {
        let now = (t, inserted, removed);
        self.latest = Some(now);
        if self.samples.last().is_none_or(|s| t - s.0 >= rule.window / 50.0) {
            self.samples.push(now);
        }
        // Keep one sample at or before the window's start.
        let start = t - rule.window;
        let cut = self.samples.iter().rposition(|s| s.0 <= start).unwrap_or(0);
        self.samples.drain(..cut);
        match self.rates(rule) {
            Some(r) if r.removed >= rule.min_removed && r.imbalance <= rule.tolerance => {
                self.steady_since.get_or_insert(t);
                self.first_steady.get_or_insert(t);
            }
            _ => self.steady_since = None,
        }
    }

    /// The rates over the window, once the samples span it.
    pub fn rates(&self, rule: &SteadyRule) -> Option<Rates> {
        let (a, b) = (self.samples.first()?, self.latest?);
        let dt = b.0 - a.0;
        if dt < rule.window * (1.0 - 1e-9) || dt <= 0.0 {
            return None;
        }
        let (r_in, r_out) = ((b.1 - a.1) as f64 / dt, (b.2 - a.2) as f64 / dt);
        let top = r_in.max(r_out);
        Some(Rates {
            r_in,
            r_out,
            removed: b.2 - a.2,
            imbalance: if top > 0.0 {
                (r_in - r_out).abs() / top
            } else {
                0.0
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steady_when_the_rates_agree_over_a_full_window() {
        let rule = SteadyRule {
            window: 1.0,
            tolerance: 0.1,
            min_removed: 50,
        };
        let mut b = Balance::default();
        // Filling: 100 in per second, nothing out, for 2 s; then 100 in and 95 out per second.
        for k in 0..=400u64 {
            let t = k as f64 * 0.01;
            let out = if t > 2.0 { ((t - 2.0) * 95.0) as u64 } else { 0 };
            b.record(&rule, t, (t * 100.0) as u64, out);
            // |r_in - r_out| <= 0.1 r_in needs (t - 2) 95 >= 90 grains out over the window:
            // t >= 2.947 s.
            if t < 2.93 {
                assert!(b.steady_since.is_none(), "steady at {t} while filling");
            }
        }
        let r = b.rates(&rule).unwrap();
        assert!(
            (r.r_in - 100.0).abs() < 2.0 && (r.r_out - 95.0).abs() < 2.0,
            "{r:?}"
        );
        assert!(
            b.first_steady.is_some_and(|t| (2.93..=3.01).contains(&t)),
            "{:?}",
            b.first_steady
        );
        assert!(b.samples.len() <= 52, "{} samples kept", b.samples.len());
    }
}
