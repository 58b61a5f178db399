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

    #[test]
    fn restitution_round_trip() {
        for e in [0.1, 0.5, 0.9, 0.99] {
            let z = damping_ratio_from_restitution(e);
            assert!((restitution_from_damping_ratio(z) - e).abs() < 1e-12);
        }
    }
}
