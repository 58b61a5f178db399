//! The Noble-Torczynski weighting between the fluid collision and the solid
//! bounce-back term.

/// B(f_S, tau) of Su et al. Eq. 10 (Noble & Torczynski 1998):
/// `B = f_S (tau - 1/2) / ((1 - f_S) + (tau - 1/2))`.
///
/// B = 0 in pure fluid (Eq. 9 falls back to BGK) and B = 1 in a fully covered cell;
/// between them it rises monotonically, faster for small tau - 1/2.
#[inline]
pub fn psm_weight(solid_fraction: f64, tau: f64) -> f64 {
    let e = solid_fraction.clamp(0.0, 1.0);
    let t = tau - 0.5;
    e * t / ((1.0 - e) + t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn limits_and_monotonicity() {
        for tau in [0.51, 0.6, 1.0, 2.0] {
            assert_eq!(psm_weight(0.0, tau), 0.0);
            assert_relative_eq!(psm_weight(1.0, tau), 1.0, epsilon = 1e-15);
            let mut last = 0.0;
            for i in 1..=100 {
                let b = psm_weight(i as f64 / 100.0, tau);
                assert!(
                    b > last,
                    "B not increasing at f_S = {} (tau {tau})",
                    i as f64 / 100.0
                );
                last = b;
            }
        }
        // At tau = 1, B = f_S / (3 - 2 f_S): a half-covered cell gets 1/4.
        assert_relative_eq!(psm_weight(0.5, 1.0), 0.25, epsilon = 1e-15);
        // For a fixed cover, B grows with tau - 1/2 towards f_S.
        assert!(psm_weight(0.5, 0.55) < psm_weight(0.5, 1.0));
        assert!(psm_weight(0.5, 1.0) < psm_weight(0.5, 5.0) && psm_weight(0.5, 5.0) < 0.5);
    }
}
