//! A compressed triangular packing of equal disks in a periodic box, undamped and frictionless
//! under the linear law or Hertz's, set vibrating by small random velocities: its total energy
//! (kinetic plus the elastic energy of each contact, ½ k δ² or (2/5) K δ^{5/2}) is conserved by
//! the exact dynamics, so the drift of the integrator's energy measures the step. Each disk is
//! held by six contacts, the stiffest spring a grain of a dense packing sees; the `dem-step-map`
//! stage runs it beside the isolated pair ([`super::head_on`]) to show how far the critical step
//! sqrt(m_min/k_max) holds in a packing.

use crate::contact::{HertzMindlin, Law, LinearSpringDashpot};
use crate::{Bodies, ClumpShape, Damping, DemError, Domain, StepParams, Stepper, System, Vec2, Vector};
use rand::RngExt;

/// Disk radius (m) and the compression of the lattice (overlap over diameter).
pub const RADIUS: f64 = 0.5;
pub const COMPRESSION: f64 = 0.01;

/// What one run did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drift {
    /// Largest |E(t) − E(0)| over the run, over the initial kinetic energy (∞ if non-finite).
    pub energy_error: f64,
    /// The stepper's critical step (s).
    pub critical: f64,
    pub steps: u64,
}

/// The linear law of the case: stiffness `k` (N/m), no damping, no friction.
pub fn law(k: f64) -> LinearSpringDashpot {
    LinearSpringDashpot::new(k, 0.0, Damping::Ratio(0.0), 0.0)
}

/// Hertz's law of the case (Leonardi et al. 2014 Eq. 5), undamped and frictionless, with its
/// tangent stiffness (3/2) K √δ at the lattice's overlap equal to `k` (N/m): Young's modulus
/// from K = (2/3) Y √r_eff / (1 − ν²), ν = 0.3, r_eff = R/2. Its critical step is computed at
/// the default largest overlap, 5 % of r_eff, a quarter above the lattice's 4 %.
pub fn hertz(k: f64) -> HertzMindlin {
    let (poisson, r_eff, delta) = (0.3, RADIUS / 2.0, COMPRESSION * 2.0 * RADIUS);
    let prefactor = k / (1.5 * delta.sqrt());
    HertzMindlin {
        young: prefactor * 1.5 * (1.0 - poisson * poisson) / r_eff.sqrt(),
        poisson,
        a_damp: 0.0,
        eta: 0.0,
        mu: 0.0,
        max_overlap: 0.05,
    }
}

/// The laws whose energy the case conserves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PackingLaw {
    /// [`law`]: ½ k δ² per contact.
    Linear,
    /// [`hertz`]: (2/5) K δ^{5/2} per contact.
    Hertz,
}

impl PackingLaw {
    /// The law of the case with tangent stiffness `k` at the lattice's overlap.
    pub fn law(self, k: f64) -> Law {
        match self {
            PackingLaw::Linear => Law::Linear(law(k)),
            PackingLaw::Hertz => Law::Hertz(hertz(k)),
        }
    }

    /// The elastic energy of a contact of overlap δ.
    fn potential(self, k: f64, delta: f64) -> f64 {
        match self {
            PackingLaw::Linear => 0.5 * k * delta * delta,
            PackingLaw::Hertz => 0.4 * hertz(k).prefactor(RADIUS / 2.0) * delta * delta * delta.sqrt(),
        }
    }
}

fn energy(sys: &System, which: PackingLaw, k: f64) -> f64 {
    let b = &sys.bodies;
    let kinetic: f64 = (0..b.len()).map(|i| 0.5 * b.mass[i] * b.vel[i].norm2()).sum();
    let mut elastic = 0.0;
    for i in 0..b.len() {
        for j in i + 1..b.len() {
            let overlap = 2.0 * RADIUS - sys.domain.min_image(b.pos[j] - b.pos[i]).norm();
            if overlap > 0.0 {
                elastic += which.potential(k, overlap);
            }
        }
    }
    kinetic + elastic
}

/// Run `nx` × `ny` disks (ny even) under `which` law, of tangent stiffness `k` at the lattice's
/// overlap, for `duration` critical steps at `ratio` × the critical step; `force` runs a step the
/// stepper refuses. Errors are the stepper's set-up refusals.
#[allow(clippy::too_many_arguments)]
pub fn run_law(
    which: PackingLaw,
    k: f64,
    nx: usize,
    ny: usize,
    ratio: f64,
    duration: f64,
    force: bool,
    seed: u64,
) -> Result<Drift, DemError> {
    let d = 2.0 * RADIUS * (1.0 - COMPRESSION);
    let h = d * 3f64.sqrt() / 2.0;
    let mut bodies = Bodies::new();
    let disk = ClumpShape::disk(RADIUS);
    for row in 0..ny {
        for col in 0..nx {
            let x = (col as f64 + 0.5 * (row % 2) as f64 + 0.25) * d;
            bodies.add(&disk, 1.0, Vec2::new(x, (row as f64 + 0.5) * h), 0.0)?;
        }
    }
    let mut r = crate::generate::rng(seed);
    // velocities of a twentieth of the compression's overlap per natural period: small vibrations
    let v0 = 0.05 * COMPRESSION * 2.0 * RADIUS * (k / bodies.mass[0]).sqrt();
    for v in bodies.vel.iter_mut() {
        *v = Vec2::new(r.random::<f64>() - 0.5, r.random::<f64>() - 0.5) * (2.0 * v0);
    }
    let mut sys = System::new(
        bodies,
        Domain::periodic(Vec2::ZERO, Vec2::new(nx as f64 * d, ny as f64 * h)),
    );
    let law = &which.law(k);
    let (critical, _, _) = Stepper::critical_time_step(&sys, law, law);
    let dt = ratio * critical;
    let p = StepParams::new(dt, 0.05);
    let mut st = if force {
        Stepper::past_critical_check()
    } else {
        Stepper::new()
    };
    let kinetic0: f64 = (0..sys.bodies.len())
        .map(|i| 0.5 * sys.bodies.mass[i] * sys.bodies.vel[i].norm2())
        .sum();
    let e0 = energy(&sys, which, k);
    let steps = (duration / ratio).ceil() as u64;
    let mut worst = 0.0f64;
    for step in 1..=steps {
        match st.step(&p, law, law, &mut sys) {
            Ok(()) => {}
            Err(DemError::NonFinite { .. }) => {
                return Ok(Drift {
                    energy_error: f64::INFINITY,
                    critical,
                    steps: step,
                });
            }
            Err(e) => return Err(e),
        }
        let e = (energy(&sys, which, k) - e0).abs() / kinetic0;
        worst = if e.is_finite() {
            worst.max(e)
        } else {
            f64::INFINITY
        };
        if worst > 1e6 {
            return Ok(Drift {
                energy_error: worst,
                critical,
                steps: step,
            });
        }
    }
    Ok(Drift {
        energy_error: worst,
        critical,
        steps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_steps_conserve_the_energy_and_large_ones_do_not() {
        let small = run_law(PackingLaw::Linear, 1e4, 8, 8, 0.05, 100.0, false, 1).unwrap();
        let large = run_law(PackingLaw::Linear, 1e4, 8, 8, 2.0, 100.0, true, 1).unwrap();
        eprintln!(
            "packing: energy error {:.2e} at 0.05 dt_crit, {:.2e} at 2",
            small.energy_error, large.energy_error
        );
        assert!(small.energy_error < 0.05, "{small:?}");
        assert!(large.energy_error > 1.0, "{large:?}");
    }
}
