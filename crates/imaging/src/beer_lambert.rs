//! Beer-Lambert solid fraction and sample thickness, Su et al. (2020) Sect. 2.2.
//!
//! Through a thin sample of thickness `L` holding solid of path length `L_S`,
//! `I = I_0 exp(-mu_S L_S - mu_L (L - L_S))`, so `ln I` is affine in `L_S / L`. Eq. (1a)
//! (frame 0, from the reference intensities) and Eqs. (4a, 4b) (frame n, with the
//! thickness `L^n` from Eq. (2) or (3)) are therefore both `g = a ln I + b`; [`FractionMap`]
//! holds `a` and `b` so one kernel serves every frame.

use crate::{ImagingError, Result};
use ndarray::{Array2, ArrayView2, Zip};
use rayon::prelude::*;

/// Pixel solid fraction `L_S / L_alloy = a ln I + b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FractionMap {
    pub a: f64,
    pub b: f64,
}

impl FractionMap {
    /// Eq. (1a): `L_S^0 / L_alloy^0 = (ln I_SL^0 - ln I_L^0) / (ln I_S^0 - ln I_L^0)`.
    pub fn eq1(i_l0: f64, i_s0: f64) -> Result<Self> {
        check_positive("i_l0", i_l0)?;
        check_positive("i_s0", i_s0)?;
        let d = i_s0.ln() - i_l0.ln();
        if d.abs() < 1e-9 {
            return Err(ImagingError::EqualReferences { i_s: i_s0, i_l: i_l0 });
        }
        Ok(Self {
            a: 1.0 / d,
            b: -i_l0.ln() / d,
        })
    }

    /// Eqs. (4a, 4b) for frame n: `I_L^n = I_L^0 exp(-mu_L (L^n - L^0))` and
    /// `L_S^n / L^n = (ln I_SL^n - ln I_L^n) / (L^n (mu_L - mu_S))`.
    pub fn eq4(i_l0: f64, mu_s: f64, mu_l: f64, l0: f64, ln_: f64) -> Result<Self> {
        check_positive("i_l0", i_l0)?;
        check_positive("thickness L_alloy^n", ln_)?;
        let dmu = mu_l - mu_s;
        if dmu.abs() < 1e-12 * mu_l.abs().max(mu_s.abs()).max(1e-300) || dmu == 0.0 {
            return Err(ImagingError::invalid(
                "mu_l - mu_s",
                dmu,
                "solid and liquid attenuate alike, so no solid fraction can be measured; \
                 check mu_s and mu_l (1/m)",
            ));
        }
        let ln_il = i_l0.ln() - mu_l * (ln_ - l0);
        let den = ln_ * dmu;
        Ok(Self {
            a: 1.0 / den,
            b: -ln_il / den,
        })
    }

    #[inline]
    pub fn apply(&self, i: f64) -> f64 {
        self.a * i.ln() + self.b
    }

    /// Pixel fraction field; NaN (masked) pixels stay NaN.
    pub fn field(&self, intensity: ArrayView2<f64>) -> Array2<f64> {
        let mut out = Array2::zeros(intensity.dim());
        Zip::from(&mut out)
            .and(&intensity)
            .par_for_each(|o, &i| *o = self.apply(i));
        out
    }

    /// Lookup table over every 16-bit count (count 0 maps to NaN, i.e. masked): raw
    /// integer frames then cost one load per pixel instead of a logarithm. Built in parallel
    /// (65 536 logarithms, a millisecond on one core, once per frame); each entry is the same
    /// for any thread count.
    pub fn lut_u16(&self) -> Vec<f64> {
        (0..=u16::MAX as u32)
            .into_par_iter()
            .map(|c| if c == 0 { f64::NAN } else { self.apply(c as f64) })
            .collect()
    }
}

fn check_positive(name: &str, v: f64) -> Result<()> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(ImagingError::invalid(
            name,
            v,
            "must be a positive, finite intensity",
        ))
    }
}

/// Eq. (2): `L^n = L^0 + ln(I_SL.min^0 / I_SL.min^n) / mu_L + (mu_L - mu_S)(L_S.min^n - L_S.min^0) / mu_L`.
/// With the defaults `ls_min_n = ls_min_0` (a negligibly deformed region) or both 0 (a
/// fully liquid region) the last term vanishes.
pub fn thickness_eq2(
    l0: f64,
    mu_s: f64,
    mu_l: f64,
    i_min0: f64,
    i_min_n: f64,
    ls_min0: f64,
    ls_min_n: f64,
) -> f64 {
    l0 + (i_min0 / i_min_n).ln() / mu_l + (mu_l - mu_s) * (ls_min_n - ls_min0) / mu_l
}

/// Eq. (3): `L^n = (ln I_S^0 - ln I_S^n) / mu_S + L^0`, from a region of nearly 100% solid.
pub fn thickness_eq3(l0: f64, mu_s: f64, i_s0: f64, i_sn: f64) -> f64 {
    (i_s0.ln() - i_sn.ln()) / mu_s + l0
}

/// Eq. (2) pixel by pixel with `L_S.min^n = L_S.min^0`: the thickness field used for the
/// meniscus line scan (Fig. 12h).
pub fn thickness_field_eq2(l0: f64, mu_l: f64, i0: ArrayView2<f64>, i_n: ArrayView2<f64>) -> Array2<f64> {
    let mut out = Array2::zeros(i0.dim());
    Zip::from(&mut out)
        .and(&i0)
        .and(&i_n)
        .par_for_each(|o, &a, &b| *o = l0 + (a / b).ln() / mu_l);
    out
}

/// Eq. (5): `eps_vol^n = g_S.REV^0 / g_S.REV^n - 1`.
#[inline]
pub fn eps_vol(g0: f64, gn: f64) -> f64 {
    g0 / gn - 1.0
}

/// [`eps_vol_field`] into a preallocated map (same shape as `g0`).
pub fn eps_vol_into(g0: ArrayView2<f64>, gn: ArrayView2<f64>, min_gs: f64, out: &mut Array2<f64>) {
    Zip::from(out)
        .and(&g0)
        .and(&gn)
        .par_for_each(|o, &a, &b| *o = if a >= min_gs { eps_vol(a, b) } else { f64::NAN });
}

/// Eq. (5) over two REV maps. Where the reference REV holds less solid than `min_gs`
/// (nearly all liquid) the ratio is meaningless (0/0 in pure liquid) and is set to NaN.
pub fn eps_vol_field(g0: ArrayView2<f64>, gn: ArrayView2<f64>, min_gs: f64) -> Array2<f64> {
    let mut out = Array2::zeros(g0.dim());
    Zip::from(&mut out)
        .and(&g0)
        .and(&gn)
        .par_for_each(|o, &a, &b| *o = if a >= min_gs { eps_vol(a, b) } else { f64::NAN });
    out
}

/// Linear attenuation coefficient (1/m) of a phase from NIST mass attenuation
/// coefficients: `mu = rho sum_i w_i (mu/rho)_i` (Hubbell & Seltzer; REFERENCES.md).
/// `density` in kg/m^3, `mass_atten` in m^2/kg, weight fractions summing to 1.
pub fn mixture_mu(density: f64, parts: &[(f64, f64)]) -> f64 {
    density * parts.iter().map(|(w, m)| w * m).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq1_and_eq4_agree_when_thickness_unchanged() {
        let (mu_s, mu_l, l0) = (2000.0f64, 9000.0f64, 2e-4f64);
        let i_l0 = (-mu_l * l0).exp();
        let i_s0 = (-mu_s * l0).exp();
        let f1 = FractionMap::eq1(i_l0, i_s0).unwrap();
        let f4 = FractionMap::eq4(i_l0, mu_s, mu_l, l0, l0).unwrap();
        for g in [0.0, 0.3, 1.0] {
            let i = (-mu_s * g * l0 - mu_l * (1.0 - g) * l0).exp();
            assert!((f1.apply(i) - g).abs() < 1e-12);
            assert!((f4.apply(i) - g).abs() < 1e-12);
        }
    }

    #[test]
    fn eq2_and_eq3_recover_a_thickness_change() {
        let (mu_s, mu_l, l0, ln_) = (2000.0, 9000.0, 2e-4, 2.1e-4);
        let liq = |l: f64| (-mu_l * l).exp();
        let sol = |l: f64| (-mu_s * l).exp();
        assert!((thickness_eq2(l0, mu_s, mu_l, liq(l0), liq(ln_), 0.0, 0.0) - ln_).abs() < 1e-15);
        assert!((thickness_eq3(l0, mu_s, sol(l0), sol(ln_)) - ln_).abs() < 1e-15);
    }

    #[test]
    fn equal_references_are_refused() {
        assert!(matches!(
            FractionMap::eq1(0.5, 0.5),
            Err(ImagingError::EqualReferences { .. })
        ));
    }
}
