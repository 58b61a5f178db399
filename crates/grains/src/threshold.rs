//! Automatic grey-level threshold between grains and liquid.
//!
//! Otsu's method (N. Otsu, IEEE Trans. SMC 9 (1979) 62): the level that maximises the
//! between-class variance of a two-class split of the histogram. Written here rather than
//! taken from `imageproc::contrast::otsu_level` because the input is an f64 field (solid
//! fraction 0..1, or 16-bit grey) restricted to a mask, not an 8-bit image.

use crate::{GrainsError, Result};

/// Histogram bins used by [`otsu`]; 1024 resolves a 0..1 solid fraction to 0.001.
pub const OTSU_BINS: usize = 1024;

/// Otsu threshold of the finite `values`. Pixels `> t` are one class, `<= t` the other.
pub fn otsu<I: IntoIterator<Item = f64> + Clone>(values: I) -> Result<f64> {
    let (mut lo, mut hi, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0usize);
    for v in values.clone().into_iter().filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
        n += 1;
    }
    if n == 0 {
        return Err(GrainsError::NoFinitePixels { inside: 0 });
    }
    if hi - lo <= f64::EPSILON * hi.abs().max(1.0) {
        return Err(GrainsError::UniformImage { value: lo });
    }
    let width = (hi - lo) / OTSU_BINS as f64;
    let mut hist = vec![0u64; OTSU_BINS];
    for v in values.into_iter().filter(|v| v.is_finite()) {
        let b = (((v - lo) / width) as usize).min(OTSU_BINS - 1);
        hist[b] += 1;
    }
    let total = n as f64;
    let sum_all: f64 = hist.iter().enumerate().map(|(i, &c)| i as f64 * c as f64).sum();
    let (mut w0, mut sum0, mut best, mut best_k) = (0.0, 0.0, -1.0, 0usize);
    for (k, &c) in hist.iter().enumerate().take(OTSU_BINS - 1) {
        w0 += c as f64;
        sum0 += k as f64 * c as f64;
        let w1 = total - w0;
        if w0 == 0.0 || w1 == 0.0 {
            continue;
        }
        let m0 = sum0 / w0;
        let m1 = (sum_all - sum0) / w1;
        let between = w0 * w1 * (m0 - m1) * (m0 - m1);
        if between > best {
            best = between;
            best_k = k;
        }
    }
    // Upper edge of the last bin of the lower class.
    Ok(lo + (best_k + 1) as f64 * width)
}

/// Two thresholds splitting the finite `values` into three classes (Otsu's criterion
/// extended to three classes: maximise the between-class variance over both levels).
/// Used to find the dark surround of a container (outside < t1 < liquid < t2 < grains).
pub fn otsu3<I: IntoIterator<Item = f64> + Clone>(values: I) -> Result<(f64, f64)> {
    const B: usize = 256;
    let (mut lo, mut hi, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0usize);
    for v in values.clone().into_iter().filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
        n += 1;
    }
    if n == 0 {
        return Err(GrainsError::NoFinitePixels { inside: 0 });
    }
    if hi - lo <= f64::EPSILON * hi.abs().max(1.0) {
        return Err(GrainsError::UniformImage { value: lo });
    }
    let width = (hi - lo) / B as f64;
    let mut hist = vec![0.0f64; B];
    for v in values.into_iter().filter(|v| v.is_finite()) {
        hist[(((v - lo) / width) as usize).min(B - 1)] += 1.0;
    }
    // Prefix sums of counts and first moments.
    let (mut w, mut m) = (vec![0.0; B + 1], vec![0.0; B + 1]);
    for k in 0..B {
        w[k + 1] = w[k] + hist[k];
        m[k + 1] = m[k] + k as f64 * hist[k];
    }
    let class = |a: usize, b: usize| {
        let (wc, mc) = (w[b] - w[a], m[b] - m[a]);
        if wc > 0.0 { mc * mc / wc } else { 0.0 }
    };
    let (mut best, mut bk) = (-1.0, (1, 2));
    for i in 1..B - 1 {
        for j in i + 1..B {
            let s = class(0, i) + class(i, j) + class(j, B);
            if s > best {
                best = s;
                bk = (i, j);
            }
        }
    }
    Ok((lo + bk.0 as f64 * width, lo + bk.1 as f64 * width))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_two_levels_between_them() {
        let v: Vec<f64> = (0..1000).map(|i| if i % 3 == 0 { 0.9 } else { 0.2 }).collect();
        let t = otsu(v.iter().copied()).unwrap();
        assert!(t > 0.2 && t < 0.9, "t = {t}");
    }

    #[test]
    fn three_levels_get_two_thresholds() {
        let v: Vec<f64> = (0..900).map(|i| [0.0, 0.4, 1.0][i % 3]).collect();
        let (a, b) = otsu3(v.iter().copied()).unwrap();
        assert!(a > 0.0 && a <= 0.4 && b > 0.4 && b <= 1.0, "{a} {b}");
    }

    #[test]
    fn uniform_is_an_error() {
        let v = [0.5; 10];
        assert!(matches!(
            otsu(v.iter().copied()),
            Err(GrainsError::UniformImage { .. })
        ));
    }
}
