//! Detector corrections before Beer-Lambert: gamma-spot removal, dark- and flat-field
//! correction, dose normalisation on an open-beam region, and the positivity check.
//! Every function is deterministic for any thread count (per-row parallelism only).

use crate::{ImagingError, Result, Roi};
use ndarray::{Array2, ArrayView2, Axis, Zip};
use rayon::prelude::*;

/// Median filter with a `size` x `size` window (odd), edges clamped; NaN pixels ignored.
pub fn median_filter(f: ArrayView2<f64>, size: usize) -> Array2<f64> {
    let (h, w) = f.dim();
    let k = size / 2;
    let mut out = Array2::zeros((h, w));
    out.axis_iter_mut(Axis(0))
        .into_par_iter()
        .enumerate()
        .for_each(|(r, mut orow)| {
            let mut buf = Vec::with_capacity(size * size);
            for (c, o) in orow.iter_mut().enumerate() {
                buf.clear();
                for rr in r.saturating_sub(k)..(r + k + 1).min(h) {
                    for cc in c.saturating_sub(k)..(c + k + 1).min(w) {
                        let v = f[[rr, cc]];
                        if !v.is_nan() {
                            buf.push(v);
                        }
                    }
                }
                *o = if buf.is_empty() {
                    f64::NAN
                } else {
                    let m = buf.len() / 2;
                    *buf.select_nth_unstable_by(m, f64::total_cmp).1
                };
            }
        });
    out
}

/// Median of the finite values (copy); NaN if none.
pub fn median(values: impl Iterator<Item = f64>) -> f64 {
    let mut v: Vec<f64> = values.filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    let m = v.len() / 2;
    *v.select_nth_unstable_by(m, f64::total_cmp).1
}

/// Gamma spots (isolated bright or dark outliers from stray gamma rays hitting the
/// detector) replaced by the local median: a pixel is an outlier when it departs from the
/// `size` x `size` median by more than `threshold` robust standard deviations
/// (1.4826 x the median absolute departure over the whole frame). Returns the cleaned frame
/// and the number of pixels replaced.
pub fn remove_gamma_spots(f: ArrayView2<f64>, size: usize, threshold: f64) -> Result<(Array2<f64>, usize)> {
    if size < 3 || size.is_multiple_of(2) {
        return Err(ImagingError::invalid(
            "gamma_size",
            size,
            "must be odd and at least 3",
        ));
    }
    if threshold.is_nan() || threshold <= 0.0 {
        return Err(ImagingError::invalid(
            "gamma_threshold",
            threshold,
            "must be positive (sigmas)",
        ));
    }
    let med = median_filter(f, size);
    let sigma = 1.4826 * median(f.iter().zip(&med).map(|(a, b)| (a - b).abs()));
    let limit = threshold * sigma.max(f64::MIN_POSITIVE);
    let mut out = f.to_owned();
    let mut n = 0;
    Zip::from(&mut out).and(&med).for_each(|o, &m| {
        if (*o - m).abs() > limit {
            *o = m;
            n += 1;
        }
    });
    Ok((out, n))
}

/// `(I - D) / (F - D)`: dark current `D` removed and the beam profile divided out with an
/// open-beam (flat) frame `F`. Either may be absent.
pub fn flat_dark(
    raw: ArrayView2<f64>,
    dark: Option<ArrayView2<f64>>,
    flat: Option<ArrayView2<f64>>,
) -> Array2<f64> {
    let mut out = raw.to_owned();
    if let Some(d) = dark {
        out -= &d;
    }
    if let Some(fl) = flat {
        match dark {
            Some(d) => Zip::from(&mut out)
                .and(&fl)
                .and(&d)
                .par_for_each(|o, &f, &d| *o /= f - d),
            None => Zip::from(&mut out).and(&fl).par_for_each(|o, &f| *o /= f),
        }
    }
    out
}

/// Divide by the mean over an open-beam region (no sample in the beam): frames taken with
/// different doses become transmissions on one scale. Returns the divisor.
pub fn dose_normalise(f: &mut Array2<f64>, roi: Roi) -> Result<f64> {
    let m = roi.mean("open_roi", f.view())?;
    if m.is_nan() || m <= 0.0 {
        return Err(ImagingError::invalid(
            "open_roi",
            format!("{:?} (mean {m})", <[usize; 4]>::from(roi)),
            "the open-beam region must have a positive mean intensity; put it where no sample is",
        ));
    }
    f.mapv_inplace(|v| v / m);
    Ok(m)
}

/// Beer-Lambert needs `I > 0`. With `mask` such pixels become NaN (masked) and are
/// counted; without it the first one is an error naming `what` and the pixel.
pub fn check_positive(f: &mut Array2<f64>, what: &str, mask: bool) -> Result<usize> {
    if mask {
        let mut n = 0;
        f.iter_mut()
            .filter(|v| !v.is_nan() && **v <= 0.0 || v.is_infinite())
            .for_each(|v| {
                *v = f64::NAN;
                n += 1;
            });
        return Ok(n);
    }
    for ((row, col), &v) in f.indexed_iter() {
        if !v.is_nan() && (v <= 0.0 || v.is_infinite()) {
            return Err(ImagingError::NonPositive {
                what: what.into(),
                row,
                col,
                value: v,
            });
        }
    }
    Ok(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_spot_is_removed_and_smooth_field_untouched() {
        let mut f = Array2::from_shape_fn((40, 40), |(r, c)| {
            100.0 + (r + c) as f64 * 0.01 + ((r * 31 + c * 17) % 7) as f64 * 0.1
        });
        let clean = f.clone();
        f[[10, 12]] = 5000.0;
        let (g, n) = remove_gamma_spots(f.view(), 3, 6.0).unwrap();
        assert!((1..20).contains(&n), "replaced {n}");
        assert!((g[[10, 12]] - clean[[10, 12]]).abs() < 1.0);
    }

    #[test]
    fn nonpositive_pixel_is_named() {
        let mut f = Array2::from_elem((3, 3), 1.0);
        f[[1, 2]] = -0.5;
        let e = check_positive(&mut f.clone(), "frame x.tif", false).unwrap_err();
        assert!(e.to_string().contains("row 1, col 2") && e.to_string().contains("x.tif"));
        assert_eq!(check_positive(&mut f, "f", true).unwrap(), 1);
        assert!(f[[1, 2]].is_nan());
    }
}
