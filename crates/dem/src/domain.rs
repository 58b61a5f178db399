//! The simulation box: periodic or open per axis. Open axes only bound the cell grid (walls do
//! the confining); bodies outside it are clamped into the border cells, which keeps the list exact.

use crate::body::Bodies;
use crate::vector::Vec2;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Domain {
    pub lo: Vec2,
    pub hi: Vec2,
    pub periodic: [bool; 2],
}

impl Domain {
    pub fn open(lo: Vec2, hi: Vec2) -> Self {
        Self {
            lo,
            hi,
            periodic: [false, false],
        }
    }
    pub fn periodic(lo: Vec2, hi: Vec2) -> Self {
        Self {
            lo,
            hi,
            periodic: [true, true],
        }
    }
    #[inline]
    pub fn size(&self) -> Vec2 {
        self.hi - self.lo
    }
    /// Minimum-image separation vector on periodic axes.
    #[inline]
    pub fn min_image(&self, mut d: Vec2) -> Vec2 {
        // Separations of candidate pairs never exceed one box length, so one conditional
        // shift suffices (cheaper than a division and rounding per pair).
        let l = self.size();
        if self.periodic[0] && d.x.abs() > 0.5 * l.x {
            d.x -= l.x.copysign(d.x);
        }
        if self.periodic[1] && d.y.abs() > 0.5 * l.y {
            d.y -= l.y.copysign(d.y);
        }
        d
    }
    /// Wrap a position into the box on periodic axes.
    #[inline]
    pub fn wrap(&self, mut p: Vec2) -> Vec2 {
        // A body moves far less than a box length per step: one conditional shift (no
        // division) is the common case; anything still outside takes the general path.
        let l = self.size();
        if self.periodic[0] {
            if p.x < self.lo.x {
                p.x += l.x;
            } else if p.x >= self.hi.x {
                p.x -= l.x;
            }
        }
        if self.periodic[1] {
            if p.y < self.lo.y {
                p.y += l.y;
            } else if p.y >= self.hi.y {
                p.y -= l.y;
            }
        }
        let out = |v: f64, lo: f64, hi: f64| !(v >= lo && v < hi);
        if (self.periodic[0] && out(p.x, self.lo.x, self.hi.x))
            || (self.periodic[1] && out(p.y, self.lo.y, self.hi.y))
        {
            return self.wrap_far(p);
        }
        p
    }

    /// Wrap an arbitrary position (any number of box lengths away).
    #[cold]
    fn wrap_far(&self, mut p: Vec2) -> Vec2 {
        let l = self.size();
        if self.periodic[0] {
            p.x -= l.x * ((p.x - self.lo.x) / l.x).floor();
        }
        if self.periodic[1] {
            p.y -= l.y * ((p.y - self.lo.y) / l.y).floor();
        }
        p
    }
    /// Change the box to `[lo, hi]`, mapping body positions affinely (LAMMPS `fix deform ... remap x`).
    pub fn remap_affine(&mut self, lo: Vec2, hi: Vec2, bodies: &mut Bodies) {
        let (ol, os) = (self.lo, self.size());
        let ns = hi - lo;
        let (sx, sy) = (ns.x / os.x, ns.y / os.y);
        bodies.pos.par_iter_mut().with_min_len(4096).for_each(|p| {
            p.x = lo.x + (p.x - ol.x) * sx;
            p.y = lo.y + (p.y - ol.y) * sy;
        });
        self.lo = lo;
        self.hi = hi;
    }
}
