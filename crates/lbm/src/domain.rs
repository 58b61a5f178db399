//! The lattice as plain data: dimensions, the rule on each face of the box, and per-node kinds
//! (fluid, obstacle solid, inactive). Geometry is set by filling circles/spheres or a mask.

use serde::{Deserialize, Serialize};

/// Node kind: a fluid node is updated; solid and inactive nodes are never updated (they cost
/// nothing but one byte) and act as halfway bounce-back walls for their fluid neighbours.
pub const FLUID: u8 = 0;
pub const SOLID: u8 = 1;
pub const INACTIVE: u8 = 2;

/// Obstacle id of a node that belongs to no obstacle.
pub const NO_OBSTACLE: u16 = u16::MAX;

/// What happens to populations that would stream in from outside the box through one face.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum Face {
    /// Wrap around to the opposite face.
    Periodic,
    /// Halfway bounce-back wall moving tangentially with `velocity` (lattice units; Leonardi Eq. 19).
    Wall { velocity: [f64; 3] },
    /// Zou-He velocity boundary on the nodes of the face (D2Q9).
    Velocity { velocity: [f64; 3] },
    /// Zou-He pressure (density) boundary on the nodes of the face (D2Q9).
    Pressure { rho: f64 },
}

impl Face {
    pub fn is_periodic(&self) -> bool {
        matches!(self, Face::Periodic)
    }
    pub fn is_zou_he(&self) -> bool {
        matches!(self, Face::Velocity { .. } | Face::Pressure { .. })
    }
}

/// Box of `n[0] x n[1] x n[2]` nodes (n[2] = 1 in 2D), index = x + nx (y + ny z).
/// `faces` = [x-, x+, y-, y+, z-, z+].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Domain {
    pub n: [usize; 3],
    pub faces: [Face; 6],
    pub kind: Vec<u8>,
    pub obstacle: Vec<u16>,
}

/// Rigid-body motion of an obstacle; the wall velocity at a link is u + ω × r (Leonardi Eq. 20).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Motion {
    pub centre: [f64; 3],
    pub velocity: [f64; 3],
    pub omega: [f64; 3],
}

impl Motion {
    /// Wall velocity at point `p`, with `r` the (minimum-image) offset from the centre.
    pub fn velocity_at(&self, r: [f64; 3]) -> [f64; 3] {
        let w = self.omega;
        [
            self.velocity[0] + w[1] * r[2] - w[2] * r[1],
            self.velocity[1] + w[2] * r[0] - w[0] * r[2],
            self.velocity[2] + w[0] * r[1] - w[1] * r[0],
        ]
    }
}

impl Domain {
    /// All-fluid box; 2D when `n[2] == 1`.
    pub fn new(n: [usize; 3], faces: [Face; 6]) -> Self {
        let len = n[0] * n[1] * n[2];
        Self {
            n,
            faces,
            kind: vec![FLUID; len],
            obstacle: vec![NO_OBSTACLE; len],
        }
    }
    /// Fully periodic box.
    pub fn periodic(n: [usize; 3]) -> Self {
        Self::new(n, [Face::Periodic; 6])
    }
    pub fn len(&self) -> usize {
        self.kind.len()
    }
    pub fn is_empty(&self) -> bool {
        self.kind.is_empty()
    }
    #[inline]
    pub fn index(&self, x: usize, y: usize, z: usize) -> usize {
        x + self.n[0] * (y + self.n[1] * z)
    }
    #[inline]
    pub fn coords(&self, idx: usize) -> [usize; 3] {
        let x = idx % self.n[0];
        let r = idx / self.n[0];
        [x, r % self.n[1], r / self.n[1]]
    }
    pub fn fluid_count(&self) -> usize {
        self.kind.iter().filter(|&&k| k == FLUID).count()
    }
    /// Minimum-image offset b − a along periodic axes.
    pub fn offset(&self, a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        let mut r = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        for (ax, ra) in r.iter_mut().enumerate() {
            if self.faces[2 * ax].is_periodic() && self.faces[2 * ax + 1].is_periodic() {
                let l = self.n[ax] as f64;
                *ra -= l * (*ra / l).round();
            }
        }
        r
    }
    /// Mark as solid obstacle `id` every node whose centre lies within `radius` of `centre`
    /// (a circle in 2D, a sphere in 3D; node coordinates are their indices; periodic images
    /// included). Staircase approximation: first-order in the radius (REFERENCES.md).
    pub fn fill_sphere(&mut self, id: u16, centre: [f64; 3], radius: f64) {
        let r2 = radius * radius;
        let dims = if self.n[2] == 1 { 2 } else { 3 };
        let mut lo = [0usize; 3];
        let mut hi = [1usize; 3];
        for a in 0..dims {
            lo[a] = 0;
            hi[a] = self.n[a];
        }
        for z in lo[2]..hi[2] {
            for y in lo[1]..hi[1] {
                for x in lo[0]..hi[0] {
                    let p = [x as f64, y as f64, if dims == 3 { z as f64 } else { centre[2] }];
                    let r = self.offset(centre, p);
                    if r[0] * r[0] + r[1] * r[1] + r[2] * r[2] <= r2 {
                        let i = self.index(x, y, z);
                        self.kind[i] = SOLID;
                        self.obstacle[i] = id;
                    }
                }
            }
        }
    }
    /// Mark nodes where `mask` is true as solid obstacle `id` (mask in node order).
    pub fn fill_mask(&mut self, id: u16, mask: &[bool]) {
        for (i, &m) in mask.iter().enumerate().take(self.len()) {
            if m {
                self.kind[i] = SOLID;
                self.obstacle[i] = id;
            }
        }
    }
}
