//! Everything a DEM run is, as plain data (checkpointed whole): bodies, walls, bonds, contacts,
//! the membrane driver, the box and the clock. The stepper is scratch that can be rebuilt.

use crate::body::Bodies;
use crate::contact::{Bond, BondParams};
use crate::domain::Domain;
use crate::neighbor::Contacts;
use crate::vector::{Vec2, Vector};
use crate::wall::Wall;
use serde::{Deserialize, Serialize};

/// The membrane boundary of Su et al. 2020 Sect. 2.4: a bonded ring of grains; each receives an
/// inward force F_N when it has moved outward from its reference position by more than
/// `threshold` (Su: 50 µm, F_N = 0.25 F_y, Table 1).
///
/// The paper's force is a step. In an explicit integrator a step force on a grain resting at the
/// threshold switches on and off from one step to the next and keeps it vibrating: with Table
/// 1's F_N and masses at 0.2 mm depth, about 1e-6 m/s per step, ten times Su's 1e-7 m/s "at
/// rest" criterion. `ramp` > 0 raises the force linearly over that distance beyond the
/// threshold instead (0: the paper's step).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Membrane {
    pub bodies: Vec<u32>,
    pub reference: Vec<Vec2>,
    pub centre: Vec2,
    pub threshold: f64,
    pub force: f64,
    #[serde(default)]
    pub ramp: f64,
}

impl Membrane {
    pub fn new(bodies: Vec<u32>, b: &Bodies, threshold: f64, force: f64) -> Self {
        let reference: Vec<Vec2> = bodies.iter().map(|&k| b.pos[k as usize]).collect();
        let mut centre = Vec2::ZERO;
        for p in &reference {
            centre += *p;
        }
        centre = centre * (1.0 / reference.len().max(1) as f64);
        Self {
            bodies,
            reference,
            centre,
            threshold,
            force,
            ramp: 0.0,
        }
    }

    /// Driver force on member `k` at position `p`.
    #[inline]
    pub fn force_on(&self, k: usize, p: Vec2) -> Vec2 {
        let out = self.reference[k] - self.centre;
        let l = out.norm();
        if l == 0.0 {
            return Vec2::ZERO;
        }
        let e = out * (1.0 / l);
        let beyond = (p - self.reference[k]).dot(e) - self.threshold;
        if beyond <= 0.0 {
            Vec2::ZERO
        } else if self.ramp > 0.0 && beyond < self.ramp {
            e * (-self.force * beyond / self.ramp)
        } else {
            e * (-self.force)
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct System {
    pub bodies: Bodies,
    pub walls: Vec<Wall>,
    pub bonds: Vec<Bond>,
    pub bond_params: Option<BondParams>,
    pub membrane: Option<Membrane>,
    pub contacts: Contacts,
    pub domain: Domain,
    pub time: f64,
    pub step: u64,
}

impl System {
    pub fn new(bodies: Bodies, domain: Domain) -> Self {
        Self {
            bodies,
            walls: Vec::new(),
            bonds: Vec::new(),
            bond_params: None,
            membrane: None,
            contacts: Contacts::default(),
            domain,
            time: 0.0,
            step: 0,
        }
    }

    /// Area fraction of the bodies in the domain (or in the box of four plane walls if given:
    /// walls 0,1 = left/right and 2,3 = bottom/top).
    pub fn packing_fraction(&self) -> f64 {
        let area = if self.walls.len() >= 4 {
            Wall::gap(&self.walls[0], &self.walls[1]) * Wall::gap(&self.walls[2], &self.walls[3])
        } else {
            let s = self.domain.size();
            s.x * s.y
        };
        self.bodies.total_area() / area
    }
}

impl System {
    /// Serialise for a checkpoint (JSON with exact f64 round trip: serde_json `float_roundtrip`).
    pub fn to_checkpoint(&self) -> Vec<u8> {
        serde_json::to_vec(self).expect("a System always serialises")
    }
    pub fn from_checkpoint(bytes: &[u8]) -> Result<Self, serde_json::Error> {
        serde_json::from_slice(bytes)
    }
}
