//! Hertzian normal contact with damping and viscous-Coulomb tangential force, Leonardi et al.
//! 2014 Eqs. 5-6: F_n = (2/3) Y √R_eff/(1−ν²) (ξ^{3/2} + A √ξ dξ/dt),
//! F_t = −min(η |u_t|, μ_d |F_n|) t̂ (no tangential history).

use super::{ContactInput, ContactLaw, ContactOutput, History};
use crate::vector::{Vec2, Vector};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HertzMindlin {
    /// Young's modulus Y (Pa).
    pub young: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Damping constant A (s).
    #[serde(default)]
    pub a_damp: f64,
    /// Tangential shear viscosity η (N s/m).
    #[serde(default)]
    pub eta: f64,
    /// Dynamic friction μ_d.
    pub mu: f64,
    /// Largest overlap expected, as a fraction of r_eff, for the critical time step (default 0.05).
    #[serde(default = "five_percent")]
    pub max_overlap: f64,
}

fn five_percent() -> f64 {
    0.05
}

impl HertzMindlin {
    /// The prefactor K of Eq. 5: F_n = K ξ^{3/2}.
    #[inline]
    pub fn prefactor(&self, r_eff: f64) -> f64 {
        2.0 / 3.0 * self.young * r_eff.sqrt() / (1.0 - self.poisson * self.poisson)
    }
}

impl ContactLaw for HertzMindlin {
    type History = History;
    #[inline]
    fn force(&self, c: &ContactInput, _h: &mut History) -> ContactOutput {
        let k = self.prefactor(c.r_eff);
        let s = c.delta.sqrt();
        let vn = c.v_rel.dot(c.n);
        let f_n = (k * (c.delta * s + self.a_damp * s * vn)).max(0.0);
        let vt = c.v_rel - c.n * vn;
        let vtm = vt.norm();
        let ft = if vtm > 0.0 {
            vt * (-(self.eta * vtm).min(self.mu * f_n) / vtm)
        } else {
            Vec2::ZERO
        };
        ContactOutput {
            f: ft - c.n * f_n,
            m_roll: 0.0,
            f_n,
        }
    }
    /// Tangent stiffness dF/dξ = (3/2) K √ξ at the largest expected overlap.
    fn max_stiffness(&self, r_eff: f64) -> f64 {
        1.5 * self.prefactor(r_eff) * (self.max_overlap * r_eff).sqrt()
    }
    fn friction(&self) -> f64 {
        self.mu
    }
}
