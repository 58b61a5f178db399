//! The elastic-plastic normal law of Su et al. 2020 (Sect. 2.3, Table 1, Eq. 6): elastic with
//! k_n,e up to the yield force F_y, then plastic flow with the small slope k_n,p, elastic
//! unloading with k_n,e from the plastic state (a permanent overlap remains). F_y is rate
//! dependent through Eq. 6: F_y − F_0 ≈ 2.40e-8 (du_y/dt)^0.26 (SI: N, m/s), see [`su_yield_force`].
//! Tangential spring with Coulomb limit, damping and rolling resistance as in the linear law.

use super::{
    Batched, BatchedNormal, ContactInput, ContactLaw, ContactOutput, Damping, History, Rolling, tangential,
};
use crate::vector::Vec2;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElasticPlastic {
    /// Elastic normal stiffness k_n,e (N/m).
    pub k_e: f64,
    /// Slope of the plastic flow regime k_n,p (N/m).
    pub k_p: f64,
    /// Yield force F_y (N): a number, or `{ f_0 = F_0, rate = du_y/dt }` for the rate-sensitive
    /// yield of Eq. 6 (F_0 in N, the push-plate's rate in m/s), resolved when read.
    #[serde(deserialize_with = "yield_force")]
    pub f_y: f64,
    pub k_t: f64,
    pub damping: Damping,
    pub mu: f64,
    #[serde(default)]
    pub rolling: Option<Rolling>,
}

/// Su et al. 2020 Eq. 6: F_y = F_0 + 2.40e-8 · (du_y/dt)^0.26, with the push-plate speed in m/s
/// and forces in N.
pub fn su_yield_force(f0: f64, plate_speed: f64) -> f64 {
    f0 + 2.40e-8 * plate_speed.abs().powf(0.26)
}

/// F_y as a scene gives it: a number, or F_0 and the plate's rate for Eq. 6.
#[derive(Deserialize)]
#[serde(untagged)]
enum YieldSpec {
    Force(f64),
    Rate(RateYield),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RateYield {
    f_0: f64,
    rate: f64,
}

fn yield_force<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    match YieldSpec::deserialize(d)? {
        YieldSpec::Force(f) => Ok(f),
        YieldSpec::Rate(RateYield { f_0, rate }) => {
            if !(f_0 >= 0.0 && f_0.is_finite() && rate >= 0.0 && rate.is_finite()) {
                return Err(serde::de::Error::custom(format!(
                    "f_y = {{ f_0 = {f_0}, rate = {rate} }}: F_0 (N) and the push-plate rate (m/s) must be \
                     finite and non-negative (Su et al. 2020 Eq. 6, Table 1)"
                )));
            }
            Ok(su_yield_force(f_0, rate))
        }
    }
}

impl ElasticPlastic {
    /// Elastic-plastic normal force for overlap `delta`, updating the plastic overlap.
    #[inline]
    pub fn normal(&self, delta: f64, h: &mut History) -> f64 {
        let mut f = self.k_e * (delta - h.delta_p);
        // Yield envelope: F_y + k_p (δ − F_y/k_e) beyond the yield overlap U_y = F_y/k_e.
        let env = self.f_y + self.k_p * (delta - self.f_y / self.k_e);
        if f > env {
            f = env;
            h.delta_p = delta - env / self.k_e;
        }
        f.max(0.0)
    }
}

/// Tangential dashpot as a fraction of the normal one (as the linear law's default).
const TANGENTIAL_DAMPING: f64 = 0.5;

impl ContactLaw for ElasticPlastic {
    type History = History;
    #[inline]
    fn force(&self, c: &ContactInput, h: &mut History) -> ContactOutput {
        let f_el = self.normal(c.delta, h);
        let cn = self.damping.coefficient(self.k_e, c.m_eff);
        let vn = c.v_rel.x * c.n.x + c.v_rel.y * c.n.y;
        let f_n = if f_el > 0.0 {
            (f_el + cn * vn).max(0.0)
        } else {
            0.0
        };
        let ft = if self.mu > 0.0 {
            tangential(c, h, self.k_t, TANGENTIAL_DAMPING * cn, self.mu, f_n)
        } else {
            Vec2::ZERO
        };
        let m_roll = match &self.rolling {
            Some(r) => r.torque(c, h, f_n),
            None => 0.0,
        };
        ContactOutput {
            f: ft - c.n * f_n,
            m_roll,
            f_n,
        }
    }
    fn max_stiffness(&self, _r_eff: f64) -> f64 {
        self.k_e.max(self.k_t)
    }
    fn spring_dashpots(&self, _r_eff: f64, m_eff: f64) -> super::SpringDashpots {
        let cn = self.damping.coefficient(self.k_e, m_eff);
        super::SpringDashpots::frictional((self.k_e, cn), (self.k_t, TANGENTIAL_DAMPING * cn), self.mu)
    }
    fn friction(&self) -> f64 {
        self.mu
    }
    fn batched(&self) -> Option<Batched> {
        (self.mu > 0.0).then_some(Batched {
            normal: BatchedNormal::Plastic {
                k_e: self.k_e,
                k_p: self.k_p,
                f_y: self.f_y,
            },
            damping: self.damping,
            k_t: self.k_t,
            t_frac: TANGENTIAL_DAMPING,
            mu: self.mu,
            rolling: self.rolling,
        })
    }
}
