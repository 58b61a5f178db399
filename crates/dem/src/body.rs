//! Body state as plain data (struct of arrays): rigid clumps of circles in 2D. The coupling
//! engineer reads positions/velocities and writes `ext_force`/`ext_torque`, which the stepper
//! adds every sub-step until changed.

use crate::error::DemError;
use crate::shape::ClumpShape;
use crate::vector::{Vec2, Vector};
use serde::{Deserialize, Serialize};

/// All bodies of a system. Circles of body `b` are `circle_start[b]..circle_start[b+1]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Bodies {
    pub pos: Vec<Vec2>,
    pub vel: Vec<Vec2>,
    pub angle: Vec<f64>,
    pub omega: Vec<f64>,
    pub mass: Vec<f64>,
    pub inertia: Vec<f64>,
    /// Density of each body (kg/m² for unit thickness: mass = density × area).
    pub density: Vec<f64>,
    /// External force and torque (hydrodynamics, user drivers), held over sub-steps.
    pub ext_force: Vec<Vec2>,
    pub ext_torque: Vec<f64>,
    /// Total force and torque of the last force evaluation (needed by velocity Verlet).
    pub force: Vec<Vec2>,
    pub torque: Vec<f64>,
    /// Free-form tag per body (e.g. 1 = membrane grain, 0 = interior grain).
    pub tag: Vec<u32>,
    pub circle_start: Vec<usize>,
    /// Circle centres in the body frame (centroid at the origin) and radii.
    pub circle_offset: Vec<Vec2>,
    pub circle_r: Vec<f64>,
    pub circle_body: Vec<u32>,
}

impl Bodies {
    pub fn new() -> Self {
        Self {
            circle_start: vec![0],
            ..Default::default()
        }
    }

    pub fn len(&self) -> usize {
        self.pos.len()
    }
    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }
    pub fn n_circles(&self) -> usize {
        self.circle_r.len()
    }

    /// Add a rigid clump with density `rho` (kg/m², unit thickness). `shape` may be in any frame:
    /// its centroid is placed at `at` and it is rotated by `angle`. Returns the body index.
    pub fn add(
        &mut self,
        shape: &ClumpShape<Vec2>,
        rho: f64,
        at: Vec2,
        angle: f64,
    ) -> Result<usize, DemError> {
        if !(rho > 0.0 && rho.is_finite()) {
            return Err(DemError::BadParameter {
                name: "density",
                value: rho,
                why: "must be positive",
            });
        }
        let (c, mp) = shape.centred()?;
        let b = self.pos.len();
        self.pos.push(at);
        self.vel.push(Vec2::ZERO);
        self.angle.push(angle);
        self.omega.push(0.0);
        self.mass.push(rho * mp.area);
        self.inertia.push(rho * mp.polar_moment);
        self.density.push(rho);
        self.ext_force.push(Vec2::ZERO);
        self.ext_torque.push(0.0);
        self.force.push(Vec2::ZERO);
        self.torque.push(0.0);
        self.tag.push(0);
        for ball in &c.balls {
            self.circle_offset.push(ball.centre);
            self.circle_r.push(ball.r);
            self.circle_body.push(b as u32);
        }
        self.circle_start.push(self.circle_r.len());
        Ok(b)
    }

    /// Shape of body `b` in its body frame.
    pub fn shape(&self, b: usize) -> ClumpShape<Vec2> {
        let r = self.circle_start[b]..self.circle_start[b + 1];
        ClumpShape {
            balls: r
                .map(|c| crate::shape::Ball {
                    centre: self.circle_offset[c],
                    r: self.circle_r[c],
                })
                .collect(),
        }
    }

    /// World position of circle `c`.
    #[inline]
    pub fn circle_pos(&self, c: usize) -> Vec2 {
        let b = self.circle_body[c] as usize;
        self.pos[b] + self.circle_offset[c].rotated(self.angle[b])
    }

    /// Keep only bodies for which `keep(b)` is true (order preserved).
    pub fn retain(&mut self, keep: impl Fn(usize) -> bool) {
        let mut out = Bodies::new();
        for b in 0..self.len() {
            if keep(b) {
                out.push_copy(self, b);
            }
        }
        *self = out;
    }

    fn push_copy(&mut self, src: &Bodies, b: usize) {
        let nb = self.pos.len() as u32;
        self.pos.push(src.pos[b]);
        self.vel.push(src.vel[b]);
        self.angle.push(src.angle[b]);
        self.omega.push(src.omega[b]);
        self.mass.push(src.mass[b]);
        self.inertia.push(src.inertia[b]);
        self.density.push(src.density[b]);
        self.ext_force.push(src.ext_force[b]);
        self.ext_torque.push(src.ext_torque[b]);
        self.force.push(src.force[b]);
        self.torque.push(src.torque[b]);
        self.tag.push(src.tag[b]);
        for c in src.circle_start[b]..src.circle_start[b + 1] {
            self.circle_offset.push(src.circle_offset[c]);
            self.circle_r.push(src.circle_r[c]);
            self.circle_body.push(nb);
        }
        self.circle_start.push(self.circle_r.len());
    }

    /// Scale every body's size by `s` about its own centroid (positions unchanged), keeping
    /// the density: mass scales by s², inertia by s⁴ (Su Sect. 2.4 radius scaling).
    pub fn scale_sizes(&mut self, s: f64) {
        for c in 0..self.n_circles() {
            self.circle_offset[c] = self.circle_offset[c] * s;
            self.circle_r[c] *= s;
        }
        for b in 0..self.len() {
            self.mass[b] *= s * s;
            self.inertia[b] *= s.powi(4);
        }
    }

    /// Multiply every body's density, mass and moment of inertia by `s` (mass scaling: the
    /// critical time step grows by √s; areas are unchanged).
    pub fn scale_mass(&mut self, s: f64) {
        for b in 0..self.len() {
            self.density[b] *= s;
            self.mass[b] *= s;
            self.inertia[b] *= s;
        }
    }

    /// Total area of the bodies (mass / density).
    pub fn total_area(&self) -> f64 {
        (0..self.len()).map(|b| self.mass[b] / self.density[b]).sum()
    }

    /// Translational plus rotational kinetic energy (summed in body order).
    pub fn kinetic_energy(&self) -> f64 {
        (0..self.len())
            .map(|b| 0.5 * self.mass[b] * self.vel[b].norm2() + 0.5 * self.inertia[b] * self.omega[b].powi(2))
            .sum()
    }

    pub fn max_speed(&self) -> f64 {
        self.vel.iter().map(|v| v.norm2().sqrt()).fold(0.0, f64::max)
    }
}
