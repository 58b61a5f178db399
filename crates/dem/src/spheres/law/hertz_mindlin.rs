//! Hertz-Mindlin contact of spheres with the Mindlin tangential spring, Coulomb friction and
//! restitution damping, in the form of LIGGGHTS `pair gran model hertz tangential history`
//! (after Tsuji et al. 1992, Powder Technol. 71:239; Di Renzo & Di Maio 2004, Chem. Eng. Sci.
//! 59:525) — one kernel for sphere-sphere and sphere-plane contacts. (Not the 2D engine's
//! `lbdem_dem::HertzMindlin`, Leonardi et al. 2014 Eqs. 5-6, which has no tangential spring.)
//!
//! For a contact of overlap δ > 0, effective radius R*, effective mass m*:
//! - effective moduli 1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂ and 1/G* = 2(2−ν₁)(1+ν₁)/E₁ +
//!   2(2−ν₂)(1+ν₂)/E₂ (= (2−ν₁)/G₁ + (2−ν₂)/G₂); a rigid plane adds nothing;
//! - normal: F_n = (4/3) E* √R* δ^{3/2} + c_n δ̇ (Hertz 1882), tangent stiffness
//!   S_n = 2 E* √(R* δ);
//! - tangential: the Mindlin no-slip stiffness k_t = S_t = 8 G* √(R* δ) on the tangential
//!   displacement ξ accumulated while in contact, F_t = −k_t ξ − c_t v_t (total form; see
//!   [`super::tangential_spring`]);
//! - damping from the restitution coefficient e: β = ln e / √(ln² e + π²),
//!   c_n = −2 √(5/6) β √(S_n m*), c_t = −2 √(5/6) β √(S_t m*) (β = −1 at e = 0);
//! - Coulomb: |F_t| ≤ μ max(F_n, 0) (as the 2D engine: no friction from the damped attractive
//!   tail); when sliding, the spring is reset to hold exactly the sliding force;
//! - ξ is zeroed when the contact opens.
//!
//! With no damping and full stick the tangential-to-normal stiffness ratio is
//! k_t/S_n = 4G*/E*, which for like materials (or a rigid plane) is 2(1−ν)/(2−ν) (Mindlin 1949).
//! The normal force is not clipped at zero (LIGGGHTS' default): with damping it may pull
//! slightly as the contact opens.

use super::{Interaction, Response, SphereLaw, TimeStepLimit, check_fraction, tangential_spring};
use crate::spheres::error::SphereError;
use crate::vector::{Vec3, Vector};
use serde::{Deserialize, Serialize};

/// Elastic constants of a material.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Elastic {
    /// Young's modulus E (Pa).
    pub young: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
}

impl Elastic {
    /// (1 − ν²)/E: this material's share of 1/E*.
    fn normal_compliance(&self) -> f64 {
        (1.0 - self.poisson * self.poisson) / self.young
    }
    /// 2(2 − ν)(1 + ν)/E = (2 − ν)/G: this material's share of 1/G*.
    fn shear_compliance(&self) -> f64 {
        2.0 * (2.0 - self.poisson) * (1.0 + self.poisson) / self.young
    }
    fn check(&self, young: &'static str, poisson: &'static str) -> Result<(), SphereError> {
        if !(self.young > 0.0 && self.young.is_finite()) {
            return Err(SphereError::BadParameter {
                name: young,
                value: self.young,
                why: "Young's modulus must be positive and finite (Pa)",
            });
        }
        if !(self.poisson > -1.0 && self.poisson < 0.5) {
            return Err(SphereError::BadParameter {
                name: poisson,
                value: self.poisson,
                why: "it must lie in (-1, 0.5)",
            });
        }
        Ok(())
    }
}

/// Friction and restitution of a pair of surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Surface {
    /// Coulomb friction coefficient μ.
    pub mu: f64,
    /// Normal restitution coefficient e in [0, 1] (1: elastic, no damping).
    pub restitution: f64,
}

impl Surface {
    fn check(&self, what: &'static str) -> Result<(), SphereError> {
        if !(self.mu >= 0.0 && self.mu.is_finite()) {
            return Err(SphereError::BadParameter {
                name: what,
                value: self.mu,
                why: "a friction coefficient must be zero or positive and finite",
            });
        }
        if !(0.0..=1.0).contains(&self.restitution) {
            return Err(SphereError::BadParameter {
                name: "restitution coefficient e",
                value: self.restitution,
                why: "it must lie in [0, 1]",
            });
        }
        Ok(())
    }
}

/// The default fraction of the Rayleigh time step accepted, 0.2 (the customary Hertzian DEM
/// bound; the error it gives on Chung & Ooi Tests 3-4 is in `docs/dem3d.md`).
pub const RAYLEIGH_FRACTION: f64 = 0.2;

fn default_rayleigh_fraction() -> f64 {
    RAYLEIGH_FRACTION
}

/// The Hertz-Mindlin law with a tangential spring, for a sphere assembly: one sphere material,
/// one wall material (rigid if `None`), and the surface properties of sphere-sphere and
/// sphere-wall contacts.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HertzMindlinSpring {
    pub sphere: Elastic,
    /// Material of the plane walls; `None`: rigid (E → ∞).
    #[serde(default)]
    pub wall: Option<Elastic>,
    pub pair: Surface,
    pub wall_pair: Surface,
    /// The time step accepted: at most this fraction of the Rayleigh time step (default 0.2).
    #[serde(default = "default_rayleigh_fraction")]
    pub rayleigh_fraction: f64,
}

/// Effective constants of one kind of contact (sphere-sphere or sphere-wall).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coeffs {
    /// E* (Pa).
    pub e_star: f64,
    /// G* (Pa).
    pub g_star: f64,
    /// −2 √(5/6) β (≥ 0): c = this × √(S m*).
    pub damp: f64,
    pub mu: f64,
}

/// β = ln e / √(ln² e + π²) (Tsuji et al. 1992; −1 at e = 0, 0 at e = 1).
pub fn beta_of_restitution(e: f64) -> f64 {
    if e <= 0.0 {
        return -1.0;
    }
    let l = e.ln();
    l / (l * l + std::f64::consts::PI * std::f64::consts::PI).sqrt()
}

impl HertzMindlinSpring {
    /// Like spheres on a rigid wall, one surface for both kinds of contact.
    pub fn uniform(sphere: Elastic, surface: Surface) -> Self {
        Self {
            sphere,
            wall: None,
            pair: surface,
            wall_pair: surface,
            rayleigh_fraction: RAYLEIGH_FRACTION,
        }
    }

    fn coeffs(normal_compliance: f64, shear_compliance: f64, s: &Surface) -> Coeffs {
        Coeffs {
            e_star: 1.0 / normal_compliance,
            g_star: 1.0 / shear_compliance,
            damp: -2.0 * (5.0f64 / 6.0).sqrt() * beta_of_restitution(s.restitution),
            mu: s.mu,
        }
    }

    /// Effective constants of sphere-sphere contacts.
    pub fn pair_coeffs(&self) -> Coeffs {
        let m = &self.sphere;
        Self::coeffs(
            2.0 * m.normal_compliance(),
            2.0 * m.shear_compliance(),
            &self.pair,
        )
    }

    /// Effective constants of sphere-wall contacts.
    pub fn wall_coeffs(&self) -> Coeffs {
        let m = &self.sphere;
        let (wn, ws) = self
            .wall
            .map_or((0.0, 0.0), |w| (w.normal_compliance(), w.shear_compliance()));
        Self::coeffs(
            m.normal_compliance() + wn,
            m.shear_compliance() + ws,
            &self.wall_pair,
        )
    }

    /// Rayleigh time step of a sphere of radius `r` and mass `m` of this law's material:
    /// t_R = π r √(ρ/G) / (0.1631 ν + 0.8766), G = E / (2(1 + ν)) (Ning & Thornton; Li et al.
    /// 2005), the customary bound for Hertzian DEM steps.
    pub fn rayleigh_time_step(&self, r: f64, m: f64) -> f64 {
        let rho = m / (4.0 / 3.0 * std::f64::consts::PI * r * r * r);
        let nu = self.sphere.poisson;
        let g = self.sphere.young / (2.0 * (1.0 + nu));
        std::f64::consts::PI * r * (rho / g).sqrt() / (0.1631 * nu + 0.8766)
    }
}

impl SphereLaw for HertzMindlinSpring {
    /// The tangential spring ξ (m).
    type History = Vec3;

    #[inline(always)]
    fn force(&self, c: &Interaction, xi: &mut Vec3) -> Response {
        let k = if c.wall {
            self.wall_coeffs()
        } else {
            self.pair_coeffs()
        };
        Response {
            f: hertz_mindlin_force(&k, c, xi),
            ..Response::default()
        }
    }

    fn check(&self) -> Result<(), SphereError> {
        self.sphere
            .check("Young's modulus of the spheres", "Poisson's ratio of the spheres")?;
        if let Some(w) = &self.wall {
            w.check("Young's modulus of the walls", "Poisson's ratio of the walls")?;
        }
        self.pair.check("sphere-sphere friction coefficient mu")?;
        self.wall_pair.check("sphere-wall friction coefficient mu")?;
        check_fraction("rayleigh_fraction", self.rayleigh_fraction)
    }

    #[inline]
    fn hertz_mindlin_pairs(&self) -> Option<Coeffs> {
        Some(self.pair_coeffs())
    }

    fn max_time_step(&self, r: f64, m: f64) -> TimeStepLimit {
        TimeStepLimit {
            dt: self.rayleigh_fraction * self.rayleigh_time_step(r, m),
            bound: "rayleigh_fraction (default 0.2) of the Rayleigh time step t_R = pi r sqrt(rho/G) / (0.1631 nu + 0.8766)",
        }
    }
}

/// The contact force on body i (the reaction acts on j); 0 when not overlapping (the spring
/// zeroed). `xi` is the tangential spring of the contact, updated in place.
#[inline(always)]
pub fn hertz_mindlin_force(c: &Coeffs, k: &Interaction, xi: &mut Vec3) -> Vec3 {
    if k.delta <= 0.0 {
        *xi = Vec3::ZERO;
        return Vec3::ZERO;
    }
    let sqrt_rd = (k.r_eff * k.delta).sqrt();
    let s_n = 2.0 * c.e_star * sqrt_rd;
    let k_t = 8.0 * c.g_star * sqrt_rd;
    let c_n = c.damp * (s_n * k.m_eff).sqrt();
    let c_t = c.damp * (k_t * k.m_eff).sqrt();
    let vn = k.v_rel.dot(k.n);
    let f_n = 4.0 / 3.0 * c.e_star * sqrt_rd * k.delta + c_n * vn;
    let vt = k.v_rel - k.n * vn;
    let f_t = tangential_spring(xi, k.n, vt, k.dt, k_t, c_t, c.mu * f_n.max(0.0));
    f_t - k.n * f_n
}

#[cfg(test)]
mod tests {
    use super::*;

    fn alumina() -> Elastic {
        Elastic {
            young: 3.8e11,
            poisson: 0.23,
        }
    }

    #[test]
    fn effective_moduli_and_stiffness_ratio() {
        let law = HertzMindlinSpring::uniform(
            alumina(),
            Surface {
                mu: 0.1,
                restitution: 1.0,
            },
        );
        let (p, w) = (law.pair_coeffs(), law.wall_coeffs());
        // Like spheres: E* = E / (2(1 − ν²)); on a rigid wall: twice that.
        let es = 3.8e11 / (2.0 * (1.0 - 0.23 * 0.23));
        assert!((p.e_star / es - 1.0).abs() < 1e-14 && (w.e_star / (2.0 * es) - 1.0).abs() < 1e-14);
        // k_t / S_n = 4 G*/E* = 2(1 − ν)/(2 − ν) (Mindlin 1949) for both.
        let ratio = 2.0 * (1.0 - 0.23) / (2.0 - 0.23);
        assert!((4.0 * p.g_star / p.e_star / ratio - 1.0).abs() < 1e-14);
        assert!((4.0 * w.g_star / w.e_star / ratio - 1.0).abs() < 1e-14);
        assert_eq!(p.damp, 0.0);
        assert_eq!(beta_of_restitution(0.0), -1.0);
        assert!((beta_of_restitution(0.5) + 0.2155).abs() < 1e-4);
    }

    fn contact(v_rel: Vec3) -> Interaction {
        Interaction {
            n: Vec3::new(0.0, 0.0, 1.0),
            delta: 1e-5,
            r_i: 2e-3,
            r_j: 2e-3,
            r_eff: 1e-3,
            m_eff: 1e-3,
            v_rel,
            dv: v_rel,
            dw: Vec3::ZERO,
            wall: false,
            frozen: false,
            dt: 1e-4,
        }
    }

    #[test]
    fn coulomb_cap_holds_and_rescales_the_spring() {
        let c = Coeffs {
            e_star: 1e9,
            g_star: 4e8,
            damp: 0.0,
            mu: 0.3,
        };
        let k = contact(Vec3::new(10.0, 0.0, 0.0));
        let f_n = 4.0 / 3.0 * 1e9 * (1e-3f64 * 1e-5).sqrt() * 1e-5;
        let mut xi = Vec3::new(0.0, 0.0, 0.0);
        let f = hertz_mindlin_force(&c, &k, &mut xi);
        let ft = (f.x * f.x + f.y * f.y).sqrt();
        assert!((ft - 0.3 * f_n).abs() <= 1e-12 * f_n, "{ft} vs {}", 0.3 * f_n);
        assert!(f.x < 0.0 && (f.z + f_n).abs() < 1e-12 * f_n);
        let k_t = 8.0 * 4e8 * (1e-3f64 * 1e-5).sqrt();
        assert!(
            (xi.x * k_t - 0.3 * f_n).abs() < 1e-9 * f_n,
            "spring holds the sliding force"
        );
        // A stale history is rotated onto the new tangent plane with its length kept.
        let mut xi = Vec3::new(3e-7, 0.0, 4e-7);
        let _ = hertz_mindlin_force(&Coeffs { mu: 10.0, ..c }, &contact(Vec3::ZERO), &mut xi);
        assert!(xi.z == 0.0 && (xi.x - 5e-7).abs() < 1e-20, "{xi:?}");
        // Out of contact: no force, the spring zeroed.
        let open = Interaction {
            delta: -1e-6,
            ..contact(Vec3::ZERO)
        };
        assert_eq!(hertz_mindlin_force(&c, &open, &mut xi), Vec3::ZERO);
        assert_eq!(xi, Vec3::ZERO);
    }

    #[test]
    fn friction_is_capped_by_the_repulsive_normal_force_only() {
        // Separating fast with strong damping: the damped normal force pulls (F_n < 0), and
        // the tangential force is capped at μ max(F_n, 0) = 0.
        let c = Coeffs {
            e_star: 1e9,
            g_star: 4e8,
            damp: 2.0,
            mu: 0.3,
        };
        let k = contact(Vec3::new(1.0, 0.0, -50.0));
        let mut xi = Vec3::ZERO;
        let f = hertz_mindlin_force(&c, &k, &mut xi);
        assert!(f.z > 0.0, "the damped normal force pulls here: {f:?}");
        assert_eq!((f.x, f.y), (0.0, 0.0));
    }
}
