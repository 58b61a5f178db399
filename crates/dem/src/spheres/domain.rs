//! The simulation box of the sphere engine: periodic or open per axis. Open axes bound the cell
//! grid (walls do the confining); a sphere found outside the box on an open axis is refused by
//! the cell list ([`super::SphereError::OutsideBox`]) rather than piled into a border cell.
//!
//! Lees-Edwards boundaries ([`LeesEdwards`]; Lees & Edwards 1972, J. Phys. C 5, 1921; Allen &
//! Tildesley, "Computer Simulation of Liquids", Sect. 11.3): simple shear with the velocity
//! along x varying with y at the rate γ̇. The periodic images across the y faces are displaced
//! along x by the strain offset s(t) = γ̇ L_y t (kept modulo L_x, advanced by γ̇ L_y dt each
//! step and stored in the state, so a resumed run continues bit for bit) and move at ±γ̇ L_y
//! along x: the image of sphere j one box up sits at x_j + s, y_j + L_y and moves at
//! v_j + γ̇ L_y x̂. A sphere leaving through the top face re-enters at the bottom shifted by −s
//! along x, its x-velocity lowered by γ̇ L_y (and the reverse at the bottom face), so the
//! velocities stay those of the lab frame (no SLLOD: see `docs/dem3d.md`).

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
    /// Lees-Edwards shear of the x-y faces (absent in older checkpoints: none).
    #[serde(default)]
    pub shear: Option<LeesEdwards>,
}

/// Lees-Edwards boundaries: simple shear, velocity along x, gradient along y (see the module
/// docs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LeesEdwards {
    /// Shear rate γ̇ (1/s): the image one box up moves at +γ̇ L_y along x.
    pub rate: f64,
    /// Strain offset s (m) of the image one box up along x, in [0, L_x).
    pub offset: f64,
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
        Ok(Self {
            lo,
            hi,
            periodic,
            shear: None,
        })
    }

    /// This box with Lees-Edwards boundaries shearing at `rate` (1/s), offset 0: x and y must
    /// be periodic.
    pub fn with_lees_edwards(mut self, rate: f64) -> Result<Self, SphereError> {
        self.shear = Some(LeesEdwards { rate, offset: 0.0 });
        self.check_shear()?;
        Ok(self)
    }

    /// Refuse a Lees-Edwards shear on a box not periodic in x and y, a non-finite rate or an
    /// offset outside [0, L_x).
    pub fn check_shear(&self) -> Result<(), SphereError> {
        let Some(le) = self.shear else {
            return Ok(());
        };
        if !(self.periodic[0] && self.periodic[1]) {
            // The open axis named (x first if both are).
            return Err(SphereError::BadParameter {
                name: if self.periodic[0] {
                    "periodic flag of the y axis (0 = open)"
                } else {
                    "periodic flag of the x axis (0 = open)"
                },
                value: 0.0,
                why: "Lees-Edwards boundaries need a box periodic in x (flow) and y (gradient); make both \
                      axes periodic",
            });
        }
        if !le.rate.is_finite() {
            return Err(SphereError::BadParameter {
                name: "Lees-Edwards shear rate",
                value: le.rate,
                why: "it must be finite (1/s)",
            });
        }
        if !(le.offset >= 0.0 && le.offset < self.size().x) {
            return Err(SphereError::BadParameter {
                name: "Lees-Edwards offset",
                value: le.offset,
                why: "it must lie in [0, L_x) (m)",
            });
        }
        Ok(())
    }

    /// The strain offset (m) of the image one box up (0 without Lees-Edwards).
    #[inline]
    pub fn shear_offset(&self) -> f64 {
        self.shear.map_or(0.0, |le| le.offset)
    }

    /// Advance the Lees-Edwards offset by γ̇ L_y dt, modulo L_x (nothing without shear).
    #[inline]
    pub fn advance(&mut self, dt: f64) {
        let l = self.size();
        if let Some(le) = &mut self.shear {
            let mut s = le.offset + le.rate * l.y * dt;
            if s >= l.x {
                s -= l.x;
            } else if s < 0.0 {
                s += l.x;
            }
            if !(s >= 0.0 && s < l.x) {
                // A step beyond one box length, or rounding onto L_x.
                s -= l.x * (s / l.x).floor();
                if !(s >= 0.0 && s < l.x) {
                    s = 0.0;
                }
            }
            le.offset = s;
        }
    }

    /// Minimum-image separation `d` = x_j − x_i and the velocity to add to v_j for the image
    /// used (Lees-Edwards: ∓γ̇ L_y x̂ when the image is one box down or up; zero otherwise).
    #[inline(always)]
    pub fn min_image_moving(&self, d: Vec3) -> (Vec3, Vec3) {
        let Some(le) = self.shear else {
            return (self.min_image(d), Vec3::ZERO);
        };
        let l = self.size();
        let mut d = d;
        let mut dv = Vec3::ZERO;
        if d.y.abs() > 0.5 * l.y {
            // Image of j one box down (d.y > 0) or up (d.y < 0).
            let k = if d.y > 0.0 { -1.0 } else { 1.0 };
            d.y += k * l.y;
            d.x += k * le.offset;
            dv.x = k * le.rate * l.y;
        }
        // After the offset |d.x| < 2 L_x: at most two shifts, each exact (Sterbenz), so this
        // is d.x − L_x round(d.x/L_x) without the division or libm's `round`.
        let half = 0.5 * l.x;
        if d.x >= half {
            d.x -= l.x;
            if d.x >= half {
                d.x -= l.x;
            }
        } else if d.x <= -half {
            d.x += l.x;
            if d.x <= -half {
                d.x += l.x;
            }
        }
        if self.periodic[2] && d.z.abs() > 0.5 * l.z {
            d.z -= l.z.copysign(d.z);
        }
        (d, dv)
    }

    /// Wrap a position and its velocity into the box: on a Lees-Edwards box a crossing of a y
    /// face shifts x by ∓ the offset and v_x by ∓ γ̇ L_y per box crossed; then [`Self::wrap`]
    /// (which then finds y inside the box and leaves it alone).
    #[inline]
    pub fn wrap_moving(&self, mut p: Vec3, mut v: Vec3) -> (Vec3, Vec3) {
        if let Some(le) = self.shear {
            let (lo, hi, ly) = (self.lo.y, self.hi.y, self.size().y);
            if !(p.y >= lo && p.y < hi) && p.y.is_finite() {
                let k = ((p.y - lo) / ly).floor();
                p.y -= k * ly;
                p.x -= k * le.offset;
                v.x -= k * le.rate * ly;
                // The shift may round onto an end: y just below lo plus L_y gives exactly hi.
                // Keep the k crossings applied to x and v and put y at the nearest point inside
                // (within rounding of the exact one); a plain wrap of hi to lo would undo the
                // crossing in y alone.
                if p.y >= hi {
                    p.y = hi.next_down();
                } else if p.y < lo {
                    p.y = lo;
                }
            }
        }
        (self.wrap(p), v)
    }

    #[inline]
    pub fn size(&self) -> Vec3 {
        self.hi - self.lo
    }

    /// Minimum-image separation vector on periodic axes. Candidate separations never exceed one
    /// box length (positions are wrapped), so one conditional shift per axis suffices. On a
    /// Lees-Edwards box the image across a y face is the sheared one
    /// ([`Self::min_image_moving`]).
    #[inline]
    pub fn min_image(&self, mut d: Vec3) -> Vec3 {
        if self.shear.is_some() {
            return self.min_image_moving(d).0;
        }
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
        // Lees-Edwards needs x and y periodic: the error names the open axis.
        let e = d.with_lees_edwards(1.0).unwrap_err().to_string();
        assert!(e.starts_with("periodic flag of the y axis (0 = open) = 0"), "{e}");
        // One ulp below lo: lo - ulp + L rounds to hi, and the old `hi -> lo` fallback shifted
        // it to lo - ulp again, outside the box (found by a random search).
        let (lo, hi) = (0.7355621288699867, 3.6571500849874647);
        let d = Domain3::new(Vec3::new(lo, lo, lo), Vec3::new(hi, hi, hi), [true; 3]).unwrap();
        for x in [0.7355621288699866, hi, 2.0 * lo - hi, -40.0] {
            let w = d.wrap(Vec3::new(x, x, x)).x;
            assert!((lo..hi).contains(&w), "{x} -> {w}");
        }
    }

    #[test]
    fn lees_edwards_image_and_wrap_agree() {
        let (lx, ly) = (2.0, 3.0);
        let mut d = Domain3::new(Vec3::ZERO, Vec3::new(lx, ly, 1.0), [true, true, true])
            .unwrap()
            .with_lees_edwards(0.5)
            .unwrap();
        // Offset after t = 1.7: γ̇ L_y t = 2.55, modulo L_x = 0.55.
        for _ in 0..17 {
            d.advance(0.1);
        }
        let s = d.shear_offset();
        assert!((s - 0.55).abs() < 1e-14, "{s}");
        // A sphere at the top leaving upwards re-enters at the bottom shifted by -s in x, its
        // v_x lowered by γ̇ L_y.
        let (p, v) = d.wrap_moving(Vec3::new(1.9, ly + 0.1, 0.5), Vec3::new(0.3, 0.2, 0.0));
        assert!(
            (p.x - (1.9 - s)).abs() < 1e-14 && (p.y - 0.1).abs() < 1e-14,
            "{p:?}"
        );
        assert!((v.x - (0.3 - 0.5 * ly)).abs() < 1e-14 && v.y == 0.2, "{v:?}");
        // Seen from a sphere just below the top, the wrapped one is its near neighbour again,
        // moving at its old velocity.
        let q = Vec3::new(1.85, ly - 0.05, 0.5);
        let (dd, dv) = d.min_image_moving(p - q);
        assert!(
            (dd.x - 0.05).abs() < 1e-14 && (dd.y - 0.15).abs() < 1e-14,
            "{dd:?}"
        );
        assert!((v.x + dv.x - 0.3).abs() < 1e-14, "{dv:?}");
        // And the reverse at the bottom face; several boxes away at once.
        let (p2, v2) = d.wrap_moving(Vec3::new(0.1, -2.0 * ly - 0.2, 0.5), Vec3::ZERO);
        assert!((p2.y - (ly - 0.2)).abs() < 1e-13, "{p2:?}");
        let want_x = (0.1 + 3.0 * s).rem_euclid(lx);
        assert!(
            (p2.x - want_x).abs() < 1e-13 && (v2.x - 1.5 * ly).abs() < 1e-14,
            "{p2:?} {v2:?}"
        );
        // Offsets outside [0, L_x) are refused.
        let mut e = d;
        e.shear.as_mut().unwrap().offset = lx;
        assert!(e.check_shear().is_err());
        // Just below the bottom face: lo - tiny + L_y rounds to exactly hi. The sphere crosses
        // once (x by +s, v_x by +γ̇ L_y) and lands at the top, not back at lo with the shift
        // (which put it s away from where it was, moving γ̇ L_y too fast).
        let (vx, rate) = (0.3, 0.5);
        for y in [-1e-300, -f64::MIN_POSITIVE, -1e-17] {
            let (p, v) = d.wrap_moving(Vec3::new(1.0, y, 0.5), Vec3::new(vx, 0.0, 0.0));
            assert!(p.y >= 0.0 && p.y < ly && p.y > ly - 1e-15, "{y}: {p:?}");
            assert!(
                (p.x - (1.0 + s)).abs() < 1e-15 && v.x == vx + rate * ly,
                "{y}: {p:?} {v:?}"
            );
            // Its neighbour just above the bottom face sees it where it was, at its velocity.
            let q = Vec3::new(1.0, 1e-9, 0.5);
            let (dd, dv) = d.min_image_moving(p - q);
            assert!(
                dd.x.abs() < 1e-14 && (dd.y + 1e-9).abs() < 1e-14 && (v.x + dv.x - vx).abs() < 1e-15,
                "{y}: {dd:?} {dv:?}"
            );
        }
        // The same with lo away from 0.
        let (lo, hi) = (0.7355621288699867, 3.6571500849874647);
        let d = Domain3::new(Vec3::new(lo, lo, lo), Vec3::new(hi, hi, hi), [true; 3])
            .unwrap()
            .with_lees_edwards(rate)
            .unwrap();
        let (p, v) = d.wrap_moving(Vec3::new(1.0, lo.next_down(), 1.0), Vec3::ZERO);
        assert!(p.y >= lo && p.y < hi && p.y > hi - 1e-15, "{p:?}");
        assert!(p.x == 1.0 && v.x == rate * (hi - lo), "{p:?} {v:?}");
    }
}
