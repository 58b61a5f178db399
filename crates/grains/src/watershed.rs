//! Splitting touching grains: a watershed of the distance map, flooded from its maxima
//! downwards, where two basins that meet are merged unless both are deep.
//!
//! Pixels are visited in decreasing distance to the liquid (ties in raster order, so the
//! result does not depend on thread count). A pixel with no visited neighbour starts a
//! basin; one touching visited pixels joins the basin with the highest peak. When it also
//! touches another basin, that basin's *dynamic* (its peak minus the level of this saddle
//! pixel) decides: below `h = max(h_abs, h_rel * peak)` the shallower basin is merged into
//! the deeper one, above it both are kept and this pixel lies on the line between them.
//! This is the watershed with markers at the h-maxima of the distance map (Vincent &
//! Soille, IEEE PAMI 13 (1991) 583; marker selection by dynamics, Grimaud 1992), with an h
//! relative to the grain size: the neck between two touching disks is deep (its level is
//! a small fraction of their radius), while the waist of one two-circle grain with centre
//! spacing 2s and radius r only dips from r to sqrt(r^2 - s^2) (a fraction 1 - sqrt(1 - t^2),
//! t = s/r, i.e. 0.13 at t = 0.5 and 0.29 at t = 0.7), so `h_rel = 0.45` keeps such grains whole.

use ndarray::Array2;
use rayon::slice::ParallelSliceMut;

#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct WatershedParams {
    /// Relative depth a basin needs to stay a grain of its own (fraction of its peak distance).
    pub h_rel: f64,
    /// Absolute depth in pixels below which a basin is always merged (noise on the boundary).
    pub h_abs: f64,
}

impl Default for WatershedParams {
    fn default() -> Self {
        Self {
            h_rel: 0.25,
            h_abs: 1.5,
        }
    }
}

fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let p = parent[i as usize];
        parent[i as usize] = parent[p as usize];
        i = p;
    }
    i
}

const UNSEEN: u32 = u32::MAX;

/// Label the solid pixels (`sqdist > 0`) into grains 1..=n in raster order of their first
/// pixel; 0 is liquid. Returns the labels and n.
pub fn watershed(sqdist: &Array2<f64>, p: WatershedParams) -> (Array2<u32>, usize) {
    let (h, w) = sqdist.dim();
    let d: Vec<f64> = sqdist.iter().map(|v| v.sqrt()).collect();
    let mut order: Vec<u32> = (0..d.len() as u32).filter(|&i| d[i as usize] > 0.0).collect();
    // Unique keys (index breaks ties), so the parallel unstable sort is deterministic.
    order.par_sort_unstable_by(|&a, &b| d[b as usize].total_cmp(&d[a as usize]).then(a.cmp(&b)));
    let mut parent = vec![UNSEEN; d.len()];
    let mut peak = vec![0.0f64; d.len()];
    let mut roots: Vec<u32> = Vec::with_capacity(8);
    for &i in &order {
        let (r, c) = ((i as usize) / w, (i as usize) % w);
        let v = d[i as usize];
        roots.clear();
        // The visited neighbour with the largest distance (ties: lowest index): the pixel
        // drains up the steepest path, so it joins that neighbour's basin.
        let mut up: Option<(f64, u32)> = None;
        for dr in -1i64..=1 {
            for dc in -1i64..=1 {
                if dr == 0 && dc == 0 {
                    continue;
                }
                let (rr, cc) = (r as i64 + dr, c as i64 + dc);
                if rr < 0 || cc < 0 || rr >= h as i64 || cc >= w as i64 {
                    continue;
                }
                let j = (rr as usize * w + cc as usize) as u32;
                if parent[j as usize] != UNSEEN {
                    let root = find(&mut parent, j);
                    if !roots.contains(&root) {
                        roots.push(root);
                    }
                    let dj = d[j as usize];
                    if up.is_none_or(|(du, ju)| dj > du || (dj == du && j < ju)) {
                        up = Some((dj, j));
                    }
                }
            }
        }
        let Some((_, upj)) = up else {
            parent[i as usize] = i;
            peak[i as usize] = v;
            continue;
        };
        let main = find(&mut parent, upj);
        parent[i as usize] = main;
        // Every other basin met here: this pixel is a saddle between it and `main`. The
        // shallower of the two is merged into the deeper when its dynamic is small.
        for &root in &roots {
            let a = find(&mut parent, main);
            let b = find(&mut parent, root);
            if a == b {
                continue;
            }
            let (deep, shallow) =
                if peak[a as usize] > peak[b as usize] || (peak[a as usize] == peak[b as usize] && a < b) {
                    (a, b)
                } else {
                    (b, a)
                };
            let pk = peak[shallow as usize];
            if pk - v < p.h_abs.max(p.h_rel * pk) {
                parent[shallow as usize] = deep;
            }
        }
    }
    let mut labels = Array2::<u32>::zeros((h, w));
    let mut ids = vec![0u32; d.len()];
    let mut n = 0u32;
    for i in 0..d.len() {
        if parent[i] == UNSEEN {
            continue;
        }
        let root = find(&mut parent, i as u32) as usize;
        if ids[root] == 0 {
            n += 1;
            ids[root] = n;
        }
        labels[[i / w, i % w]] = ids[root];
    }
    (labels, n as usize)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edt::squared_distance_to_liquid;

    fn disks(centres: &[(f64, f64, f64)], h: usize, w: usize) -> Array2<bool> {
        Array2::from_shape_fn((h, w), |(r, c)| {
            let (x, y) = (c as f64 + 0.5, r as f64 + 0.5);
            centres
                .iter()
                .any(|&(cx, cy, rad)| (x - cx).powi(2) + (y - cy).powi(2) < rad * rad)
        })
    }

    #[test]
    fn splits_two_touching_disks() {
        let m = disks(&[(20.0, 20.0, 12.0), (44.0, 20.0, 12.0)], 40, 64);
        let (lab, n) = watershed(&squared_distance_to_liquid(&m), WatershedParams::default());
        assert_eq!(n, 2);
        assert_ne!(lab[[20, 20]], lab[[20, 44]]);
    }

    #[test]
    fn keeps_a_two_circle_grain_whole() {
        // t = s / r = 0.5: centres 12 px apart, r = 12.
        let m = disks(&[(26.0, 20.0, 12.0), (38.0, 20.0, 12.0)], 40, 64);
        let (_, n) = watershed(&squared_distance_to_liquid(&m), WatershedParams::default());
        assert_eq!(n, 1);
    }
}
