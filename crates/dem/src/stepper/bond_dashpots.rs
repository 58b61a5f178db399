//! How hard the bonds' dashpots (`BondParams::damping`) may damp at a given step. A dashpot
//! integrated explicitly overshoots once c Δt / m* passes 2, and a bond's contact point lies off
//! the centroids (clumps, bonding gaps), where a grain moves like a lighter mass: the rotation
//! adds (a × e)²/I to its inverse mass along each direction e. The number bounds the decay rate
//! of every body's dashpots times the step (a row sum over its bonds, as Gershgorin's bound).

use super::Stepper;
use crate::system::System;
use crate::vector::{Vec2, Vector};

/// The largest [`Stepper::bond_dashpot_number`] a step may have. Measured on the reduced Su shear
/// cell's random assemblies (`sweeps/su2020-membrane-damping.toml`, membrane at Table 1's mass,
/// DEM step 4e-6 s): runs at numbers 2.38-3.89 went through, runs at 4.32-4.58 blew up within 7
/// LBM steps (docs/stability.md, "Damped membrane bonds"). The bound is a row sum, so it exceeds
/// the true rate, which is why the runs stand it beyond 2.
pub const BOND_DASHPOT_LIMIT: f64 = 3.9;

/// The bond whose dashpots limit the step: its body, the number and the damping ratio at which
/// the number would reach [`BOND_DASHPOT_LIMIT`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BondDashpotLimit {
    pub body: usize,
    pub number: f64,
    pub largest_ratio: f64,
}

/// m_i m_j / (m_i + m_j), the mass the bond's dashpots are set for (as the pair law's m*).
#[inline]
pub(super) fn reduced_mass(mi: f64, mj: f64) -> f64 {
    mi * mj / (mi + mj)
}

/// 1/m + (a × e)²/I of a body at arm `a` along unit `e`.
fn inverse_mass(m: f64, inertia: f64, a: Vec2, e: Vec2) -> f64 {
    1.0 / m + a.cross(e).powi(2) / inertia
}

impl Stepper {
    /// Δt × the largest, over bodies, of Σ over the body's unbroken bonds and both directions
    /// (normal, shear) of c_e (w_i,e + w_j,e), with c_e = 2ζ √(k̄_e A m*) and w the inverse mass at
    /// the bond's contact point ([`inverse_mass`]); `None` without damped bonds.
    pub fn bond_dashpot_number(sys: &System, dt: f64) -> Option<BondDashpotLimit> {
        let p = sys.bond_params.as_ref()?;
        if p.damping <= 0.0 {
            return None;
        }
        let b = &sys.bodies;
        let mut rate = vec![0.0f64; b.len()];
        for bond in sys.bonds.iter().filter(|x| !x.broken) {
            let (i, j) = (bond.i as usize, bond.j as usize);
            let (bi, bj) = (b.circle_body[i] as usize, b.circle_body[j] as usize);
            if bi == bj {
                continue;
            }
            let (pi, pj) = (b.circle_pos(i), b.circle_pos(j));
            let d = sys.domain.min_image(pj - pi);
            let dist = d.norm();
            if dist <= 0.0 {
                continue;
            }
            let n = d * (1.0 / dist);
            let t = n.perp();
            let (ri, rj) = (b.circle_r[i], b.circle_r[j]);
            let ai = ri + 0.5 * (dist - ri - rj);
            let arm_i = (pi - b.pos[bi]) + n * ai;
            let arm_j = (pj - b.pos[bj]) - n * (dist - ai);
            let (mi, mj) = (b.mass[bi], b.mass[bj]);
            let m_eff = reduced_mass(mi, mj);
            let area = 2.0 * p.lambda * ri.min(rj);
            let mut s = 0.0;
            for (k, e) in [(p.k_n, n), (p.k_s, t)] {
                let c = 2.0 * p.damping * (k * area * m_eff).sqrt();
                let w = inverse_mass(mi, b.inertia[bi], arm_i, e) + inverse_mass(mj, b.inertia[bj], arm_j, e);
                s += c * w;
            }
            rate[bi] += s;
            rate[bj] += s;
        }
        let (body, r) = rate
            .iter()
            .copied()
            .enumerate()
            .fold((0, 0.0), |a, (k, r)| if r > a.1 { (k, r) } else { a });
        let number = r * dt;
        Some(BondDashpotLimit {
            body,
            number,
            largest_ratio: p.damping * BOND_DASHPOT_LIMIT / number,
        })
    }
}
