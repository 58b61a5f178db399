//! Contact laws behind one trait ([`ContactLaw`]), chosen per scene ([`Law`]). Each law is a small
//! struct whose `force` the compiler inlines into the pair loop (monomorphised stepper).
//!
//! Sign conventions: `n` is the unit normal from body i to body j; `delta > 0` is the overlap;
//! `v_rel` is the velocity of i's contact point minus j's; `w_rel = ω_i − ω_j`. The returned
//! force acts on i (j receives its negative); the returned rolling torque acts on i (j: negative).

pub mod bond;
pub mod hertz;
pub mod linear;
pub mod plastic;

use crate::vector::{Vec2, Vector};
use serde::{Deserialize, Serialize};

pub use bond::{Bond, BondParams};
pub use hertz::HertzMindlin;
pub use linear::LinearSpringDashpot;
pub use plastic::ElasticPlastic;

/// Persistent per-contact state carried between steps (`repr(C)`: the pair kernel loads four
/// of them as two 512-bit lines).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[repr(C)]
pub struct History {
    /// Tangential spring elongation.
    pub xi_t: Vec2,
    /// Relative rolling rotation of the rolling spring.
    pub theta_r: f64,
    /// Plastic (permanent) overlap of the elastic-plastic law.
    pub delta_p: f64,
}

/// Kinematics of one contact.
#[derive(Clone, Copy, Debug)]
pub struct ContactInput {
    pub delta: f64,
    pub n: Vec2,
    pub v_rel: Vec2,
    pub w_rel: f64,
    /// Effective radius r_i r_j/(r_i + r_j) (r_i for a wall).
    pub r_eff: f64,
    /// Effective mass m_i m_j/(m_i + m_j) (m_i for a wall).
    pub m_eff: f64,
    pub dt: f64,
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactOutput {
    /// Force on i.
    pub f: Vec2,
    /// Rolling-resistance torque on i.
    pub m_roll: f64,
    /// Magnitude of the normal force (≥ 0 unless the law allows attraction).
    pub f_n: f64,
}

/// A contact law: force from overlap and relative motion, updating its history.
pub trait ContactLaw: Sync + Send {
    fn force(&self, c: &ContactInput, h: &mut History) -> ContactOutput;
    /// Largest normal stiffness (N/m) the law can present, for the critical time step.
    fn max_stiffness(&self, r_eff: f64) -> f64;
    /// Friction coefficient (for diagnostics and generation protocols).
    fn friction(&self) -> f64;
    /// The law as the linear spring-dashpot, if it is one: the stepper then uses its batched
    /// pair kernel (same bits as [`ContactLaw::force`]).
    fn linear(&self) -> Option<&LinearSpringDashpot> {
        None
    }
}

/// How the normal dashpot coefficient is set.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Damping {
    /// c_n = 2 ζ sqrt(k_n m*): damping ratio ζ (restitution e = exp(−πζ/√(1−ζ²))).
    Ratio(f64),
    /// c_n = γ m* (LAMMPS gran/hooke `gamma_n`, 1/s).
    Gamma(f64),
}

impl Damping {
    #[inline]
    pub fn coefficient(&self, k: f64, m_eff: f64) -> f64 {
        match *self {
            Damping::Ratio(z) => 2.0 * z * (k * m_eff).sqrt(),
            Damping::Gamma(g) => g * m_eff,
        }
    }
}

/// Tangential spring with Coulomb limit (Cundall & Strack 1979; LAMMPS pair gran/hooke/history):
/// the spring elongation is projected onto the current tangent plane (as LAMMPS does, without
/// restoring its length: a second-order effect in the rotation per step), incremented by v_t dt,
/// and rescaled to the Coulomb limit μ F_n when sliding.
#[inline]
pub fn tangential(c: &ContactInput, h: &mut History, kt: f64, ct: f64, mu: f64, f_n: f64) -> Vec2 {
    let vn = c.v_rel.dot(c.n);
    let vt = c.v_rel - c.n * vn;
    let mut xi = h.xi_t - c.n * h.xi_t.dot(c.n);
    xi += vt * c.dt;
    let mut ft = -(xi * kt) - vt * ct;
    let lim = mu * f_n.max(0.0);
    let ftm2 = ft.norm2();
    if ftm2 > lim * lim {
        let ftm = ftm2.sqrt();
        ft = if ftm > 0.0 { ft * (lim / ftm) } else { Vec2::ZERO };
        xi = if kt > 0.0 {
            -(ft + vt * ct) * (1.0 / kt)
        } else {
            Vec2::ZERO
        };
    }
    h.xi_t = xi;
    ft
}

/// Linear rolling resistance with a limit (elastic-plastic spring-dashpot without dashpot,
/// model "C" of Ai, Chen, Rotter & Ooi, Powder Technol. 206 (2011) 269): M_r = −k_r θ_r,
/// |M_r| ≤ μ_r r_eff F_n.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rolling {
    /// Rolling stiffness k_r (N m / rad).
    pub k_r: f64,
    /// Rolling friction coefficient μ_r (Su et al. Table 1: 0.5).
    pub mu_r: f64,
}

impl Rolling {
    #[inline]
    pub fn torque(&self, c: &ContactInput, h: &mut History, f_n: f64) -> f64 {
        h.theta_r += c.w_rel * c.dt;
        let mut m = -self.k_r * h.theta_r;
        let lim = self.mu_r * c.r_eff * f_n.max(0.0);
        if m.abs() > lim {
            m = lim.copysign(m);
            h.theta_r = -m / self.k_r;
        }
        m
    }
}

/// The laws a scene can choose (`[contact] law = "linear" | "hertz" | "plastic"`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "law", rename_all = "snake_case")]
pub enum Law {
    Linear(LinearSpringDashpot),
    Hertz(HertzMindlin),
    Plastic(ElasticPlastic),
}

impl ContactLaw for Law {
    #[inline]
    fn force(&self, c: &ContactInput, h: &mut History) -> ContactOutput {
        match self {
            Law::Linear(l) => l.force(c, h),
            Law::Hertz(l) => l.force(c, h),
            Law::Plastic(l) => l.force(c, h),
        }
    }
    fn max_stiffness(&self, r_eff: f64) -> f64 {
        match self {
            Law::Linear(l) => l.max_stiffness(r_eff),
            Law::Hertz(l) => l.max_stiffness(r_eff),
            Law::Plastic(l) => l.max_stiffness(r_eff),
        }
    }
    fn friction(&self) -> f64 {
        match self {
            Law::Linear(l) => l.friction(),
            Law::Hertz(l) => l.friction(),
            Law::Plastic(l) => l.friction(),
        }
    }
    fn linear(&self) -> Option<&LinearSpringDashpot> {
        match self {
            Law::Linear(l) => Some(l),
            _ => None,
        }
    }
}
