//! Linear spring-dashpot normal force with a tangential spring and Coulomb limit, and optional
//! rolling resistance (Cundall & Strack, Géotechnique 29 (1979) 47; the "elastic, damping and
//! rolling resistance parts" of Su et al. 2020 Sect. 2.3; Ness et al. 2017 Eq. 6 frictional
//! contacts: F_n = k_n δ n, |F_t| ≤ μ |F_n|).

use super::{
    Batched, BatchedNormal, ContactInput, ContactLaw, ContactOutput, Damping, History, Rolling,
    SpringDashpots, tangential,
};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinearSpringDashpot {
    /// Normal stiffness k_n (N/m).
    pub k_n: f64,
    /// Tangential stiffness k_t (N/m); Su et al. Table 1 use k_n/k_t = κ = 2.
    pub k_t: f64,
    pub damping: Damping,
    /// Tangential dashpot as a fraction of the normal one (LAMMPS default 0.5).
    #[serde(default = "half")]
    pub tangential_damping: f64,
    /// Coulomb friction coefficient μ.
    pub mu: f64,
    #[serde(default)]
    pub rolling: Option<Rolling>,
    /// Clip the normal force at zero (no attraction); off only for analytic restitution tests.
    #[serde(default = "yes")]
    pub clip: bool,
}

fn half() -> f64 {
    0.5
}
fn yes() -> bool {
    true
}

impl LinearSpringDashpot {
    pub fn new(k_n: f64, k_t: f64, damping: Damping, mu: f64) -> Self {
        Self {
            k_n,
            k_t,
            damping,
            tangential_damping: 0.5,
            mu,
            rolling: None,
            clip: true,
        }
    }
}

impl ContactLaw for LinearSpringDashpot {
    type History = History;
    #[inline]
    fn force(&self, c: &ContactInput, h: &mut History) -> ContactOutput {
        let cn = self.damping.coefficient(self.k_n, c.m_eff);
        let vn = c.v_rel.x * c.n.x + c.v_rel.y * c.n.y;
        let mut f_n = self.k_n * c.delta + cn * vn;
        if self.clip && f_n < 0.0 {
            f_n = 0.0;
        }
        let ft = if self.mu > 0.0 {
            tangential(c, h, self.k_t, cn * self.tangential_damping, self.mu, f_n)
        } else {
            crate::Vec2::ZERO
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
        self.k_n.max(self.k_t)
    }
    fn friction(&self) -> f64 {
        self.mu
    }
    fn spring_dashpots(&self, _r_eff: f64, m_eff: f64) -> SpringDashpots {
        let cn = self.damping.coefficient(self.k_n, m_eff);
        SpringDashpots::frictional((self.k_n, cn), (self.k_t, cn * self.tangential_damping), self.mu)
    }
    fn batched(&self) -> Option<Batched> {
        (self.mu > 0.0).then_some(Batched {
            normal: BatchedNormal::Linear {
                k_n: self.k_n,
                clip: self.clip,
            },
            damping: self.damping,
            k_t: self.k_t,
            t_frac: self.tangential_damping,
            mu: self.mu,
            rolling: self.rolling,
        })
    }
}
