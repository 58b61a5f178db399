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

use crate::history::{HistoryData, stride_of};
use crate::vector::{Vec2, Vector};
use serde::{Deserialize, Serialize};

pub use bond::{Bond, BondParams};
pub use hertz::HertzMindlin;
pub use linear::LinearSpringDashpot;
pub use plastic::ElasticPlastic;

/// The history of the linear, Hertz and elastic-plastic laws (`repr(C)`: the batched pair
/// kernel loads four of them as two 512-bit lines).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, bytemuck::Pod, bytemuck::Zeroable,
)]
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
    /// Overlap r_i + r_j − distance: negative across a gap (laws with a [`ContactLaw::range`]).
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

/// A contact law: force from overlap (or gap) and relative motion, updating its own history.
///
/// Adding a law: one file in `contact/` with a struct implementing this trait, plus one line in
/// the `register_laws!` list below if scenes should select it by name. The stepper's generic
/// pair pass is monomorphised over the law (its `force` inlines into the loop); nothing in the
/// stepper or the batched kernels changes.
pub trait ContactLaw: Sync + Send {
    /// Per-contact state carried between steps (and across Verlet-list rebuilds and checkpoints,
    /// stored as f64 slots: see [`crate::history`]). `Default` is a fresh contact; a pair that
    /// leaves the law's range is reset to it.
    type History: HistoryData;
    fn force(&self, c: &ContactInput, h: &mut Self::History) -> ContactOutput;
    /// Largest normal stiffness (N/m) the law can present, for the critical time step.
    fn max_stiffness(&self, r_eff: f64) -> f64;
    /// Friction coefficient (for diagnostics and generation protocols).
    fn friction(&self) -> f64;
    /// The (stiffness N/m, dashpot N s/m) pairs the law puts along the normal and along the
    /// tangent of a contact between a circle of radius `r_eff` and a body of mass `m_eff`, for
    /// the damped step limit of a wall contact ([`crate::Stepper::unstable_wall_contact`]). The
    /// default is the largest stiffness along the normal and no dashpot (laws whose dashpot the
    /// check does not model).
    fn spring_dashpots(&self, r_eff: f64, _m_eff: f64) -> SpringDashpots {
        SpringDashpots {
            normal: (self.max_stiffness(r_eff), 0.0),
            tangential: (0.0, 0.0),
        }
    }
    /// Gap (m) beyond touching within which the law acts between circles of radii `r_i`, `r_j`
    /// (0: contact only). Pairs with a gap below it are evaluated with `delta < 0`; the Verlet
    /// list reaches r_i + r_j + range + skin. Must not decrease with the radii (the cell size
    /// uses `range(r_max, r_max)`).
    #[inline]
    fn range(&self, _r_i: f64, _r_j: f64) -> f64 {
        0.0
    }
    /// The same between a circle of radius `r` and a wall (default 0: walls act on touching
    /// circles only).
    #[inline]
    fn wall_range(&self, _r: f64) -> f64 {
        0.0
    }
    /// The law in the terms of the stepper's batched pair kernel, if it has them: the stepper
    /// then evaluates eight pairs per instruction (same bits as [`ContactLaw::force`]). Return
    /// `Some` only if `Self::History` is laid out as [`History`] (the kernel reads and writes
    /// the records as `History`) and `force` is, operation for operation, the [`Batched`] form.
    fn batched(&self) -> Option<Batched> {
        None
    }
}

/// The normal force of a law the batched pair kernel evaluates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BatchedNormal {
    /// k_n δ + c_n v_n, clipped at zero if `clip` ([`LinearSpringDashpot`]).
    Linear { k_n: f64, clip: bool },
    /// Su et al. 2020 Eq. 6's elastic-plastic envelope with its plastic overlap in
    /// [`History::delta_p`] ([`ElasticPlastic::normal`]), then the dashpot, clipped at zero.
    Plastic { k_e: f64, k_p: f64, f_y: f64 },
}

/// A law as the batched pair kernel sees it: a normal force ([`BatchedNormal`]) with the dashpot
/// `damping` of its normal stiffness, the tangential spring of [`tangential`] (dashpot
/// `t_frac` × c_n, Coulomb `mu` > 0) and an optional [`Rolling`] spring.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Batched {
    pub normal: BatchedNormal,
    pub damping: Damping,
    pub k_t: f64,
    pub t_frac: f64,
    pub mu: f64,
    pub rolling: Option<Rolling>,
}

/// A contact's springs and dashpots, as (k N/m, c N s/m), along the normal and the tangent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpringDashpots {
    pub normal: (f64, f64),
    pub tangential: (f64, f64),
}

impl SpringDashpots {
    /// A spring-dashpot law's pairs: normal (k_n, c_n), tangential (k_t, c_t) where the
    /// tangential spring acts (μ > 0), none otherwise.
    pub fn frictional(normal: (f64, f64), tangential: (f64, f64), mu: f64) -> Self {
        Self {
            normal,
            tangential: if mu > 0.0 { tangential } else { (0.0, 0.0) },
        }
    }
}

/// Calls `visit` with the concrete law inside a [`Law`] (static dispatch: the callee is
/// monomorphised per registered law, as the stepper's pair pass is in `Stepper::step_law`).
pub trait LawVisitor {
    type Output;
    fn visit<L: ContactLaw>(self, law: &L) -> Self::Output;
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
#[serde(deny_unknown_fields)]
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

/// Generates [`Law`] (the scene-selectable laws, serde `law = "<name>"` with the law's fields
/// beside it), its [`ContactLaw`] impl (dispatch per variant; the history is [`LawHistory`], the
/// largest registered history, each variant reading its own prefix), [`Law::name`] and
/// [`Law::visit`].
macro_rules! register_laws {
    ($($(#[$meta:meta])* $variant:ident($ty:ty) = $name:literal,)+) => {
        #[doc = concat!("The laws a scene can choose (`[contact] law = \"<name>\"`, the law's fields beside it):", $(" `", $name, "`",)+ ".")]
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        #[serde(tag = "law", rename_all = "snake_case")]
        pub enum Law {
            $($(#[$meta])* #[serde(rename = $name)] $variant($ty),)+
        }

        /// f64 slots of the largest history of the registered laws.
        pub const LAW_SLOTS: usize = max_slots(&[$(stride_of::<<$ty as ContactLaw>::History>()),+]);

        impl Law {
            /// The name a scene uses for the law.
            pub fn name(&self) -> &'static str {
                match self {
                    $(Law::$variant(_) => $name,)+
                }
            }

            /// `v.visit(law)` with the concrete law.
            #[inline]
            pub fn visit<V: LawVisitor>(&self, v: V) -> V::Output {
                match self {
                    $(Law::$variant(l) => v.visit(l),)+
                }
            }
        }

        impl ContactLaw for Law {
            type History = LawHistory;
            #[inline]
            fn force(&self, c: &ContactInput, h: &mut LawHistory) -> ContactOutput {
                match self {
                    $(Law::$variant(l) => l.force(c, h.prefix_mut::<<$ty as ContactLaw>::History>()),)+
                }
            }
            fn max_stiffness(&self, r_eff: f64) -> f64 {
                match self {
                    $(Law::$variant(l) => l.max_stiffness(r_eff),)+
                }
            }
            fn friction(&self) -> f64 {
                match self {
                    $(Law::$variant(l) => l.friction(),)+
                }
            }
            fn spring_dashpots(&self, r_eff: f64, m_eff: f64) -> SpringDashpots {
                match self {
                    $(Law::$variant(l) => l.spring_dashpots(r_eff, m_eff),)+
                }
            }
            #[inline]
            fn range(&self, r_i: f64, r_j: f64) -> f64 {
                match self {
                    $(Law::$variant(l) => l.range(r_i, r_j),)+
                }
            }
            #[inline]
            fn wall_range(&self, r: f64) -> f64 {
                match self {
                    $(Law::$variant(l) => l.wall_range(r),)+
                }
            }
            fn batched(&self) -> Option<Batched> {
                match self {
                    $(Law::$variant(l) => l.batched(),)+
                }
            }
        }
    };
}

// The registration list: one line per scene-selectable law.
register_laws! {
    Linear(LinearSpringDashpot) = "linear",
    Hertz(HertzMindlin) = "hertz",
    Plastic(ElasticPlastic) = "plastic",
}

const fn max_slots(s: &[usize]) -> usize {
    let (mut m, mut k) = (0, 0);
    while k < s.len() {
        if s[k] > m {
            m = s[k];
        }
        k += 1;
    }
    m
}

/// The history of [`Law`]: room for the largest registered history; each variant uses its own
/// history type as a prefix (so with today's laws it is laid out as [`History`]).
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct LawHistory(pub [f64; LAW_SLOTS]);

impl Default for LawHistory {
    fn default() -> Self {
        Self([0.0; LAW_SLOTS])
    }
}

impl LawHistory {
    /// The first `size_of::<H>()` bytes as `H`.
    #[inline]
    fn prefix_mut<H: HistoryData>(&mut self) -> &mut H {
        const { assert!(stride_of::<H>() <= LAW_SLOTS) };
        bytemuck::from_bytes_mut(&mut bytemuck::bytes_of_mut(self)[..size_of::<H>()])
    }
}
