//! Pairwise lubrication of Ness et al. (2017), Eqs. 3-5, the leading resistances of two nearly
//! touching spheres in a Newtonian liquid of viscosity η (Kim & Karrila 1991, "Microhydrodynamics",
//! Ch. 9; Jeffrey & Onishi 1984), and [`Lubricated`], it added to a contact law.
//!
//! For spheres of radii a_i, a_j (diameters d = 2a), β = a_j/a_i, surface gap h = |r_ij| − a_i −
//! a_j, d_ij = d_i d_j/(d_i + d_j):
//! - h_eff = max(h, h_min), h_min = 0.001 d_ij (Eq. 5: the divergence cut at an asperity scale,
//!   so spheres can touch; in contact h < 0 and h_eff = h_min);
//! - nothing beyond h_max = 0.05 d_ij (the law's [`SphereLaw::range`]);
//! - with L = ln(a_i/h_eff) (Ness's ln(d_i/2h_eff)), the resistances of Eq. 4:
//!   a_sq = β²/(1+β)² a_i²/h_eff + (1+7β+β²)/(5(1+β)³) a_i L + (1+18β−29β²+18β³+β⁴)/(21(1+β)⁴) h_eff L,
//!   a_sh = 4β(2+β+2β²)/(15(1+β)³) a_i L + 4(16−45β+58β²−45β³+16β⁴)/(375(1+β)⁴) h_eff L,
//!   a_pu = β(4+β)/(10(1+β)²) L + (32−33β+83β²+43β³)/(250(1+β)³) (h_eff/a_i) L.
//!   The printed Eq. 4 has d_i²/(4h_eff) and d_i/(2h_eff) in the third terms of a_sq, a_sh and
//!   a_pu, which is dimensionally inconsistent with the other terms; the forms above (h_eff and
//!   h_eff/a_i) are those of Kim & Karrila's expansions and of LAMMPS `pair lubricate/poly`,
//!   which Ness's simulations ran;
//! - force on i (Eq. 3a), v_i − v_j of the centres: F = −6πη [a_sq (Δv·n) n + a_sh (I − nn) Δv];
//! - couple on i (Eq. 3b, first term): −a_pu π η d_i³ (I − nn)(ω_i − ω_j); the second term,
//!   −(d_i/2)(n_ij × F), is the moment of F, which the stepper takes at the middle of the gap
//!   (arm a_i + h/2 instead of d_i/2: the pair then conserves angular momentum; they differ by at
//!   most h_max/2 = 0.025 d_ij).
//!
//! Ness's expressions are written from sphere i's side. a_sh and the 1/h and h L terms of a_sq
//! are symmetric in i ↔ j, but the a_i L term of a_sq is not for β ≠ 1 (Kim & Karrila's has a
//! factor β there); so that the pair force is one vector (momentum kept) whatever the
//! numbering, the force is the mean of the two sides' expressions — Ness's exactly for equal
//! spheres. The couples are each sphere's own (a_pu(β) d_i³ on i, a_pu(1/β) d_j³ on j).
//! Plane walls feel no lubrication (Ness's walls are frozen spheres).
//!
//! Stable step: for relative motion of two identical spheres (m* = m/2) the squeeze damping
//! c = 6πη a_sq(h_min) makes velocity Verlet's half-step velocities decay by (1 − c dt/m*) per
//! step, stable for dt < 2 m*/c; the pump couple c_pu = π η d³ a_pu(h_min) on each sphere damps
//! ω_i − ω_j by (1 − 2 c_pu dt/I), stable for dt < I/c_pu. The law accepts
//! `stability_fraction` (default 0.2) of the smaller.

use super::linear::STABILITY_FRACTION;
use super::{Interaction, Response, SphereLaw, TimeStepLimit, check_fraction};
use crate::spheres::error::SphereError;
use crate::vector::Vector;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

fn default_fraction() -> f64 {
    STABILITY_FRACTION
}

/// Ness et al.'s pairwise lubrication (Eqs. 3-5).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lubrication {
    /// Viscosity η of the liquid (Pa s).
    pub viscosity: f64,
    /// h_min / d_ij (Ness: 0.001).
    pub h_min: f64,
    /// h_max / d_ij (Ness: 0.05).
    pub h_max: f64,
    /// The time step accepted: at most this fraction of the viscous stability limit (default 0.2).
    #[serde(default = "default_fraction")]
    pub stability_fraction: f64,
}

/// The three resistances of Eq. 4 seen from a sphere of radius `a` with a neighbour of ratio
/// `beta` = a_j/a at effective gap `h`: (a_sq, a_sh in m; a_pu dimensionless).
#[inline]
pub fn resistances(a: f64, beta: f64, h: f64) -> (f64, f64, f64) {
    let b = beta;
    let (b2, b3, b4) = (b * b, b * b * b, b * b * b * b);
    let p = 1.0 + b;
    let (p2, p3, p4) = (p * p, p * p * p, p * p * p * p);
    let l = (a / h).ln();
    let a_sq = b2 / p2 * a * a / h
        + (1.0 + 7.0 * b + b2) / (5.0 * p3) * a * l
        + (1.0 + 18.0 * b - 29.0 * b2 + 18.0 * b3 + b4) / (21.0 * p4) * h * l;
    let a_sh = 4.0 * b * (2.0 + b + 2.0 * b2) / (15.0 * p3) * a * l
        + 4.0 * (16.0 - 45.0 * b + 58.0 * b2 - 45.0 * b3 + 16.0 * b4) / (375.0 * p4) * h * l;
    let a_pu = b * (4.0 + b) / (10.0 * p2) * l
        + (32.0 - 33.0 * b + 83.0 * b2 + 43.0 * b3) / (250.0 * p3) * (h / a) * l;
    (a_sq, a_sh, a_pu)
}

impl Lubrication {
    /// Ness et al.'s cut-offs: h_min = 0.001 d_ij, h_max = 0.05 d_ij.
    pub fn ness(viscosity: f64) -> Self {
        Self {
            viscosity,
            h_min: 0.001,
            h_max: 0.05,
            stability_fraction: STABILITY_FRACTION,
        }
    }

    /// d_ij = d_i d_j/(d_i + d_j) of spheres of radii `r_i`, `r_j` (m).
    #[inline]
    fn d_ij(r_i: f64, r_j: f64) -> f64 {
        2.0 * r_i * r_j / (r_i + r_j)
    }

    /// The force on i and the couples on i and j at surface gap `h` (m).
    #[inline]
    fn response(&self, c: &Interaction, h: f64) -> Response {
        let (ri, rj) = (c.r_i, c.r_j);
        let h_eff = h.max(self.h_min * Self::d_ij(ri, rj));
        let (sq_i, sh_i, pu_i) = resistances(ri, rj / ri, h_eff);
        let (sq_j, sh_j, pu_j) = resistances(rj, ri / rj, h_eff);
        let (a_sq, a_sh) = (0.5 * (sq_i + sq_j), 0.5 * (sh_i + sh_j));
        let eta = self.viscosity;
        let vn = c.dv.dot(c.n);
        let dv_t = c.dv - c.n * vn;
        let f = -(c.n * (a_sq * vn) + dv_t * a_sh) * (6.0 * PI * eta);
        let dw_t = c.dw - c.n * c.dw.dot(c.n);
        let (di, dj) = (2.0 * ri, 2.0 * rj);
        Response {
            f,
            torque_i: -dw_t * (pu_i * PI * eta * di * di * di),
            torque_j: dw_t * (pu_j * PI * eta * dj * dj * dj),
            f_hydro: f,
        }
    }

    /// (squeeze, pump) damping coefficients (kg/s, kg m²/s) of two identical spheres of radius
    /// `r` at h_min, the largest the law presents.
    fn max_damping(&self, r: f64) -> (f64, f64) {
        let (a_sq, _, a_pu) = resistances(r, 1.0, self.h_min * r);
        let d = 2.0 * r;
        (
            6.0 * PI * self.viscosity * a_sq,
            PI * self.viscosity * d * d * d * a_pu,
        )
    }
}

impl SphereLaw for Lubrication {
    type History = ();

    #[inline]
    fn force(&self, c: &Interaction, _: &mut ()) -> Response {
        let h = -c.delta;
        if c.wall || h >= self.h_max * Self::d_ij(c.r_i, c.r_j) {
            return Response::default();
        }
        self.response(c, h)
    }

    #[inline]
    fn range(&self, r_i: f64, r_j: f64) -> f64 {
        self.h_max * Self::d_ij(r_i, r_j)
    }

    fn check(&self) -> Result<(), SphereError> {
        if !(self.viscosity > 0.0 && self.viscosity.is_finite()) {
            return Err(SphereError::BadParameter {
                name: "lubrication viscosity (Pa s)",
                value: self.viscosity,
                why: "it must be positive and finite",
            });
        }
        if !(self.h_min > 0.0 && self.h_min < self.h_max && self.h_max < 1.0) {
            return Err(SphereError::BadParameter {
                name: "lubrication h_min / d_ij",
                value: self.h_min,
                why: "0 < h_min < h_max < 1 (in units of d_ij; Ness: 0.001 and 0.05)",
            });
        }
        check_fraction("stability_fraction", self.stability_fraction)
    }

    fn max_time_step(&self, r: f64, m: f64) -> TimeStepLimit {
        let (c_sq, c_pu) = self.max_damping(r);
        let squeeze = 2.0 * (0.5 * m) / c_sq;
        let pump = 0.4 * m * r * r / c_pu;
        TimeStepLimit {
            dt: self.stability_fraction * squeeze.min(pump),
            bound: "stability_fraction (default 0.2) of the viscous limit of the lubrication at h_min: \
                    2 m*/(6 pi eta a_sq) for squeeze, I/(pi eta d^3 a_pu) for pump",
        }
    }
}

/// A contact law with Ness's lubrication added (Ness et al. 2017: Eqs. 3-5 plus Eq. 6 with
/// [`super::LinearSpring`]): forces and couples summed, the range the larger of the two, the
/// history the contact law's, the time step the smaller of the two limits.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lubricated<C> {
    pub lubrication: Lubrication,
    pub contact: C,
}

impl<C: SphereLaw> SphereLaw for Lubricated<C> {
    type History = C::History;

    #[inline]
    fn force(&self, c: &Interaction, h: &mut C::History) -> Response {
        let a = self.lubrication.force(c, &mut ());
        let b = self.contact.force(c, h);
        Response {
            f: a.f + b.f,
            torque_i: a.torque_i + b.torque_i,
            torque_j: a.torque_j + b.torque_j,
            f_hydro: a.f_hydro + b.f_hydro,
        }
    }

    #[inline]
    fn range(&self, r_i: f64, r_j: f64) -> f64 {
        self.lubrication.range(r_i, r_j).max(self.contact.range(r_i, r_j))
    }

    #[inline]
    fn wall_range(&self, r: f64) -> f64 {
        self.contact.wall_range(r)
    }

    fn check(&self) -> Result<(), SphereError> {
        self.lubrication.check()?;
        self.contact.check()
    }

    fn max_time_step(&self, r: f64, m: f64) -> TimeStepLimit {
        self.lubrication
            .max_time_step(r, m)
            .min(self.contact.max_time_step(r, m))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_spheres_reduce_to_the_known_coefficients() {
        // β = 1: a_sq = a²/(4h) + (9/40) a L + (3/112) h L and a_sh = (1/6) a L, the equal-sphere
        // squeeze and shear expansions (Kim & Karrila 1991, Ch. 9); a_pu = L/8 + (1/16)(h/a) L,
        // Eq. 4c at β = 1.
        let (a, h) = (2.0f64, 0.01);
        let l = (a / h).ln();
        let (sq, sh, pu) = resistances(a, 1.0, h);
        let want = (
            a * a / (4.0 * h) + 9.0 / 40.0 * a * l + 3.0 / 112.0 * h * l,
            a * l / 6.0,
            l / 8.0 + h / a * l / 16.0,
        );
        for (g, w) in [(sq, want.0), (sh, want.1), (pu, want.2)] {
            assert!((g / w - 1.0).abs() < 1e-15, "{g} vs {w}");
        }
    }
}
