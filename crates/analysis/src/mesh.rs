//! The triangulation the strain is measured on: Delaunay triangles of the grain centroids in the
//! reference snapshot (Su et al. 2020 Sect. 2.5, the "continuum-based triangulation approach"
//! of refs. [104-106]). Every grain is a vertex; the triangles connect neighbours, so each
//! triangle is a small piece of continuum whose three corners move with three grains.
//!
//! Delaunay triangles of a granular sample include long, thin triangles along a concave
//! outline (they span empty space, not material). `max_edge` drops every triangle with an edge
//! longer than it; the stages take it as a multiple of d̄.

use crate::{AnalysisError, P2, Result};

/// Triangles over a set of points, each counter-clockwise (positive area, y up).
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Vertex indices of each triangle, counter-clockwise.
    pub triangles: Vec<[usize; 3]>,
    /// Reference (undeformed) area of each triangle.
    pub area: Vec<f64>,
}

/// Signed area of the triangle a, b, c (positive when counter-clockwise, y up).
#[inline]
pub fn signed_area(a: P2, b: P2, c: P2) -> f64 {
    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
}

fn edge(a: P2, b: P2) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

impl Mesh {
    /// Delaunay triangulation of `points`, keeping triangles whose edges are all at most
    /// `max_edge` long (`f64::INFINITY` keeps all) and whose area is not negligible (below
    /// 1e-12 of the mean: collinear slivers delaunator can leave on the hull).
    pub fn delaunay(points: &[P2], max_edge: f64) -> Result<Self> {
        if max_edge.is_nan() || max_edge <= 0.0 {
            return Err(AnalysisError::invalid(
                "max_edge",
                max_edge,
                "must be positive (a length, e.g. 3 mean grain diameters)",
            ));
        }
        if let Some((i, p)) = points
            .iter()
            .enumerate()
            .find(|(_, p)| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(AnalysisError::invalid(
                &format!("point {i}"),
                format!("({}, {})", p[0], p[1]),
                "is not finite; the snapshot holds a NaN position (a blown-up run?)",
            ));
        }
        let pts: Vec<delaunator::Point> = points
            .iter()
            .map(|p| delaunator::Point { x: p[0], y: p[1] })
            .collect();
        let t = delaunator::triangulate(&pts);
        let mut tris = Vec::with_capacity(t.triangles.len() / 3);
        let mut area = Vec::with_capacity(t.triangles.len() / 3);
        for c in t.triangles.chunks_exact(3) {
            let (a, b, d) = (points[c[0]], points[c[1]], points[c[2]]);
            if edge(a, b) > max_edge || edge(b, d) > max_edge || edge(d, a) > max_edge {
                continue;
            }
            let s = signed_area(a, b, d);
            // delaunator orders its triangles clockwise in a y-up frame; store them
            // counter-clockwise so that every area is positive.
            if s < 0.0 {
                tris.push([c[0], c[2], c[1]]);
                area.push(-s);
            } else {
                tris.push([c[0], c[1], c[2]]);
                area.push(s);
            }
        }
        let mean = area.iter().sum::<f64>() / area.len().max(1) as f64;
        let (tris, area): (Vec<[usize; 3]>, Vec<f64>) = tris
            .into_iter()
            .zip(area)
            .filter(|(_, a)| *a > 1e-12 * mean)
            .unzip();
        if tris.is_empty() {
            return Err(AnalysisError::NoTriangles {
                points: points.len(),
                max_edge,
            });
        }
        Ok(Self {
            triangles: tris,
            area,
        })
    }

    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Total reference area of the triangles.
    pub fn total_area(&self) -> f64 {
        self.area.iter().sum()
    }

    /// The vertices of triangle `t` in `points`.
    #[inline]
    pub fn corners(&self, t: usize, points: &[P2]) -> [P2; 3] {
        let [a, b, c] = self.triangles[t];
        [points[a], points[b], points[c]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_grid_gives_two_triangles_per_cell_all_counter_clockwise() {
        let pts: Vec<P2> = (0..5)
            .flat_map(|j| (0..4).map(move |i| [i as f64, j as f64 * 1.1]))
            .collect();
        let m = Mesh::delaunay(&pts, f64::INFINITY).unwrap();
        assert_eq!(m.len(), 2 * 3 * 4);
        assert!((m.total_area() - 3.0 * 4.0 * 1.1).abs() < 1e-12);
        for t in 0..m.len() {
            let [a, b, c] = m.corners(t, &pts);
            assert!(signed_area(a, b, c) > 0.0);
        }
    }

    #[test]
    fn long_edges_are_dropped_and_nothing_left_is_an_error() {
        // Two clusters far apart: the triangles bridging them have long edges.
        let mut pts: Vec<P2> = vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
        pts.extend([[10.0, 0.0], [11.0, 0.0], [10.0, 1.0], [11.0, 1.0]]);
        let all = Mesh::delaunay(&pts, f64::INFINITY).unwrap();
        let near = Mesh::delaunay(&pts, 2.0).unwrap();
        assert!(all.len() > near.len());
        assert_eq!(near.len(), 4);
        assert!(matches!(
            Mesh::delaunay(&pts, 0.5),
            Err(AnalysisError::NoTriangles { .. })
        ));
        let collinear: Vec<P2> = (0..5).map(|i| [i as f64, 2.0 * i as f64]).collect();
        assert!(Mesh::delaunay(&collinear, f64::INFINITY).is_err());
        assert!(Mesh::delaunay(&[[0.0, f64::NAN], [1.0, 0.0], [0.0, 1.0]], 1.0).is_err());
    }
}
