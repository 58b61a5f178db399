//! Walls: infinite planes (lines) or finite segments, fixed, moving at a prescribed velocity
//! (the push-plate of Su et al. 2020) or servo-controlled to hold a target stress (Su Sect. 2.4:
//! isotropic compression to a 2D stress of 500 N/m).

use crate::vector::{Vec2, Vector};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case")]
pub enum WallShape {
    /// Half-plane boundary through `p` with unit normal `n` pointing into the particle region.
    Plane { p: Vec2, n: Vec2 },
    /// Two-sided finite segment from `a` to `b`.
    Segment { a: Vec2, b: Vec2 },
}

/// Length used to turn the servo wall's force into a 2D stress (N/m).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ServoLength {
    Fixed(f64),
    /// Distance between two plane walls (the perpendicular pair of a box).
    Between(usize, usize),
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum WallMotion {
    Fixed,
    Velocity {
        v: Vec2,
    },
    /// Servo (PFC-style, Itasca): the speed along the normal closes a fraction `alpha` of the
    /// stress error per step, v = α L (σ_target − σ) / (k_n N_c Δt) with N_c the wall's contacts,
    /// clamped to ±v_max (full speed while nothing touches the wall).
    Servo {
        target_stress: f64,
        alpha: f64,
        v_max: f64,
        length: ServoLength,
    },
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Wall {
    pub shape: WallShape,
    pub motion: WallMotion,
    /// Current velocity.
    pub vel: Vec2,
    /// Force exerted by the particles on the wall at the last step.
    pub force: Vec2,
    /// Number of circles touching the wall at the last step.
    #[serde(default)]
    pub n_contacts: u32,
}

impl Wall {
    pub fn new(shape: WallShape, motion: WallMotion) -> Self {
        let vel = match motion {
            WallMotion::Velocity { v } => v,
            _ => Vec2::ZERO,
        };
        Self {
            shape,
            motion,
            vel,
            force: Vec2::ZERO,
            n_contacts: 0,
        }
    }
    pub fn plane(p: Vec2, n: Vec2) -> Self {
        Self::new(
            WallShape::Plane {
                p,
                n: n * (1.0 / n.norm()),
            },
            WallMotion::Fixed,
        )
    }

    /// Overlap and unit normal from the circle towards the wall, if touching.
    #[inline]
    pub fn touch(&self, c: Vec2, r: f64) -> Option<(f64, Vec2)> {
        self.touch_within(c, r, 0.0)
    }

    /// [`Wall::touch`] for a law acting across a gap up to `range`: also a circle whose gap to
    /// the wall is below `range` (overlap < 0 then).
    #[inline]
    pub fn touch_within(&self, c: Vec2, r: f64, range: f64) -> Option<(f64, Vec2)> {
        let reach = r + range;
        match self.shape {
            WallShape::Plane { p, n } => {
                let d = (c - p).dot(n);
                (d < reach).then_some((r - d, -n))
            }
            WallShape::Segment { a, b } => {
                let ab = b - a;
                let t = ((c - a).dot(ab) / ab.norm2()).clamp(0.0, 1.0);
                let q = a + ab * t;
                let d = c - q;
                let dist = d.norm();
                (dist < reach && dist > 0.0).then(|| (r - dist, d * (-1.0 / dist)))
            }
        }
    }

    /// False where [`Wall::touch_within`] with reach `reach` (r + range) surely gives `None`: a
    /// plane's circles farther than the reach, a segment's outside its bounding box grown by the
    /// reach (each with a hair more than the round-off of the distance). The wall pass's search
    /// for the circles near a wall (`stepper/walls.rs`).
    #[inline]
    pub fn may_touch(&self, c: Vec2, reach: f64) -> bool {
        // The reach and a hair more than the round-off of a distance among these coordinates.
        let grown = |scale: f64| reach + 1e-6 * reach.abs() + 1e-12 * scale;
        match self.shape {
            WallShape::Plane { p, n } => (c - p).dot(n) < grown(p.x.abs() + p.y.abs()),
            WallShape::Segment { a, b } => {
                let g = grown(a.x.abs() + a.y.abs() + b.x.abs() + b.y.abs());
                c.x >= a.x.min(b.x) - g
                    && c.x <= a.x.max(b.x) + g
                    && c.y >= a.y.min(b.y) - g
                    && c.y <= a.y.max(b.y) + g
            }
        }
    }

    /// How far the wall is from where it was as `before`: the larger displacement of its points
    /// (p, or a and b); infinite if its kind or its normal changed.
    pub fn moved_from(&self, before: &Wall) -> f64 {
        match (self.shape, before.shape) {
            (WallShape::Plane { p, n }, WallShape::Plane { p: p0, n: n0 }) if n == n0 => (p - p0).norm(),
            (WallShape::Segment { a, b }, WallShape::Segment { a: a0, b: b0 }) => {
                (a - a0).norm().max((b - b0).norm())
            }
            _ => f64::INFINITY,
        }
    }

    /// Normal stress on a servo wall (N/m), compressive positive.
    pub fn stress(&self, length: f64) -> f64 {
        match self.shape {
            WallShape::Plane { n, .. } => -self.force.dot(n) / length,
            WallShape::Segment { a, b } => self.force.norm() / (b - a).norm(),
        }
    }

    pub fn translate(&mut self, d: Vec2) {
        match &mut self.shape {
            WallShape::Plane { p, .. } => *p += d,
            WallShape::Segment { a, b } => {
                *a += d;
                *b += d;
            }
        }
    }

    /// Distance between two plane walls (0 for segments).
    pub fn gap(w1: &Wall, w2: &Wall) -> f64 {
        match (w1.shape, w2.shape) {
            (WallShape::Plane { p: p1, n }, WallShape::Plane { p: p2, .. }) => (p2 - p1).dot(n).abs(),
            _ => 0.0,
        }
    }
}

/// Set each wall's velocity for the coming step from its motion (servo: from the last force;
/// `k_n` is the contact stiffness, `dt` the step).
pub fn update_wall_velocities(walls: &mut [Wall], k_n: f64, dt: f64) {
    for k in 0..walls.len() {
        if let WallMotion::Servo {
            target_stress,
            alpha,
            v_max,
            length,
        } = walls[k].motion
        {
            let l = match length {
                ServoLength::Fixed(l) => l,
                ServoLength::Between(a, b) => Wall::gap(&walls[a], &walls[b]),
            };
            let sigma = walls[k].stress(l.max(f64::MIN_POSITIVE));
            let err = target_stress - sigma;
            let nc = walls[k].n_contacts as f64;
            let v = if nc > 0.0 {
                alpha * l * err / (k_n * nc * dt)
            } else {
                v_max.copysign(err)
            };
            let v = v.clamp(-v_max, v_max);
            if let WallShape::Plane { n, .. } = walls[k].shape {
                walls[k].vel = n * v;
            }
        }
    }
}
