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
        let two = |v: [f64; 2]| [F8::splat(v[0]), F8::splat(v[1])];
        Self {
            dt: F8::splat(k.dt),
            lo: two(k.lo),
            hi: two(k.hi),
            len: two(k.len),
            half: two(k.half),
        }
    }
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
    let wrap = |p: F8, k: usize| {
        if kd.periodic[k] {
            let below = p.lt(c.lo[k]);
            let above = p.ge(c.hi[k]);
            below.select(p + c.len[k], above.select(p - c.len[k], p))
        } else {
            p
        }
    };
    let x = wrap(x0 + vx * c.dt, 0);
    let y = wrap(y0 + vy * c.dt, 1);
    let far = |p: F8, k: usize| kd.periodic[k] && p.outside(c.lo[k], c.hi[k]).any();
    if far(x, 0) || far(y, 1) {
        return None;
    }
    let a = F8::from_array(*e.a) + w * c.dt;
    // Displacement since the list build (Domain::min_image, norm2).
    let (rx, ry) = deinterleave(pairs(e.refp));
    let min_image = |d: F8, k: usize| {
        let shift = d.abs().gt(c.half[k]);
        shift.select(d - c.len[k].copysign(d), d)
    };
    let (dx, dy) = (min_image(x - rx, 0), min_image(y - ry, 1));
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
