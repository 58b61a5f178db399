//! Hertz-Mindlin contact of spheres with the Mindlin tangential spring, Coulomb friction and
//! restitution damping, in the form of LIGGGHTS `pair gran model hertz tangential history`
//! (after Tsuji et al. 1992, Powder Technol. 71:239; Di Renzo & Di Maio 2004, Chem. Eng. Sci.
//! 59:525) — one kernel for sphere-sphere and sphere-plane contacts.
//!
//! For a contact of overlap δ > 0, effective radius R*, effective mass m*:
//! - effective moduli 1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂ and 1/G* = 2(2−ν₁)(1+ν₁)/E₁ +
//!   2(2−ν₂)(1+ν₂)/E₂ (= (2−ν₁)/G₁ + (2−ν₂)/G₂); a rigid plane adds nothing;
//! - normal: F_n = (4/3) E* √R* δ^{3/2} + c_n δ̇ (Hertz 1882), tangent stiffness
//!   S_n = 2 E* √(R* δ);
//! - tangential: the Mindlin no-slip stiffness k_t = S_t = 8 G* √(R* δ) on the tangential
//!   displacement ξ accumulated while in contact, F_t = −k_t ξ − c_t v_t;
//! - damping from the restitution coefficient e: β = ln e / √(ln² e + π²),
//!   c_n = −2 √(5/6) β √(S_n m*), c_t = −2 √(5/6) β √(S_t m*) (β = −1 at e = 0);
//! - Coulomb: |F_t| ≤ μ |F_n|; when sliding, F_t is scaled onto the cone and the spring reset to
//!   ξ = −(F_t + c_t v_t)/k_t, so it holds exactly the force that slides;
//! - ξ is carried between steps, first rotated onto the current tangent plane (projected, length
//!   kept), then incremented by v_t dt; it is zeroed when the contact opens.
//!
//! With no damping and full stick the tangential-to-normal stiffness ratio is
//! k_t/S_n = 4G*/E*, which for like materials (or a rigid plane) is 2(1−ν)/(2−ν) (Mindlin 1949).
//! The normal force is not clipped at zero (LIGGGHTS' default): with damping it may pull
//! slightly as the contact opens.

use super::error::SphereError;
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
    fn check(&self, what: &'static str) -> Result<(), SphereError> {
        if !(self.young > 0.0 && self.young.is_finite()) {
            return Err(SphereError::BadParameter {
                name: what,
                value: self.young,
                why: "Young's modulus must be positive and finite (Pa)",
            });
        }
        if !(self.poisson > -1.0 && self.poisson < 0.5) {
            return Err(SphereError::BadParameter {
                name: "Poisson's ratio",
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
    fn check(&self) -> Result<(), SphereError> {
        if !(self.mu >= 0.0 && self.mu.is_finite()) {
            return Err(SphereError::BadParameter {
                name: "friction coefficient mu",
                value: self.mu,
                why: "it must be zero or positive and finite",
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

/// The Hertz-Mindlin law of a sphere assembly: one sphere material, one wall material (rigid
/// if `None`), and the surface properties of sphere-sphere and sphere-wall contacts.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HertzMindlin {
    pub sphere: Elastic,
    /// Material of the plane walls; `None`: rigid (E → ∞).
    #[serde(default)]
    pub wall: Option<Elastic>,
    pub pair: Surface,
    pub wall_pair: Surface,
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

impl HertzMindlin {
    /// Like spheres on a rigid wall, one surface for both kinds of contact.
    pub fn uniform(sphere: Elastic, surface: Surface) -> Self {
        Self {
            sphere,
            wall: None,
            pair: surface,
            wall_pair: surface,
        }
    }

    /// Refuse non-physical parameters, naming the one at fault.
    pub fn check(&self) -> Result<(), SphereError> {
        self.sphere.check("Young's modulus of the spheres")?;
        if let Some(w) = &self.wall {
            w.check("Young's modulus of the walls")?;
        }
        self.pair.check()?;
        self.wall_pair.check()
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

/// Geometry and kinematics of one contact, seen from body i.
#[derive(Clone, Copy, Debug)]
pub struct ContactKin {
    /// Unit normal from body i towards body j (or the wall).
    pub n: Vec3,
    /// Overlap δ > 0 (m).
    pub delta: f64,
    /// R* (m).
    pub r_eff: f64,
    /// m* (kg).
    pub m_eff: f64,
    /// Velocity of i's contact point relative to j's (m/s).
    pub v_rel: Vec3,
}

/// The contact force on body i (the reaction acts on j), and its normal part F_n (N, positive
/// when repulsive). `xi` is the tangential spring of the contact, updated in place.
#[inline]
pub fn hertz_mindlin_force(c: &Coeffs, k: &ContactKin, dt: f64, xi: &mut Vec3) -> (Vec3, f64) {
    let sqrt_rd = (k.r_eff * k.delta).sqrt();
    let s_n = 2.0 * c.e_star * sqrt_rd;
    let k_t = 8.0 * c.g_star * sqrt_rd;
    let c_n = c.damp * (s_n * k.m_eff).sqrt();
    let c_t = c.damp * (k_t * k.m_eff).sqrt();
    let vn = k.v_rel.dot(k.n);
    let f_n = 4.0 / 3.0 * c.e_star * sqrt_rd * k.delta + c_n * vn;
    let vt = k.v_rel - k.n * vn;
    // Carry the spring onto the current tangent plane: project, keep its length.
    let xn = xi.dot(k.n);
    if xn != 0.0 {
        let old2 = xi.norm2();
        let p = *xi - k.n * xn;
        let p2 = p.norm2();
        *xi = if p2 > 0.0 {
            p * (old2 / p2).sqrt()
        } else {
            Vec3::ZERO
        };
    }
    *xi += vt * dt;
    let mut f_t = -(*xi * k_t) - vt * c_t;
    let cap = c.mu * f_n.abs();
    let ft2 = f_t.norm2();
    if ft2 > cap * cap {
        f_t = f_t * (cap / ft2.sqrt());
        *xi = -(f_t + vt * c_t) * (1.0 / k_t);
    }
    (f_t - k.n * f_n, f_n)
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
        let law = HertzMindlin::uniform(
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

    #[test]
    fn coulomb_cap_holds_and_rescales_the_spring() {
        let c = Coeffs {
            e_star: 1e9,
            g_star: 4e8,
            damp: 0.0,
            mu: 0.3,
        };
        let k = ContactKin {
            n: Vec3::new(0.0, 0.0, 1.0),
            delta: 1e-5,
            r_eff: 1e-3,
            m_eff: 1e-3,
            v_rel: Vec3::new(10.0, 0.0, 0.0),
        };
        let mut xi = Vec3::new(0.0, 0.0, 0.0);
        let (f, f_n) = hertz_mindlin_force(&c, &k, 1e-4, &mut xi);
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
        let k2 = ContactKin {
            v_rel: Vec3::ZERO,
            ..k
        };
        let _ = hertz_mindlin_force(&Coeffs { mu: 10.0, ..c }, &k2, 1e-4, &mut xi);
        assert!(xi.z == 0.0 && (xi.x - 5e-7).abs() < 1e-20, "{xi:?}");
    }
}
