//! The liquid confined to the sample (Su et al. 2020 Sect. 2.4, Fig. 2 step 15): "the LBM nodes
//! outside of the DEM membrane boundary or overlapping with the push-plate were identified as an
//! effective solid zone", rebuilt before every LBM step from the membrane's shape and the
//! plate's position. The lattice is larger than the sample so the membrane can move.
//!
//! The membrane boundary is the polygon joining the centroids of the membrane grains (the one of
//! Eq. 18); a push-plate's solid region is the quadrilateral behind its segment
//! (`lbdem_dem::polygon::plate_region`). Nodes behind a plate show the liquid the plate's
//! velocity; nodes outside the polygon next to the liquid show it the velocity of the nearest
//! membrane grain, so that a membrane pushed inward compresses the liquid instead of eating
//! it while appearing to stand still (which sucks the liquid away from the grains that move).

use crate::error::CouplingError;
use crate::psm::LIQUID;
use crate::units::CouplingUnits;
use lbdem_dem::System;
use lbdem_dem::polygon::{plate_region, scan_rows};
use lbdem_dem::{Vec2, Vector};

/// Which nodes hold liquid, recomputed from the grains and walls.
#[derive(Clone, Debug)]
pub struct Confinement {
    /// Membrane members in ring order (`Membrane::ring_order`).
    order: Vec<usize>,
    /// Walls (indices in `System::walls`) whose region behind is solid: the push-plates.
    plates: Vec<usize>,
    zone: Vec<u32>,
    velocities: Vec<[f64; 3]>,
}

impl Confinement {
    /// Confine the liquid to the membrane of `sys` minus the regions behind the walls `plates`.
    pub fn new(sys: &System, plates: Vec<usize>) -> Result<Self, CouplingError> {
        let mem = sys.membrane.as_ref().ok_or_else(|| {
            CouplingError::Unsupported(
                "confining the liquid needs a membrane: add [membrane] (and [bonds]) to the scene".into(),
            )
        })?;
        if mem.bodies.len() < 3 {
            return Err(CouplingError::Unsupported(format!(
                "the membrane has {} grains: a sample outline needs at least 3; widen [membrane] shell",
                mem.bodies.len()
            )));
        }
        for &k in &plates {
            let w = sys.walls.get(k).ok_or_else(|| {
                CouplingError::Unsupported(format!("push-plate wall {k} of {}", sys.walls.len()))
            })?;
            if plate_region(w).is_none() {
                return Err(CouplingError::Unsupported(format!(
                    "wall {k} is the push-plate but has no region behind it: give it a segment \
                     (a, b) and a velocity"
                )));
            }
        }
        Ok(Self {
            order: mem.ring_order(),
            plates,
            zone: Vec::new(),
            velocities: Vec::new(),
        })
    }

    /// The solid zone of an `nx` × `ny` lattice for the present grains and walls, and the
    /// boundary velocities it refers to (lattice units): 0 at rest (outside the membrane, away
    /// from the liquid), 1 + k behind plate k, 1 + plates + m next to the liquid outside the
    /// membrane where member m is the nearest.
    pub fn zone(
        &mut self,
        sys: &System,
        units: &CouplingUnits,
        nx: usize,
        ny: usize,
    ) -> (&[u32], &[[f64; 3]]) {
        let to_lattice = |p: Vec2| {
            let q = units.position_to_lattice([p.x, p.y]);
            Vec2::new(q[0], q[1])
        };
        self.zone.clear();
        self.zone.resize(nx * ny, 0);
        self.velocities.clear();
        self.velocities.push([0.0; 3]);
        let mem = sys.membrane.as_ref().expect("checked in new");
        let ring: Vec<Vec2> = mem
            .polygon(&self.order, &sys.bodies)
            .into_iter()
            .map(to_lattice)
            .collect();
        fill(&ring, nx, ny, |i| self.zone[i] = LIQUID);
        for (k, &w) in self.plates.iter().enumerate() {
            let wall = &sys.walls[w];
            let Some(q) = plate_region(wall) else { continue };
            let v = units.velocity_to_lattice([wall.vel.x, wall.vel.y]);
            self.velocities.push([v[0], v[1], 0.0]);
            let quad: Vec<Vec2> = q.into_iter().map(to_lattice).collect();
            let z = 1 + k as u32;
            fill(&quad, nx, ny, |i| self.zone[i] = z);
        }
        // The membrane's own velocity on the outside nodes that border the liquid.
        let first = self.velocities.len() as u32;
        let members: Vec<(Vec2, [f64; 3])> = mem
            .bodies
            .iter()
            .map(|&k| {
                let k = k as usize;
                let b = &sys.bodies;
                let v = units.velocity_to_lattice([b.vel[k].x, b.vel[k].y]);
                (to_lattice(b.pos[k]), [v[0], v[1], 0.0])
            })
            .collect();
        self.velocities.extend(members.iter().map(|m| m.1));
        for j in 0..ny {
            for i in 0..nx {
                if self.zone[j * nx + i] != 0 || !borders_liquid(&self.zone, nx, ny, i, j) {
                    continue;
                }
                let at = Vec2::new(i as f64 + 0.5, j as f64 + 0.5);
                let nearest = (0..members.len())
                    .min_by(|&a, &b| {
                        let (da, db) = ((members[a].0 - at).norm2(), (members[b].0 - at).norm2());
                        da.total_cmp(&db)
                    })
                    .unwrap_or(0);
                self.zone[j * nx + i] = first + nearest as u32;
            }
        }
        (&self.zone, &self.velocities)
    }
}

/// Whether node (i, j) has a liquid node among its eight neighbours.
fn borders_liquid(zone: &[u32], nx: usize, ny: usize, i: usize, j: usize) -> bool {
    (j.saturating_sub(1)..(j + 2).min(ny))
        .any(|y| (i.saturating_sub(1)..(i + 2).min(nx)).any(|x| zone[y * nx + x] == LIQUID))
}

/// Call `f(node)` for every node whose centre (i + ½, j + ½) lies inside `poly` (lattice
/// coordinates).
fn fill(poly: &[Vec2], nx: usize, ny: usize, mut f: impl FnMut(usize)) {
    scan_rows(poly, (0..ny).map(|j| j as f64 + 0.5), |j, x0, x1| {
        // centres i + ½ in [x0, x1)
        let i0 = (x0 - 0.5).ceil().max(0.0);
        let i1 = (x1 - 0.5).ceil().min(nx as f64);
        let mut i = i0;
        while i < i1 {
            f(j * nx + i as usize);
            i += 1.0;
        }
    });
}
