//! The liquid confined to the sample (Su et al. 2020 Sect. 2.4, Fig. 2 step 15): "the LBM nodes
//! outside of the DEM membrane boundary or overlapping with the push-plate were identified as an
//! effective solid zone", rebuilt before every LBM step from the membrane's shape and the
//! plate's position. The lattice is larger than the sample so the membrane can move.
//!
//! The membrane boundary is the polygon joining the centroids of the membrane grains (the one of
//! Eq. 18); a push-plate's solid region is the quadrilateral behind its segment
//! (`lbdem_dem::polygon::plate_region`). Nodes behind a plate show the liquid the plate's
//! velocity; nodes outside the polygon are at rest. They once showed the nearest membrane
//! grain's velocity, which put momentum into the liquid that no grain paid for and ran away at
//! the paper's densities (docs/su2020.md, "The liquid confined to the sample").

use crate::error::CouplingError;
use crate::psm::LIQUID;
use crate::units::CouplingUnits;
use lbdem_dem::System;
use lbdem_dem::Vec2;
use lbdem_dem::polygon::{plate_region, scan_rows};

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
    /// boundary velocities it refers to (lattice units): 0 at rest (outside the membrane),
    /// 1 + k behind plate k.
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
        (&self.zone, &self.velocities)
    }
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
