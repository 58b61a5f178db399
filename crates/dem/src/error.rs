//! Errors of the DEM kernels: each names the parameter, its value, the limit and the fix.

use thiserror::Error;

#[derive(Debug, Error, PartialEq)]
pub enum DemError {
    #[error("a clump needs at least one circle; give the template one or more (x, y, r) rows")]
    EmptyClump,
    #[error("circle radius r = {r} must be positive and finite; fix the particle file or generator")]
    BadRadius { r: f64 },
    #[error(
        "time step dt = {dt:e} s is above the largest accepted step {limit:.4e} s (the lightest grain held \
         by six grain springs and two walls; the critical time step sqrt(m_min/k_max) is {critical:.4e} s \
         with m_min = {m_min:.4e} kg, k_max = {k_max:.4e} N/m; a dense packing blows up beyond it, \
         docs/stability.md); lower dt below {limit:.4e} s or soften the contacts"
    )]
    TimeStepTooLarge {
        dt: f64,
        limit: f64,
        critical: f64,
        m_min: f64,
        k_max: f64,
    },
    #[error(
        "time step dt = {dt:e} s is above {limit:.4e} s, the largest step at which body {body} resting \
         on a wall stays still: the contact's spring ({k_wall:.4e} N/m) and dashpot ({c_wall:.4e} N s/m) \
         act off the centroid, where the grain moves like a lighter mass than the dashpot was set \
         for, and past this step the explicit dashpot overshoots every step, so grains rattle \
         against the walls or creep along them without end (docs/stability.md, \"Wall contacts of \
         clumps\"); lower dt below {limit:.4e} s, or lower the wall law's damping ratio"
    )]
    WallContactStepTooLarge {
        dt: f64,
        limit: f64,
        body: usize,
        k_wall: f64,
        c_wall: f64,
    },
    #[error(
        "the membrane bonds' dashpots ([bonds] params.damping) are too stiff for the time step dt = \
         {dt:e} s: at body {body} their decay rate times the step is {number:.3}, above {limit} \
         (past it the explicit dashpots overshoot and the grains blow up within a few steps; \
         docs/stability.md, \"Damped membrane bonds\"); lower the damping ratio to at most \
         {largest_ratio:.3}, or dt to at most {largest_step:.4e} s"
    )]
    BondDashpotsTooStiff {
        dt: f64,
        number: f64,
        limit: f64,
        body: usize,
        largest_ratio: f64,
        largest_step: f64,
    },
    #[error("body {body}: non-finite state at step {step} (position or velocity is NaN/inf); {}", blame(*step))]
    NonFinite { body: usize, step: u64 },
    #[error(
        "time step dt = {dt:e} s must be a positive, finite number of seconds; give dt below the critical step"
    )]
    BadTimeStep { dt: f64 },
    #[error("{name} = {value} is invalid: {why}")]
    BadParameter {
        name: &'static str,
        value: f64,
        why: &'static str,
    },
    #[error(
        "cell list would need {cells} cells (domain / cutoff); the domain is too large for the particle size \
         — give a smaller domain (walls) or larger particles"
    )]
    TooManyCells { cells: usize },
}

/// What a non-finite state at `step` points to: in the first step the initial state (a NaN
/// position, velocity or force, coincident circles), later an unstable run.
fn blame(step: u64) -> &'static str {
    if step == 0 {
        "it is not finite from the start, so the initial state is to blame, not dt: check the particle \
         positions and velocities, coincident circles, gravity and the wall velocities"
    } else {
        "the run blew up: lower dt (or stiffen less, damp more)"
    }
}
