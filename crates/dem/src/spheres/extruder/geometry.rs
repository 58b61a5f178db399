//! The square-entry extruder of Ness et al. (2017), Fig. 1: a barrel of width W_b from the ram
//! face at x = 0 to the square die entry at x = L_b, a die of width W_d from there to the open
//! outlet at x = L_b + L_d, flow along +x, y across (centred on the axis), depth D periodic in z
//! (pseudo-2D), or a single layer of grains in the plane z = D/2 (`monolayer`: disks that
//! keep the spheres' contact and lubrication laws; docs/ness2017.md, "The monolayer"). The
//! walls are lines in the x-y plane made of frozen grains of diameter d_w
//! ("particles of diameter 0.5d at very high area fraction", Sect. "Geometry and boundary
//! conditions"), each line a lattice of spacing ≤ s along the line and D/round(D/s) along z; a
//! wall realisation is a seed that jitters every grain along the line and along z by up to
//! ±jitter × spacing (jitter 0 and any seed: the plain lattice). Wall-grain centres lie on the
//! lines, so W_b and W_d are measured between wall-grain centres and the first paste layer
//! sits about (d_w + d)/2 inside (as Ness describe).

use super::error::ExtruderError;
use crate::spheres::domain::Domain3;
use crate::vector::Vec3;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::{Deserialize, Serialize};

/// The extruder's shape and walls, lengths in m.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Geometry {
    /// Barrel width W_b (Ness: 100 d).
    pub barrel_width: f64,
    /// Barrel length L_b, ram face to die entry (Ness: the entry at x = 300 d).
    pub barrel_length: f64,
    /// Die width W_d (Ness: 20 d).
    pub die_width: f64,
    /// Die length L_d (not stated in the text of Ness et al.; docs/ness2017.md).
    pub die_length: f64,
    /// Depth D along z, periodic (Ness: 5 d).
    pub depth: f64,
    /// Length of the inlet box from the ram face, where grains are inserted and driven.
    pub inlet_length: f64,
    /// Wall-grain diameter d_w (Ness: 0.5 d).
    pub wall_diameter: f64,
    /// Largest spacing of wall-grain centres along a line and along z.
    pub wall_spacing: f64,
    /// Jitter of each wall grain along its line and along z, a fraction of the spacing in [0, 0.5).
    pub wall_jitter: f64,
    /// The wall realisation.
    pub wall_seed: u64,
    /// Grains are removed once their centre is this far past the die's end (m, ≥ 0).
    pub outlet_gap: f64,
    /// One layer of grains with their centres in the plane z = D/2, z not periodic, one wall
    /// grain across the depth of each line (issue 19 item 6: the extruder as 2D disks). The
    /// spheres' laws act in the plane and nothing pushes a grain out of it, so the run stays
    /// planar to the bit. D is then the layer's thickness for volume fractions and stresses.
    #[serde(default)]
    pub monolayer: bool,
}

/// Jamming (random close packing) volume fraction of bidisperse spheres, and area fraction of
/// bidisperse disks (O'Hern et al. 2003, Phys. Rev. E 68:011306: 0.64 and 0.84), for
/// [`monolayer_thickness`].
pub const JAMMING_3D: f64 = 0.64;
pub const JAMMING_2D: f64 = 0.84;

/// The thickness D of a monolayer of the 1:1 paste of `diameters` standing in for the slab: a
/// volume fraction φ of its grains over D is then the area fraction φ × JAMMING_2D/JAMMING_3D,
/// as far below 2D jamming as φ is below 3D jamming, so the inlet box's φ = 0.5 (Ness) keeps
/// the paste as loose relative to jamming, and the ram's pressure F × grains / (W_b D) is the
/// slab's at the same force. D = (mean grain volume / mean disk area) × JAMMING_2D/JAMMING_3D
/// = (2/3)(⟨d³⟩/⟨d²⟩) × 1.3125: 1.178 d for Ness's d and 1.5 d.
pub fn monolayer_thickness(diameters: [f64; 2]) -> f64 {
    let [a, b] = diameters;
    let (d3, d2) = (a.powi(3) + b.powi(3), a * a + b * b);
    2.0 / 3.0 * d3 / d2 * (JAMMING_2D / JAMMING_3D)
}

/// Which wall a frozen grain belongs to (its load is summed per segment).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Segment {
    /// The ram face at x = 0, behind the inlet box.
    Ram,
    /// The barrel's side walls, y = ±W_b/2.
    Barrel,
    /// The square entry's faces at x = L_b, W_d/2 < |y| < W_b/2.
    Entry,
    /// The die's side walls, y = ±W_d/2.
    Die,
}

impl Segment {
    pub const ALL: [Segment; 4] = [Segment::Ram, Segment::Barrel, Segment::Entry, Segment::Die];
    pub fn index(self) -> usize {
        self as usize
    }
    pub fn name(self) -> &'static str {
        match self {
            Segment::Ram => "ram",
            Segment::Barrel => "barrel",
            Segment::Entry => "entry",
            Segment::Die => "die",
        }
    }
}

fn bad(name: &'static str, value: f64, why: impl Into<String>, fix: impl Into<String>) -> ExtruderError {
    ExtruderError::Parameter {
        name,
        value,
        why: why.into(),
        fix: fix.into(),
    }
}

impl Geometry {
    /// x of the die's end (the open outlet).
    pub fn die_end(&self) -> f64 {
        self.barrel_length + self.die_length
    }

    /// Grains whose centre is past this x are removed.
    pub fn outlet_x(&self) -> f64 {
        self.die_end() + self.outlet_gap
    }

    /// Half the channel's width at `x` (between wall-grain centres).
    pub fn half_width(&self, x: f64) -> f64 {
        if x < self.barrel_length {
            0.5 * self.barrel_width
        } else {
            0.5 * self.die_width
        }
    }

    /// Whether a grain centre at `p` is inside the channel (ram face to die end, between the
    /// wall lines).
    pub fn inside(&self, p: Vec3) -> bool {
        p.x > 0.0 && p.x <= self.die_end() && p.y.abs() < self.half_width(p.x)
    }

    /// Refuse what cannot make an extruder for paste grains of diameters `d_min`..`d_max`.
    pub fn check(&self, d_min: f64, d_max: f64) -> Result<(), ExtruderError> {
        let lengths = [
            ("barrel_width", self.barrel_width),
            ("barrel_length", self.barrel_length),
            ("die_width", self.die_width),
            ("die_length", self.die_length),
            ("depth", self.depth),
            ("inlet_length", self.inlet_length),
            ("wall_diameter", self.wall_diameter),
            ("wall_spacing", self.wall_spacing),
        ];
        for (name, v) in lengths {
            if !(v > 0.0 && v.is_finite()) {
                return Err(bad(
                    name,
                    v,
                    "it must be a positive, finite length (m)",
                    "give a length in m",
                ));
            }
        }
        if !(self.outlet_gap >= 0.0 && self.outlet_gap.is_finite()) {
            return Err(bad(
                "outlet_gap",
                self.outlet_gap,
                "it must be zero or positive (m)",
                "give 0",
            ));
        }
        if !(0.0..0.5).contains(&self.wall_jitter) {
            return Err(bad(
                "wall_jitter",
                self.wall_jitter,
                "it is a fraction of the wall spacing in [0, 0.5)",
                "give 0 (a lattice) to 0.25",
            ));
        }
        if self.die_width >= self.barrel_width {
            return Err(bad(
                "die_width",
                self.die_width,
                format!(
                    "the die is not narrower than the barrel (barrel_width = {:e} m)",
                    self.barrel_width
                ),
                "make die_width smaller than barrel_width (Ness: 20 d and 100 d)",
            ));
        }
        let passage = self.die_width - self.wall_diameter;
        if passage <= 2.0 * d_max {
            return Err(bad(
                "die_width",
                self.die_width,
                format!(
                    "the die leaves {passage:e} m between its wall grains, not two of the largest grains ({d_max:e} m) side by side"
                ),
                format!("give die_width above {:e} m", 2.0 * d_max + self.wall_diameter),
            ));
        }
        let room = self.inlet_length - 0.5 * self.wall_diameter;
        if room <= d_max {
            return Err(bad(
                "inlet_length",
                self.inlet_length,
                format!(
                    "the inlet box has no room for a grain of {d_max:e} m in front of the ram's wall grains"
                ),
                format!("give inlet_length above {:e} m", d_max + 0.5 * self.wall_diameter),
            ));
        }
        if self.inlet_length >= self.barrel_length {
            return Err(bad(
                "inlet_length",
                self.inlet_length,
                format!(
                    "the inlet box reaches the die entry (barrel_length = {:e} m)",
                    self.barrel_length
                ),
                "make the inlet box shorter than the barrel (Ness: about 10 d of 300 d)",
            ));
        }
        if self.wall_diameter >= d_min {
            return Err(bad(
                "wall_diameter",
                self.wall_diameter,
                format!("wall grains are meant to be smaller than the paste's grains ({d_min:e} m)"),
                "give wall_diameter = 0.5 d (Ness)",
            ));
        }
        // The widest hole between four wall grains, with every neighbour jittered apart.
        let (a, b) = self.spacings(self.barrel_width.min(self.die_length));
        let stretch = 1.0 + 2.0 * self.wall_jitter;
        let hole = if self.monolayer {
            a * stretch - self.wall_diameter
        } else {
            ((a * stretch).powi(2) + (b * stretch).powi(2)).sqrt() - self.wall_diameter
        };
        if hole >= d_min {
            return Err(bad(
                "wall_spacing",
                self.wall_spacing,
                format!(
                    "with wall_jitter = {} a hole of {hole:e} m can open between wall grains, wide enough for a grain of {d_min:e} m to pass",
                    self.wall_jitter
                ),
                "lower wall_spacing (Ness: touching 0.5 d grains) or wall_jitter",
            ));
        }
        if !self.monolayer && self.depth < 2.2 * d_max {
            return Err(bad(
                "depth",
                self.depth,
                format!(
                    "the periodic depth must exceed twice the pair cutoff (about 2.2 × the largest diameter {d_max:e} m)"
                ),
                format!("give depth at least {:e} m (Ness: 5 d)", 2.2 * d_max),
            ));
        }
        Ok(())
    }

    /// The box of the engine: the channel with a margin `m` on the open axes x and y, z
    /// periodic over the depth (closed for a monolayer, whose grains never leave z = D/2).
    pub fn domain(&self, margin: f64) -> Result<Domain3, ExtruderError> {
        let hw = 0.5 * self.barrel_width + margin;
        Ok(Domain3::new(
            Vec3::new(-margin, -hw, 0.0),
            Vec3::new(self.outlet_x() + margin, hw, self.depth),
            [false, false, !self.monolayer],
        )?)
    }

    /// z of a new grain from a uniform draw `u` in [0, 1): anywhere in the depth, or the
    /// monolayer's plane.
    pub fn grain_z(&self, u: f64) -> f64 {
        if self.monolayer {
            0.5 * self.depth
        } else {
            u * self.depth
        }
    }

    /// Spacing along a line of length `len` and along z (one grain across a monolayer).
    fn spacings(&self, len: f64) -> (f64, f64) {
        let along = len / (len / self.wall_spacing).ceil().max(1.0);
        let nz = if self.monolayer {
            1.0
        } else {
            (self.depth / self.wall_spacing).round().max(1.0)
        };
        (along, self.depth / nz)
    }

    /// The wall lines: (start, end, segment) in the x-y plane.
    pub fn lines(&self) -> Vec<([f64; 2], [f64; 2], Segment)> {
        let (lb, le) = (self.barrel_length, self.die_end());
        let (hb, hd) = (0.5 * self.barrel_width, 0.5 * self.die_width);
        vec![
            ([0.0, -hb], [0.0, hb], Segment::Ram),
            ([0.0, -hb], [lb, -hb], Segment::Barrel),
            ([0.0, hb], [lb, hb], Segment::Barrel),
            ([lb, -hb], [lb, -hd], Segment::Entry),
            ([lb, hd], [lb, hb], Segment::Entry),
            ([lb, -hd], [le, -hd], Segment::Die),
            ([lb, hd], [le, hd], Segment::Die),
        ]
    }

    /// The wall grains' centres and segments for this realisation (`wall_seed`). Lines share
    /// their corner points; a grain repeated there is harmless (frozen pairs are never listed).
    pub fn wall_grains(&self) -> Vec<(Vec3, Segment)> {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(self.wall_seed);
        let j = self.wall_jitter;
        let mut out = Vec::new();
        for (a, b, seg) in self.lines() {
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let len = dx.hypot(dy);
            let (along, dz) = self.spacings(len);
            let n = (len / along).round() as usize;
            let nz = (self.depth / dz).round() as usize;
            for i in 0..=n {
                for k in 0..nz {
                    let (mut u, mut z) = (i as f64 * along, (k as f64 + 0.5) * dz);
                    if j > 0.0 {
                        u = (u + rng.random_range(-j..j) * along).clamp(0.0, len);
                        // Drawn in a monolayer too, so a seed jitters the lines alike.
                        let shift = rng.random_range(-j..j) * dz;
                        if !self.monolayer {
                            z = (z + shift).rem_euclid(self.depth);
                        }
                    }
                    let t = u / len;
                    out.push((Vec3::new(a[0] + t * dx, a[1] + t * dy, z), seg));
                }
            }
        }
        out
    }

    /// Volume of the channel (m³), for the expected grain count (a monolayer's: its area
    /// times its thickness D).
    pub fn channel_volume(&self) -> f64 {
        (self.barrel_width * self.barrel_length + self.die_width * self.die_length) * self.depth
    }
}
