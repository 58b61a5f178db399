//! Two equal disks (radius ½, density 1) meeting head on at relative speed v, in open space: the
//! coefficient of restitution (relative speed after / before) and the contact's duration
//! against their exact values (linear spring-dashpot: e = exp(−πζ/√(1−ζ²)), t_c =
//! π/(√(k/m*)√(1−ζ²)); REFERENCES.md, DEM) or a converged run. The `dem-step-map` stage runs it
//! at dt from a twentieth of the critical step to several times it, forced past the stepper's
//! refusal, to show where the refusal stands against what the integrator does.

use crate::{ClumpShape, ContactLaw, DemError, Domain, StepParams, Stepper, System, Vec2, Vector};

/// Radius of each disk (m); the effective radius of the pair is half of it.
pub const RADIUS: f64 = 0.5;

/// What one collision did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Collision {
    /// Relative normal speed after the contact over the one before (NaN if the state went
    /// non-finite).
    pub restitution: f64,
    /// Contact duration (s): steps with overlap × dt.
    pub duration: f64,
    /// Largest overlap over the effective radius r_i r_j/(r_i + r_j).
    pub max_overlap: f64,
    /// The stepper's critical step for this pair and law (s).
    pub critical: f64,
    /// Steps run; the run ends when the disks separate, or after `max_steps`.
    pub steps: u64,
    /// False when the stepper stopped the run on a non-finite state, or the disks never
    /// separated within `max_steps`.
    pub finished: bool,
}

/// The mass m* = m/2 of the pair (density 1 per unit depth).
pub fn effective_mass() -> f64 {
    0.5 * std::f64::consts::PI * RADIUS * RADIUS
}

/// Collide at relative speed `v` with step `dt`; `force` runs a dt above the critical step that
/// the stepper refuses otherwise ([`Stepper::past_critical_check`]). Errors are the stepper's
/// refusals at set-up.
pub fn run<L: ContactLaw>(
    law: &L,
    v: f64,
    dt: f64,
    force: bool,
    max_steps: u64,
) -> Result<Collision, DemError> {
    let d = ClumpShape::disk(RADIUS);
    // start a quarter step's travel apart, so the run is the contact itself
    let x0 = RADIUS + 0.25 * v * dt;
    let mut bodies = crate::Bodies::new();
    bodies.add(&d, 1.0, Vec2::new(-x0, 0.0), 0.0)?;
    bodies.add(&d, 1.0, Vec2::new(x0, 0.0), 0.0)?;
    let mut s = System::new(
        bodies,
        Domain::open(Vec2::new(-10.0, -10.0), Vec2::new(10.0, 10.0)),
    );
    s.bodies.vel[0] = Vec2::new(0.5 * v, 0.0);
    s.bodies.vel[1] = Vec2::new(-0.5 * v, 0.0);
    let (critical, _, _) = Stepper::critical_time_step(&s, law, law);
    let p = StepParams::new(dt, 0.05);
    let mut st = if force {
        Stepper::past_critical_check()
    } else {
        Stepper::new()
    };
    // What the pair did, measured when it parted or the steps ran out.
    let outcome = |s: &System, touching: u64, max_overlap: f64, steps: u64, finished: bool| Collision {
        restitution: (s.bodies.vel[1].x - s.bodies.vel[0].x) / v,
        duration: touching as f64 * dt,
        max_overlap,
        critical,
        steps,
        finished,
    };
    let (mut touching, mut touched, mut max_overlap) = (0u64, false, 0.0f64);
    let r_eff = 0.5 * RADIUS;
    for k in 1..=max_steps {
        match st.step(&p, law, law, &mut s) {
            Ok(()) => {}
            Err(DemError::NonFinite { .. }) => {
                return Ok(Collision {
                    restitution: f64::NAN,
                    duration: touching as f64 * dt,
                    max_overlap: f64::INFINITY,
                    critical,
                    steps: k,
                    finished: false,
                });
            }
            Err(e) => return Err(e),
        }
        let overlap = 2.0 * RADIUS - (s.bodies.pos[1] - s.bodies.pos[0]).norm();
        if overlap > 0.0 {
            touching += 1;
            touched = true;
            max_overlap = max_overlap.max(overlap / r_eff);
        } else if touched {
            return Ok(outcome(&s, touching, max_overlap, k, true));
        }
    }
    Ok(outcome(&s, touching, max_overlap, max_steps, false))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Damping;
    use crate::contact::LinearSpringDashpot;

    #[test]
    fn refused_above_the_critical_step_unless_forced() {
        let law = LinearSpringDashpot::new(1e4, 5e3, Damping::Ratio(0.1), 0.0);
        let crit = run(&law, 0.1, 1e-4, false, 10).unwrap().critical;
        assert!(matches!(
            run(&law, 0.1, 1.5 * crit, false, 100),
            Err(DemError::TimeStepTooLarge { .. })
        ));
        let c = run(&law, 0.1, 1.5 * crit, true, 100).unwrap();
        assert!(c.steps > 0, "{c:?}");
    }
}
