//! Packed scratch records shared by the stepper's passes and the batched kernels
//! (`pair_batched.rs`, `kick_disks.rs`): they import these from here, never from the stepper.

use crate::vector::Vec2;

/// What the pair loop reads of a circle, packed in one cache line.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
pub(crate) struct CircleState {
    pub pos: Vec2,
    /// Velocity of the circle centre.
    pub vel: Vec2,
    pub omega: f64,
    pub r: f64,
    pub mass: f64,
    /// Fills the line (the pair kernel loads whole lines).
    pub pad: f64,
}

impl CircleState {
    /// The line as eight numbers: x, y, vx, vy, ω, r, m, 0 (portable pair kernel).
    #[inline(always)]
    pub(crate) fn line(&self) -> [f64; 8] {
        [
            self.pos.x, self.pos.y, self.vel.x, self.vel.y, self.omega, self.r, self.mass, self.pad,
        ]
    }
}

/// Result of pair (i, j): force on i (j receives −f), torques on i and j; zero when the pair
/// does not interact. One 32-byte record: the reaction gather reads one cache line per pair.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
pub(crate) struct PairOut {
    pub fx: f64,
    pub fy: f64,
    pub ti: f64,
    pub tj: f64,
}

/// Per body: h/m and h/I of the half kicks, kept while h, m and I stay the same (divisions are
/// the dearest part of the per-body passes).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Kick {
    pub h: f64,
    pub m: f64,
    pub i: f64,
    pub hm: f64,
    pub hi: f64,
}

impl Kick {
    #[inline(always)]
    pub(crate) fn refresh(&mut self, h: f64, m: f64, i: f64) {
        if self.h != h || self.m != m || self.i != i {
            *self = Kick {
                h,
                m,
                i,
                hm: h / m,
                hi: h / i,
            };
        }
    }
}

/// Maximum that propagates NaN (a non-finite position must stop the run).
#[inline]
pub(crate) fn nan_max(p: f64, q: f64) -> f64 {
    if p.is_nan() || q.is_nan() {
        f64::NAN
    } else {
        p.max(q)
    }
}
