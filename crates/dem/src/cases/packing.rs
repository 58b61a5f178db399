//! A compressed triangular packing of equal disks in a periodic box, undamped and frictionless
//! under the linear law or Hertz's, set vibrating by small random velocities: its total energy
//! (kinetic plus the elastic energy of each contact, ½ k δ² or (2/5) K δ^{5/2}) is conserved by
//! the exact dynamics, so the drift of the integrator's energy measures the step. Each disk is
//! held by six contacts, the stiffest spring a grain of a dense packing sees; the `dem-step-map`
//! stage runs it beside the isolated pair ([`super::head_on`]) to show how far the critical step
//! sqrt(m_min/k_max) holds in a packing.
//!
//! Under Su's elastic-plastic law ([`plastic`]) the contacts yield and the energy is not
//! conserved; that row is judged by the kinetic energy left in the second half of the run
//! ([`Drift::late_kinetic`]) against a run at a fiftieth of the critical step.

use crate::contact::{ElasticPlastic, HertzMindlin, Law, LinearSpringDashpot};
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
    /// Mean kinetic energy over the second half of the run, over the initial one (∞ if the run
    /// went non-finite).
    pub late_kinetic: f64,
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

/// Su's elastic-plastic law (Sect. 2.3, Eq. 6 at a fixed F_y) for the case: elastic stiffness
/// `k`, plastic slope k/10, undamped and frictionless, yielding at half the force of the
/// lattice's overlap, so every contact yields at the first step and the vibrations lose energy
/// on the hysteresis of each loading and unloading.
pub fn plastic(k: f64) -> ElasticPlastic {
    ElasticPlastic {
        k_e: k,
        k_p: 0.1 * k,
        f_y: 0.5 * k * COMPRESSION * 2.0 * RADIUS,
        k_t: 0.0,
        damping: Damping::Ratio(0.0),
        mu: 0.0,
        rolling: None,
    }
}

/// The laws of the case: the two whose energy it conserves, and the elastic-plastic one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PackingLaw {
    /// [`law`]: ½ k δ² per contact.
    Linear,
    /// [`hertz`]: (2/5) K δ^{5/2} per contact.
    Hertz,
    /// [`plastic`]: not conservative; its energy error is not measured (NaN).
    Plastic,
}

impl PackingLaw {
    /// The law of the case with tangent stiffness `k` at the lattice's overlap.
    pub fn law(self, k: f64) -> Law {
        match self {
            PackingLaw::Linear => Law::Linear(law(k)),
            PackingLaw::Hertz => Law::Hertz(hertz(k)),
            PackingLaw::Plastic => Law::Plastic(plastic(k)),
        }
    }

    /// The elastic energy of a contact of overlap δ (None: the law stores energy in its
    /// history, which this case does not count).
    fn potential(self, k: f64, delta: f64) -> Option<f64> {
        match self {
            PackingLaw::Linear => Some(0.5 * k * delta * delta),
            PackingLaw::Hertz => Some(0.4 * hertz(k).prefactor(RADIUS / 2.0) * delta * delta * delta.sqrt()),
            PackingLaw::Plastic => None,
        }
    }
}

fn kinetic(sys: &System) -> f64 {
    let b = &sys.bodies;
    (0..b.len()).map(|i| 0.5 * b.mass[i] * b.vel[i].norm2()).sum()
}

/// `kinetic` plus the elastic energy; None for a law whose elastic energy is not counted.
fn energy(sys: &System, which: PackingLaw, k: f64, kinetic: f64) -> Option<f64> {
    let b = &sys.bodies;
    let mut elastic = 0.0;
    for i in 0..b.len() {
        for j in i + 1..b.len() {
            let overlap = 2.0 * RADIUS - sys.domain.min_image(b.pos[j] - b.pos[i]).norm();
            if overlap > 0.0 {
                elastic += which.potential(k, overlap)?;
            }
        }
    }
    Some(kinetic + elastic)
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
    let kinetic0 = kinetic(&sys);
    let e0 = energy(&sys, which, k, kinetic0);
    let steps = (duration / ratio).ceil() as u64;
    let blown = |step| Drift {
        energy_error: f64::INFINITY,
        critical,
        steps: step,
        late_kinetic: f64::INFINITY,
    };
    let mut worst = 0.0f64;
    let (mut late, mut counted) = (0.0, 0u64);
    for step in 1..=steps {
        match st.step(&p, law, law, &mut sys) {
            Ok(()) => {}
            Err(DemError::NonFinite { .. }) => return Ok(blown(step)),
            Err(e) => return Err(e),
        }
        let kinetic_now = kinetic(&sys);
        let now = kinetic_now / kinetic0;
        // Without an energy to follow, a run blows up when its kinetic energy does (the
        // conservative laws stop on the energy error below, as they always did).
        if e0.is_none() && (now.is_nan() || now > 1e6) {
            return Ok(blown(step));
        }
        if 2 * step > steps {
            late += now;
            counted += 1;
        }
        if let (Some(e), Some(e0)) = (energy(&sys, which, k, kinetic_now), e0) {
            let e = (e - e0).abs() / kinetic0;
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
                    late_kinetic: f64::INFINITY,
                });
            }
        }
    }
    Ok(Drift {
        energy_error: if e0.is_some() { worst } else { f64::NAN },
        critical,
        steps,
        late_kinetic: late / counted.max(1) as f64,
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

    /// Under the elastic-plastic law the vibrations lose energy on the contacts' hysteresis
    /// (the kinetic energy of the second half falls under the first's), and a step past the
    /// critical one still blows up.
    #[test]
    fn the_plastic_packing_dissipates_and_large_steps_blow_up() {
        let small = run_law(PackingLaw::Plastic, 1e4, 8, 8, 0.05, 100.0, false, 1).unwrap();
        let large = run_law(PackingLaw::Plastic, 1e4, 8, 8, 3.0, 100.0, true, 1).unwrap();
        eprintln!("plastic packing: {small:?} and {large:?}");
        assert!(small.energy_error.is_nan(), "{small:?}");
        assert!(small.late_kinetic < 1.0, "{small:?}");
        assert!(large.late_kinetic.is_infinite(), "{large:?}");
    }
}
