//! DEM time and stiffness scales: the critical time step (issue 4).
//!
//! The explicit (velocity-Verlet) integration of a contact is stable for ω Δt < 2 with
//! ω = sqrt(k/m*) (a two-body contact has m* = m/2, so Δt < sqrt(2 m/k)). A grain held by several
//! contacts sees a stiffer effective spring, so the usual DEM estimate Δt_c = sqrt(m_min/k_max)
//! (Cundall & Strack, Géotechnique 29 (1979) 47; O'Sullivan & Bray, Eng. Comput. 21 (2004) 278)
//! is the scale every DEM step is quoted against; practical runs use a fraction of it (0.1-0.2).
//!
//! The refusal limit, [`largest_accepted_step`], bounds the fastest mode of a grain instead: held
//! by up to six grain springs (a dense hexagonal packing of disks, ω² ≈ 6 k/m) and pressed by up
//! to two walls (a corner), ω² ≤ (6 k + 2 k_wall)/m, and Verlet needs ω Δt < 2. Without walls
//! that is 2/√6 = [`ACCEPTED_FRACTION`] of sqrt(m_min/k_max): the DEM stability map found a
//! compressed packing blowing up from 0.80-0.85 of it, inside the earlier limit of 1
//! (docs/stability.md, issue 16 item 2). A stiff wall alone (one spring per axis) allows up to
//! 2 sqrt(m/k_wall), so a soft packing beside stiff walls (Su's Float case, grain-wall 31.1 N/m
//! against 4e-3 N/m between grains) keeps its published step.

/// Critical time step sqrt(m_min / k_max) (s) for the lightest body and stiffest contact.
pub fn critical_time_step(m_min: f64, k_max: f64) -> f64 {
    (m_min / k_max).sqrt()
}

/// The largest step as a fraction of [`critical_time_step`] for grains alone (no walls): 2/√6,
/// Verlet's limit for the fastest mode of a grain held by six equal springs.
pub const ACCEPTED_FRACTION: f64 = 0.816_496_580_927_726;

/// The largest step the stepper accepts (s) for the lightest grain of mass `m_min` held by six
/// grain springs of stiffness `k_grain` and, if `walls`, pressed by two walls of `k_wall`:
/// 2 sqrt(m_min / (6 k_grain + 2 k_wall)).
pub fn largest_accepted_step(m_min: f64, k_grain: f64, k_wall: f64, walls: bool) -> f64 {
    let k = 6.0 * k_grain + if walls { 2.0 * k_wall } else { 0.0 };
    2.0 * (m_min / k).sqrt()
}

/// The largest step (s) at which the kick-drift-kick leapfrog keeps a spring `k` (N/m) and a
/// dashpot `c` (N s/m) on a mass `m` (kg) stable, the dashpot reading the half-step velocity as
/// the stepper's force pass does. With u = h v the step maps (x, u) by [[1 − a², 1 − b],
/// [−a², 1 − b]], a = h √(k/m), b = h c/m: trace 2 − a² − b, determinant 1 − b, and the Jury
/// conditions reduce to a² + 2b < 4, i.e. k h² + 2 c h < 4 m. Without the dashpot it is Verlet's
/// 2 √(m/k); with damping ratio ζ = c/(2√(km)) it is 2(√(1+ζ²) − ζ)/ω. Written as
/// 4m/(c + √(c² + 4km)) so that it stays exact for c ≫ √(km).
pub fn damped_step_limit(k: f64, c: f64, m: f64) -> f64 {
    4.0 * m / (c + (c * c + 4.0 * k * m).sqrt())
}

/// Damping ratio ζ of a linear spring-dashpot that gives the restitution coefficient `e`:
/// e = exp(−πζ/√(1−ζ²))  ⇔  ζ = −ln e / √(π² + ln² e).
pub fn damping_ratio_from_restitution(e: f64) -> f64 {
    let l = e.ln();
    -l / (std::f64::consts::PI.powi(2) + l * l).sqrt()
}

/// Restitution of a linear spring-dashpot with damping ratio ζ < 1 (unclipped force).
pub fn restitution_from_damping_ratio(zeta: f64) -> f64 {
    (-std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()).exp()
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn the_accepted_fraction_is_verlets_limit_for_six_springs() {
        // ω² = 6 k/m and ω Δt < 2.
        assert!((ACCEPTED_FRACTION - 2.0 / 6f64.sqrt()).abs() < 1e-15);
        assert!((largest_accepted_step(6.0, 1.0, 1e9, false) - 2.0).abs() < 1e-14);
        // Equal grain and wall springs: 2/√8 of sqrt(m/k); a wall 1e4 times stiffer than the
        // grains: just under 2/√2 of sqrt(m/k_wall), above the old limit of 1.
        assert!((largest_accepted_step(8.0, 1.0, 1.0, true) - 2.0).abs() < 1e-14);
        let s = largest_accepted_step(1.0, 1e-4, 1.0, true);
        assert!(s > 1.0 && s < 2f64.sqrt(), "{s}");
    }

    /// The scalar recurrence itself, run just inside and just outside the closed form: a
    /// displaced mass decays inside and grows outside, at ζ = 0, 0.5 and 2 (where the dashpot
    /// alone, not the spring, sets the limit).
    #[test]
    fn the_damped_limit_separates_decaying_from_growing_runs() {
        let (k, m) = (31.1_f64, 2.9e-9_f64);
        for zeta in [0.0, 0.5, 2.0] {
            let c = 2.0 * zeta * (k * m).sqrt();
            let h_max = damped_step_limit(k, c, m);
            let amplitude = |h: f64| {
                let (mut x, mut v, mut f) = (1e-9, 0.0, -k * 1e-9);
                for _ in 0..2_000 {
                    v += 0.5 * h * f / m;
                    x += h * v;
                    f = -k * x - c * v;
                    v += 0.5 * h * f / m;
                }
                x.abs().max((v * h).abs())
            };
            // Inside: bounded by a few times the 1 nm start (undamped) or decayed; outside: a
            // thousandfold growth or an overflow within 2000 steps.
            let inside = amplitude(0.99 * h_max);
            let outside = amplitude(1.01 * h_max);
            assert!(inside < 1e-8, "zeta {zeta}: {inside}");
            assert!(outside.is_nan() || outside >= 1e-6, "zeta {zeta}: {outside}");
        }
        // The undamped limit is Verlet's 2 sqrt(m/k), and a dashpot only lowers it.
        assert!((damped_step_limit(4.0, 0.0, 1.0) - 1.0).abs() < 1e-15);
        assert!(damped_step_limit(4.0, 0.1, 1.0) < 1.0);
    }

    #[test]
    fn restitution_round_trip() {
        for e in [0.1, 0.5, 0.9, 0.99] {
            let z = damping_ratio_from_restitution(e);
            assert!((restitution_from_damping_ratio(z) - e).abs() < 1e-12);
        }
    }
}
