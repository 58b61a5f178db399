//! User forces on spheres: a [`SphereForceHook`] passed to
//! [`super::SphereStepper::step_with`] adds forces and torques to the spheres at every force
//! evaluation, after the contact forces and gravity and before the clumps gather their members'
//! forces and the closing half kick, as the 2D engine's [`crate::ForceHook`] (a LAMMPS
//! `post_force` fix). Forces on a clump's member act on the clump at the member's centre.

use super::system::SphereSystem;
use crate::vector::Vec3;

/// Forces a caller adds to the spheres (hydrodynamic forces of a coupling, drivers, tests).
pub trait SphereForceHook {
    /// Add to `force[k]` and `torque[k]` of sphere k. `sys` is the state at the force
    /// evaluation: positions at time `t`, velocities at the half step (as every
    /// velocity-dependent force of velocity Verlet); its `spheres.force`/`spheres.torque` are
    /// empty during the call (the sums so far are in `force`/`torque`). Called once before the
    /// first step (t = 0, to prime F(0)) and once per step.
    fn post_force(&mut self, t: f64, sys: &SphereSystem, force: &mut [Vec3], torque: &mut [Vec3]);
}

/// Closures `|t, sys, force, torque| ...` are hooks.
impl<F: FnMut(f64, &SphereSystem, &mut [Vec3], &mut [Vec3])> SphereForceHook for F {
    fn post_force(&mut self, t: f64, sys: &SphereSystem, force: &mut [Vec3], torque: &mut [Vec3]) {
        self(t, sys, force, torque)
    }
}

/// No user forces.
pub struct NoHook;

impl SphereForceHook for NoHook {
    #[inline]
    fn post_force(&mut self, _: f64, _: &SphereSystem, _: &mut [Vec3], _: &mut [Vec3]) {}
}

/// Call `hook` with the force and torque arrays taken out of `sys`.
pub(super) fn user_forces(hook: &mut impl SphereForceHook, t: f64, sys: &mut SphereSystem) {
    let mut force = std::mem::take(&mut sys.spheres.force);
    let mut torque = std::mem::take(&mut sys.spheres.torque);
    hook.post_force(t, sys, &mut force, &mut torque);
    sys.spheres.force = force;
    sys.spheres.torque = torque;
}
