//! The time step of the sphere engine: velocity Verlet for translation and rotation (Verlet
//! 1967; Allen & Tildesley, "Computer Simulation of Liquids", Sect. 3.2), the same scheme as the
//! 2D engine: half kick with the last forces, drift, Verlet-list check, forces at the new
//! positions with the half-step velocities, closing half kick.
//!
//! Serial in this first version. Determinism: the pair list is sorted (i < j), every pair that
//! is not in contact is skipped (adds nothing) and wall contacts follow in wall order, so each
//! sphere's force is summed in an order fixed by the set of contacts alone; and the list's
//! reference positions live in the state, so a resumed run rebuilds the list at the same steps
//! and continues bit for bit.

use super::cells::CellList3;
use super::clump::{Clumps, free_rotation, from_na, quat_array, to_na};
use super::error::SphereError;
use super::law::{ContactKin, HertzMindlin, hertz_mindlin_force};
use super::system::{FREE, SphereSystem, Spheres};
use crate::neighbor::carry_history_into;
use crate::vector::{Vec3, Vector};
use serde::{Deserialize, Serialize};

/// Parameters of a step.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereStepParams {
    /// Time step (s).
    pub dt: f64,
    /// Gravitational acceleration (m/s²).
    #[serde(default)]
    pub gravity: Vec3,
    /// Verlet-list skin (m): the list is rebuilt when a sphere has moved skin/2.
    pub skin: f64,
}

impl SphereStepParams {
    pub fn new(dt: f64, skin: f64) -> Self {
        Self {
            dt,
            gravity: Vec3::ZERO,
            skin,
        }
    }
}

/// Scratch for stepping a [`SphereSystem`] (nothing here is state).
#[derive(Default, Debug)]
pub struct SphereStepper {
    cells: CellList3,
    new_xi: Vec<Vec3>,
    /// The (dt, law, sphere count) last checked against the Rayleigh step.
    checked: Option<(f64, HertzMindlin, usize)>,
    /// List rebuilds so far (diagnostic).
    pub rebuilds: u64,
}

impl SphereStepper {
    pub fn new() -> Self {
        Self::default()
    }

    /// The smallest Rayleigh time step over the spheres (s); infinite with no spheres.
    pub fn rayleigh_time_step(sys: &SphereSystem, law: &HertzMindlin) -> f64 {
        let s = &sys.spheres;
        (0..s.len())
            .map(|k| law.rayleigh_time_step(s.radius[k], s.mass[k]))
            .fold(f64::INFINITY, f64::min)
    }

    fn check(
        &mut self,
        p: &SphereStepParams,
        law: &HertzMindlin,
        sys: &SphereSystem,
    ) -> Result<(), SphereError> {
        if self.checked == Some((p.dt, *law, sys.spheres.len())) {
            return Ok(());
        }
        if !(p.dt > 0.0 && p.dt.is_finite()) {
            return Err(SphereError::BadTimeStep { dt: p.dt });
        }
        if !(p.skin >= 0.0 && p.skin.is_finite()) {
            return Err(SphereError::BadParameter {
                name: "Verlet skin",
                value: p.skin,
                why: "it must be zero or positive and finite (m)",
            });
        }
        if !p.gravity.is_finite() {
            return Err(SphereError::BadParameter {
                name: "gravity magnitude",
                value: p.gravity.norm(),
                why: "gravity must be finite",
            });
        }
        law.check()?;
        let rayleigh = Self::rayleigh_time_step(sys, law);
        if p.dt > rayleigh {
            return Err(SphereError::TimeStepTooLarge { dt: p.dt, rayleigh });
        }
        self.checked = Some((p.dt, *law, sys.spheres.len()));
        Ok(())
    }

    /// Advance `sys` by one step of `p.dt` under `law`.
    pub fn step(
        &mut self,
        p: &SphereStepParams,
        law: &HertzMindlin,
        sys: &mut SphereSystem,
    ) -> Result<(), SphereError> {
        self.check(p, law, sys)?;
        let dt = p.dt;
        let h = 0.5 * dt;
        let dom = sys.domain;
        let n = sys.spheres.len();
        // Opening half kick and drift: free spheres, then clumps (members placed on them).
        for k in 0..n {
            if sys.is_free(k) {
                let s = &mut sys.spheres;
                s.vel[k] += s.force[k] * (h / s.mass[k]);
                s.omega[k] += s.torque[k] * (h / s.inertia[k]);
                s.pos[k] = dom.wrap(s.pos[k] + s.vel[k] * dt);
            }
        }
        let c = &mut sys.clumps;
        for k in 0..c.len() {
            c.vel[k] += c.force[k] * (h / c.mass[k]);
            c.ang_mom[k] += c.torque[k] * h;
            c.pos[k] = dom.wrap(c.pos[k] + c.vel[k] * dt);
            let q = free_rotation(c.orientation(k), c.ang_mom[k], c.inertia[k], dt);
            c.quat[k] = quat_array(&q);
        }
        place_members(sys, true);
        for w in &mut sys.walls {
            w.point += w.vel * dt;
        }
        self.refresh_list(p.skin, sys)?;
        self.forces(p, law, sys);
        gather_clumps(sys, p.gravity);
        // Closing half kick.
        for k in 0..n {
            if sys.is_free(k) {
                let s = &mut sys.spheres;
                s.vel[k] += s.force[k] * (h / s.mass[k]);
                s.omega[k] += s.torque[k] * (h / s.inertia[k]);
            }
        }
        let c = &mut sys.clumps;
        for k in 0..c.len() {
            c.vel[k] += c.force[k] * (h / c.mass[k]);
            c.ang_mom[k] += c.torque[k] * h;
        }
        place_members(sys, false);
        sys.time += dt;
        sys.step += 1;
        let s = &sys.spheres;
        if let Some(k) =
            (0..n).find(|&k| !(s.pos[k].is_finite() && s.vel[k].is_finite() && s.omega[k].is_finite()))
        {
            return Err(SphereError::NonFinite {
                sphere: k,
                step: sys.step - 1,
            });
        }
        Ok(())
    }

    /// Rebuild the Verlet list if it is missing or a sphere has moved more than skin/2 since
    /// it was built, carrying each pair's history onto the new list.
    fn refresh_list(&mut self, skin: f64, sys: &mut SphereSystem) -> Result<(), SphereError> {
        let dom = sys.domain;
        let s = &sys.spheres;
        let c = &mut sys.contacts;
        let n = s.len();
        let fresh = c.list_ref.len() == n && c.xi.len() == c.pairs.len() && {
            let lim = 0.25 * skin * skin;
            s.pos
                .iter()
                .zip(&c.list_ref)
                .all(|(&p, &q)| dom.min_image(p - q).norm2() <= lim)
        };
        if !fresh {
            let pairs = self.cells.build_pairs(&dom, &s.pos, &s.radius, &s.owner, skin)?;
            self.new_xi.clear();
            self.new_xi.resize(pairs.len(), Vec3::ZERO);
            let keep = c.pairs.len().min(c.xi.len());
            carry_history_into(&c.pairs[..keep], &c.xi[..keep], &pairs, &mut self.new_xi);
            c.pairs = pairs;
            std::mem::swap(&mut c.xi, &mut self.new_xi);
            c.list_ref.clear();
            c.list_ref.extend_from_slice(&s.pos);
            self.rebuilds += 1;
        }
        let nw = sys.walls.len();
        if c.wall_xi.len() != n * nw {
            c.wall_xi.clear();
            c.wall_xi.resize(n * nw, Vec3::ZERO);
        }
        Ok(())
    }

    /// Contact forces (pairs in list order, then walls), gravity.
    fn forces(&mut self, p: &SphereStepParams, law: &HertzMindlin, sys: &mut SphereSystem) {
        let dom = sys.domain;
        let s = &mut sys.spheres;
        let c = &mut sys.contacts;
        let cl = &sys.clumps;
        let n = s.len();
        for k in 0..n {
            s.force[k] = Vec3::ZERO;
            s.torque[k] = Vec3::ZERO;
        }
        let pc = law.pair_coeffs();
        for (pair, xi) in c.pairs.iter().zip(c.xi.iter_mut()) {
            let (i, j) = (pair[0] as usize, pair[1] as usize);
            let d = dom.min_image(s.pos[j] - s.pos[i]);
            let (ri, rj) = (s.radius[i], s.radius[j]);
            let dist2 = d.norm2();
            let rs = ri + rj;
            if dist2 >= rs * rs || dist2 == 0.0 {
                *xi = Vec3::ZERO;
                continue;
            }
            let dist = dist2.sqrt();
            let nrm = d * (1.0 / dist);
            let delta = rs - dist;
            // Arms to the contact point, halfway into the overlap (a_i + a_j = distance, so the
            // pair conserves angular momentum).
            let (ai, aj) = (ri - 0.5 * delta, rj - 0.5 * delta);
            let v_rel = (s.vel[i] + s.omega[i].cross(nrm * ai)) - (s.vel[j] + s.omega[j].cross(nrm * -aj));
            let (mi, mj) = (body_mass(s, cl, i), body_mass(s, cl, j));
            let kin = ContactKin {
                n: nrm,
                delta,
                r_eff: ri * rj / rs,
                m_eff: mi * mj / (mi + mj),
                v_rel,
            };
            let (f, _) = hertz_mindlin_force(&pc, &kin, p.dt, xi);
            s.force[i] += f;
            s.force[j] -= f;
            let tq = nrm.cross(f);
            s.torque[i] += tq * ai;
            s.torque[j] += tq * aj;
        }
        let nw = sys.walls.len();
        if nw > 0 {
            let wc = law.wall_coeffs();
            for k in 0..n {
                for (w, wall) in sys.walls.iter().enumerate() {
                    let xi = &mut c.wall_xi[k * nw + w];
                    let r = s.radius[k];
                    let gap = (s.pos[k] - wall.point).dot(wall.normal);
                    if gap >= r {
                        *xi = Vec3::ZERO;
                        continue;
                    }
                    let nrm = -wall.normal;
                    let delta = r - gap;
                    let a = r - 0.5 * delta;
                    let v_rel = s.vel[k] + s.omega[k].cross(nrm * a) - wall.vel;
                    let kin = ContactKin {
                        n: nrm,
                        delta,
                        r_eff: r,
                        m_eff: body_mass(s, cl, k),
                        v_rel,
                    };
                    let (f, _) = hertz_mindlin_force(&wc, &kin, p.dt, xi);
                    s.force[k] += f;
                    s.torque[k] += nrm.cross(f) * a;
                }
            }
        }
        if p.gravity != Vec3::ZERO {
            for k in 0..n {
                if s.owner.get(k).is_none_or(|&o| o == FREE) {
                    s.force[k] += p.gravity * s.mass[k];
                }
            }
        }
    }
}

/// The mass that moves with sphere `k`: its own, or its clump's.
#[inline]
fn body_mass(s: &Spheres, cl: &Clumps, k: usize) -> f64 {
    match s.owner.get(k) {
        Some(&o) if o != FREE => cl.mass[o as usize],
        _ => s.mass[k],
    }
}

/// Place each clump's members on it: velocities and spins always, positions if `positions`
/// (x_s = x_c + Q b_s, v_s = v_c + ω × Q b_s, ω_s = ω).
fn place_members(sys: &mut SphereSystem, positions: bool) {
    let dom = sys.domain;
    let (c, s) = (&sys.clumps, &mut sys.spheres);
    for k in 0..c.len() {
        let q = c.orientation(k);
        let w = c.omega(k);
        for (m, b) in c.members_of(k) {
            let arm = from_na(q.transform_vector(&to_na(b)));
            if positions {
                s.pos[m] = dom.wrap(c.pos[k] + arm);
            }
            s.vel[m] = c.vel[k] + w.cross(arm);
            s.omega[m] = w;
        }
    }
}

/// Each clump's force and torque about its centre of mass: its members' contact forces (in
/// member order) and gravity on its mass.
fn gather_clumps(sys: &mut SphereSystem, gravity: Vec3) {
    let (c, s) = (&mut sys.clumps, &sys.spheres);
    for k in 0..c.len() {
        let q = c.orientation(k);
        let (mut f, mut t) = (Vec3::ZERO, Vec3::ZERO);
        let r = c.start[k] as usize..c.start[k + 1] as usize;
        for (&m, &b) in c.members[r.clone()].iter().zip(&c.offset[r]) {
            let m = m as usize;
            let arm = from_na(q.transform_vector(&to_na(b)));
            f += s.force[m];
            t += arm.cross(s.force[m]) + s.torque[m];
        }
        c.force[k] = f + gravity * c.mass[k];
        c.torque[k] = t;
    }
}
