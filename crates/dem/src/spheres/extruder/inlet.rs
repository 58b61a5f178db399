//! The inlet box (Ness et al. 2017, Fig. 1's dashed box): "particles are generated inside the
//! dashed box at each timestep, such that the particle volume fraction ... within this region
//! remains at approximately φ = 0.5", and "a constant body force F in the +x direction" acts on
//! every grain inside it. Here the box is the barrel's first `inlet_length` from the ram face.
//! Every `insert_every` steps new grains are placed at random, clear of every grain (gap ≥ 0)
//! and of the wall lines, until the box's φ (grain volume with the centre in the box over the
//! box's volume) reaches `phi_inlet` or `insert_attempts` random positions in a row failed; the
//! sizes alternate d_small, d_large in the order grains are placed, so the paste is 1:1 by
//! number (Ness's bidisperse paste) at every moment. A new grain takes the mean velocity of the
//! grains in the box. The random positions of a pass come from a generator seeded by the
//! scene's seed and the step, so a resumed run places the same grains.

use super::error::ExtruderError;
use super::geometry::Geometry;
use super::grid::Grid;
use crate::spheres::system::SphereSystem;
use crate::vector::Vec3;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The paste's grains: two diameters, 1:1 by number, one density (m, kg/m³).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Paste {
    /// [d, 1.5 d] (Ness).
    pub diameters: [f64; 2],
    pub density: f64,
}

impl Paste {
    /// [smallest, largest] diameter.
    pub fn range(&self) -> [f64; 2] {
        let [a, b] = self.diameters;
        [a.min(b), a.max(b)]
    }

    /// Diameter of the `n`-th grain placed (0-based).
    pub fn diameter(&self, n: u64) -> f64 {
        self.diameters[(n % 2) as usize]
    }

    pub fn check(&self) -> Result<(), ExtruderError> {
        for d in self.diameters {
            if !(d > 0.0 && d.is_finite()) {
                return Err(ExtruderError::Parameter {
                    name: "paste diameter",
                    value: d,
                    why: "it must be a positive, finite length (m)".into(),
                    fix: "give diameters = [d, 1.5 d] (Ness)".into(),
                });
            }
        }
        if !(self.density > 0.0 && self.density.is_finite()) {
            return Err(ExtruderError::Parameter {
                name: "paste density",
                value: self.density,
                why: "it must be positive and finite (kg/m^3)".into(),
                fix: "give the liquid's density (density-matched paste)".into(),
            });
        }
        Ok(())
    }
}

/// How the paste is fed and driven.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Drive {
    /// Body force F on every grain whose centre is in the inlet box, along +x (N).
    pub body_force: f64,
    /// Volume fraction kept in the inlet box (Ness: 0.5).
    pub phi_inlet: f64,
    /// Steps between insertion passes.
    pub insert_every: u64,
    /// Failed random positions in a row that end a pass.
    pub insert_attempts: u32,
    /// Seed of the insertion positions (and of the initial fill).
    pub seed: u64,
    /// Volume fraction of an initial fill of the whole channel (0: start empty, as Ness).
    pub prefill_phi: f64,
}

impl Drive {
    pub fn check(&self) -> Result<(), ExtruderError> {
        let bad = |name, value: f64, why: &str, fix: &str| ExtruderError::Parameter {
            name,
            value,
            why: why.into(),
            fix: fix.into(),
        };
        if !(self.body_force > 0.0 && self.body_force.is_finite()) {
            return Err(bad(
                "body_force",
                self.body_force,
                "it must be a positive force in N (along +x)",
                "give a force F with F/(k_n d) << 1 (Ness: 1e-5 to 1e-3 k_n d)",
            ));
        }
        if !(self.phi_inlet > 0.0 && self.phi_inlet < 0.64) {
            return Err(bad(
                "phi_inlet",
                self.phi_inlet,
                "a volume fraction of spheres must lie in (0, 0.64)",
                "give 0.5 (Ness)",
            ));
        }
        if self.insert_every == 0 {
            return Err(bad("insert_every", 0.0, "it must be at least 1 step", "give 10"));
        }
        if self.insert_attempts == 0 {
            return Err(bad("insert_attempts", 0.0, "it must be at least 1", "give 200"));
        }
        if !(0.0..0.4).contains(&self.prefill_phi) {
            return Err(bad(
                "prefill_phi",
                self.prefill_phi,
                "random placement without overlap cannot pass about 0.38; it must lie in [0, 0.4)",
                "give 0 (start empty) or at most 0.35",
            ));
        }
        Ok(())
    }
}

/// A generator for the pass at `step` (seeded by the scene's seed and the step).
pub fn pass_rng(seed: u64, step: u64) -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(seed ^ step.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15))
}

/// Volume of a sphere of diameter `d`.
pub fn ball(d: f64) -> f64 {
    PI / 6.0 * d * d * d
}

/// φ of the inlet box and the mean velocity of the grains in it, over the mobile spheres from
/// `first` on.
pub fn inlet_state(g: &Geometry, sys: &SphereSystem, first: usize) -> (f64, Vec3) {
    let s = &sys.spheres;
    let (mut vol, mut v, mut n) = (0.0, Vec3::ZERO, 0usize);
    for k in first..s.len() {
        if s.pos[k].x < g.inlet_length {
            vol += ball(2.0 * s.radius[k]);
            v += s.vel[k];
            n += 1;
        }
    }
    let box_volume = g.inlet_length * g.barrel_width * g.depth;
    (
        vol / box_volume,
        if n > 0 { v * (1.0 / n as f64) } else { Vec3::ZERO },
    )
}

/// Whether a grain of radius `r` centred at `p` lies in the channel clear of every wall line
/// (wall grains sit on the lines, so this keeps it clear of them).
pub fn clear_of_walls(g: &Geometry, p: Vec3, r: f64) -> bool {
    if !g.inside(p) {
        return false;
    }
    let reach = 0.5 * g.wall_diameter + r;
    g.lines().iter().all(|(a, b, _)| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let t = (((p.x - a[0]) * dx + (p.y - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
        let (ex, ey) = (p.x - a[0] - t * dx, p.y - a[1] - t * dy);
        ex * ex + ey * ey >= reach * reach
    })
}

/// Where new grains go and how many tries a pass gets.
#[derive(Clone, Copy, Debug)]
pub struct Region {
    /// x range of the centres (m).
    pub x: (f64, f64),
    /// Grain volume to place (m³).
    pub target: f64,
    /// Failed positions in a row that end the pass.
    pub attempts: u32,
    /// Velocity of the new grains.
    pub vel: Vec3,
}

/// Place grains at random in `region`, clear of the mobile grains (from index `first` on) and
/// of the walls, until the placed volume reaches `region.target` or `region.attempts`
/// positions in a row fail. `placed` counts every grain placed so far (it picks the size and
/// is advanced). Returns the number placed.
pub fn place(
    g: &Geometry,
    paste: &Paste,
    sys: &mut SphereSystem,
    first: usize,
    region: Region,
    rng: &mut Xoshiro256PlusPlus,
    placed: &mut u64,
) -> Result<u64, ExtruderError> {
    let d_max = paste.range()[1];
    let hb = 0.5 * g.barrel_width;
    let (x_lo, x_hi) = region.x;
    let mut grid = Grid::new(
        [x_lo - d_max, -hb - d_max],
        [x_hi + d_max, hb + d_max],
        g.depth,
        d_max,
    );
    let s = &sys.spheres;
    for k in first..s.len() {
        let p = s.pos[k];
        if p.x > x_lo - d_max && p.x < x_hi + d_max {
            grid.insert(p, s.radius[k]);
        }
    }
    let dom = sys.domain;
    let (mut volume, mut count, mut fails) = (0.0, 0u64, 0u32);
    while volume < region.target && fails < region.attempts {
        let d = paste.diameter(*placed);
        let r = 0.5 * d;
        let x = x_lo + rng.random::<f64>() * (x_hi - x_lo);
        let hw = g.half_width(x);
        let y = hw * (2.0 * rng.random::<f64>() - 1.0);
        let z = g.grain_z(rng.random::<f64>());
        let p = Vec3::new(x, y, z);
        if !clear_of_walls(g, p, r) || !grid.clear(&dom, p, r) {
            fails += 1;
            continue;
        }
        sys.add_sphere(p, region.vel, Vec3::ZERO, r, paste.density)?;
        grid.insert(p, r);
        volume += ball(d);
        count += 1;
        *placed += 1;
        fails = 0;
    }
    Ok(count)
}
