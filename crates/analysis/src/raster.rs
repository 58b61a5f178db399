//! Triangle fields onto the pixel grid of a radiograph, so that the strain from grain motion is
//! averaged by the very operator that averages intensities: each pixel takes the value of the
//! triangle that holds its centre (NaN outside the mesh), then [`lbdem_imaging::rev::Sat`]
//! forms the √10 d̄ REV means (sliding window and tiles) exactly as the `radiograph` stage does
//! (Su et al. 2020 Sect. 2.5: "smoothed using a √10 d̄ × √10 d̄ average filter").
//!
//! A fine grid makes the pixel mean the area-weighted mean of the triangles a window covers.
//! Rows run from the top (largest y) down, as in an image; columns from the left.

use crate::mesh::Mesh;
use crate::{AnalysisError, P2, Result};
use lbdem_imaging::rev::Sat;
use ndarray::{Array2, Axis};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// A regular grid of square pixels over a rectangle of the plane (y up).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Grid {
    /// Lower-left corner of the grid (m).
    pub x0: f64,
    pub y0: f64,
    /// Pixel side (m).
    pub dx: f64,
    pub nx: usize,
    pub ny: usize,
}

impl Grid {
    /// A grid covering [x0, x1] × [y0, y1] with pixels of side `dx` (the last column and row
    /// may end past x1, y1 by less than a pixel).
    pub fn cover(x0: f64, y0: f64, x1: f64, y1: f64, dx: f64) -> Result<Self> {
        if !(dx > 0.0 && dx.is_finite()) {
            return Err(AnalysisError::invalid(
                "pixel size",
                dx,
                "must be positive and finite",
            ));
        }
        if !(x1 > x0 && y1 > y0 && (x1 - x0).is_finite() && (y1 - y0).is_finite()) {
            return Err(AnalysisError::invalid(
                "grid extent",
                format!("[{x0}, {x1}] x [{y0}, {y1}]"),
                "must be a non-empty finite rectangle",
            ));
        }
        let nx = ((x1 - x0) / dx).ceil() as usize;
        let ny = ((y1 - y0) / dx).ceil() as usize;
        if nx.saturating_mul(ny) > 64_000_000 {
            return Err(AnalysisError::invalid(
                "grid",
                format!("{nx} x {ny} pixels"),
                "is too large (over 64 million pixels); use a larger pixel size",
            ));
        }
        Ok(Self { x0, y0, dx, nx, ny })
    }

    /// Centre of pixel (row, col).
    #[inline]
    pub fn centre(&self, row: usize, col: usize) -> P2 {
        [
            self.x0 + (col as f64 + 0.5) * self.dx,
            self.y0 + (self.ny as f64 - row as f64 - 0.5) * self.dx,
        ]
    }

    /// Top edge of the grid (m).
    pub fn y1(&self) -> f64 {
        self.y0 + self.ny as f64 * self.dx
    }

    /// (row, col) of the pixel holding `p`, if inside.
    pub fn pixel_of(&self, p: P2) -> Option<(usize, usize)> {
        let c = ((p[0] - self.x0) / self.dx).floor();
        let r = ((self.y1() - p[1]) / self.dx).floor();
        (c >= 0.0 && r >= 0.0 && (c as usize) < self.nx && (r as usize) < self.ny)
            .then_some((r as usize, c as usize))
    }
}

/// Which triangle of `mesh` (on the vertices `points`: the reference positions, or the deformed
/// ones to paint a field where the material is now) holds each pixel centre of `grid`;
/// `u32::MAX` outside the mesh. A centre on an edge shared by two triangles goes to the one
/// listed first, so the map does not depend on the thread count.
pub fn locate(grid: &Grid, mesh: &Mesh, points: &[P2]) -> Array2<u32> {
    let mut owner = Array2::from_elem((grid.ny, grid.nx), u32::MAX);
    // Triangles overlapping each row, in mesh order.
    let mut by_row: Vec<Vec<u32>> = vec![Vec::new(); grid.ny];
    for t in 0..mesh.len() {
        let c = mesh.corners(t, points);
        let ymax = c.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max);
        let ymin = c.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        let r0 = ((grid.y1() - ymax) / grid.dx - 0.5).floor().max(0.0) as usize;
        let r1 = (((grid.y1() - ymin) / grid.dx - 0.5).ceil() + 1.0).max(0.0) as usize;
        for row in by_row.iter_mut().take(r1.min(grid.ny)).skip(r0) {
            row.push(t as u32);
        }
    }
    owner
        .axis_iter_mut(Axis(0))
        .into_par_iter()
        .enumerate()
        .for_each(|(r, mut orow)| {
            for &t in &by_row[r] {
                let [a, mut b, mut c] = mesh.corners(t as usize, points);
                // A deformed triangle may have turned over: test it counter-clockwise.
                if crate::mesh::signed_area(a, b, c) < 0.0 {
                    std::mem::swap(&mut b, &mut c);
                }
                let xmin = a[0].min(b[0]).min(c[0]);
                let xmax = a[0].max(b[0]).max(c[0]);
                let c0 = ((xmin - grid.x0) / grid.dx - 0.5).floor().max(0.0) as usize;
                let c1 = (((xmax - grid.x0) / grid.dx - 0.5).ceil() + 1.0).max(0.0) as usize;
                let area2 = 2.0 * crate::mesh::signed_area(a, b, c);
                // Relative tolerance so that centres on a shared edge belong to some triangle.
                let tol = -1e-12 * area2;
                for col in c0..c1.min(grid.nx) {
                    if orow[col] != u32::MAX {
                        continue;
                    }
                    let p = grid.centre(r, col);
                    let w0 = 2.0 * crate::mesh::signed_area(b, c, p);
                    let w1 = 2.0 * crate::mesh::signed_area(c, a, p);
                    let w2 = 2.0 * crate::mesh::signed_area(a, b, p);
                    if w0 >= tol && w1 >= tol && w2 >= tol {
                        orow[col] = t;
                    }
                }
            }
        });
    owner
}

/// The pixel field of per-triangle `values` (NaN where no triangle).
pub fn paint(owner: &Array2<u32>, values: &[f64]) -> Array2<f64> {
    owner.mapv(|t| {
        if t == u32::MAX {
            f64::NAN
        } else {
            values[t as usize]
        }
    })
}

/// REV side in pixels for a grid of pixel side `dx`: `rev_factor d̄ / dx`, rounded, as the
/// radiograph stage ([`lbdem_imaging::rev::rev_side_px`]).
pub fn rev_side(rev_factor: f64, d_bar: f64, dx: f64) -> Result<usize> {
    lbdem_imaging::rev::rev_side_px(rev_factor, d_bar, dx)
        .map_err(|e| AnalysisError::invalid("REV", format!("{rev_factor} x {d_bar} / {dx}"), &e.to_string()))
}

/// Sliding-window REV mean of a pixel field (window `side` px, at least `min_valid` of it
/// finite), the radiograph stage's operator.
pub fn rev_mean(field: &Array2<f64>, side: usize, min_valid: f64) -> Result<Array2<f64>> {
    let mut sat = Sat::new();
    sat.build(field.view());
    sat.rev_mean(side, min_valid)
        .map_err(|e| AnalysisError::invalid("REV side", side, &e.to_string()))
}

/// Means over non-overlapping `side` × `side` tiles from the top-left corner (the radiograph
/// stage's `grid.csv`).
pub fn rev_tiles(field: &Array2<f64>, side: usize, min_valid: f64) -> Result<Array2<f64>> {
    let mut sat = Sat::new();
    sat.build(field.view());
    sat.tiles(side, min_valid)
        .map_err(|e| AnalysisError::invalid("REV side", side, &e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(n: usize) -> Vec<P2> {
        // A jittered lattice, so that no pixel centre sits on many edges.
        (0..n)
            .flat_map(|j| {
                (0..n).map(move |i| {
                    let k = (i * 7 + j * 13) % 11;
                    [i as f64 + 0.03 * k as f64, j as f64 + 0.02 * k as f64]
                })
            })
            .collect()
    }

    #[test]
    fn every_pixel_inside_the_mesh_gets_a_triangle_and_areas_match() {
        let pts = lattice(12);
        let mesh = Mesh::delaunay(&pts, f64::INFINITY).unwrap();
        let grid = Grid::cover(-1.0, -1.0, 13.0, 13.0, 0.05).unwrap();
        let own = locate(&grid, &mesh, &pts);
        // Pixel counts per triangle approximate the triangle areas.
        let mut count = vec![0usize; mesh.len()];
        for &t in own.iter().filter(|&&t| t != u32::MAX) {
            count[t as usize] += 1;
        }
        let covered = count.iter().sum::<usize>() as f64 * 0.05 * 0.05;
        assert!((covered - mesh.total_area()).abs() / mesh.total_area() < 0.01);
        // Inside the mesh no pixel is left out (centres on shared edges included).
        for r in 0..grid.ny {
            for c in 0..grid.nx {
                let p = grid.centre(r, c);
                if p[0] > 0.5 && p[0] < 10.5 && p[1] > 0.5 && p[1] < 10.5 {
                    assert_ne!(own[[r, c]], u32::MAX, "hole at {p:?}");
                }
            }
        }
        assert_eq!(grid.pixel_of(grid.centre(7, 9)), Some((7, 9)));
        assert_eq!(grid.pixel_of([-2.0, 0.0]), None);
    }

    #[test]
    fn a_uniform_field_averages_to_itself_and_the_rev_matches_the_radiograph_side() {
        let pts = lattice(10);
        let mesh = Mesh::delaunay(&pts, f64::INFINITY).unwrap();
        let grid = Grid::cover(0.0, 0.0, 9.0, 9.0, 0.1).unwrap();
        let own = locate(&grid, &mesh, &pts);
        let f = paint(&own, &vec![0.0625; mesh.len()]);
        let side = rev_side(10f64.sqrt(), 1.0, 0.1).unwrap();
        assert_eq!(side, 32);
        let m = rev_mean(&f, side, 0.5).unwrap();
        let fin: Vec<f64> = m.iter().copied().filter(|v| v.is_finite()).collect();
        assert!(fin.len() > m.len() / 2);
        assert!(fin.iter().all(|v| (v - 0.0625).abs() < 1e-14));
        let t = rev_tiles(&f, side, 0.5).unwrap();
        assert_eq!(t.dim(), (2, 2));
        assert!(Grid::cover(0.0, 0.0, 1.0, 1.0, 0.0).is_err());
        assert!(Grid::cover(1.0, 0.0, 1.0, 1.0, 0.1).is_err());
    }

    /// Strains, pixel owners and REV means are the same bits on one and on two threads.
    #[test]
    fn results_do_not_depend_on_the_thread_count() {
        let pts = lattice(30);
        let def: Vec<P2> = pts
            .iter()
            .map(|p| [p[0] + 0.01 * (p[1] * 0.7).sin(), p[1] + 0.02 * (p[0] * 0.3).cos()])
            .collect();
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    let mesh = Mesh::delaunay(&pts, 3.0).unwrap();
                    let s = crate::strain::triangle_strains(&mesh, &pts, &def).unwrap();
                    let v: Vec<f64> = s.iter().map(|t| t.eps_vol()).collect();
                    let grid = Grid::cover(0.0, 0.0, 29.0, 29.0, 0.1).unwrap();
                    let f = paint(&locate(&grid, &mesh, &pts), &v);
                    rev_mean(&f, 32, 0.5).unwrap()
                })
        };
        let (a, b) = (run(1), run(2));
        assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
        assert!(a.iter().any(|v| v.is_finite() && *v != 0.0));
    }
}
