//! Solid fraction of every lattice cell covered by clumped grains (Su et al. 2020,
//! Fig. 1d and Eq. 10), using the hydrodynamic radius factor r_hd in the LBM step only.
//!
//! A cell touched by one circle of a grain gets the exact overlap ([`cell_fraction`]).
//! The circles of one clump overlap each other: where a cell is cut by two of them the
//! union is exact too ([`cell_fraction_pair`]: the two overlaps minus the lens's); where
//! three or more cut it (clumps of more circles) it is sub-sampled on a fixed grid. Where several grains cover one cell (at contacts) their fractions are
//! kept apart (each grain gets its own force, Eq. 14) and scaled down together if they
//! add up to more than one.

use crate::overlap::{cell_fraction, rect_lens_area};
use rayon::prelude::*;

/// One circle of a grain, in lattice units (cell (i, j) spans [i, i+1] x [j, j+1]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GrainCircle {
    pub body: u32,
    pub centre: [f64; 2],
    pub radius: f64,
}

/// The share of one cell covered by one grain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellCover {
    /// Cell index `i + nx * j`.
    pub cell: u32,
    pub body: u32,
    pub fraction: f64,
}

/// Every covered cell's share per grain, sorted by cell (within a cell in the order the grains
/// were given, ascending body for the coupled loop), and the total
/// solid fraction per cell (capped at one).
#[derive(Clone, Debug, PartialEq)]
pub struct SolidMap {
    pub nx: usize,
    pub ny: usize,
    pub covers: Vec<CellCover>,
    pub total: Vec<f64>,
}

/// Points per side used to sub-sample a cell cut by two or more circles of one clump.
pub const UNION_SAMPLES: usize = 16;

fn union_fraction(circles: &[GrainCircle], i: i64, j: i64) -> f64 {
    let n = UNION_SAMPLES;
    let mut inside = 0usize;
    for a in 0..n {
        let x = i as f64 + (a as f64 + 0.5) / n as f64;
        for b in 0..n {
            let y = j as f64 + (b as f64 + 0.5) / n as f64;
            let hit = circles.iter().any(|c| {
                let (dx, dy) = (x - c.centre[0], y - c.centre[1]);
                dx * dx + dy * dy <= c.radius * c.radius
            });
            inside += usize::from(hit);
        }
    }
    inside as f64 / (n * n) as f64
}

/// Cell index `i` on an axis of `n` cells: wrapped if periodic, `None` outside otherwise.
pub(crate) fn wrap(i: i64, n: usize, periodic: bool) -> Option<usize> {
    if periodic {
        Some(i.rem_euclid(n as i64) as usize)
    } else {
        (0..n as i64).contains(&i).then_some(i as usize)
    }
}

/// Cover of one grain (its circles already scaled by r_hd), unsorted, fractions not yet shared
/// with the other grains.
pub(crate) fn grain_cover(
    circles: &[GrainCircle],
    nx: usize,
    ny: usize,
    periodic: [bool; 2],
) -> Vec<CellCover> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for c in circles {
        for d in 0..2 {
            lo[d] = lo[d].min(c.centre[d] - c.radius);
            hi[d] = hi[d].max(c.centre[d] + c.radius);
        }
    }
    let body = circles[0].body;
    let mut out = Vec::new();
    let mut parts = Vec::with_capacity(circles.len());
    for j in lo[1].floor() as i64..hi[1].ceil() as i64 {
        let Some(wj) = wrap(j, ny, periodic[1]) else {
            continue;
        };
        for i in lo[0].floor() as i64..hi[0].ceil() as i64 {
            let Some(wi) = wrap(i, nx, periodic[0]) else {
                continue;
            };
            parts.clear();
            parts.extend(circles.iter().map(|c| cell_fraction(c.centre, c.radius, i, j)));
            let cutting = parts.iter().filter(|&&f| f > 0.0).count();
            let fraction = if parts.iter().any(|&f| f >= 1.0) {
                1.0
            } else if cutting <= 1 {
                parts.iter().copied().fold(0.0, f64::max)
            } else if cutting == 2 {
                // |C ∩ A| + |C ∩ B| − |C ∩ A ∩ B| with the two overlaps already at hand (the
                // sum `cell_fraction_pair` computes).
                let mut two = circles.iter().zip(&parts).filter(|(_, f)| **f > 0.0);
                match (two.next(), two.next()) {
                    (Some((a, fa)), Some((b, fb))) => {
                        let (x, y) = (i as f64, j as f64);
                        let lens = rect_lens_area(
                            (a.centre, a.radius),
                            (b.centre, b.radius),
                            x,
                            x + 1.0,
                            y,
                            y + 1.0,
                        );
                        (fa + fb - lens).clamp(0.0, 1.0)
                    }
                    _ => union_fraction(circles, i, j),
                }
            } else {
                union_fraction(circles, i, j)
            };
            if fraction > 0.0 {
                out.push(CellCover {
                    cell: (wi + nx * wj) as u32,
                    body,
                    fraction,
                });
            }
        }
    }
    out
}

/// Map grains onto an `nx` x `ny` lattice. `circles` must be grouped by body (all
/// circles of one grain adjacent); `r_hd` scales every radius (Su et al. use 0.8 in 2D
/// so that liquid can percolate between touching grains).
pub fn solid_map(circles: &[GrainCircle], r_hd: f64, nx: usize, ny: usize, periodic: [bool; 2]) -> SolidMap {
    let scaled: Vec<GrainCircle> = circles
        .iter()
        .map(|c| GrainCircle {
            radius: c.radius * r_hd,
            ..*c
        })
        .collect();
    let groups: Vec<&[GrainCircle]> = scaled.chunk_by(|a, b| a.body == b.body).collect();
    let per_grain: Vec<Vec<CellCover>> = groups
        .par_iter()
        .map(|g| grain_cover(g, nx, ny, periodic))
        .collect();
    let mut map = SolidMap {
        nx,
        ny,
        covers: Vec::new(),
        total: Vec::new(),
    };
    assemble(&per_grain, &mut map, &mut Vec::new());
    map
}

/// Gather the grains' covers into `map` (whose `nx`, `ny` are set): a counting sort by cell,
/// stable in grain order, so each cell lists its grains in the order of `per_grain` without a
/// comparison sort; then the totals, with the fractions of a cell that overlapping grains (at
/// contacts) cover more than once scaled down together.
pub(crate) fn assemble(per_grain: &[Vec<CellCover>], map: &mut SolidMap, start: &mut Vec<u32>) {
    let n = map.nx * map.ny;
    start.clear();
    start.resize(n + 1, 0);
    for cv in per_grain.iter().flatten() {
        start[cv.cell as usize + 1] += 1;
    }
    for c in 0..n {
        start[c + 1] += start[c];
    }
    let empty = CellCover {
        cell: 0,
        body: 0,
        fraction: 0.0,
    };
    map.covers.clear();
    map.covers.resize(start[n] as usize, empty);
    for cv in per_grain.iter().flatten() {
        let at = &mut start[cv.cell as usize];
        map.covers[*at as usize] = *cv;
        *at += 1;
    }
    map.total.clear();
    map.total.resize(n, 0.0);
    for c in &map.covers {
        map.total[c.cell as usize] += c.fraction;
    }
    for c in map.covers.iter_mut() {
        let t = map.total[c.cell as usize];
        if t > 1.0 {
            c.fraction /= t;
        }
    }
    map.total.iter_mut().for_each(|t| *t = t.min(1.0));
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    fn disk(body: u32, x: f64, y: f64, r: f64) -> GrainCircle {
        GrainCircle {
            body,
            centre: [x, y],
            radius: r,
        }
    }

    #[test]
    fn single_disk_area_with_hydrodynamic_radius() {
        let m = solid_map(&[disk(0, 20.3, 15.7, 6.0)], 0.8, 40, 32, [false; 2]);
        let area: f64 = m.total.iter().sum();
        assert_relative_eq!(area, PI * 4.8 * 4.8, max_relative = 1e-13);
        assert!(m.covers.iter().all(|c| c.body == 0));
    }

    #[test]
    fn two_circle_clump_counts_its_overlap_once() {
        // Equal circles r at distance d: union = 2 pi r^2 - lens,
        // lens = 2 r^2 acos(d / 2r) - (d / 2) sqrt(4 r^2 - d^2).
        let (r, d) = (7.0, 6.0);
        let c = [disk(3, 30.0, 25.0, r), disk(3, 30.0 + d, 25.0, r)];
        let m = solid_map(&c, 1.0, 64, 50, [false; 2]);
        let lens = 2.0 * r * r * (d / (2.0 * r)).acos() - 0.5 * d * (4.0 * r * r - d * d).sqrt();
        let exact = 2.0 * PI * r * r - lens;
        let area: f64 = m.total.iter().sum();
        // Only the cells cut by both circles are sub-sampled (16 x 16): a few cells of
        // error at most 1/256 each.
        assert_relative_eq!(area, exact, max_relative = 2e-4);
        assert!(m.total.iter().all(|&t| (0.0..=1.0).contains(&t)));
    }

    #[test]
    fn periodic_wrap_keeps_area_and_walls_cut_it() {
        let c = [disk(0, 1.5, 10.0, 4.0)];
        let wrapped = solid_map(&c, 1.0, 30, 20, [true, false]);
        assert_relative_eq!(wrapped.total.iter().sum::<f64>(), PI * 16.0, max_relative = 1e-13);
        let cut = solid_map(&c, 1.0, 30, 20, [false, false]);
        assert!(cut.total.iter().sum::<f64>() < 0.75 * PI * 16.0);
    }

    #[test]
    fn overlapping_grains_never_exceed_one() {
        let c = [disk(0, 10.0, 10.0, 5.0), disk(1, 14.0, 10.0, 5.0)];
        let m = solid_map(&c, 1.0, 25, 20, [false; 2]);
        for cell in 0..m.nx * m.ny {
            let s: f64 = m
                .covers
                .iter()
                .filter(|c| c.cell as usize == cell)
                .map(|c| c.fraction)
                .sum();
            assert!(s <= 1.0 + 1e-12, "cell {cell} covered {s}");
            assert_relative_eq!(s, m.total[cell], epsilon = 1e-12);
        }
        // Grains 0 and 1 share cells in the overlap and are kept apart there.
        let shared = m.covers.windows(2).filter(|w| w[0].cell == w[1].cell).count();
        assert!(shared > 0);
    }

    #[test]
    fn identical_for_one_and_two_threads() {
        let circles: Vec<GrainCircle> = (0..200)
            .flat_map(|k| {
                let (x, y) = ((k % 20) as f64 * 6.1 + 3.0, (k / 20) as f64 * 6.3 + 3.0);
                [disk(k, x, y, 2.4), disk(k, x + 1.9, y + 0.7, 2.1)]
            })
            .collect();
        let run = |t: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build().unwrap();
            pool.install(|| solid_map(&circles, 0.8, 128, 70, [true, true]))
        };
        assert_eq!(run(1), run(2));
    }
}
