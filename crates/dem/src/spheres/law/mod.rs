//! Contact laws of the sphere engine behind one trait ([`SphereLaw`]), the 3D twin of the 2D
//! engine's [`crate::ContactLaw`]: each law is a small struct declaring its range beyond
//! contact (so lubrication acts across gaps), its per-contact history and its stable time step;
//! the stepper is generic over it and monomorphised, so `force` inlines into the pair loop (the
//! HOOMD-blue "generic loop + small law struct" habit).
//!
//! Sign conventions: `n` is the unit normal from sphere i towards sphere j (or the wall);
//! `delta = r_i + r_j − distance` is the overlap, negative across a gap; `v_rel` is the velocity
//! of i's contact point minus j's; `dv = v_i − v_j` of the centres. The returned force acts on i
//! at the contact point (j receives its negative); the couples `torque_i`, `torque_j` are added
//! on top of the moments of the force about the centres.
//!
//! - `hertz_mindlin.rs`: [`HertzMindlinSpring`], LIGGGHTS `hertz tangential history`;
//! - `linear.rs`: [`LinearSpring`], Ness et al. (2017) Eq. 6 (Cundall & Strack spring, no damping);
//! - `lubrication.rs`: [`Lubrication`], Ness et al. (2017) Eqs. 3-5, and [`Lubricated`], it
//!   added to any contact law.

pub mod hertz_mindlin;
pub mod linear;
pub mod lubrication;

use super::error::SphereError;
use crate::history::HistoryData;
use crate::vector::{Vec3, Vector};

pub use hertz_mindlin::{Elastic, HertzMindlinSpring, Surface};
pub use linear::LinearSpring;
pub use lubrication::{Lubricated, Lubrication};

/// Geometry and kinematics of one sphere-sphere or sphere-wall interaction, seen from sphere i.
#[derive(Clone, Copy, Debug)]
pub struct Interaction {
    /// Unit normal from i towards j (or the wall).
    pub n: Vec3,
    /// Overlap (m): positive in contact, negative across a gap (laws with a range).
    pub delta: f64,
    /// Radius of i (m).
    pub r_i: f64,
    /// Radius of j (m); infinite for a plane wall.
    pub r_j: f64,
    /// R* = r_i r_j / (r_i + r_j) (r_i for a wall), m.
    pub r_eff: f64,
    /// m* = m_i m_j / (m_i + m_j) of the bodies the spheres belong to (m_i for a wall), kg.
    pub m_eff: f64,
    /// Velocity of i's contact point relative to j's (m/s).
    pub v_rel: Vec3,
    /// Velocity of i's centre relative to j's (the wall's velocity for a wall), m/s.
    pub dv: Vec3,
    /// Angular velocity of i relative to j (ω_i for a wall), rad/s.
    pub dw: Vec3,
    /// True for a sphere-wall contact.
    pub wall: bool,
    /// True if one sphere of the pair is frozen (a wall of grains, Ness et al. 2017): the
    /// friction of [`LinearSpring`] is then μ_w, as against a plane wall, its geometry that of
    /// two spheres. With `wall`, the pair table of friction: μ_p between mobile spheres, μ_w
    /// against walls of either kind.
    pub frozen: bool,
    /// Time step (s).
    pub dt: f64,
}

/// What a law returns for one interaction.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Response {
    /// Force on i, acting at the contact point (N).
    pub f: Vec3,
    /// Couple on i besides the moment of `f` (N m).
    pub torque_i: Vec3,
    /// Couple on j besides the moment of −`f` (N m; ignored for a wall).
    pub torque_j: Vec3,
    /// The hydrodynamic part of `f` (N): lubrication, for the split of the stress into
    /// Ness et al.'s Σ^H and Σ^C (Eq. 7a, 7b); zero for a contact law.
    pub f_hydro: Vec3,
}

/// A contact law of spheres.
///
/// Adding a law: one file in `spheres/law/` with a struct implementing this trait; the stepper
/// ([`super::SphereStepper`]) needs no change.
pub trait SphereLaw: Clone + PartialEq + Send + Sync {
    /// Per-contact state carried between steps, across Verlet-list rebuilds and in checkpoints
    /// (stored as f64 slots, [`crate::Histories`]). `Default` is a fresh contact; a pair beyond
    /// the law's range is reset to it.
    type History: HistoryData;
    /// The response to one interaction, updating its history.
    fn force(&self, c: &Interaction, h: &mut Self::History) -> Response;
    /// Gap (m) beyond touching within which the law acts between spheres of radii `r_i`, `r_j`
    /// (0: contact only). Must not decrease with the radii (the cell size uses
    /// `range(r_max, r_max)`).
    #[inline]
    fn range(&self, _r_i: f64, _r_j: f64) -> f64 {
        0.0
    }
    /// The same between a sphere of radius `r` and a plane wall (default 0).
    #[inline]
    fn wall_range(&self, _r: f64) -> f64 {
        0.0
    }
    /// Refuse non-physical parameters, naming the one at fault.
    fn check(&self) -> Result<(), SphereError>;
    /// The largest time step (s) this law accepts for a sphere of radius `r` and mass `m`
    /// (against an identical sphere and against a wall), and what sets it.
    fn max_time_step(&self, r: f64, m: f64) -> TimeStepLimit;
    /// The sphere-sphere constants of the Hertz-Mindlin spring law, if this is it: the stepper
    /// then evaluates pairs with the batched kernel (`spheres::hm_batched`, the same bits as
    /// [`Self::force`]). Default: none, every pair through `force`.
    #[inline]
    fn hertz_mindlin_pairs(&self) -> Option<hertz_mindlin::Coeffs> {
        None
    }
}

/// A time-step bound and its origin, for the refusal message.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeStepLimit {
    /// The largest accepted step (s).
    pub dt: f64,
    /// What sets it, e.g. "0.2 of the Rayleigh time step".
    pub bound: &'static str,
}

impl TimeStepLimit {
    /// The smaller of two bounds.
    pub fn min(self, o: TimeStepLimit) -> TimeStepLimit {
        if o.dt < self.dt { o } else { self }
    }
}

/// Check that a step fraction lies in (0, 1].
pub(crate) fn check_fraction(name: &'static str, value: f64) -> Result<(), SphereError> {
    if value > 0.0 && value <= 1.0 {
        Ok(())
    } else {
        Err(SphereError::BadParameter {
            name,
            value,
            why: "a fraction of the stability limit must lie in (0, 1]",
        })
    }
}

/// The tangential spring of a contact with Coulomb cap (Cundall & Strack 1979), shared by the
/// Hertz-Mindlin and linear laws, in the *total* form F_t = −k_t ξ − c_t v_t: ξ is the
/// tangential displacement accumulated while in contact, first carried onto the current tangent
/// plane (projected, length kept), then incremented by v_t dt. With a constant k_t (linear law)
/// this is the same as the incremental form dF_t = −k_t v_t dt; with the Hertz-Mindlin k_t ∝ √δ
/// the total form lets |F_t| grow with δ at fixed ξ (as LIGGGHTS `tangential history` does),
/// where the incremental form would not. When |F_t| > μ max(F_n, 0) the force is scaled onto
/// the cone and the spring reset to ξ = −(F_t + c_t v_t)/k_t, so it holds exactly the force that
/// slides. Returns F_t.
#[inline(always)]
pub(crate) fn tangential_spring(
    xi: &mut Vec3,
    n: Vec3,
    vt: Vec3,
    dt: f64,
    k_t: f64,
    c_t: f64,
    cap: f64,
) -> Vec3 {
    let xn = xi.dot(n);
    if xn != 0.0 {
        let old2 = xi.norm2();
        let p = *xi - n * xn;
        let p2 = p.norm2();
        *xi = if p2 > 0.0 {
            p * (old2 / p2).sqrt()
        } else {
            Vec3::ZERO
        };
    }
    *xi += vt * dt;
    let mut f_t = -(*xi * k_t) - vt * c_t;
    let ft2 = f_t.norm2();
    if ft2 > cap * cap {
        f_t = if ft2 > 0.0 {
            f_t * (cap / ft2.sqrt())
        } else {
            Vec3::ZERO
        };
        *xi = if k_t > 0.0 {
            -(f_t + vt * c_t) * (1.0 / k_t)
        } else {
            Vec3::ZERO
        };
    }
    f_t
}
