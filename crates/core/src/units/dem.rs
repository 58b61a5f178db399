//! DEM time and stiffness scales: the critical time step (issue 4).
//!
//! The explicit (velocity-Verlet) integration of a contact is stable for ω Δt < 2 with
//! ω = sqrt(k/m*) (a two-body contact has m* = m/2, so Δt < sqrt(2 m/k)). A grain held by several
//! contacts sees a stiffer effective spring, so the usual DEM estimate Δt_c = sqrt(m_min/k_max)
//! (Cundall & Strack, Géotechnique 29 (1979) 47; O'Sullivan & Bray, Eng. Comput. 21 (2004) 278)
//! is used as the refusal limit; practical runs use a fraction of it (0.1-0.2).

/// Critical time step sqrt(m_min / k_max) (s) for the lightest body and stiffest contact.
pub fn critical_time_step(m_min: f64, k_max: f64) -> f64 {
    (m_min / k_max).sqrt()
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
    fn restitution_round_trip() {
        for e in [0.1, 0.5, 0.9, 0.99] {
            let z = damping_ratio_from_restitution(e);
            assert!((restitution_from_damping_ratio(z) - e).abs() < 1e-12);
        }
    }
}
