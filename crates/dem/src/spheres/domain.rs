//! The simulation box of the sphere engine: periodic or open per axis. Open axes bound the cell
//! grid (walls do the confining); a sphere found outside the box on an open axis is refused by
//! the cell list ([`super::SphereError::OutsideBox`]) rather than piled into a border cell.

use super::error::SphereError;
use crate::vector::{Vec3, Vector};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Domain3 {
    pub lo: Vec3,
    pub hi: Vec3,
    /// Periodic axes (x, y, z).
    pub periodic: [bool; 3],
}

impl Domain3 {
    /// The box `[lo, hi)` with the given periodic axes; refuses an empty or non-finite box.
    pub fn new(lo: Vec3, hi: Vec3, periodic: [bool; 3]) -> Result<Self, SphereError> {
        const NAMES: [&str; 3] = ["box length along x", "box length along y", "box length along z"];
        let l = hi - lo;
        for (k, name) in NAMES.iter().enumerate() {
            let v = l.component(k);
            if !(v > 0.0 && v.is_finite()) {
                return Err(SphereError::BadParameter {
                    name,
                    value: v,
                    why: "the box must have hi > lo on every axis, both finite",
                });
            }
        }
        Ok(Self { lo, hi, periodic })
    }

    #[inline]
    pub fn size(&self) -> Vec3 {
        self.hi - self.lo
    }

    /// Minimum-image separation vector on periodic axes. Candidate separations never exceed one
    /// box length (positions are wrapped), so one conditional shift per axis suffices.
    #[inline]
    pub fn min_image(&self, mut d: Vec3) -> Vec3 {
        let l = self.size();
        for k in 0..3 {
            if self.periodic[k] {
                let (lk, dk) = (l.component(k), d.component_mut(k));
                if dk.abs() > 0.5 * lk {
                    *dk -= lk.copysign(*dk);
                }
            }
        }
        d
    }

    /// Wrap a position into `[lo, hi)` on periodic axes.
    #[inline]
    pub fn wrap(&self, mut p: Vec3) -> Vec3 {
        let l = self.size();
        for k in 0..3 {
            if self.periodic[k] {
                let (lo, hi, lk) = (self.lo.component(k), self.hi.component(k), l.component(k));
                let x = p.component_mut(k);
                if *x < lo {
                    *x += lk;
                } else if *x >= hi {
                    *x -= lk;
                }
                if !(*x >= lo && *x < hi) && x.is_finite() {
                    // More than one box length away (not reached by a stable run), or a shift
                    // that rounded past an end.
                    *x -= lk * ((*x - lo) / lk).floor();
                    if !(*x >= lo && *x < hi) {
                        // Within rounding of lo or hi, the same point of the periodic axis.
                        *x = lo;
                    }
                }
            }
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn min_image_and_wrap_on_periodic_axes_only() {
        let d = Domain3::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 4.0), [true, false, true]).unwrap();
        let m = d.min_image(Vec3::new(0.9, 1.9, -3.5));
        assert!(
            (m.x + 0.1).abs() < 1e-15 && m.y == 1.9 && (m.z - 0.5).abs() < 1e-15,
            "{m:?}"
        );
        let w = d.wrap(Vec3::new(-0.25, 2.5, 4.5));
        assert_eq!(w, Vec3::new(0.75, 2.5, 0.5));
        let far = d.wrap(Vec3::new(3.5, 0.0, -9.0));
        assert!(
            (far.x - 0.5).abs() < 1e-12 && (far.z - 3.0).abs() < 1e-12,
            "{far:?}"
        );
        assert!(Domain3::new(Vec3::ZERO, Vec3::new(1.0, 0.0, 1.0), [false; 3]).is_err());
        // One ulp below lo: lo - ulp + L rounds to hi, and the old `hi -> lo` fallback shifted
        // it to lo - ulp again, outside the box (found by a random search).
        let (lo, hi) = (0.7355621288699867, 3.6571500849874647);
        let d = Domain3::new(Vec3::new(lo, lo, lo), Vec3::new(hi, hi, hi), [true; 3]).unwrap();
        for x in [0.7355621288699866, hi, 2.0 * lo - hi, -40.0] {
            let w = d.wrap(Vec3::new(x, x, x)).x;
            assert!((lo..hi).contains(&w), "{x} -> {w}");
        }
    }
}
