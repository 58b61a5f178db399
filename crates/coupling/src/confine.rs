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
use rayon::prelude::*;

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
        let near = Nearest::new(&members);
        // Rows in parallel, read from the zone as the fills left it: the marks written here are
        // never LIQUID, so they change no other node's test.
        let zone = &self.zone;
        let marks: Vec<Vec<(usize, u32)>> = (0..ny)
            .into_par_iter()
            .map(|j| {
                (0..nx)
                    .filter(|&i| zone[j * nx + i] == 0 && borders_liquid(zone, nx, ny, i, j))
                    .map(|i| {
                        let at = Vec2::new(i as f64 + 0.5, j as f64 + 0.5);
                        (j * nx + i, first + near.of(at) as u32)
                    })
                    .collect()
            })
            .collect();
        for (idx, z) in marks.into_iter().flatten() {
            self.zone[idx] = z;
        }
        (&self.zone, &self.velocities)
    }
}

/// The nearest membrane member to a lattice point, found through square buckets of members
/// (a scan of every member per outside node was most of the zone's cost on Simulation I).
struct Nearest<'a> {
    members: &'a [(Vec2, [f64; 3])],
    lo: Vec2,
    side: f64,
    n: [usize; 2],
    /// Members of bucket b are `list[start[b]..start[b + 1]]`, ascending.
    start: Vec<u32>,
    list: Vec<u32>,
}

impl<'a> Nearest<'a> {
    fn new(members: &'a [(Vec2, [f64; 3])]) -> Self {
        let (mut lo, mut hi) = (
            Vec2::new(f64::INFINITY, f64::INFINITY),
            Vec2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        for (p, _) in members {
            lo = Vec2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Vec2::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        // About two members per bucket along a ring of m members.
        let extent = (hi.x - lo.x).max(hi.y - lo.y).max(1e-9);
        let side = (2.0 * 4.0 * extent / members.len().max(1) as f64).max(1.0);
        let finite = lo.x.is_finite() && lo.y.is_finite() && hi.x.is_finite() && hi.y.is_finite();
        let n = if finite {
            [
                ((hi.x - lo.x) / side) as usize + 1,
                ((hi.y - lo.y) / side) as usize + 1,
            ]
        } else {
            [1, 1]
        };
        let mut me = Self {
            members,
            lo: if finite { lo } else { Vec2::ZERO },
            side: if finite { side } else { f64::INFINITY },
            n,
            start: vec![0; n[0] * n[1] + 1],
            list: vec![0; members.len()],
        };
        for (p, _) in members {
            let b = me.bucket(*p);
            me.start[b + 1] += 1;
        }
        for b in 0..n[0] * n[1] {
            me.start[b + 1] += me.start[b];
        }
        let mut at = me.start.clone();
        for (k, (p, _)) in members.iter().enumerate() {
            let b = me.bucket(*p);
            me.list[at[b] as usize] = k as u32;
            at[b] += 1;
        }
        me
    }

    fn cell(&self, p: Vec2) -> [i64; 2] {
        let c = |v: f64, lo: f64, n: usize| (((v - lo) / self.side).floor() as i64).clamp(0, n as i64 - 1);
        [c(p.x, self.lo.x, self.n[0]), c(p.y, self.lo.y, self.n[1])]
    }

    fn bucket(&self, p: Vec2) -> usize {
        let [x, y] = self.cell(p);
        x as usize + self.n[0] * y as usize
    }

    /// Index of the member nearest to `at` (the lowest index among equally near ones, as a
    /// scan of all members in order finds; 0 without members).
    fn of(&self, at: Vec2) -> usize {
        if self.members.is_empty() {
            return 0;
        }
        if !self.side.is_finite() {
            return self.scan(at, 0..self.members.len());
        }
        let [cx, cy] = self.cell(at);
        let mut best = (f64::INFINITY, usize::MAX);
        // Rings of buckets around the point's bucket (its own, or the nearest if the point is
        // outside them), until no bucket further out can hold a member as near: any point of a
        // bucket in ring r + 1 differs from the point by at least r side lengths along one axis.
        for r in 0i64.. {
            let (x0, x1, y0, y1) = (cx - r, cx + r, cy - r, cy + r);
            for y in y0.max(0)..=y1.min(self.n[1] as i64 - 1) {
                for x in x0.max(0)..=x1.min(self.n[0] as i64 - 1) {
                    if (x - cx).abs() != r && (y - cy).abs() != r {
                        continue;
                    }
                    let b = x as usize + self.n[0] * y as usize;
                    for &k in &self.list[self.start[b] as usize..self.start[b + 1] as usize] {
                        let d = (self.members[k as usize].0 - at).norm2();
                        if d < best.0 || (d == best.0 && (k as usize) < best.1) {
                            best = (d, k as usize);
                        }
                    }
                }
            }
            let reach = (r as f64 * self.side).powi(2);
            let covered = x0 <= 0 && y0 <= 0 && x1 >= self.n[0] as i64 - 1 && y1 >= self.n[1] as i64 - 1;
            if best.1 != usize::MAX && (reach > best.0 || covered) {
                break;
            }
            if covered {
                break;
            }
        }
        best.1
    }

    fn scan(&self, at: Vec2, range: std::ops::Range<usize>) -> usize {
        range
            .min_by(|&a, &b| {
                let (da, db) = ((self.members[a].0 - at).norm2(), (self.members[b].0 - at).norm2());
                da.total_cmp(&db)
            })
            .unwrap_or(0)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The buckets find the member a scan of all members finds, ties included, for points
    /// inside and outside the ring.
    #[test]
    fn nearest_member_matches_a_full_scan() {
        let members: Vec<(Vec2, [f64; 3])> = (0..300)
            .map(|k| {
                let t = k as f64 / 300.0 * std::f64::consts::TAU;
                (
                    Vec2::new(
                        120.0 + 90.0 * t.cos(),
                        150.0 + 110.0 * (t.sin() + 0.1 * (5.0 * t).sin()),
                    ),
                    [0.0; 3],
                )
            })
            .chain([
                (Vec2::new(120.0, 40.0), [0.0; 3]),
                (Vec2::new(120.0, 40.0), [0.0; 3]),
            ])
            .collect();
        let near = Nearest::new(&members);
        for j in 0..300 {
            for i in 0..240 {
                let at = Vec2::new(i as f64 + 0.5, j as f64 + 0.5);
                assert_eq!(near.of(at), near.scan(at, 0..members.len()), "at {at:?}");
            }
        }
        let at = Vec2::new(-500.0, 1000.0);
        assert_eq!(near.of(at), near.scan(at, 0..members.len()));
    }
}
