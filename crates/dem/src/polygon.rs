//! The shapes of a shear cell's sample (Su et al. 2020 Sects. 2.4-2.5): the polygon joining the
//! centroids of the membrane grains, the region behind the push-plate, their areas and their
//! overlap. Eq. 18 needs the polygon's area minus the plate's penetration area, and the
//! coupling's "solid zone" (step 15 of Su Fig. 2) needs to know which lattice nodes lie inside.
//!
//! A few lines of plane geometry, written here rather than pulled from a GIS crate: the shapes
//! are a simple ring of a few hundred vertices and one convex quadrilateral.

use crate::body::Bodies;
use crate::system::Membrane;
use crate::vector::{Vec2, Vector};
use crate::wall::{Wall, WallShape};

/// Signed area of a closed polygon (shoelace; positive when counter-clockwise).
pub fn signed_area(p: &[Vec2]) -> f64 {
    let n = p.len();
    if n < 3 {
        return 0.0;
    }
    0.5 * (0..n).map(|i| p[i].cross(p[(i + 1) % n])).sum::<f64>()
}

/// The part of `subject` on the left of the directed line a → b (Sutherland-Hodgman, one edge).
fn clip_left(subject: &[Vec2], a: Vec2, b: Vec2) -> Vec<Vec2> {
    let side = |p: Vec2| (b - a).cross(p - a);
    let mut out = Vec::with_capacity(subject.len() + 2);
    let n = subject.len();
    for i in 0..n {
        let (p, q) = (subject[i], subject[(i + 1) % n]);
        let (sp, sq) = (side(p), side(q));
        if sp >= 0.0 {
            out.push(p);
        }
        if (sp >= 0.0) != (sq >= 0.0) {
            let t = sp / (sp - sq);
            out.push(p + (q - p) * t);
        }
    }
    out
}

/// Area of `subject ∩ clip` for any simple polygon `subject` and a convex, counter-clockwise
/// `clip` (Sutherland-Hodgman: for a non-convex subject the clipped ring may contain
/// zero-width bridges, which add no area).
pub fn intersection_area(subject: &[Vec2], clip: &[Vec2]) -> f64 {
    let mut poly = subject.to_vec();
    if signed_area(&poly) < 0.0 {
        poly.reverse();
    }
    let m = clip.len();
    for i in 0..m {
        if poly.is_empty() {
            return 0.0;
        }
        poly = clip_left(&poly, clip[i], clip[(i + 1) % m]);
    }
    signed_area(&poly).abs()
}

/// Whether `p` lies inside the closed polygon (even-odd rule).
pub fn contains(poly: &[Vec2], p: Vec2) -> bool {
    let n = poly.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

/// For each row `y` of `ys`, the x intervals [x0, x1) inside the polygon (even-odd rule), as
/// `f(row, x0, x1)` calls: a scanline fill for rasterising the sample onto a lattice every LBM
/// step. With ascending rows each edge finds the rows it crosses by bisection, O(edges log rows
/// + crossings), not O(rows × edges); the crossings and their order are the same either way.
pub fn scan_rows(poly: &[Vec2], ys: impl Iterator<Item = f64>, mut f: impl FnMut(usize, f64, f64)) {
    let ys: Vec<f64> = ys.collect();
    let n = poly.len();
    let cross = |a: Vec2, b: Vec2, y: f64| a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x);
    if !ys.windows(2).all(|w| w[0] <= w[1]) {
        let mut xs = Vec::new();
        for (row, &y) in ys.iter().enumerate() {
            xs.clear();
            for i in 0..n {
                let (a, b) = (poly[i], poly[(i + 1) % n]);
                if (a.y > y) != (b.y > y) {
                    xs.push(cross(a, b, y));
                }
            }
            xs.sort_by(f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                f(row, pair[0], pair[1]);
            }
        }
        return;
    }
    // (a.y > y) != (b.y > y) holds exactly for min(a.y, b.y) <= y < max(a.y, b.y).
    let mut hits: Vec<(usize, f64)> = Vec::new();
    for i in 0..n {
        let (a, b) = (poly[i], poly[if i + 1 == n { 0 } else { i + 1 }]);
        let (lo, hi) = if a.y < b.y { (a.y, b.y) } else { (b.y, a.y) };
        let r0 = ys.partition_point(|&y| y < lo);
        let r1 = ys.partition_point(|&y| y < hi);
        for (r, &y) in ys.iter().enumerate().take(r1).skip(r0) {
            hits.push((r, cross(a, b, y)));
        }
    }
    hits.sort_by(|p, q| p.0.cmp(&q.0).then(p.1.total_cmp(&q.1)));
    for row in hits.chunk_by(|p, q| p.0 == q.0) {
        for pair in row.chunks_exact(2) {
            f(pair[0].0, pair[0].1, pair[1].1);
        }
    }
}

impl Membrane {
    /// The members in the order they go round the sample: by angle of their reference positions
    /// about the membrane's centre (the ring is star-shaped about it when built, and the order is
    /// kept while the ring deforms).
    pub fn ring_order(&self) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.bodies.len()).collect();
        let angle = |k: usize| {
            let d = self.reference[k] - self.centre;
            d.y.atan2(d.x)
        };
        order.sort_by(|&a, &b| angle(a).total_cmp(&angle(b)).then(a.cmp(&b)));
        order
    }

    /// The polygon joining the centroids of the members in `order` (Su Sect. 2.5, Eq. 18),
    /// counter-clockwise.
    pub fn polygon(&self, order: &[usize], b: &Bodies) -> Vec<Vec2> {
        order.iter().map(|&k| b.pos[self.bodies[k] as usize]).collect()
    }
}

/// How far behind a push-plate its solid region reaches (m): far beyond any sample.
const PLATE_DEPTH: f64 = 1.0;

/// The solid region of a push-plate: the quadrilateral swept behind its segment, opposite to the
/// direction it moves in (counter-clockwise). `None` for planes and for walls at rest, which
/// have no "behind".
pub fn plate_region(w: &Wall) -> Option<[Vec2; 4]> {
    let WallShape::Segment { a, b } = w.shape else {
        return None;
    };
    let speed = w.vel.norm();
    let dir = match w.motion {
        crate::wall::WallMotion::Velocity { v } if v.norm() > 0.0 => v * (1.0 / v.norm()),
        _ if speed > 0.0 => w.vel * (1.0 / speed),
        _ => return None,
    };
    let back = dir * (-PLATE_DEPTH);
    let mut q = [a, b, b + back, a + back];
    if signed_area(&q) < 0.0 {
        q.reverse();
    }
    Some(q)
}

/// A_def of Su Eq. 18: the area of the membrane polygon minus the part of it the push-plates'
/// regions cover (their penetration).
pub fn sample_area(ring: &[Vec2], plates: &[[Vec2; 4]]) -> f64 {
    let a = signed_area(ring).abs();
    a - plates.iter().map(|q| intersection_area(ring, q)).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(lo: f64, hi: f64) -> Vec<Vec2> {
        vec![
            Vec2::new(lo, lo),
            Vec2::new(hi, lo),
            Vec2::new(hi, hi),
            Vec2::new(lo, hi),
        ]
    }

    #[test]
    fn areas_of_a_square_and_its_overlap_with_another() {
        let s = square(0.0, 2.0);
        assert_eq!(signed_area(&s), 4.0);
        let mut cw = s.clone();
        cw.reverse();
        assert_eq!(signed_area(&cw), -4.0);
        // unit square [1, 3]² overlaps [0, 2]² in [1, 2]²
        assert!((intersection_area(&cw, &square(1.0, 3.0)) - 1.0).abs() < 1e-15);
        assert_eq!(intersection_area(&s, &square(5.0, 6.0)), 0.0);
    }

    #[test]
    fn clipping_a_non_convex_ring_keeps_the_covered_area() {
        // A "U": [0,3]x[0,3] minus the notch [1,2]x[1,3]; area 9 - 2 = 7.
        let u = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(3.0, 0.0),
            Vec2::new(3.0, 3.0),
            Vec2::new(2.0, 3.0),
            Vec2::new(2.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 3.0),
            Vec2::new(0.0, 3.0),
        ];
        assert!((signed_area(&u) - 7.0).abs() < 1e-15);
        // The band y in [2, 4] covers the two prongs: 2 x (1 x 1).
        let band = vec![
            Vec2::new(-1.0, 2.0),
            Vec2::new(4.0, 2.0),
            Vec2::new(4.0, 4.0),
            Vec2::new(-1.0, 4.0),
        ];
        assert!((intersection_area(&u, &band) - 2.0).abs() < 1e-14);
        assert!(contains(&u, Vec2::new(0.5, 2.5)));
        assert!(!contains(&u, Vec2::new(1.5, 2.5)));
        let mut spans = Vec::new();
        scan_rows(&u, [0.5, 2.5].into_iter(), |r, x0, x1| spans.push((r, x0, x1)));
        assert_eq!(spans, vec![(0, 0.0, 3.0), (1, 0.0, 1.0), (1, 2.0, 3.0)]);
    }

    /// The bisection path gives the spans of the row-by-row scan (which rows given in
    /// descending order take), on star-shaped rings with vertices on and between the rows.
    #[test]
    fn scanline_spans_agree_between_the_two_paths() {
        for seed in 0..20u32 {
            let m = 40 + seed as usize * 7;
            let ring: Vec<Vec2> = (0..m)
                .map(|k| {
                    let t = k as f64 / m as f64 * std::f64::consts::TAU;
                    let r = 30.0 + 8.0 * ((seed as f64 + 3.0) * t).sin();
                    let y = 40.0 + r * t.sin();
                    // Every fifth vertex exactly on a row centre.
                    let y = if k % 5 == 0 { y.floor() + 0.5 } else { y };
                    Vec2::new(40.0 + r * t.cos(), y)
                })
                .collect();
            let rows: Vec<f64> = (0..80).map(|j| j as f64 + 0.5).collect();
            let mut fast = Vec::new();
            scan_rows(&ring, rows.iter().copied(), |r, a, b| fast.push((r, a, b)));
            let mut slow = Vec::new();
            scan_rows(&ring, rows.iter().rev().copied(), |r, a, b| {
                slow.push((79 - r, a, b))
            });
            slow.sort_by(|p, q| p.0.cmp(&q.0).then(p.1.total_cmp(&q.1)));
            assert!(!fast.is_empty());
            assert_eq!(fast, slow, "seed {seed}");
        }
    }

    #[test]
    fn a_push_plate_region_lies_behind_its_motion() {
        let w = Wall::new(
            WallShape::Segment {
                a: Vec2::new(1.0, 0.0),
                b: Vec2::new(2.0, 0.0),
            },
            crate::wall::WallMotion::Velocity {
                v: Vec2::new(0.0, 0.1),
            },
        );
        let q = plate_region(&w).expect("a moving segment has a region");
        assert!(signed_area(&q) > 0.0);
        assert!(contains(&q, Vec2::new(1.5, -0.5)));
        assert!(!contains(&q, Vec2::new(1.5, 0.5)));
        // A sample [0, 3] x [-0.5, 3] is penetrated by the plate over 1 x 0.5.
        let ring = vec![
            Vec2::new(0.0, -0.5),
            Vec2::new(3.0, -0.5),
            Vec2::new(3.0, 3.0),
            Vec2::new(0.0, 3.0),
        ];
        assert!((sample_area(&ring, &[q]) - (3.0 * 3.5 - 0.5)).abs() < 1e-12);
        let at_rest = Wall::new(w.shape, crate::wall::WallMotion::Fixed);
        assert!(plate_region(&at_rest).is_none());
    }
}
