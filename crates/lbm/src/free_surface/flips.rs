//! Cells converting back and forth at the free surface, counted while a run goes (issue 20
//! item 6).
//!
//! The conversion rules fill an interface node at m > (1 + κ)ρ and empty it at m < −κρ
//! (`convert`). With no margin (κ = 0) a surface lying on a node boundary sits exactly at the
//! threshold, and round-off and the liquid's acoustic breathing fill and empty its nodes step after
//! step: a flat layer at rest that should never convert a node flips a fifth of its interface
//! nodes every step, and a steep wave at low τ goes on to fail at the Mach limit
//! (`a_layer_flip_flopping_at_its_surface_is_named`). Körner et al.'s κ = 1e-3 stops it.
//!
//! A *flip* is a conversion that undoes the node's own previous one within [`WITHIN`] steps
//! (interface → liquid → interface, interface → gas → interface, gas → interface → gas, liquid →
//! interface → liquid). The counter records every node's last conversion and counts flips per
//! interface node and step, over the run and over the last closed window of [`WINDOW`] steps;
//! above [`FLIP_LIMIT`] the surface is named as flip-flopping, at the end of a run and in the
//! failure diagnosis of a run that stops.

use serde::{Deserialize, Serialize};

/// A conversion undone within this many steps is a flip.
pub const WITHIN: u64 = 3;
/// Steps per window of the recent rate the failure diagnosis reads.
pub const WINDOW: u64 = 100;
/// Flips per interface node and step above which the surface is named as flip-flopping: about
/// twice the healthy coarse dam break's 4.3e-3 (the front within 10 % of Martin & Moyce; a
/// violent surface flips some nodes legitimately). Measured (2026-12-01, D2Q9 layers 64 nodes wide; a scratch study of 3000 steps whose counter
/// saw only each step's net change, so these are lower bounds): κ = 0 gives 0.12 on a flat layer
/// at rest (0.21 by this counter, 1000 steps) and 9e-3 to 1.7e-2 on waves; κ = 1e-3 gives 0 at
/// rest, 6e-5 and 2.7e-3 on gentle and moderate waves, 1.3e-2 on a steep wave at τ 0.505 (the same
/// wave with κ = 0 fails at the Mach limit).
pub const FLIP_LIMIT: f64 = 1e-2;

/// The kinds of node a conversion goes between (the `cells` constants fit in a nibble).
fn code(from: u8, to: u8) -> u8 {
    (from << 4) | (to & 0x0f)
}

/// The flip counter of a free-surface run. The failure diagnosis reads the larger of the run's
/// rate and the last window's: the steep wave of the test flips at 1.8e-2 over its run and 3.2e-3
/// in the window before it fails.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FlipFlops {
    /// Per node: the step of its last conversion (0: none yet) and its kinds, `code(from, to)`.
    last_step: Vec<u64>,
    last_code: Vec<u8>,
    /// Over the run: conversions, flips, and Σ over steps of the interface nodes.
    pub conversions: u64,
    pub flips: u64,
    pub node_steps: u64,
    /// The window being filled and the last closed one: (flips, interface node-steps).
    window: (u64, u64),
    pub last_window: (u64, u64),
}

impl FlipFlops {
    /// A counter for `nodes` nodes.
    pub fn new(nodes: usize) -> Self {
        Self {
            last_step: vec![0; nodes],
            last_code: vec![0; nodes],
            ..Self::default()
        }
    }

    /// Record that node `x` went from kind `from` to kind `to` at step `step` (≥ 1).
    pub fn record(&mut self, step: u64, x: usize, from: u8, to: u8) {
        let Some(t) = self.last_step.get_mut(x) else {
            return;
        };
        self.conversions += 1;
        if *t > 0 && step - *t <= WITHIN && self.last_code[x] == code(to, from) {
            self.flips += 1;
            self.window.0 += 1;
        }
        *t = step;
        self.last_code[x] = code(from, to);
    }

    /// Close step `step` with `interface` interface nodes.
    pub fn end_step(&mut self, step: u64, interface: usize) {
        self.node_steps += interface as u64;
        self.window.1 += interface as u64;
        if step.is_multiple_of(WINDOW) {
            self.last_window = std::mem::take(&mut self.window);
        }
    }

    /// Flips per interface node and step over the run.
    pub fn rate(&self) -> f64 {
        ratio(self.flips, self.node_steps)
    }

    /// Flips per interface node and step over the last closed window (the run's rate before the
    /// first window closes).
    pub fn recent_rate(&self) -> f64 {
        if self.last_window.1 == 0 {
            self.rate()
        } else {
            ratio(self.last_window.0, self.last_window.1)
        }
    }

    /// The surface named as flip-flopping, when `rate` is above [`FLIP_LIMIT`]; `kappa` and
    /// `lonely` are the run's conversion margin and lonely-node threshold (the fix names them).
    pub fn describe(rate: f64, kappa: f64, lonely: f64) -> Option<String> {
        (rate > FLIP_LIMIT).then(|| {
            let fix = if kappa < 1e-3 {
                "raise kappa to 1e-3 (Koerner et al. 2005), which stops it on a surface at rest".to_string()
            } else if lonely > 0.0 {
                format!(
                    "the lonely-node rule (theta = {lonely}) fills and empties the nodes of a film one or \
                     two nodes thick at wide thresholds, so the surface is under-resolved there: refine \
                     the lattice"
                )
            } else {
                "the surface moves faster than its nodes settle (a steep or breaking wave at low tau): \
                 raise tau or refine the lattice"
                    .to_string()
            };
            format!(
                "cells converting back and forth at the free surface: {rate:.2e} flips per interface \
                 node and step (a conversion undone within {WITHIN} steps; limit {FLIP_LIMIT:e}) with \
                 the conversion margin kappa = {kappa:e}: {fix}"
            )
        })
    }
}

fn ratio(a: u64, b: u64) -> f64 {
    if b == 0 { 0.0 } else { a as f64 / b as f64 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::free_surface::{GAS, INTERFACE, LIQUID};

    #[test]
    fn a_conversion_undone_within_three_steps_is_a_flip_and_a_later_one_is_not() {
        let mut f = FlipFlops::new(4);
        f.record(1, 0, INTERFACE, LIQUID);
        f.record(3, 0, LIQUID, INTERFACE); // undone 2 steps later: a flip
        f.record(10, 1, INTERFACE, GAS);
        f.record(14, 1, GAS, INTERFACE); // 4 steps later: not
        f.record(20, 2, GAS, INTERFACE);
        f.record(21, 2, INTERFACE, LIQUID); // onwards, not back: not
        assert_eq!((f.conversions, f.flips), (6, 1));
        for step in 1..=100 {
            f.end_step(step, 10);
        }
        assert_eq!(f.node_steps, 1000);
        assert!((f.rate() - 1e-3).abs() < 1e-15);
        assert_eq!(f.last_window, (1, 1000));
        assert!(FlipFlops::describe(f.rate(), 0.0, 0.0).is_none());
        assert!(
            FlipFlops::describe(FLIP_LIMIT, 0.0, 0.0).is_none(),
            "at the limit, not above it"
        );
        let w = FlipFlops::describe(0.12, 0.0, 0.0).expect("above the limit");
        assert!(w.contains("raise kappa"), "{w}");
        let w = FlipFlops::describe(0.02, 1e-3, 0.0).expect("above the limit");
        assert!(w.contains("raise tau"), "{w}");
        let w = FlipFlops::describe(0.02, 1e-3, 1.0).expect("above the limit");
        assert!(w.contains("lonely-node rule (theta = 1)"), "{w}");
    }
}
