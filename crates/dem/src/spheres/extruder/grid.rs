//! A bucket grid of grain centres for placing new grains without overlap (insertion and the
//! initial fill): cells at least as wide as the largest diameter, so a new grain can only
//! overlap grains of its own and the neighbouring cells; z is periodic over the depth.

use crate::spheres::domain::Domain3;
use crate::vector::{Vec3, Vector};

pub struct Grid {
    lo: [f64; 2],
    cell: [f64; 3],
    n: [usize; 3],
    buckets: Vec<Vec<(Vec3, f64)>>,
}

impl Grid {
    /// A grid over x in [lo[0], hi[0]], y in [lo[1], hi[1]], z over `depth`, cells at least
    /// `width` wide.
    pub fn new(lo: [f64; 2], hi: [f64; 2], depth: f64, width: f64) -> Self {
        let count = |len: f64| ((len / width).floor() as usize).max(1);
        let n = [count(hi[0] - lo[0]), count(hi[1] - lo[1]), count(depth)];
        Self {
            lo,
            cell: [
                (hi[0] - lo[0]) / n[0] as f64,
                (hi[1] - lo[1]) / n[1] as f64,
                depth / n[2] as f64,
            ],
            n,
            buckets: vec![Vec::new(); n[0] * n[1] * n[2]],
        }
    }

    fn coord(&self, p: Vec3) -> [usize; 3] {
        let c = |v: f64, lo: f64, w: f64, n: usize| (((v - lo) / w).floor().max(0.0) as usize).min(n - 1);
        [
            c(p.x, self.lo[0], self.cell[0], self.n[0]),
            c(p.y, self.lo[1], self.cell[1], self.n[1]),
            c(p.z, 0.0, self.cell[2], self.n[2]),
        ]
    }

    pub fn insert(&mut self, p: Vec3, r: f64) {
        let [i, j, k] = self.coord(p);
        self.buckets[(k * self.n[1] + j) * self.n[0] + i].push((p, r));
    }

    /// Whether a grain of radius `r` at `p` stays clear (gap ≥ 0) of every grain in the grid,
    /// distances by `dom`'s minimum image.
    pub fn clear(&self, dom: &Domain3, p: Vec3, r: f64) -> bool {
        let [i, j, k] = self.coord(p);
        let span = |c: usize, n: usize, periodic: bool| -> Vec<usize> {
            if periodic && n < 3 {
                (0..n).collect()
            } else if periodic {
                vec![(c + n - 1) % n, c, (c + 1) % n]
            } else {
                (c.saturating_sub(1)..=(c + 1).min(n - 1)).collect()
            }
        };
        for kk in span(k, self.n[2], true) {
            for jj in span(j, self.n[1], false) {
                for ii in span(i, self.n[0], false) {
                    for &(q, rq) in &self.buckets[(kk * self.n[1] + jj) * self.n[0] + ii] {
                        let s = r + rq;
                        if dom.min_image(p - q).norm2() < s * s {
                            return false;
                        }
                    }
                }
            }
        }
        true
    }
}
