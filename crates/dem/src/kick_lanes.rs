//! The lane code of the all-disk kick (`crate::kick_disks`), written once against a lane type
//! `super::lanes` and compiled for each (`crate::on_avx512`, `crate::on_arrays`).

use super::lanes::{F8, deinterleave, interleave, transpose};
use crate::kick_disks::{DiskKick, Eight, pairs, pairs_mut};
use crate::scratch::CircleState;
use crate::vector::Vec2;

/// The box constants in lanes.
struct Consts {
    dt: F8,
    lo: [F8; 2],
    hi: [F8; 2],
    len: [F8; 2],
    half: [F8; 2],
}

impl Consts {
    #[inline(always)]
    fn of(k: &DiskKick) -> Self {
        Self {
            dt: F8::splat(k.dt),
            lo: [F8::splat(k.lo[0]), F8::splat(k.lo[1])],
            hi: [F8::splat(k.hi[0]), F8::splat(k.hi[1])],
            len: [F8::splat(k.len[0]), F8::splat(k.len[1])],
            half: [F8::splat(k.half[0]), F8::splat(k.half[1])],
        }
    }
}

// Functions, not closures: a closure would be compiled without the features of the
// `#[target_feature]` entry, and the AVX-512 intrinsics would stay calls.

/// One conditional shift per periodic axis (Domain::wrap).
#[inline(always)]
fn wrap(p: F8, periodic: bool, c: &Consts, k: usize) -> F8 {
    if periodic {
        let below = p.lt(c.lo[k]);
        let above = p.ge(c.hi[k]);
        below.select(p + c.len[k], above.select(p - c.len[k], p))
    } else {
        p
    }
}

/// A lane still outside the box after one shift (it must take the far wrap).
#[inline(always)]
fn far(p: F8, periodic: bool, c: &Consts, k: usize) -> bool {
    periodic && p.outside(c.lo[k], c.hi[k]).any()
}

/// Domain::min_image along axis k.
#[inline(always)]
fn min_image(d: F8, c: &Consts, k: usize) -> F8 {
    let shift = d.abs().gt(c.half[k]);
    shift.select(d - c.len[k].copysign(d), d)
}

/// Kick, drift and lines of eight disks; the largest squared displacement since the list
/// build (NaN if any is NaN), or None (nothing written) if a disk must take the far wrap.
#[inline(always)]
pub(crate) fn eight(kd: &DiskKick, e: Eight<'_>) -> Option<f64> {
    let c = Consts::of(kd);
    let (fx, fy) = deinterleave(pairs(e.f));
    let (mut vx, mut vy) = deinterleave(pairs(e.v));
    let (x0, y0) = deinterleave(pairs(e.x));
    let (hm, hi) = (F8::from_array(e.hm), F8::from_array(e.hi));
    // v += F (h/m); ω += T (h/I)
    vx = vx + fx * hm;
    vy = vy + fy * hm;
    let w = F8::from_array(*e.w) + F8::from_array(*e.t) * hi;
    // x = wrap(x + v dt): one conditional shift per periodic axis (Domain::wrap)
    let x = wrap(x0 + vx * c.dt, kd.periodic[0], &c, 0);
    let y = wrap(y0 + vy * c.dt, kd.periodic[1], &c, 1);
    if far(x, kd.periodic[0], &c, 0) || far(y, kd.periodic[1], &c, 1) {
        return None;
    }
    let a = F8::from_array(*e.a) + w * c.dt;
    // Displacement since the list build (Domain::min_image, norm2).
    let (rx, ry) = deinterleave(pairs(e.refp));
    let (dx, dy) = (min_image(x - rx, &c, 0), min_image(y - ry, &c, 1));
    let d2 = (dx * dx + dy * dy).to_array();
    interleave(vx, vy, pairs_mut(e.v));
    interleave(x, y, pairs_mut(e.x));
    *e.w = w.to_array();
    *e.a = a.to_array();
    let rows = transpose([
        x,
        y,
        vx,
        vy,
        w,
        F8::from_array(*e.r),
        F8::from_array(*e.m),
        F8::splat(0.0),
    ]);
    for (s, row) in e.st.iter_mut().zip(rows) {
        *s = CircleState {
            pos: Vec2::new(row[0], row[1]),
            vel: Vec2::new(row[2], row[3]),
            omega: row[4],
            r: row[5],
            mass: row[6],
            pad: 0.0,
        };
    }
    Some(d2.into_iter().fold(0.0, crate::scratch::nan_max))
}
