//! Synthetic grain images with a known answer, for the tests and the benchmark: disks and
//! two-circle grains (equal circles, t = s / r drawn from a range), many placed in contact
//! with an earlier grain, rendered with exact area coverage (supersampled at the edges),
//! then blurred and given Gaussian noise. The true grains (circles, analytic area,
//! centroid) come back with the image.

use crate::smooth::gaussian;
use crate::twocircle::{FitCircle, shape};
use ndarray::Array2;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Normal};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::PI;

#[derive(Clone, Debug)]
pub struct SynthSpec {
    pub width: usize,
    pub height: usize,
    /// Grains to place (fewer if the image fills up).
    pub n_grains: usize,
    /// Equivalent diameters are uniform in d_mean * (1 +- d_spread).
    pub d_mean_px: f64,
    pub d_spread: f64,
    /// Share of grains made of two circles; the rest are disks.
    pub two_circle_fraction: f64,
    /// Range of t = s / r of the two-circle grains.
    pub t_range: (f64, f64),
    /// Share of grains placed in contact with an earlier grain.
    pub touch_fraction: f64,
    /// Smallest gap between grains not placed in contact, px.
    pub gap_px: f64,
    /// Distance kept from the image edge, px.
    pub margin_px: f64,
    pub grain_level: f64,
    pub liquid_level: f64,
    pub blur_px: f64,
    /// Standard deviation of the added noise (same units as the levels).
    pub noise: f64,
    pub seed: u64,
}

impl Default for SynthSpec {
    fn default() -> Self {
        Self {
            width: 400,
            height: 400,
            n_grains: 100,
            d_mean_px: 30.0,
            d_spread: 0.3,
            two_circle_fraction: 0.5,
            t_range: (0.2, 0.6),
            touch_fraction: 0.6,
            gap_px: 2.0,
            margin_px: 4.0,
            grain_level: 0.9,
            liquid_level: 0.2,
            blur_px: 1.0,
            noise: 0.05,
            seed: 1,
        }
    }
}

#[derive(Clone, Debug)]
pub struct TrueGrain {
    pub circles: Vec<FitCircle>,
    pub area_px: f64,
    pub d_eq_px: f64,
    pub x: f64,
    pub y: f64,
    /// t = s / r (0 for a disk).
    pub t: f64,
}

#[derive(Clone, Debug)]
pub struct SynthImage {
    pub image: Array2<f64>,
    pub grains: Vec<TrueGrain>,
    /// Exact solid area fraction of the image.
    pub solid_fraction: f64,
}

fn make_grain(d: f64, t: f64, theta: f64, x: f64, y: f64) -> TrueGrain {
    let area = PI * d * d / 4.0;
    let (a, _, _) = shape(t);
    let r = (area / a).sqrt();
    let s = t * r;
    let circles = if t == 0.0 {
        vec![FitCircle { x, y, r }]
    } else {
        let (ux, uy) = (theta.cos(), theta.sin());
        vec![
            FitCircle {
                x: x - s * ux,
                y: y - s * uy,
                r,
            },
            FitCircle {
                x: x + s * ux,
                y: y + s * uy,
                r,
            },
        ]
    };
    TrueGrain {
        circles,
        area_px: area,
        d_eq_px: d,
        x,
        y,
        t,
    }
}

fn moved(g: &TrueGrain, x: f64, y: f64) -> TrueGrain {
    let mut n = g.clone();
    for c in &mut n.circles {
        c.x += x - g.x;
        c.y += y - g.y;
    }
    n.x = x;
    n.y = y;
    n
}

/// Smallest surface gap between two grains (negative when they overlap).
fn gap(a: &TrueGrain, b: &TrueGrain) -> f64 {
    let mut g = f64::INFINITY;
    for p in &a.circles {
        for q in &b.circles {
            g = g.min((p.x - q.x).hypot(p.y - q.y) - p.r - q.r);
        }
    }
    g
}

fn inside(g: &TrueGrain, w: f64, h: f64, margin: f64) -> bool {
    g.circles.iter().all(|c| {
        c.x - c.r >= margin && c.y - c.r >= margin && c.x + c.r <= w - margin && c.y + c.r <= h - margin
    })
}

/// Draw the image of `spec`. Deterministic for a given seed.
pub fn generate(spec: &SynthSpec) -> SynthImage {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(spec.seed);
    let (w, h) = (spec.width as f64, spec.height as f64);
    let mut grains: Vec<TrueGrain> = Vec::new();
    let mut misses = 0;
    while grains.len() < spec.n_grains && misses < 2000 {
        let d = spec.d_mean_px * (1.0 + spec.d_spread * (2.0 * rng.random::<f64>() - 1.0));
        let t = if rng.random::<f64>() < spec.two_circle_fraction {
            spec.t_range.0 + (spec.t_range.1 - spec.t_range.0) * rng.random::<f64>()
        } else {
            0.0
        };
        let theta = PI * rng.random::<f64>();
        let touch = !grains.is_empty() && rng.random::<f64>() < spec.touch_fraction;
        let candidate = if touch {
            // In contact with a random earlier grain, along a random direction: bisect the
            // centre distance to where the gap closes.
            let anchor = &grains[rng.random_range(0..grains.len())];
            let phi = 2.0 * PI * rng.random::<f64>();
            let (ux, uy) = (phi.cos(), phi.sin());
            let g0 = make_grain(d, t, theta, anchor.x, anchor.y);
            let (mut lo, mut hi) = (0.0, 4.0 * (d + anchor.d_eq_px));
            for _ in 0..50 {
                let mid = 0.5 * (lo + hi);
                if gap(&moved(&g0, anchor.x + mid * ux, anchor.y + mid * uy), anchor) < 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            moved(&g0, anchor.x + hi * ux, anchor.y + hi * uy)
        } else {
            let (x, y) = (w * rng.random::<f64>(), h * rng.random::<f64>());
            make_grain(d, t, theta, x, y)
        };
        let min_gap = if touch { -1e-9 } else { spec.gap_px };
        let ok =
            inside(&candidate, w, h, spec.margin_px) && grains.iter().all(|g| gap(&candidate, g) >= min_gap);
        if ok {
            grains.push(candidate);
            misses = 0;
        } else {
            misses += 1;
        }
    }
    let cover = render(&grains, spec.width, spec.height);
    let solid_fraction = grains.iter().map(|g| g.area_px).sum::<f64>() / (w * h);
    let ideal = cover.mapv(|c| spec.liquid_level + (spec.grain_level - spec.liquid_level) * c);
    let mut image = gaussian(ideal.view(), spec.blur_px, spec.liquid_level);
    if spec.noise > 0.0 {
        let normal = Normal::new(0.0, spec.noise).expect("noise >= 0");
        image.iter_mut().for_each(|v| *v += normal.sample(&mut rng));
    }
    SynthImage {
        image,
        grains,
        solid_fraction,
    }
}

/// Area coverage of each pixel by the grains (exact inside, 8x8 samples at the edges).
fn render(grains: &[TrueGrain], w: usize, h: usize) -> Array2<f64> {
    let mut cover = Array2::<f64>::zeros((h, w));
    const S: usize = 8;
    for g in grains {
        let sd = |x: f64, y: f64| {
            g.circles
                .iter()
                .map(|c| c.r - (x - c.x).hypot(y - c.y))
                .fold(f64::MIN, f64::max)
        };
        let x0 = g
            .circles
            .iter()
            .map(|c| c.x - c.r)
            .fold(f64::INFINITY, f64::min)
            .floor()
            .max(0.0) as usize;
        let x1 = (g.circles.iter().map(|c| c.x + c.r).fold(0.0, f64::max).ceil() as usize + 1).min(w);
        let y0 = g
            .circles
            .iter()
            .map(|c| c.y - c.r)
            .fold(f64::INFINITY, f64::min)
            .floor()
            .max(0.0) as usize;
        let y1 = (g.circles.iter().map(|c| c.y + c.r).fold(0.0, f64::max).ceil() as usize + 1).min(h);
        for r in y0..y1 {
            for c in x0..x1 {
                let d = sd(c as f64 + 0.5, r as f64 + 0.5);
                let v = if d > 0.75 {
                    1.0
                } else if d < -0.75 {
                    0.0
                } else {
                    let mut k = 0;
                    for i in 0..S {
                        for j in 0..S {
                            let (x, y) = (
                                c as f64 + (j as f64 + 0.5) / S as f64,
                                r as f64 + (i as f64 + 0.5) / S as f64,
                            );
                            k += usize::from(sd(x, y) > 0.0);
                        }
                    }
                    k as f64 / (S * S) as f64
                };
                cover[[r, c]] = (cover[[r, c]] + v).min(1.0);
            }
        }
    }
    cover
}
