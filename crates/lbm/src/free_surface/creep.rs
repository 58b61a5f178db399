//! The Bingham clamp at low shear rate, measured while a run goes (issue 20 item 6).
//!
//! Where the Bingham law asks for an infinite viscosity (unyielded paste, stress under σ_y) the
//! kernel clamps τ at τ_max (Leonardi et al. 2014 Sect. 5.3, Fig. 4): the "rigid" paste is a
//! liquid of viscosity ν_max = (τ_max − ½)/3 instead, and it creeps. That is an accuracy
//! failure, not a blow-up: a heap that should stand slumps, slowly and smoothly, and nothing in
//! the state looks wrong.
//!
//! What does not tell it: a snapshot of the clamped nodes' speed (the free surface's spurious
//! currents are as fast: docs/free_surface.md), nor the clamped nodes' shear rate summed over
//! time (a column that stands at τ_max = 3.5 sums 1.1 in 3000 steps, one that slumps at 0.6 sums
//! 7.3: both grow with the run's length, tried 2026-12-01). What does: the paste's *shape* keeps
//! changing while it is nominally at rest. So every `every` steps the monitor compares the fill
//! field φ (1 in the liquid, m/ρ at the interface, 0 in the gas) with the one `every` steps
//! before, φ_0: the share of the paste's volume that moved in the window is Σ |φ − φ_0| / (2 Σ φ)
//! (what left one node arrived at another; oscillations within the window cancel, a steady
//! circulation at a standing surface moves no volume, and the acoustic breathing of the liquid's
//! density does not count: the mass field counted it, 31 % in the standing column). The windows in
//! which at least [`AT_REST`] of the wet nodes sat at τ_max (Leonardi's own stopping rule: 95 %
//! of the liquid at the maximum viscosity) add their share to `moved`: the paste displaced while
//! the rheology held it rigid. Above [`CREEP_LIMIT`], [`ClampCreep::warning`] names it with the
//! fix (raise τ_max; docs/stability.md's Bingham map gives how far).

use serde::{Deserialize, Serialize};

/// The share of the paste displaced while at rest above which the creep is named.
pub const CREEP_LIMIT: f64 = 0.02;

/// The share of wet nodes at τ_max from which the paste counts as at rest (Leonardi et al. 2014
/// Sect. 6 stop the incline there).
pub const AT_REST: f64 = 0.95;

/// The creep of the paste held at τ_max, accumulated over the run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClampCreep {
    /// Steps per window.
    pub every: u64,
    /// The fill field at the start of the window (empty before the first).
    pub fill0: Vec<f64>,
    /// Σ over the windows at rest of the share of the paste that moved.
    pub moved: f64,
    /// Windows closed, and how many of them at rest.
    pub windows: u64,
    pub at_rest: u64,
    /// The share of wet nodes at τ_max in the last window, and the largest share moved in one
    /// window at rest.
    pub clamped_share: f64,
    pub peak: f64,
}

impl ClampCreep {
    /// A monitor with windows of `every` steps (at least 1).
    pub fn new(every: u64) -> Self {
        Self {
            every: every.max(1),
            fill0: Vec::new(),
            moved: 0.0,
            windows: 0,
            at_rest: 0,
            clamped_share: 0.0,
            peak: 0.0,
        }
    }

    /// Close a window with the present fill `fill(x)`, τ per node `tau` (NaN where no Bingham
    /// collision ran; one entry per node) and `wet(x)` (a liquid or interface node); the first
    /// call only opens one. Sums run in node order: the same bits on any thread count.
    pub fn sample(
        &mut self,
        wet: impl Fn(usize) -> bool,
        fill: impl Fn(usize) -> f64,
        tau: &[f64],
        tau_max: f64,
    ) {
        let n = tau.len();
        if self.fill0.len() == n {
            let at_ceiling = tau_max * (1.0 - 1e-9);
            let (mut n_wet, mut clamped) = (0u64, 0u64);
            for (x, &t) in tau.iter().enumerate() {
                if wet(x) {
                    n_wet += 1;
                    clamped += u64::from(t >= at_ceiling);
                }
            }
            let (mut change, mut total) = (0.0, 0.0);
            for (x, &f0) in self.fill0.iter().enumerate() {
                let f = fill(x);
                change += (f - f0).abs();
                total += f;
            }
            let share = if n_wet > 0 {
                clamped as f64 / n_wet as f64
            } else {
                0.0
            };
            self.windows += 1;
            self.clamped_share = share;
            if share >= AT_REST && total > 0.0 {
                let moved = change / (2.0 * total);
                self.moved += moved;
                self.at_rest += 1;
                self.peak = self.peak.max(moved);
            }
        }
        self.fill0.clear();
        self.fill0.extend((0..n).map(fill));
    }

    /// The failure named, when the paste at rest has moved beyond [`CREEP_LIMIT`].
    pub fn warning(&self, tau_max: f64) -> Option<String> {
        (self.moved > CREEP_LIMIT).then(|| {
            format!(
                "the Bingham clamp at low shear rate: with at least {:.0} % of the paste at tau_max = \
                 {tau_max} (unyielded, nominally at rest) for {} windows of {} steps, {:.1} % of it moved \
                 (largest window {:.2} %), above {:.0} %: at the clamp the paste is a liquid of viscosity \
                 (tau_max - 0.5)/3 and creeps where the Bingham law keeps it rigid; raise tau_max \
                 (docs/stability.md, \"Bingham tau clamps\": every plug up to 0.6 h is within 1 % from \
                 tau_max = 35)",
                100.0 * AT_REST,
                self.at_rest,
                self.every,
                100.0 * self.moved,
                100.0 * self.peak,
                100.0 * CREEP_LIMIT
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_windows_with_the_paste_at_the_ceiling_count_and_what_moved_counts_once() {
        let mut c = ClampCreep::new(10);
        let wet = |x: usize| x < 3;
        // opens the window: nothing counted
        let at = |v: [f64; 4]| move |x: usize| v[x];
        c.sample(wet, at([1.0, 1.0, 0.5, 0.0]), &[3.5, 3.5, 3.5, f64::NAN], 3.5);
        assert_eq!((c.windows, c.moved), (0, 0.0));
        // 0.1 of fill went from node 1 to node 2: 0.1 of 2.5 moved, all wet nodes at the ceiling
        c.sample(wet, at([1.0, 0.9, 0.6, 0.0]), &[3.5, 3.5, 3.5, f64::NAN], 3.5);
        assert!((c.moved - 0.04).abs() < 1e-15, "{}", c.moved);
        assert_eq!((c.windows, c.at_rest), (1, 1));
        let w = c.warning(3.5).expect("4 % is above the limit");
        assert!(w.contains("tau_max = 3.5") && w.contains("4.0 %"), "{w}");
        // a window with a node yielded (2 of 3 at the ceiling) moves mass but does not count
        c.sample(wet, at([1.0, 0.5, 1.0, 0.0]), &[3.5, 0.7, 3.5, f64::NAN], 3.5);
        assert!((c.moved - 0.04).abs() < 1e-15);
        assert_eq!((c.windows, c.at_rest), (2, 1));
        assert!((c.clamped_share - 2.0 / 3.0).abs() < 1e-15);
    }

    #[test]
    fn paste_at_rest_that_does_not_move_is_not_named() {
        let mut c = ClampCreep::new(10);
        for _ in 0..5 {
            c.sample(|_| true, |x| [1.0, 0.5][x], &[3.5, 3.5], 3.5);
        }
        assert_eq!((c.windows, c.at_rest, c.moved), (4, 4, 0.0));
        assert!(c.warning(3.5).is_none());
    }
}
