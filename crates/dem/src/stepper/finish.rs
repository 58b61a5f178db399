//! The finish pass: body forces (gravity and the held external load `ext_force`/`ext_torque`),
//! viscous and local damping, and the closing half kick, per body.

use super::{StepParams, Stepper};
use crate::scratch::Kick;
use crate::system::System;
use crate::vector::Vec2;
use rayon::prelude::*;

/// Body forces, damping and the closing half kick for one body.
pub(super) struct Finish {
    g: Vec2,
    gv: f64,
    al: f64,
    h: f64,
}

impl Finish {
    pub(super) fn new(p: &StepParams, h: f64) -> Self {
        Self {
            g: p.gravity * p.gravity_factor,
            gv: p.viscous_damping,
            al: p.local_damping,
            h,
        }
    }

    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn apply(
        &self,
        f: &mut Vec2,
        t: &mut f64,
        v: &mut Vec2,
        w: &mut f64,
        m: f64,
        i: f64,
        kick: &Kick,
        ef: Vec2,
        et: f64,
    ) {
        *f += self.g * m + ef;
        *t += et;
        if self.gv > 0.0 {
            *f -= *v * (self.gv * m);
            *t -= self.gv * i * *w;
        }
        if self.al > 0.0 {
            f.x -= self.al * f.x.abs() * sign(v.x);
            f.y -= self.al * f.y.abs() * sign(v.y);
            *t -= self.al * t.abs() * sign(*w);
        }
        if self.h != 0.0 {
            // The opening kick of this step refreshed `kick` for this h.
            *v += *f * kick.hm;
            *w += *t * kick.hi;
        }
    }
}

impl Stepper {
    /// [`Finish::apply`] on every body, in parallel.
    pub(super) fn finish(&mut self, sys: &mut System, fin: &Finish) {
        let kick = &self.kick;
        let Bodies5 {
            force,
            torque,
            vel,
            omega,
            mass,
            inertia,
            ext_force,
            ext_torque,
            ..
        } = Bodies5::of(&mut sys.bodies);
        force
            .par_iter_mut()
            .zip(torque.par_iter_mut())
            .zip(vel.par_iter_mut().zip(omega.par_iter_mut()))
            .enumerate()
            .with_min_len(1024)
            .for_each(|(k, ((f, t), (v, w)))| {
                fin.apply(
                    f,
                    t,
                    v,
                    w,
                    mass[k],
                    inertia[k],
                    &kick[k],
                    ext_force[k],
                    ext_torque[k],
                );
            });
    }
}

#[inline]
fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Split borrows of the fields the force passes need.
pub(super) struct Bodies5<'a> {
    pub force: &'a mut Vec<Vec2>,
    pub torque: &'a mut Vec<f64>,
    pub vel: &'a mut Vec<Vec2>,
    pub omega: &'a mut Vec<f64>,
    pub mass: &'a [f64],
    pub inertia: &'a [f64],
    pub ext_force: &'a [Vec2],
    pub ext_torque: &'a [f64],
    pub cstart: &'a [usize],
}

impl<'a> Bodies5<'a> {
    pub(super) fn of(b: &'a mut crate::body::Bodies) -> Self {
        Self {
            force: &mut b.force,
            torque: &mut b.torque,
            vel: &mut b.vel,
            omega: &mut b.omega,
            mass: &b.mass,
            inertia: &b.inertia,
            ext_force: &b.ext_force,
            ext_torque: &b.ext_torque,
            cstart: &b.circle_start,
        }
    }
}
