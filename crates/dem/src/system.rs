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

impl System {
    /// Whether the state is one the stepper can advance: every per-body and per-circle array of
    /// the same length, every index in range, the clump layout consistent, every number finite,
    /// masses and radii positive. A state read back from a file (a damaged or foreign
    /// checkpoint) is checked with this before it is used, so it is refused with the reason
    /// instead of panicking inside a kernel.
    pub fn check_state(&self) -> Result<(), String> {
        let b = &self.bodies;
        let (n, nc) = (b.pos.len(), b.circle_r.len());
        let per_body = [
            ("vel", b.vel.len()),
            ("angle", b.angle.len()),
            ("omega", b.omega.len()),
            ("mass", b.mass.len()),
            ("inertia", b.inertia.len()),
            ("density", b.density.len()),
            ("ext_force", b.ext_force.len()),
            ("ext_torque", b.ext_torque.len()),
            ("force", b.force.len()),
            ("torque", b.torque.len()),
            ("tag", b.tag.len()),
        ];
        if let Some((name, len)) = per_body.iter().find(|(_, l)| *l != n) {
            return Err(format!("bodies.{name} has {len} entries for {n} bodies"));
        }
        if b.circle_offset.len() != nc || b.circle_body.len() != nc {
            return Err(format!(
                "{} circle offsets and {} circle bodies for {nc} circle radii",
                b.circle_offset.len(),
                b.circle_body.len()
            ));
        }
        if b.circle_start.len() != n + 1
            || b.circle_start.first() != Some(&0)
            || b.circle_start.last() != Some(&nc)
            || b.circle_start.windows(2).any(|w| w[0] >= w[1])
        {
            return Err(format!(
                "circle_start must rise from 0 to {nc} over {} entries (each body one circle or more)",
                n + 1
            ));
        }
        for k in 0..n {
            for c in b.circle_start[k]..b.circle_start[k + 1] {
                if b.circle_body[c] as usize != k {
                    return Err(format!(
                        "circle {c} lies in body {k}'s range but names body {}",
                        b.circle_body[c]
                    ));
                }
            }
        }
        let finite2 = |v: &[Vec2]| v.iter().all(|p| p.x.is_finite() && p.y.is_finite());
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        let positive = |v: &[f64]| v.iter().all(|x| *x > 0.0 && x.is_finite());
        if !(finite2(&b.pos) && finite2(&b.vel) && finite(&b.angle) && finite(&b.omega))
            || !(finite2(&b.circle_offset) && finite2(&b.ext_force) && finite(&b.ext_torque))
        {
            return Err("a position, velocity, angle or load is not finite".into());
        }
        if !(positive(&b.mass) && positive(&b.inertia) && positive(&b.circle_r)) {
            return Err("a mass, inertia or circle radius is not positive and finite".into());
        }
        let (lo, hi) = (self.domain.lo, self.domain.hi);
        if !(finite2(&[lo, hi]) && hi.x > lo.x && hi.y > lo.y) {
            return Err("the domain's corners are not finite or not ordered (lo < hi)".into());
        }
        // A clump's circle cannot reach farther from its body than the box is wide: a damaged
        // offset of 2^32 m once made the solid-fraction pass of a coupled run loop for minutes.
        let span = (hi - lo).norm();
        if let Some(c) = (0..nc).find(|&c| b.circle_offset[c].norm() + b.circle_r[c] > span) {
            return Err(format!(
                "circle {c} reaches {:.3e} m from its body (offset {:.3e} m, radius {:.3e} m), beyond the domain's diagonal {span:.3e} m",
                b.circle_offset[c].norm() + b.circle_r[c],
                b.circle_offset[c].norm(),
                b.circle_r[c]
            ));
        }
        if !(self.time.is_finite() && self.time >= 0.0) {
            return Err(format!(
                "time = {} is not a finite, non-negative number",
                self.time
            ));
        }
        if let Some(&[i, j]) = self
            .contacts
            .pairs
            .iter()
            .find(|p| p[0] as usize >= nc || p[1] as usize >= nc)
        {
            return Err(format!(
                "contact pair ({i}, {j}) names a circle beyond the {nc} circles"
            ));
        }
        if self.contacts.hist.len() != self.contacts.pairs.len() {
            return Err(format!(
                "{} contact histories for {} pairs",
                self.contacts.hist.len(),
                self.contacts.pairs.len()
            ));
        }
        if let Some(bond) = self
            .bonds
            .iter()
            .find(|d| d.i as usize >= nc || d.j as usize >= nc)
        {
            return Err(format!(
                "bond ({}, {}) names a circle beyond the {nc} circles",
                bond.i, bond.j
            ));
        }
        if let Some(m) = &self.membrane
            && (m.reference.len() != m.bodies.len() || m.bodies.iter().any(|&k| k as usize >= n))
        {
            return Err("the membrane's bodies and reference positions do not match the bodies".into());
        }
        for (k, w) in self.walls.iter().enumerate() {
            let ok = match w.shape {
                crate::wall::WallShape::Plane { p, n } => finite2(&[p, n]) && n.norm() > 0.0,
                crate::wall::WallShape::Segment { a, b } => finite2(&[a, b]),
            };
            if !ok || !finite2(&[w.vel]) {
                return Err(format!(
                    "wall {k} has a non-finite position or velocity, or a zero normal"
                ));
            }
        }
        Ok(())
    }
}
