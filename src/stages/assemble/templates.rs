//! Where an assembly's grain shapes come from (Su et al. 2020 Sect. 2.4: "20 grain templates,
//! defined by measuring the grain size and shape distribution of a real thin-plate experiment"):
//! the sizes of Table 2 (d_min : d̄ : d_max) with a range of two-circle elongations, the
//! `templates.csv` that `lbdem digitise` measures on an image, or a digitised microstructure
//! whose grains stay where they lie.

use crate::report::table::{f64_column, read_table};
use anyhow::{Result, bail};
use lbdem_dem::{Ball, ClumpShape, Vec2};
use std::path::Path;

/// One template: a clump shape (centroid at the origin, major axis along x) and its share.
#[derive(Clone, Debug)]
pub struct Template {
    pub shape: ClumpShape<Vec2>,
    pub weight: f64,
    /// Equivalent diameter √(4A/π), m.
    pub d_eq: f64,
    pub aspect: f64,
}

/// The two-circle clump of equivalent diameter `d` and aspect ratio `aspect` (one circle below
/// `round_aspect`), as the digitiser fits a grain (`lbdem_grains::twocircle::fit_shape`).
pub fn two_circle(d: f64, aspect: f64, round_aspect: f64) -> ClumpShape<Vec2> {
    let area = std::f64::consts::PI * d * d / 4.0;
    let (circles, _) = lbdem_grains::twocircle::fit_shape(area, 0.0, 0.0, 0.0, aspect, round_aspect);
    ClumpShape {
        balls: circles
            .iter()
            .map(|c| Ball {
                centre: Vec2::new(c.x, -c.y),
                r: c.r,
            })
            .collect(),
    }
}

/// `n` equal-share templates from Table 2's d_min : d̄ : d_max. The equivalent diameters are
/// the centres (quantiles (k + ½)/n) of n equal-count groups of the triangular distribution on
/// [d_min, d_max] whose mode c = 3 d̄ − d_min − d_max gives it the mean d̄, rescaled so their
/// mean is d̄ exactly. Aspect ratios spread evenly over `aspect` in an order uncorrelated with
/// size (golden-ratio sequence). The paper gives the sizes, not the shapes' distribution: the
/// triangle and the aspect range are this project's choice (docs/su2020.md, "Assemblies").
pub fn from_sizes(d: [f64; 3], aspect: [f64; 2], n: usize, round_aspect: f64) -> Result<Vec<Template>> {
    let [a, m, b] = d;
    if !(a > 0.0 && a < m && m < b && b.is_finite()) {
        bail!("grains.d = {d:?}: give [d_min, d_mean, d_max] in metres with 0 < d_min < d_mean < d_max");
    }
    let c = 3.0 * m - a - b;
    if !(a..=b).contains(&c) {
        bail!(
            "grains.d = {d:?}: no triangular size distribution on [d_min, d_max] has mean d_mean = {m:e} \
             (its mode would be {c:e} m); d_mean must lie between (2 d_min + d_max)/3 = {:e} and \
             (d_min + 2 d_max)/3 = {:e}",
            (2.0 * a + b) / 3.0,
            (a + 2.0 * b) / 3.0
        );
    }
    let [s_lo, s_hi] = aspect;
    if !(s_lo >= 1.0 && s_hi >= s_lo && s_hi <= lbdem_grains::twocircle::max_aspect()) {
        bail!(
            "grains.aspect = {aspect:?}: give [min, max] with 1 <= min <= max <= {:.3} (two touching circles)",
            lbdem_grains::twocircle::max_aspect()
        );
    }
    if n == 0 {
        bail!("grains.n_templates = 0: give at least 1 (Su et al. use 20)");
    }
    let f_mode = (c - a) / (b - a);
    let quantile = |u: f64| {
        if u < f_mode {
            a + (u * (b - a) * (c - a)).sqrt()
        } else {
            b - ((1.0 - u) * (b - a) * (b - c)).sqrt()
        }
    };
    let mut ds: Vec<f64> = (0..n).map(|k| quantile((k as f64 + 0.5) / n as f64)).collect();
    let mean = ds.iter().sum::<f64>() / n as f64;
    for x in ds.iter_mut() {
        *x *= m / mean;
    }
    let golden = 0.5 * (5f64.sqrt() - 1.0);
    Ok(ds
        .into_iter()
        .enumerate()
        .map(|(k, d_eq)| {
            let aspect = s_lo + (s_hi - s_lo) * ((k as f64 + 0.5) * golden).fract();
            Template {
                shape: two_circle(d_eq, aspect, round_aspect),
                weight: 1.0 / n as f64,
                d_eq,
                aspect,
            }
        })
        .collect())
}

/// The templates `lbdem digitise` measured (`templates.csv`: weight, d_eq_m, aspect_ratio, r_m,
/// offset_m, n_circles), scaled so their weighted mean equivalent diameter is `d_mean` if given.
pub fn from_csv(path: &Path, d_mean: Option<f64>) -> Result<Vec<Template>> {
    let df = read_table(path)?;
    let w = f64_column(&df, "weight", path)?;
    let d_eq = f64_column(&df, "d_eq_m", path)?;
    let aspect = f64_column(&df, "aspect_ratio", path)?;
    let r = f64_column(&df, "r_m", path)?;
    let off = f64_column(&df, "offset_m", path)?;
    let nc = f64_column(&df, "n_circles", path)?;
    if w.is_empty() {
        bail!(
            "{}: no templates (the digitise stage found no grains?)",
            path.display()
        );
    }
    let wsum: f64 = w.iter().sum();
    let scale = match d_mean {
        Some(m) => m * wsum / w.iter().zip(&d_eq).map(|(a, b)| a * b).sum::<f64>(),
        None => 1.0,
    };
    let mut out = Vec::with_capacity(w.len());
    for k in 0..w.len() {
        let ok = |v: f64| v.is_finite() && v >= 0.0;
        if !(ok(w[k]) && w[k] > 0.0 && ok(r[k]) && r[k] > 0.0 && ok(off[k]) && (nc[k] == 1.0 || nc[k] == 2.0))
        {
            bail!(
                "{} row {}: weight {}, r_m {}, offset_m {}, n_circles {}: need positive weight and radius, \
                 a non-negative offset and 1 or 2 circles",
                path.display(),
                k + 2,
                w[k],
                r[k],
                off[k],
                nc[k]
            );
        }
        let balls = if nc[k] == 1.0 {
            vec![Ball {
                centre: Vec2::ZERO,
                r: r[k] * scale,
            }]
        } else {
            [-1.0, 1.0]
                .iter()
                .map(|s| Ball {
                    centre: Vec2::new(s * off[k] * scale, 0.0),
                    r: r[k] * scale,
                })
                .collect()
        };
        out.push(Template {
            shape: ClumpShape { balls },
            weight: w[k] / wsum,
            d_eq: d_eq[k] * scale,
            aspect: aspect[k],
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_sizes_give_templates_with_the_tables_mean_inside_its_range() {
        // Su Table 2, Simulation I: 91:120:165 um.
        let t = from_sizes([91e-6, 120e-6, 165e-6], [1.0, 1.6], 20, 1.1).unwrap();
        assert_eq!(t.len(), 20);
        let mean = t.iter().map(|x| x.d_eq).sum::<f64>() / 20.0;
        assert!((mean / 120e-6 - 1.0).abs() < 1e-12);
        assert!(t.iter().all(|x| x.d_eq > 91e-6 && x.d_eq < 165e-6));
        // Each shape's area is that of its equivalent diameter (the two-circle fit matches area).
        for x in &t {
            let a = x.shape.mass_props().unwrap().area;
            let want = std::f64::consts::PI * x.d_eq * x.d_eq / 4.0;
            assert!((a / want - 1.0).abs() < 2e-3, "{} vs {want}", a);
        }
        // Both single circles (aspect < 1.1) and elongated pairs occur.
        assert!(t.iter().any(|x| x.shape.balls.len() == 1) && t.iter().any(|x| x.shape.balls.len() == 2));
    }

    #[test]
    fn sizes_no_triangle_can_hold_are_refused() {
        // Mean too close to d_min: the mode would fall below d_min.
        let e = from_sizes([100e-6, 101e-6, 200e-6], [1.0, 1.5], 20, 1.1).unwrap_err();
        assert!(e.to_string().contains("d_mean must lie between"), "{e}");
        assert!(from_sizes([1.0, 0.5, 2.0], [1.0, 1.5], 20, 1.1).is_err());
        assert!(from_sizes([1.0, 1.5, 2.0], [0.8, 1.5], 20, 1.1).is_err());
    }
}
