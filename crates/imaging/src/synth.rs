//! Forward model of a radiograph of a thin semi-solid sample (Su et al. 2020 Sect. 2.2,
//! read backwards): disks of solid in liquid across a sample of thickness `L`, each
//! detector pixel integrating Beer-Lambert transmission over its area, then detector blur
//! (Gaussian), Poisson counting noise and 16-bit quantisation. The true pixel solid
//! fraction `L_S / L` (the covered fraction of the pixel, as the disks span the thickness)
//! is returned beside the frame, so the inverse stage can be checked against it.
//!
//! Seeded with `rand_xoshiro` and one stream per image row: the same seed gives the same
//! frame for any thread count.

use crate::{ImagingError, Result, Roi};
use ndarray::{Array2, ArrayView2, Axis};
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Poisson};
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// A solid grain seen in projection, in pixels (x = column, y = row, centre of pixel (0,0) at (0.5, 0.5)).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Disk {
    pub x: f64,
    pub y: f64,
    pub r: f64,
}

/// Random sequential addition of non-overlapping disks with diameters uniform in
/// `d_mean (1 +- spread)` inside `region`, until the disk area reaches `target` of the
/// region or `max_attempts` placements fail in a row.
pub fn pack_disks(region: Roi, d_mean: f64, spread: f64, target: f64, seed: u64) -> Result<Vec<Disk>> {
    if d_mean.is_nan() || d_mean <= 1.0 || d_mean > region.w.min(region.h) as f64 {
        return Err(ImagingError::invalid(
            "d_mean_px",
            d_mean,
            "must exceed one pixel and fit inside the assembly region",
        ));
    }
    if !(0.0..1.0).contains(&spread) || !(0.0..0.75).contains(&target) {
        return Err(ImagingError::invalid(
            "spread / target_fraction",
            format!("{spread} / {target}"),
            "need 0 <= spread < 1 and 0 <= target_fraction < 0.75 (random sequential addition jams near 0.55)",
        ));
    }
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let area = (region.w * region.h) as f64;
    let mut disks: Vec<Disk> = Vec::new();
    let (mut covered, mut fails) = (0.0, 0usize);
    while covered / area < target && fails < 20_000 {
        let d = d_mean * (1.0 + spread * (2.0 * rng.random::<f64>() - 1.0));
        let r = 0.5 * d;
        let x = region.x as f64 + r + rng.random::<f64>() * (region.w as f64 - d);
        let y = region.y as f64 + r + rng.random::<f64>() * (region.h as f64 - d);
        if disks
            .iter()
            .any(|o| (o.x - x).powi(2) + (o.y - y).powi(2) < (o.r + r).powi(2))
        {
            fails += 1;
            continue;
        }
        fails = 0;
        covered += std::f64::consts::PI * r * r;
        disks.push(Disk { x, y, r });
    }
    Ok(disks)
}

/// Prescribed displacement of grain centres (pixels): a uniform strain about `centre`
/// plus a Gaussian bump `u = a r exp(-|r|^2 / 2 s^2)` (local dilation inside `sqrt(2) s`,
/// contraction around it).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Displacement {
    pub strain_xx: f64,
    pub strain_yy: f64,
    pub bump_amplitude: f64,
    pub bump_sigma_px: f64,
}

impl Displacement {
    pub fn at(&self, x: f64, y: f64, centre: (f64, f64)) -> (f64, f64) {
        let (dx, dy) = (x - centre.0, y - centre.1);
        let s2 = self.bump_sigma_px.max(1e-12).powi(2);
        let g = self.bump_amplitude * (-(dx * dx + dy * dy) / (2.0 * s2)).exp();
        (self.strain_xx * dx + g * dx, self.strain_yy * dy + g * dy)
    }

    pub fn apply(&self, disks: &[Disk], centre: (f64, f64)) -> Vec<Disk> {
        disks
            .iter()
            .map(|d| {
                let (ux, uy) = self.at(d.x, d.y, centre);
                Disk {
                    x: d.x + ux,
                    y: d.y + uy,
                    r: d.r,
                }
            })
            .collect()
    }
}

/// How a grain fills the sample thickness along the beam.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GrainShape {
    /// A cylinder spanning the thickness: `L_S / L = 1` inside the outline (sharp edges).
    Cylinder,
    /// A sphere of the outline's radius squeezed between the cell windows (Su et al. 2020
    /// Fig. 1a: the sample is sandwiched between two windows): `L_S = min(L, 2 sqrt(r^2 - rho^2))`.
    #[default]
    TruncatedSphere,
}

/// Render the true pixel solid fraction `L_S / L` and the expected counts of an `h` x `w`
/// frame. Each pixel is sampled at `ss` x `ss` points; at each point the solid path is that
/// of the grain covering it (grains do not overlap; if they do after a displacement the
/// larger path wins), and the detector averages *intensity* `I0 exp(-mu_S L_S - mu_L (L - L_S))`
/// over the points, not its logarithm. `thickness_px` is `L` in pixels. `solid_pads` are
/// 100% solid, `liquid_pads` 100% liquid.
#[allow(clippy::too_many_arguments)]
pub fn render(
    h: usize,
    w: usize,
    disks: &[Disk],
    ss: usize,
    shape: GrainShape,
    thickness_px: f64,
    thickness: f64,
    beam: &Beam,
    solid_pads: &[Roi],
    liquid_pads: &[Roi],
) -> (Array2<f64>, Array2<f64>) {
    let ss = ss.max(1);
    let mut frac = Array2::<f64>::zeros((h, w));
    let mut counts = Array2::<f64>::zeros((h, w));
    // Disks touching each row, so each row is independent (parallel, deterministic).
    let mut by_row: Vec<Vec<usize>> = vec![Vec::new(); h];
    for (i, d) in disks.iter().enumerate() {
        let r0 = (d.y - d.r).floor().max(0.0) as usize;
        let r1 = ((d.y + d.r).ceil().max(0.0) as usize).min(h);
        for row in by_row.iter_mut().take(r1).skip(r0) {
            row.push(i);
        }
    }
    let inv = 1.0 / (ss * ss) as f64;
    let att = |f: f64| beam.i0 * (-thickness * (beam.mu_s * f + beam.mu_l * (1.0 - f))).exp();
    frac.axis_iter_mut(Axis(0))
        .into_par_iter()
        .zip(counts.axis_iter_mut(Axis(0)).into_par_iter())
        .enumerate()
        .for_each(|(r, (mut frow, mut crow))| {
            let mut fsum = vec![0.0f64; w];
            let mut isum = vec![0.0f64; w];
            let mut path = vec![0.0f64; w * ss];
            for sy in 0..ss {
                let y = r as f64 + (sy as f64 + 0.5) / ss as f64;
                path.iter_mut().for_each(|p| *p = 0.0);
                for &i in &by_row[r] {
                    let d = disks[i];
                    let dy = y - d.y;
                    let h2 = d.r * d.r - dy * dy;
                    if h2 <= 0.0 {
                        continue;
                    }
                    let half = h2.sqrt();
                    let s0 = (((d.x - half) * ss as f64) - 0.5).ceil().max(0.0) as usize;
                    let s1 = ((((d.x + half) * ss as f64) - 0.5).floor() + 1.0).max(0.0) as usize;
                    for (k, p) in path.iter_mut().enumerate().take(s1.min(w * ss)).skip(s0) {
                        let f = match shape {
                            GrainShape::Cylinder => 1.0,
                            GrainShape::TruncatedSphere => {
                                let x = (k as f64 + 0.5) / ss as f64;
                                let rho2 = (x - d.x).powi(2) + dy * dy;
                                (2.0 * (d.r * d.r - rho2).max(0.0).sqrt() / thickness_px).min(1.0)
                            }
                        };
                        *p = p.max(f);
                    }
                }
                for (c, chunk) in path.chunks(ss).enumerate() {
                    for &f in chunk {
                        fsum[c] += f;
                        isum[c] += att(f);
                    }
                }
            }
            for (c, (fo, co)) in frow.iter_mut().zip(crow.iter_mut()).enumerate() {
                *fo = fsum[c] * inv;
                *co = isum[c] * inv;
            }
        });
    for (pads, f) in [(solid_pads, 1.0), (liquid_pads, 0.0)] {
        for p in pads {
            p.view_mut_fill(&mut frac, f);
            p.view_mut_fill(&mut counts, att(f));
        }
    }
    (frac, counts)
}

impl Roi {
    /// Fill the ROI (clipped to the array) with `v`.
    pub fn view_mut_fill(&self, a: &mut Array2<f64>, v: f64) {
        let (h, w) = a.dim();
        a.slice_mut(ndarray::s![
            self.y.min(h)..(self.y + self.h).min(h),
            self.x.min(w)..(self.x + self.w).min(w)
        ])
        .fill(v);
    }
}

/// Beam and phases of the forward model, SI units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Beam {
    /// Counts per pixel without a sample.
    pub i0: f64,
    /// Linear attenuation coefficients of solid and liquid, 1/m.
    pub mu_s: f64,
    pub mu_l: f64,
}

/// Separable Gaussian detector blur of standard deviation `sigma` px (edges clamped).
pub fn gaussian_blur(f: ArrayView2<f64>, sigma: f64) -> Array2<f64> {
    if sigma.is_nan() || sigma <= 0.0 {
        return f.to_owned();
    }
    let k = (3.0 * sigma).ceil() as isize;
    let mut w: Vec<f64> = (-k..=k)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp())
        .collect();
    let s: f64 = w.iter().sum();
    w.iter_mut().for_each(|v| *v /= s);
    let (h, wd) = f.dim();
    let pass = |src: ArrayView2<f64>, n: usize| -> Array2<f64> {
        let mut out = Array2::zeros(src.dim());
        out.axis_iter_mut(Axis(0))
            .into_par_iter()
            .zip(src.axis_iter(Axis(0)))
            .for_each(|(mut o, s)| {
                for (j, ov) in o.iter_mut().enumerate() {
                    let mut acc = 0.0;
                    for (t, wt) in w.iter().enumerate() {
                        let jj = (j as isize + t as isize - k).clamp(0, n as isize - 1) as usize;
                        acc += wt * s[jj];
                    }
                    *ov = acc;
                }
            });
        out
    };
    let rows = pass(f, wd);
    let cols = pass(rows.t(), h);
    cols.t().to_owned()
}

/// Poisson counting noise and 16-bit quantisation (clipped to 1..=65535 so that no pixel
/// is zero), one random stream per row derived from `seed`.
pub fn noisy_u16(expected: ArrayView2<f64>, seed: u64) -> Result<Array2<u16>> {
    if let Some(v) = expected.iter().find(|v| !(**v >= 0.0 && v.is_finite())) {
        return Err(ImagingError::invalid(
            "expected counts",
            v,
            "must be finite and >= 0",
        ));
    }
    let mut out = Array2::<u16>::zeros(expected.dim());
    out.axis_iter_mut(Axis(0))
        .into_par_iter()
        .zip(expected.axis_iter(Axis(0)))
        .enumerate()
        .for_each(|(r, (mut o, e))| {
            let mut rng =
                Xoshiro256PlusPlus::seed_from_u64(seed ^ (r as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
            for (ov, &lam) in o.iter_mut().zip(e) {
                let n = if lam > 0.0 {
                    Poisson::new(lam).map(|p| p.sample(&mut rng)).unwrap_or(lam)
                } else {
                    0.0
                };
                *ov = n.round().clamp(1.0, 65535.0) as u16;
            }
        });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rendered_solid_volume_matches_geometry() {
        let d = [Disk {
            x: 50.0,
            y: 40.0,
            r: 20.0,
        }];
        let beam = Beam {
            i0: 1.0,
            mu_s: 1.0,
            mu_l: 2.0,
        };
        let (c, _) = render(100, 100, &d, 8, GrainShape::Cylinder, 30.0, 1e-4, &beam, &[], &[]);
        let exact = std::f64::consts::PI * 400.0;
        assert!((c.sum() - exact).abs() / exact < 2e-3, "{} vs {exact}", c.sum());
        // A sphere of radius 20 px in a 30 px thick sample: volume of the sphere minus the two
        // caps of height 5 px cut off by the windows, over L.
        let (c, _) = render(
            100,
            100,
            &d,
            8,
            GrainShape::TruncatedSphere,
            30.0,
            1e-4,
            &beam,
            &[],
            &[],
        );
        let cap = std::f64::consts::PI * 25.0 * (3.0 * 20.0 - 5.0) / 3.0;
        let vol = 4.0 / 3.0 * std::f64::consts::PI * 8000.0 - 2.0 * cap;
        assert!(
            (c.sum() - vol / 30.0).abs() / (vol / 30.0) < 3e-3,
            "{} vs {}",
            c.sum(),
            vol / 30.0
        );
    }

    #[test]
    fn packing_is_seeded_and_non_overlapping() {
        let roi = Roi::new(0, 0, 200, 200);
        let a = pack_disks(roi, 20.0, 0.2, 0.45, 7).unwrap();
        let b = pack_disks(roi, 20.0, 0.2, 0.45, 7).unwrap();
        assert_eq!(a, b);
        for (i, p) in a.iter().enumerate() {
            for q in &a[i + 1..] {
                assert!((p.x - q.x).hypot(p.y - q.y) >= p.r + q.r);
            }
        }
    }

    #[test]
    fn blur_preserves_mean_of_a_constant() {
        let f = Array2::from_elem((20, 30), 3.0);
        let b = gaussian_blur(f.view(), 1.5);
        assert!(b.iter().all(|v| (v - 3.0).abs() < 1e-12));
    }
}
