//! The linear spring contact of Ness et al. (2017), Eq. 6 (after Cundall & Strack 1979): for a
//! contact of overlap δ > 0,
//! - normal F_n = k_n δ (Eq. 6a), purely repulsive, with no damping ("the damping arising from
//!   hydrodynamic interactions is always sufficient", Ness et al. Sect. "Simulation Model");
//! - tangential F_t = −k_t u (Eq. 6b), u the tangential displacement updated incrementally
//!   during the contact (with k_t constant the total and incremental forms coincide; see
//!   [`super::tangential_spring`]), k_t = (2/7) k_n in every case of Ness's Table 1;
//! - Coulomb |F_t| ≤ μ F_n, with μ_p between spheres and μ_w against plane walls;
//! - the torque Γ_i = −(d_i/2)(n_ij × F_t) (Eq. 6c, n_ij from j to i) is the moment of F_t about
//!   the centre; the stepper takes the arm to the contact point, r_i − δ/2, so that a pair
//!   conserves angular momentum (the arms differ from d_i/2 by δ/2 ≪ 0.01 d here).
//!
//! Stable step: the undamped oscillator of two identical spheres (m* = m/2) is stable under
//! velocity Verlet for dt < 2 √(m*/k_n); the law accepts `stability_fraction` (default 0.2) of it.

use super::{Interaction, Response, SphereLaw, TimeStepLimit, check_fraction, tangential_spring};
use crate::spheres::error::SphereError;
use crate::vector::{Vec3, Vector};
use serde::{Deserialize, Serialize};

/// The default fraction of a stability limit accepted as the time step.
pub const STABILITY_FRACTION: f64 = 0.2;

fn default_fraction() -> f64 {
    STABILITY_FRACTION
}

/// Linear spring with a tangential spring and Coulomb friction, no damping (Ness et al. 2017,
/// Eq. 6).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinearSpring {
    /// Normal stiffness k_n (N/m).
    pub k_n: f64,
    /// Tangential stiffness k_t (N/m).
    pub k_t: f64,
    /// Sphere-sphere friction coefficient μ_p.
    pub mu: f64,
    /// Sphere-wall friction coefficient μ_w.
    pub wall_mu: f64,
    /// The time step accepted: at most this fraction of 2 √(m*/k_n) (default 0.2).
    #[serde(default = "default_fraction")]
    pub stability_fraction: f64,
}

impl LinearSpring {
    /// Ness et al.'s choice: k_t = (2/7) k_n, friction μ_p between spheres and μ_w on walls.
    pub fn ness(k_n: f64, mu_p: f64, mu_w: f64) -> Self {
        Self {
            k_n,
            k_t: 2.0 / 7.0 * k_n,
            mu: mu_p,
            wall_mu: mu_w,
            stability_fraction: STABILITY_FRACTION,
        }
    }
}

fn positive(name: &'static str, v: f64) -> Result<(), SphereError> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(SphereError::BadParameter {
            name,
            value: v,
            why: "it must be positive and finite",
        })
    }
}

fn friction(name: &'static str, v: f64) -> Result<(), SphereError> {
    if v >= 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(SphereError::BadParameter {
            name,
            value: v,
            why: "a friction coefficient must be zero or positive and finite",
        })
    }
}

impl SphereLaw for LinearSpring {
    /// The tangential displacement u (m).
    type History = Vec3;

    #[inline]
    fn force(&self, c: &Interaction, u: &mut Vec3) -> Response {
        if c.delta <= 0.0 {
            *u = Vec3::ZERO;
            return Response::default();
        }
        let f_n = self.k_n * c.delta;
        let vt = c.v_rel - c.n * c.v_rel.dot(c.n);
        let mu = if c.wall || c.frozen { self.wall_mu } else { self.mu };
        let f_t = tangential_spring(u, c.n, vt, c.dt, self.k_t, 0.0, mu * f_n);
        Response {
            f: f_t - c.n * f_n,
            ..Response::default()
        }
    }

    fn check(&self) -> Result<(), SphereError> {
        positive("normal stiffness k_n (N/m)", self.k_n)?;
        positive("tangential stiffness k_t (N/m)", self.k_t)?;
        friction("sphere-sphere friction coefficient mu_p", self.mu)?;
        friction("sphere-wall friction coefficient mu_w", self.wall_mu)?;
        check_fraction("stability_fraction", self.stability_fraction)
    }

    fn max_time_step(&self, _r: f64, m: f64) -> TimeStepLimit {
        TimeStepLimit {
            dt: self.stability_fraction * 2.0 * (0.5 * m / self.k_n).sqrt(),
            bound: "stability_fraction (default 0.2) of the linear spring's Verlet limit 2 sqrt(m*/k_n), m* = m/2",
        }
    }
}
