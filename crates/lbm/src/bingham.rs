//! Bingham plastic rheology by a local relaxation time, inside the collision of the fast kernels
//! (Leonardi et al. 2014, Sect. 5.3: Eqs. 1-2 for the law, Eqs. 27-30 for its lattice form, the
//! clamp τ_min ≤ τ ≤ τ_max of Fig. 4).
//!
//! Every node, every step, before relaxing, the collider [`BinghamRates`] takes the
//! non-equilibrium momentum flux of the pre-collision populations,
//!
//! Π_ab = Σ_i c_ia c_ib (f_i − f_i^eq) + ½ (F_a u_b + u_a F_b),
//!
//! (the second term removes the part of Π that Guo forcing puts there, Leonardi Eqs. 15-17; it is
//! zero without a force) and from it the strain rate S_ab = −3 Π_ab / (2 ρ τ) (Leonardi Eq. 27
//! written with ρ and the sign of the Chapman-Enskog expansion: Π = −2 ρ c_s² τ S with
//! c_s² = 1/3), the shear rate γ̇ = √(2 S:S) (Eqs. 28-29), the apparent kinematic viscosity
//! ν = ν_pl + σ_y / (ρ γ̇) (Eq. 2 divided by ρ) and τ = ½ + 3ν (Eq. 30), clamped to
//! [τ_min, τ_max].
//!
//! **The implicit step, solved in closed form.** S needs τ and τ needs S. The paper uses τ of the
//! previous step in Eq. 27 (τ(x, t − 1)); that needs a per-node τ array carried from step to step
//! (state for checkpoints, and a lag of one step in the rheology). Here the pair is solved
//! exactly instead. With P = √(2 Π:Π) the shear rate is γ̇ = 3P / (2ρτ), so Eq. 30 reads
//! τ = τ_pl + 2 σ_y τ / P with τ_pl = ½ + 3ν_pl: linear in τ, with the solution
//!
//! ω = 1/τ = ω_pl (1 − 2 σ_y / P),  ω_pl = 1/τ_pl,
//!
//! then clamped to [1/τ_max, 1/τ_min]. The density cancels (the yield criterion is on the stress
//! magnitude ρ ν γ̇ = (τ − ½) P / (2τ), which is what the populations carry). For P ≤ 2σ_y the
//! unclamped ω is ≤ 0 (unyielded: infinite viscosity) and the clamp gives τ_max. Because the
//! right-hand side of Eq. 30 increases with τ with slope 2σ_y/P, this clamped ω is the unique
//! fixed point of the clamped Eqs. 27-30 at time t, so a steady state is the paper's steady
//! state; no τ is carried between steps, so the populations remain the whole state (checkpoints
//! unchanged), and the cost is one square root and one division per node on top of the moments.
//!
//! **The clamp (Fig. 4).** Below the shear rate γ̇_c = σ_y / (ρ (ν_max − ν_pl)) the fluid is
//! Newtonian with ν_max = (τ_max − ½)/3 instead of rigid; above the shear rate where ν would
//! fall under ν_min = (τ_min − ½)/3 (only when τ_min > τ_pl) it is Newtonian with ν_min: a
//! tri-viscosity fluid, a bi-viscosity one when τ_min ≤ τ_pl. The paper's values are 0.501 and
//! 3.5 ([`TAU_MIN_LEONARDI`], [`TAU_MAX_LEONARDI`]). The regularisation error of the plug is
//! worked out in `docs/bingham.md` and measured in `tests/bingham.rs`.
//!
//! **A subgrid eddy viscosity (optional, not in the paper).** With a Smagorinsky constant C > 0
//! the apparent viscosity gains ν_t = C² γ̇ (filter width one lattice spacing; Hou et al. 1996), which raises τ only where the shear rate is large, as at a
//! spreading front, where coarse lattices at τ ≈ ½ break down (docs/free_surface.md, "The
//! incline"). The pair is still solved in closed form: Eq. 30 becomes
//! τ = τ_pl + 2σ_y τ/P + 9C²P/(2ρτ), a quadratic a τ² − τ_pl τ − k = 0 with a = 1 − 2σ_y/P and
//! k = 9C²P/(2ρ), whose positive root gives ω = 2a / (τ_pl + √(τ_pl² + 4ak)) (0, so τ_max, for
//! a ≤ 0: unyielded), then the clamp. With C = 0 the kernel takes the path above, bit for bit.
//!
//! BGK (Leonardi Eq. 11) relaxes every moment with the local ω; TRT takes ω⁺ = ω and ω⁻ from its
//! magic parameter Λ per node, ω⁻ = 2(2 − ω) / (2 − ω + 4Λω) (from τ⁻ = ½ + Λ/(τ⁺ − ½)).

use crate::LbmError;
use crate::collision::{
    CollideParams, Collider, Collision, Moments, NodeRates, bgk_relax_local, moments, trt_relax_local, unroll,
};
use crate::kernel::SyncPtr;
use crate::lattice::{Lattice, QMAX};
use crate::real::Real;
use serde::{Deserialize, Serialize};

/// τ_min of Leonardi et al. 2014 Sect. 5.3 (after Švec et al.).
pub const TAU_MIN_LEONARDI: f64 = 0.501;
/// τ_max of Leonardi et al. 2014 Sect. 5.3.
pub const TAU_MAX_LEONARDI: f64 = 3.5;

/// A Bingham plastic (Leonardi et al. 2014 Eq. 1: σ = σ_y + μ_pl γ̇ where it flows, γ̇ = 0 below
/// the yield stress) and the clamp of its relaxation time (Sect. 5.3, Fig. 4). All in lattice
/// units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bingham {
    /// Plastic (dynamic) viscosity μ_pl (> 0).
    pub mu_pl: f64,
    /// Yield stress σ_y (≥ 0; 0 is the Newtonian fluid of viscosity μ_pl).
    pub yield_stress: f64,
    /// Reference density ρ of the plastic viscosity: ν_pl = μ_pl / ρ (> 0, usually 1).
    pub rho: f64,
    /// Smallest relaxation time (> ½).
    pub tau_min: f64,
    /// Largest relaxation time: the viscosity of the unyielded region (> τ_min and > τ_pl).
    pub tau_max: f64,
    /// Smagorinsky constant C of the optional eddy viscosity ν_t = C² γ̇ (module doc; ≥ 0, 0 is
    /// the paper's model). Not in Leonardi et al.: a coarse-lattice option, typically 0.1-0.2.
    #[serde(default)]
    pub smagorinsky: f64,
}

impl Bingham {
    /// The paper's clamp [0.501, 3.5] for μ_pl and σ_y at density ρ (lattice units).
    pub fn leonardi(mu_pl: f64, yield_stress: f64, rho: f64) -> Result<Self, LbmError> {
        let b = Self {
            mu_pl,
            yield_stress,
            rho,
            tau_min: TAU_MIN_LEONARDI,
            tau_max: TAU_MAX_LEONARDI,
            smagorinsky: 0.0,
        };
        b.check()?;
        Ok(b)
    }

    /// Plastic kinematic viscosity ν_pl = μ_pl / ρ.
    pub fn nu_pl(&self) -> f64 {
        self.mu_pl / self.rho
    }

    /// Relaxation time of the plastic viscosity, τ_pl = ½ + 3ν_pl (Leonardi Eq. 12).
    pub fn tau_pl(&self) -> f64 {
        0.5 + 3.0 * self.nu_pl()
    }

    /// The clamped relaxation time for a shear rate γ̇ (Leonardi Eq. 30 with the clamp of Fig. 4):
    /// the constitutive law the kernel applies, in f64, for tests and for analytic profiles.
    pub fn tau_of_shear_rate(&self, shear_rate: f64) -> f64 {
        let nu_t = self.smagorinsky * self.smagorinsky * shear_rate;
        let t = 0.5 + 3.0 * (self.nu_pl() + self.yield_stress / (self.rho * shear_rate) + nu_t);
        if t.is_nan() || t > self.tau_max {
            self.tau_max
        } else {
            t.max(self.tau_min)
        }
    }

    /// Refuse parameters the model cannot run; each message names the value and the fix.
    pub fn check(&self) -> Result<(), LbmError> {
        let bad = |name: &'static str, value: f64, fix: &str| {
            Err(LbmError::Bingham {
                name,
                value,
                fix: fix.to_string(),
            })
        };
        if !(self.mu_pl.is_finite() && self.mu_pl > 0.0) {
            return bad(
                "mu_pl",
                self.mu_pl,
                "the plastic viscosity must be finite and > 0 (Leonardi et al. 2014 Eq. 1); give the \
                 slope of the flow curve in lattice units",
            );
        }
        if !(self.yield_stress.is_finite() && self.yield_stress >= 0.0) {
            return bad(
                "yield_stress",
                self.yield_stress,
                "the yield stress must be finite and >= 0 (0 is the Newtonian fluid); give the \
                 intercept of the flow curve in lattice units",
            );
        }
        if !(self.rho.is_finite() && self.rho > 0.0) {
            return bad(
                "rho",
                self.rho,
                "the reference density must be finite and > 0; use 1 (lattice units)",
            );
        }
        if !(self.tau_min.is_finite() && self.tau_min > 0.5) {
            return bad(
                "tau_min",
                self.tau_min,
                "the smallest relaxation time must be finite and > 0.5 (zero viscosity at 0.5, Leonardi \
                 Eq. 12); the paper uses 0.501",
            );
        }
        if !(self.tau_max.is_finite() && self.tau_max > self.tau_min) {
            return bad(
                "tau_max",
                self.tau_max,
                &format!(
                    "the largest relaxation time must be finite and > tau_min = {}; the paper uses 3.5",
                    self.tau_min
                ),
            );
        }
        if !(self.smagorinsky.is_finite() && self.smagorinsky >= 0.0) {
            return bad(
                "smagorinsky",
                self.smagorinsky,
                "the Smagorinsky constant must be finite and >= 0 (0: no eddy viscosity, the \
                 paper's model); 0.1-0.2 is usual",
            );
        }
        let tau_pl = self.tau_pl();
        if tau_pl >= self.tau_max {
            return bad(
                "tau_max",
                self.tau_max,
                &format!(
                    "must exceed the plastic relaxation time tau_pl = 0.5 + 3 mu_pl/rho = {tau_pl} \
                     (otherwise every node is clamped and the fluid is Newtonian); raise tau_max or \
                     lower mu_pl (a finer time step)"
                ),
            );
        }
        Ok(())
    }
}

/// The Bingham collider (module doc): per block, the rates of every lane from the shear rate of
/// its own populations, then the relaxation of `collision::LocalRates` with those rates. `tau`,
/// when set, receives τ = 1/ω of every node collided (node order, f64).
#[derive(Clone, Copy)]
pub struct BinghamRates<T> {
    /// Force and its prefactors (the rates in it are not used).
    pub base: CollideParams<T>,
    /// BGK (true) or TRT with magic parameter `magic`.
    pub bgk: bool,
    pub magic: T,
    /// ω_pl = 1/τ_pl and 2 σ_y ω_pl.
    pub omega_pl: T,
    pub yield_term: T,
    /// 1/τ_max and 1/τ_min.
    pub omega_lo: T,
    pub omega_hi: T,
    /// The eddy viscosity (module doc): whether on, τ_pl, 2σ_y and 9C²/2.
    pub eddy: bool,
    pub tau_pl: T,
    pub two_yield: T,
    pub smag_term: T,
    /// Where to write τ per node (the stepper's `bingham_tau`), if asked for this step.
    pub tau: Option<SyncPtr<f64>>,
}

impl<T: Real> BinghamRates<T> {
    /// The constants for `bingham` with the kind of `collision` (BGK, or TRT and its Λ) and the
    /// uniform body force `force`.
    pub fn new(bingham: &Bingham, collision: &Collision, force: [f64; 3]) -> Result<Self, LbmError> {
        bingham.check()?;
        let (bgk, magic) = match *collision {
            Collision::Bgk { .. } => (true, 0.0),
            Collision::Trt { magic, .. } => {
                if magic.is_nan() || magic <= 0.0 || !magic.is_finite() {
                    return Err(LbmError::Magic { magic });
                }
                (false, magic)
            }
        };
        let omega_pl = 1.0 / bingham.tau_pl();
        Ok(Self {
            base: CollideParams::from_rates(omega_pl, omega_pl, force),
            bgk,
            magic: T::from_f64(magic),
            omega_pl: T::from_f64(omega_pl),
            yield_term: T::from_f64(2.0 * bingham.yield_stress * omega_pl),
            omega_lo: T::from_f64(1.0 / bingham.tau_max),
            omega_hi: T::from_f64(1.0 / bingham.tau_min),
            eddy: bingham.smagorinsky > 0.0,
            tau_pl: T::from_f64(bingham.tau_pl()),
            two_yield: T::from_f64(2.0 * bingham.yield_stress),
            smag_term: T::from_f64(4.5 * bingham.smagorinsky * bingham.smagorinsky),
            tau: None,
        })
    }

    /// ω⁺ of each lane from its pre-collision populations and moments (module doc).
    #[inline(always)]
    fn omegas<L: Lattice, const W: usize, const FORCED: bool>(
        &self,
        f: &[[T; W]; QMAX],
        m: &Moments<T, W>,
    ) -> [T; W] {
        let zero = T::default();
        let half = T::from_f64(0.5);
        let third = T::from_f64(1.0 / 3.0);
        let two = T::from_f64(2.0);
        // second moments Σ c_a c_b f_i, pairs xx yy zz xy xz yz; c_ia c_ib ∈ {−1, 0, 1} is a
        // compile-time constant, so these are additions and subtractions only
        const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];
        let mut mm = [[zero; W]; 6];
        unroll!(i in [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18] {
            if i < L::Q {
                let c = L::C[i];
                unroll!(k in [0, 1, 2, 3, 4, 5] {
                    let (a, b) = PAIRS[k];
                    if a < L::D && b < L::D {
                        let s = c[a] * c[b];
                        if s == 1 {
                            for w in 0..W {
                                mm[k][w] += f[i][w];
                            }
                        } else if s == -1 {
                            for w in 0..W {
                                mm[k][w] = mm[k][w] - f[i][w];
                            }
                        }
                    }
                });
            }
        });
        let force = self.base.force;
        let mut p2 = [zero; W];
        unroll!(k in [0, 1, 2, 3, 4, 5] {
            let (a, b) = PAIRS[k];
            if a < L::D && b < L::D {
                // Π_ab = M_ab − ρ (u_a u_b + δ_ab/3) + ½ (F_a u_b + u_a F_b); weight 1 on the
                // diagonal and 2 off it in Π:Π
                let weight = if a == b { two } else { two * two };
                for w in 0..W {
                    let (ua, ub) = (m.u[a][w], m.u[b][w]);
                    let mut uu = ua * ub;
                    if a == b {
                        uu += third;
                    }
                    let mut pi = mm[k][w] - m.rho[w] * uu;
                    if FORCED {
                        pi += half * (force[a] * ub + ua * force[b]);
                    }
                    p2[w] = (weight * pi).mul_add(pi, p2[w]);
                }
            }
        });
        // ω = ω_pl (1 − 2σ_y/P), P = √(2 Π:Π) floored (P = 0 with σ_y = 0 gives ω_pl, with σ_y > 0
        // the clamp's τ_max), clamped to [1/τ_max, 1/τ_min]; a NaN passes through to the range check
        let floor = T::from_f64(1e-30);
        let mut om = [zero; W];
        for w in 0..W {
            let q = if p2[w] < floor { floor } else { p2[w] };
            let o = if self.eddy {
                // a τ² − τ_pl τ − k = 0 (module doc); a ≤ 0 (unyielded) gives ω = 0, so τ_max
                let p = q.sqrt();
                let a = T::from_f64(1.0) - self.two_yield / p;
                let a = if a < zero { zero } else { a };
                let k = self.smag_term * p / m.rho[w];
                let disc = (T::from_f64(4.0) * a).mul_add(k, self.tau_pl * self.tau_pl);
                two * a / (self.tau_pl + disc.sqrt())
            } else {
                self.omega_pl - self.yield_term / q.sqrt()
            };
            om[w] = if o < self.omega_lo {
                self.omega_lo
            } else if o > self.omega_hi {
                self.omega_hi
            } else {
                o
            };
        }
        om
    }
}

impl<L: Lattice, T: Real> Collider<L, T> for BinghamRates<T> {
    const FORCE_TERMS_ALWAYS: bool = true;

    #[inline(always)]
    fn collide<const W: usize, const FORCED: bool>(
        &self,
        f: &mut [[T; W]; QMAX],
        node: usize,
    ) -> Moments<T, W> {
        let m = moments::<L, T, W, FORCED>(f, &self.base);
        let om = self.omegas::<L, W, FORCED>(f, &m);
        let one = T::from_f64(1.0);
        let half = T::from_f64(0.5);
        let two = T::from_f64(2.0);
        let four = T::from_f64(4.0);
        let mut r = [NodeRates::default(); W];
        for w in 0..W {
            let o = om[w];
            // TRT: ω⁻ = 2(2 − ω) / (2 − ω + 4Λω), i.e. τ⁻ = ½ + Λ/(τ⁺ − ½)
            let om_m = if self.bgk {
                o
            } else {
                let d = two - o;
                two * d / (four * self.magic).mul_add(o, d)
            };
            // the same expressions `collision::local_rates` forms in f64 (bitwise equal there)
            r[w] = NodeRates {
                omega_p: o,
                omega_m: om_m,
                force_p: one - half * o,
                force_m: one - half * om_m,
                keep: one - o,
            };
        }
        if let Some(p) = self.tau {
            for w in 0..W {
                // SAFETY: node + w belongs to the calling row (kernels' contract), the array has
                // one entry per node.
                unsafe { *p.0.add(node + w) = 1.0 / om[w].to_f64() };
            }
        }
        if self.bgk {
            bgk_relax_local::<L, T, W, FORCED>(f, &self.base, &r, m)
        } else {
            let mut uf = [T::default(); W];
            for w in 0..W {
                for a in 0..L::D {
                    uf[w] += m.u[a][w] * self.base.force[a];
                }
            }
            trt_relax_local::<L, T, W, FORCED>(f, &self.base, &r, m, &uf)
        }
    }
}
