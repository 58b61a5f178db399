//! User forces: a [`ForceHook`] passed to [`super::Stepper::step_with`] (or `step_law_with`) adds
//! forces and torques to the bodies at every force evaluation, after the contact, wall, bond and
//! membrane forces and before the finish pass (gravity, `ext_force`/`ext_torque`, damping,
//! closing half kick), as a LAMMPS `post_force` fix. The held external load of the coupling
//! (`Bodies::ext_force`/`ext_torque`) needs no hook: the finish pass adds it.

use crate::system::System;
use crate::vector::Vec2;

/// Forces a caller adds to the bodies (drivers, fields, test loads).
pub trait ForceHook {
    /// Add to `force[k]` and `torque[k]` of body k. `sys` is the state at the force evaluation:
    /// positions at time `t`, velocities at the half step (as every velocity-dependent force of
    /// velocity Verlet); its `bodies.force`/`bodies.torque` are empty during the call (the sums
    /// so far are in `force`/`torque`). Called once before the first step (t = `sys.time`, to
    /// prime F(0)) and once per step.
    fn post_force(&mut self, t: f64, sys: &System, force: &mut [Vec2], torque: &mut [f64]);
}

/// Closures `|t, sys, force, torque| ...` are hooks.
impl<F: FnMut(f64, &System, &mut [Vec2], &mut [f64])> ForceHook for F {
    fn post_force(&mut self, t: f64, sys: &System, force: &mut [Vec2], torque: &mut [f64]) {
        self(t, sys, force, torque)
    }
}

pub(super) fn user_forces(hook: &mut dyn ForceHook, t: f64, sys: &mut System) {
    let mut force = std::mem::take(&mut sys.bodies.force);
    let mut torque = std::mem::take(&mut sys.bodies.torque);
    hook.post_force(t, sys, &mut force, &mut torque);
    sys.bodies.force = force;
    sys.bodies.torque = torque;
}
