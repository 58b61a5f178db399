//! The solid (grain) mask: threshold inside the container, then two clean-ups with
//! connected components: solid specks smaller than the smallest grain are dropped (and
//! reported), and liquid pin-holes inside grains (dark spots, reflections) are filled.

use imageproc::image::{GrayImage, Luma};
use imageproc::region_labelling::{Connectivity, connected_components};
use ndarray::{Array2, ArrayView2};

/// A connected piece of the solid mask too small to be a grain.
#[derive(Clone, Debug, PartialEq)]
pub struct Speck {
    pub area_px: usize,
    /// Centroid, pixel coordinates (x right, y down).
    pub x: f64,
    pub y: f64,
}

/// `solid = inside && (v > t)` when grains are bright, `(v < t)` when dark.
pub fn threshold_mask(
    image: ArrayView2<f64>,
    inside: ArrayView2<bool>,
    t: f64,
    bright: bool,
) -> Array2<bool> {
    ndarray::Zip::from(image)
        .and(inside)
        .map_collect(|&v, &m| m && v.is_finite() && if bright { v > t } else { v < t })
}

struct Components {
    labels: Vec<u32>,
    area: Vec<usize>,
    sx: Vec<f64>,
    sy: Vec<f64>,
}

fn components(mask: &Array2<bool>, value: bool, conn: Connectivity) -> Components {
    let (h, w) = mask.dim();
    let img = GrayImage::from_fn(w as u32, h as u32, |x, y| {
        Luma([u8::from(mask[[y as usize, x as usize]] == value)])
    });
    let lab = connected_components(&img, conn, Luma([0u8]));
    let labels: Vec<u32> = lab.pixels().map(|p| p[0]).collect();
    let n = labels.iter().copied().max().unwrap_or(0) as usize + 1;
    let (mut area, mut sx, mut sy) = (vec![0usize; n], vec![0.0; n], vec![0.0; n]);
    for (i, &l) in labels.iter().enumerate() {
        let l = l as usize;
        area[l] += 1;
        sx[l] += (i % w) as f64 + 0.5;
        sy[l] += (i / w) as f64 + 0.5;
    }
    Components { labels, area, sx, sy }
}

/// Drop solid components smaller than `min_area` pixels; returns them.
pub fn remove_specks(solid: &mut Array2<bool>, min_area: usize) -> Vec<Speck> {
    if min_area <= 1 {
        return Vec::new();
    }
    let c = components(solid, true, Connectivity::Eight);
    let mut specks: Vec<Speck> = (1..c.area.len())
        .filter(|&l| c.area[l] > 0 && c.area[l] < min_area)
        .map(|l| Speck {
            area_px: c.area[l],
            x: c.sx[l] / c.area[l] as f64,
            y: c.sy[l] / c.area[l] as f64,
        })
        .collect();
    if specks.is_empty() {
        return specks;
    }
    for (s, &l) in solid.iter_mut().zip(&c.labels) {
        if l > 0 && c.area[l as usize] < min_area {
            *s = false;
        }
    }
    specks.sort_by(|a, b| {
        b.area_px
            .cmp(&a.area_px)
            .then(a.y.total_cmp(&b.y))
            .then(a.x.total_cmp(&b.x))
    });
    specks
}

/// Fill liquid components inside the container smaller than `max_area` pixels that do not
/// touch the container's edge; returns how many pixels were filled.
pub fn fill_holes(solid: &mut Array2<bool>, inside: ArrayView2<bool>, max_area: usize) -> usize {
    if max_area == 0 {
        return 0;
    }
    let (h, w) = solid.dim();
    let liquid_inside = ndarray::Zip::from(&*solid)
        .and(inside)
        .map_collect(|&s, &m| m && !s);
    let c = components(&liquid_inside, true, Connectivity::Four);
    // A liquid component touching the container edge (or image edge) is open, not a hole.
    let mut open = vec![false; c.area.len()];
    for r in 0..h {
        for col in 0..w {
            let l = c.labels[r * w + col] as usize;
            if l == 0 || open[l] {
                continue;
            }
            let edge = r == 0
                || col == 0
                || r + 1 == h
                || col + 1 == w
                || !inside[[r - 1, col]]
                || !inside[[r + 1, col]]
                || !inside[[r, col - 1]]
                || !inside[[r, col + 1]];
            if edge {
                open[l] = true;
            }
        }
    }
    let mut filled = 0;
    for (s, &l) in solid.iter_mut().zip(&c.labels) {
        let l = l as usize;
        if l > 0 && !open[l] && c.area[l] <= max_area {
            *s = true;
            filled += 1;
        }
    }
    filled
}
