//! Parallel bonds, sequentially in bond order.

use super::Stepper;
use super::bond_dashpots::reduced_mass;
use crate::contact::ContactInput;
use crate::system::System;
use crate::vector::Vector;

impl Stepper {
    pub(super) fn bond_forces(&mut self, dt: f64, sys: &mut System) {
        let (carm, cst, dom) = (&self.carm, &self.cstate, sys.domain);
        if let Some(bp) = sys.bond_params {
            let bodies = &mut sys.bodies;
            for bond in sys.bonds.iter_mut().filter(|b| !b.broken) {
                let (i, j) = (bond.i as usize, bond.j as usize);
                let d = dom.min_image(cst[j].pos - cst[i].pos);
                let dist = d.norm();
                let n = d * (1.0 / dist);
                let (ri, rj) = (bodies.circle_r[i], bodies.circle_r[j]);
                let (bi, bj) = (bodies.circle_body[i] as usize, bodies.circle_body[j] as usize);
                // Contact point: midway through the gap/overlap.
                let ai = ri + 0.5 * (dist - ri - rj);
                let aj = dist - ai;
                let vi = bodies.vel[bi] + (carm[i] + n * ai).spin(bodies.omega[bi]);
                let vj = bodies.vel[bj] + (carm[j] - n * aj).spin(bodies.omega[bj]);
                let c = ContactInput {
                    delta: ri + rj - dist,
                    n,
                    v_rel: vi - vj,
                    w_rel: bodies.omega[bi] - bodies.omega[bj],
                    r_eff: ri * rj / (ri + rj),
                    m_eff: reduced_mass(bodies.mass[bi], bodies.mass[bj]),
                    dt,
                };
                let (f, m) = bond.update(&bp, &c, ri, rj);
                let nxf = n.cross(f);
                bodies.force[bi] += f;
                bodies.torque[bi] += ai * nxf + m + carm[i].cross(f);
                bodies.force[bj] -= f;
                bodies.torque[bj] += aj * nxf - m - carm[j].cross(f);
            }
        }
    }
}
