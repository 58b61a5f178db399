//! Parallel bonds (Potyondy & Cundall, Int. J. Rock Mech. Min. Sci. 41 (2004) 1329; the bonded
//! membrane of Su et al. 2020 Sect. 2.4, Table 1: k_n,bond, σ_bond, C_bond, λ̄_bond, κ).
//! 2D with unit thickness: bond radius R̄ = λ̄ min(r_i, r_j), area A = 2R̄, second moment
//! I = (2/3) R̄³. Forces grow incrementally from the relative motion:
//! ΔF_n = k̄_n A Δu_n, ΔF_s = −k̄_s A Δu_s, ΔM = −k̄_n I Δθ. The bond breaks when the tensile stress
//! σ = F_n/A + |M| R̄/I reaches σ_c or the shear stress τ = |F_s|/A reaches the cohesion c.
//! Optional dashpots (`BondParams::damping`) beside the normal and shear springs.

use super::ContactInput;
use crate::vector::{Vec2, Vector};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BondParams {
    /// Normal stiffness per unit area k̄_n (N/m² in 2D with unit thickness... i.e. Pa/m · m).
    pub k_n: f64,
    /// Shear stiffness per unit area k̄_s (Su et al.: k̄_n/κ with κ = 2).
    pub k_s: f64,
    /// Tensile strength σ_c (N/m).
    pub sigma_c: f64,
    /// Cohesion c (N/m).
    pub cohesion: f64,
    /// Bond radius multiplier λ̄ (Su et al.: 0.5).
    pub lambda: f64,
    /// Damping ratio ζ of a dashpot beside each of the normal and shear springs (0, the
    /// default: Potyondy & Cundall's undamped bond). An undamped membrane under a liquid that
    /// answers its motion a step late rings on its bonds at the LBM step's period until the
    /// lattice blows up (docs/su2020.md, "The membrane's bonds must be damped"); ζ = 0.2 stops
    /// it.
    #[serde(default)]
    pub damping: f64,
}

/// A parallel bond between circles `i` and `j`, with its stored forces.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bond {
    pub i: u32,
    pub j: u32,
    /// Normal force, tension positive (N).
    pub f_n: f64,
    /// Shear force along t = perp(n) (N).
    pub f_s: f64,
    /// Bending moment (N m).
    pub m: f64,
    pub broken: bool,
}

impl Bond {
    pub fn new(i: u32, j: u32) -> Self {
        Self {
            i,
            j,
            f_n: 0.0,
            f_s: 0.0,
            m: 0.0,
            broken: false,
        }
    }

    /// Advance the bond by one step and return (force on i, torque on i about the contact);
    /// j receives the negative force. `ri`, `rj` are the circle radii.
    pub fn update(&mut self, p: &BondParams, c: &ContactInput, ri: f64, rj: f64) -> (Vec2, f64) {
        if self.broken {
            return (Vec2::ZERO, 0.0);
        }
        let rb = p.lambda * ri.min(rj);
        let area = 2.0 * rb;
        let inertia = 2.0 / 3.0 * rb.powi(3);
        let t = c.n.perp();
        let vn = c.v_rel.dot(c.n);
        // Separation (i moving away from j along −n) stretches the bond: tension grows.
        self.f_n += p.k_n * area * (-vn) * c.dt;
        self.f_s -= p.k_s * area * c.v_rel.dot(t) * c.dt;
        self.m -= p.k_n * inertia * c.w_rel * c.dt;
        let sigma = self.f_n / area + self.m.abs() * rb / inertia;
        let tau = self.f_s.abs() / area;
        if sigma >= p.sigma_c || tau >= p.cohesion {
            self.broken = true;
            return (Vec2::ZERO, 0.0);
        }
        // Tension pulls i toward j (along +n). The dashpots act on the relative velocity
        // (c = 2ζ √(k̄ A m*)); they are not stored in the bond and do not break it.
        let mut f = c.n * self.f_n + t * self.f_s;
        if p.damping > 0.0 {
            let cn = 2.0 * p.damping * (p.k_n * area * c.m_eff).sqrt();
            let cs = 2.0 * p.damping * (p.k_s * area * c.m_eff).sqrt();
            f -= c.n * (cn * vn) + t * (cs * c.v_rel.dot(t));
        }
        (f, self.m)
    }
}
