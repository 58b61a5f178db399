//! Parallel bonds: each bond's law in parallel (it owns its state), then the forces added to the
//! bodies serially in bond order, so the sums, hence the bits, are those of a serial loop for
//! any thread count.

use super::Stepper;
use super::bond_dashpots::reduced_mass;
use crate::contact::ContactInput;
use crate::system::System;
use crate::vector::{Vec2, Vector};
use rayon::prelude::*;

/// Bonds per parallel task (any value gives the same bits).
const BOND_CHUNK: usize = 256;

/// What one bond hands its two bodies: the force on body i (j receives −f) and each torque.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct BondLoad {
    /// Whether the bond was whole when the step began (one that breaks in it hands zeros).
    active: bool,
    bi: u32,
    bj: u32,
    f: Vec2,
    ti: f64,
    tj: f64,
}

impl Stepper {
    pub(super) fn bond_forces(&mut self, dt: f64, sys: &mut System) {
        let Some(bp) = sys.bond_params else {
            return;
        };
        let (carm, cst, dom) = (&self.carm, &self.cstate, sys.domain);
        let bodies = &sys.bodies;
        self.bond_load.resize(sys.bonds.len(), BondLoad::default());
        sys.bonds
            .par_chunks_mut(BOND_CHUNK)
            .zip(self.bond_load.par_chunks_mut(BOND_CHUNK))
            .for_each(|(bonds, loads)| {
                for (bond, load) in bonds.iter_mut().zip(loads) {
                    if bond.broken {
                        *load = BondLoad::default();
                        continue;
                    }
                    let (i, j) = (bond.i as usize, bond.j as usize);
                    let d = dom.min_image(cst[j].pos - cst[i].pos);
                    let dist = d.norm();
                    let n = d * (1.0 / dist);
                    let (ri, rj) = (bodies.circle_r[i], bodies.circle_r[j]);
                    let (bi, bj) = (bodies.circle_body[i], bodies.circle_body[j]);
                    let (ki, kj) = (bi as usize, bj as usize);
                    // Contact point: midway through the gap/overlap.
                    let ai = ri + 0.5 * (dist - ri - rj);
                    let aj = dist - ai;
                    let vi = bodies.vel[ki] + (carm[i] + n * ai).spin(bodies.omega[ki]);
                    let vj = bodies.vel[kj] + (carm[j] - n * aj).spin(bodies.omega[kj]);
                    let c = ContactInput {
                        delta: ri + rj - dist,
                        n,
                        v_rel: vi - vj,
                        w_rel: bodies.omega[ki] - bodies.omega[kj],
                        r_eff: ri * rj / (ri + rj),
                        m_eff: reduced_mass(bodies.mass[ki], bodies.mass[kj]),
                        dt,
                    };
                    let (f, m) = bond.update(&bp, &c, ri, rj);
                    let nxf = n.cross(f);
                    *load = BondLoad {
                        active: true,
                        bi,
                        bj,
                        f,
                        ti: ai * nxf + m + carm[i].cross(f),
                        tj: aj * nxf - m - carm[j].cross(f),
                    };
                }
            });
        let bodies = &mut sys.bodies;
        for l in self.bond_load.iter().filter(|l| l.active) {
            let (bi, bj) = (l.bi as usize, l.bj as usize);
            bodies.force[bi] += l.f;
            bodies.torque[bi] += l.ti;
            bodies.force[bj] -= l.f;
            bodies.torque[bj] += l.tj;
        }
    }
}
