//! The time step: velocity Verlet for translation and rotation (Verlet 1967; Allen & Tildesley,
//! "Computer Simulation of Liquids", Sect. 3.2), with optional viscous and local (non-viscous,
//! Cundall) damping. The stepper holds only scratch; all state lives in [`System`].
//!
//! Determinism: the pair list is sorted (i < j). One parallel pass over circles i evaluates the
//! pairs (i, j) in ascending j, sums the force on i in a register and writes the reaction on j
//! into a per-pair slot; a second pass gives each circle its own sum plus its reaction slots in
//! ascending i. Pairs that do not touch add nothing (or +0.0, an identity for a sum that starts
//! at +0.0), so the order, hence every bit, is independent of the thread count and of the step
//! at which the Verlet list was rebuilt (a resumed run continues bit for bit).

use crate::contact::{ContactInput, ContactLaw, History, Law, LinearSpringDashpot};
use crate::domain::Domain;
use crate::error::DemError;
use crate::kick_disks::{DiskKick, Eight};
use crate::lanes::W;
use crate::neighbor::{CellList, carry_history};
use crate::pair_linear::LinearPair;
use crate::system::System;
use crate::vector::{Vec2, Vector};
use crate::wall::update_wall_velocities;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepParams {
    pub dt: f64,
    #[serde(default)]
    pub gravity: Vec2,
    /// Factor on gravity: 1 for dry grains, 1 − ρ_L/ρ_S for buoyant grains in a liquid.
    #[serde(default = "one")]
    pub gravity_factor: f64,
    /// Viscous damping rate γ (1/s): F −= γ m v, T −= γ I ω.
    #[serde(default)]
    pub viscous_damping: f64,
    /// Local (non-viscous) damping α (Cundall): F_k −= α |F_k| sign(v_k).
    #[serde(default)]
    pub local_damping: f64,
    /// Verlet-list skin (m).
    pub skin: f64,
}

fn one() -> f64 {
    1.0
}

impl StepParams {
    pub fn new(dt: f64, skin: f64) -> Self {
        Self {
            dt,
            gravity: Vec2::ZERO,
            gravity_factor: 1.0,
            viscous_damping: 0.0,
            local_damping: 0.0,
            skin,
        }
    }
}

/// Result of pair (i, j): force on i (j receives −f), torques on i and j; zero when the pair
/// does not touch. One 32-byte record: the reaction gather reads one cache line per pair.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(32))]
pub(crate) struct PairOut {
    pub fx: f64,
    pub fy: f64,
    pub ti: f64,
    pub tj: f64,
}

/// Per body: h/m and h/I of the half kicks, kept while h, m and I stay the same (divisions are
/// the dearest part of the per-body passes).
#[derive(Clone, Copy, Debug, Default)]
struct Kick {
    h: f64,
    m: f64,
    i: f64,
    hm: f64,
    hi: f64,
}

impl Kick {
    #[inline(always)]
    fn refresh(&mut self, h: f64, m: f64, i: f64) {
        if self.h != h || self.m != m || self.i != i {
            *self = Kick {
                h,
                m,
                i,
                hm: h / m,
                hi: h / i,
            };
        }
    }
}

/// Bodies per parallel task of the per-body passes (any value gives the same bits).
const BODY_CHUNK: usize = 512;

/// Circles per task of the fused pair + per-body pass of disk systems (any value gives the
/// same bits).
const CIRCLE_CHUNK: usize = 1024;

/// Pairs per parallel task of the pair pass (any value gives the same bits).
const PAIR_CHUNK: usize = 1024;

/// What the pair loop reads of a circle, packed in one cache line.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
pub(crate) struct CircleState {
    pub pos: Vec2,
    /// Velocity of the circle centre.
    pub vel: Vec2,
    pub omega: f64,
    pub r: f64,
    pub mass: f64,
    /// Fills the line (the pair kernel loads whole lines).
    pub pad: f64,
}

impl CircleState {
    /// The line as eight numbers: x, y, vx, vy, ω, r, m, 0 (portable pair kernel).
    #[cfg(not(target_feature = "avx512f"))]
    #[inline(always)]
    pub(crate) fn line(&self) -> [f64; 8] {
        [
            self.pos.x, self.pos.y, self.vel.x, self.vel.y, self.omega, self.r, self.mass, self.pad,
        ]
    }
}

/// Scratch for stepping a [`System`].
#[derive(Default)]
pub struct Stepper {
    cells: CellList,
    cpos: Vec<Vec2>,
    carm: Vec<Vec2>,
    cstate: Vec<CircleState>,
    ref_pos: Vec<Vec2>,
    /// Pairs of circle i (as the lower index) are `pair_start[i]..pair_start[i + 1]`.
    pair_start: Vec<u32>,
    /// Result of every pair (force on i, torques on i and j; zero when not touching) and
    /// whether it touches (1) or not (0).
    out: Vec<PairOut>,
    touch: Vec<u8>,
    /// Per circle: the pairs in which it is j, ascending i (indices into `out_j`).
    j_start: Vec<u32>,
    j_list: Vec<u32>,
    /// Circles (ascending) with a reaction from a lower chunk of `CIRCLE_CHUNK` circles, and
    /// where each chunk's start in that list (the fused disk pass finishes them last).
    deferred: Vec<u32>,
    deferred_start: Vec<u32>,
    /// Every body is a single circle at its centre (circle c = body c): fused fast paths.
    all_disks: bool,
    wall_buf: Vec<(Vec2, f64)>,
    kick: Vec<Kick>,
    n_circles: usize,
    n_bodies: usize,
    checked_dt: f64,
    pub rebuilds: u64,
}

impl Stepper {
    pub fn new() -> Self {
        Self::default()
    }

    /// Critical time step of `sys` under `law` (and `wall_law`): sqrt(m_min / k_max).
    pub fn critical_time_step<L: ContactLaw>(sys: &System, law: &L, wall_law: &L) -> (f64, f64, f64) {
        let b = &sys.bodies;
        let m_min = b.mass.iter().copied().fold(f64::INFINITY, f64::min);
        let r_max = b.circle_r.iter().copied().fold(0.0, f64::max);
        let mut k = law.max_stiffness(0.5 * r_max).max(wall_law.max_stiffness(r_max));
        if let Some(p) = &sys.bond_params {
            k = k.max(p.k_n.max(p.k_s) * 2.0 * p.lambda * r_max);
        }
        (lbdem_core::units::dem::critical_time_step(m_min, k), m_min, k)
    }

    /// [`Stepper::step`] compiled in this crate for the scene-selectable [`Law`]: callers in
    /// other crates get this crate's optimisation level instead of their own.
    #[inline(never)]
    pub fn step_law(
        &mut self,
        p: &StepParams,
        law: &Law,
        wall_law: &Law,
        sys: &mut System,
    ) -> Result<(), DemError> {
        self.step(p, law, wall_law, sys)
    }

    /// [`Stepper::step`] for the linear law (benchmark case), compiled in this crate.
    #[inline(never)]
    pub fn step_linear(
        &mut self,
        p: &StepParams,
        law: &LinearSpringDashpot,
        sys: &mut System,
    ) -> Result<(), DemError> {
        self.step(p, law, law, sys)
    }

    /// Number of pairs in contact at the last force evaluation.
    pub fn n_contacts(&self) -> usize {
        self.touch.iter().map(|&t| t as usize).sum()
    }

    /// Each touching pair (circles i < j) of the last force evaluation with the contact force
    /// on i (j receives the opposite).
    pub fn contact_forces<'a>(&'a self, sys: &'a System) -> impl Iterator<Item = ([u32; 2], Vec2)> + 'a {
        sys.contacts
            .pairs
            .iter()
            .zip(&self.out)
            .zip(&self.touch)
            .filter(|(_, t)| **t != 0)
            .map(|((p, o), _)| (*p, Vec2::new(o.fx, o.fy)))
    }

    /// Advance `sys` by one step.
    pub fn step<L: ContactLaw>(
        &mut self,
        p: &StepParams,
        law: &L,
        wall_law: &L,
        sys: &mut System,
    ) -> Result<(), DemError> {
        let dt = p.dt;
        let shape = (sys.bodies.n_circles(), sys.bodies.len());
        self.kick.resize(sys.bodies.len(), Kick::default());
        if self.checked_dt != dt || (self.n_circles, self.n_bodies) != shape {
            let (crit, m_min, k_max) = Self::critical_time_step(sys, law, wall_law);
            if dt.is_nan() || dt <= 0.0 || dt > crit {
                return Err(DemError::TimeStepTooLarge {
                    dt,
                    critical: crit,
                    m_min,
                    k_max,
                });
            }
            self.checked_dt = dt;
            let fresh = (self.n_circles, self.n_bodies) != shape || self.ref_pos.is_empty();
            (self.n_circles, self.n_bodies) = shape;
            if fresh {
                let b = &sys.bodies;
                self.all_disks =
                    b.n_circles() == b.len() && b.circle_offset.iter().all(|o| o.x == 0.0 && o.y == 0.0);
                self.update_circles(sys);
                self.rebuild(sys, p.skin)?;
                if sys.step == 0 {
                    // Prime F(0) for the first half-kick; dt = 0 leaves the history untouched.
                    self.forces(&StepParams { dt: 0.0, ..*p }, law, wall_law, sys, 0.0);
                }
            }
        }
        update_wall_velocities(&mut sys.walls, wall_law.max_stiffness(1.0), dt);
        for w in sys.walls.iter_mut() {
            let v = w.vel;
            w.translate(v * dt);
        }
        let worst = if self.all_disks {
            self.kick_drift_disks(sys, 0.5 * dt, dt)
        } else {
            self.kick_drift(sys, 0.5 * dt, dt);
            self.update_circles(sys)
        };
        let half_skin2 = 0.25 * p.skin * p.skin;
        if !worst.is_finite() {
            let body = (0..sys.bodies.len())
                .find(|&k| !(sys.bodies.pos[k].norm2().is_finite() && sys.bodies.vel[k].norm2().is_finite()))
                .unwrap_or(0);
            return Err(DemError::NonFinite { body, step: sys.step });
        }
        if worst > half_skin2 {
            self.rebuild(sys, p.skin)?;
        }
        self.forces(p, law, wall_law, sys, 0.5 * dt);
        sys.time += dt;
        sys.step += 1;
        Ok(())
    }

    /// [`Stepper::kick_drift`] and [`Stepper::update_circles`] in one pass when every body is a
    /// single centred circle (circle k = body k).
    fn kick_drift_disks(&mut self, sys: &mut System, h: f64, dt: f64) -> f64 {
        let dom = sys.domain;
        let b = &mut sys.bodies;
        let (force, mass, torque, inertia, rad) = (&b.force, &b.mass, &b.torque, &b.inertia, &b.circle_r);
        let nc = b.pos.len();
        self.cpos.resize(nc, Vec2::ZERO);
        self.carm.resize(nc, Vec2::ZERO);
        self.cstate.resize(nc, CircleState::default());
        let refp = &self.ref_pos;
        let ch = BODY_CHUNK;
        let dk = DiskKick::new(&dom, dt);
        b.pos
            .par_chunks_mut(ch)
            .zip(b.vel.par_chunks_mut(ch))
            .zip(b.angle.par_chunks_mut(ch).zip(b.omega.par_chunks_mut(ch)))
            .zip(self.cstate.par_chunks_mut(ch).zip(self.kick.par_chunks_mut(ch)))
            .enumerate()
            .map(|(c, (((x, v), (a, w)), (st, kc)))| {
                let r = c * ch..c * ch + x.len();
                let (f, t, m, i, rad, refp) = (
                    &force[r.clone()],
                    &torque[r.clone()],
                    &mass[r.clone()],
                    &inertia[r.clone()],
                    &rad[r.clone()],
                    &refp[r],
                );
                let mut worst = 0.0;
                let mut l0 = 0;
                while l0 + W <= x.len() {
                    let lanes = l0..l0 + W;
                    for l in lanes.clone() {
                        kc[l].refresh(h, m[l], i[l]);
                    }
                    let e = Eight {
                        x: (&mut x[lanes.clone()]).try_into().expect("8"),
                        v: (&mut v[lanes.clone()]).try_into().expect("8"),
                        a: (&mut a[lanes.clone()]).try_into().expect("8"),
                        w: (&mut w[lanes.clone()]).try_into().expect("8"),
                        st: (&mut st[lanes.clone()]).try_into().expect("8"),
                        f: f[lanes.clone()].try_into().expect("8"),
                        t: t[lanes.clone()].try_into().expect("8"),
                        r: rad[lanes.clone()].try_into().expect("8"),
                        m: m[lanes.clone()].try_into().expect("8"),
                        refp: refp[lanes.clone()].try_into().expect("8"),
                        hm: std::array::from_fn(|k| kc[l0 + k].hm),
                        hi: std::array::from_fn(|k| kc[l0 + k].hi),
                    };
                    match dk.eight(e) {
                        Some(d) => worst = nan_max(worst, d),
                        None => break,
                    }
                    l0 += W;
                }
                for l in l0..x.len() {
                    let kk = &mut kc[l];
                    kk.refresh(h, m[l], i[l]);
                    v[l] += f[l] * kk.hm;
                    w[l] += t[l] * kk.hi;
                    x[l] = dom.wrap(x[l] + v[l] * dt);
                    a[l] += w[l] * dt;
                    st[l] = CircleState {
                        pos: x[l],
                        vel: v[l],
                        omega: w[l],
                        r: rad[l],
                        mass: m[l],
                        pad: 0.0,
                    };
                    worst = nan_max(worst, dom.min_image(x[l] - refp[l]).norm2());
                }
                worst
            })
            .reduce(|| 0.0, nan_max)
    }

    /// Half kick then drift, fused in one pass over the bodies.
    fn kick_drift(&mut self, sys: &mut System, h: f64, dt: f64) {
        let dom = sys.domain;
        let b = &mut sys.bodies;
        let (force, mass, torque, inertia) = (&b.force, &b.mass, &b.torque, &b.inertia);
        b.pos
            .par_iter_mut()
            .zip(b.vel.par_iter_mut())
            .zip(b.angle.par_iter_mut().zip(b.omega.par_iter_mut()))
            .zip(self.kick.par_iter_mut())
            .enumerate()
            .with_min_len(4096)
            .for_each(|(k, (((x, v), (a, w)), kk))| {
                kk.refresh(h, mass[k], inertia[k]);
                *v += force[k] * kk.hm;
                *w += torque[k] * kk.hi;
                *x = dom.wrap(*x + *v * dt);
                *a += *w * dt;
            });
    }

    /// World positions, arms and packed pair-loop state of every circle; returns the largest
    /// squared displacement since the last list build (NaN if any position is not finite).
    fn update_circles(&mut self, sys: &System) -> f64 {
        let b = &sys.bodies;
        let dom = sys.domain;
        let nc = b.n_circles();
        self.cpos.resize(nc, Vec2::ZERO);
        self.carm.resize(nc, Vec2::ZERO);
        self.cstate.resize(nc, CircleState::default());
        let have_ref = self.ref_pos.len() == nc;
        let refp = &self.ref_pos;
        self.cpos
            .par_iter_mut()
            .zip(self.carm.par_iter_mut())
            .zip(self.cstate.par_iter_mut())
            .enumerate()
            .with_min_len(4096)
            .map(|(c, ((x, a), st))| {
                let k = b.circle_body[c] as usize;
                let off = b.circle_offset[c];
                *a = if off.x == 0.0 && off.y == 0.0 {
                    Vec2::ZERO
                } else {
                    off.rotated(b.angle[k])
                };
                *x = b.pos[k] + *a;
                *st = CircleState {
                    pos: *x,
                    vel: b.vel[k] + a.spin(b.omega[k]),
                    omega: b.omega[k],
                    r: b.circle_r[c],
                    mass: b.mass[k],
                    pad: 0.0,
                };
                if have_ref {
                    dom.min_image(*x - refp[c]).norm2()
                } else {
                    x.norm2() * 0.0
                }
            })
            .reduce(|| 0.0, nan_max)
    }

    fn rebuild(&mut self, sys: &mut System, skin: f64) -> Result<(), DemError> {
        let b = &sys.bodies;
        if self.all_disks {
            self.cpos.clear();
            self.cpos.extend(self.cstate.iter().map(|c| c.pos));
        }
        let pairs = self
            .cells
            .build_pairs(&sys.domain, &self.cpos, &b.circle_r, &b.circle_body, skin)?;
        let hist = carry_history(&sys.contacts.pairs, &sys.contacts.hist, &pairs);
        sys.contacts.pairs = pairs;
        sys.contacts.hist = hist;
        let need = b.n_circles() * sys.walls.len();
        if sys.contacts.wall_hist.len() != need {
            sys.contacts.wall_hist.resize(need, History::default());
        }
        self.ref_pos.clone_from(&self.cpos);
        // Pairs of each circle as i (contiguous: the list is sorted), and as j (ascending i).
        let nc = b.n_circles();
        let pairs = &sys.contacts.pairs;
        self.pair_start.clear();
        self.pair_start.resize(nc + 1, 0);
        self.j_start.clear();
        self.j_start.resize(nc + 1, 0);
        for pr in pairs {
            self.pair_start[pr[0] as usize + 1] += 1;
            self.j_start[pr[1] as usize + 1] += 1;
        }
        for c in 0..nc {
            self.pair_start[c + 1] += self.pair_start[c];
            self.j_start[c + 1] += self.j_start[c];
        }
        self.j_list.clear();
        self.j_list.resize(pairs.len(), 0);
        let mut fill: Vec<u32> = self.j_start[..nc].to_vec();
        for (k, pr) in pairs.iter().enumerate() {
            let c = pr[1] as usize;
            self.j_list[fill[c] as usize] = k as u32;
            fill[c] += 1;
        }
        self.out.resize(pairs.len(), PairOut::default());
        self.touch.resize(pairs.len(), 0);
        // Circles whose lowest partner i lies in an earlier chunk than their own.
        self.deferred.clear();
        self.deferred_start.clear();
        for c0 in (0..nc).step_by(CIRCLE_CHUNK) {
            self.deferred_start.push(self.deferred.len() as u32);
            for c in c0..(c0 + CIRCLE_CHUNK).min(nc) {
                let (a, b) = (self.j_start[c] as usize, self.j_start[c + 1] as usize);
                if a < b && (pairs[self.j_list[a] as usize][0] as usize) < c0 {
                    self.deferred.push(c as u32);
                }
            }
        }
        self.deferred_start.push(self.deferred.len() as u32);
        self.rebuilds += 1;
        Ok(())
    }

    /// Forces and torques on every body; then, if `h > 0`, the closing half kick v += F/m h.
    fn forces<L: ContactLaw>(&mut self, p: &StepParams, law: &L, wall_law: &L, sys: &mut System, h: f64) {
        let dt = p.dt;
        let dom = sys.domain;
        let simple = sys.walls.is_empty() && sys.bond_params.is_none() && sys.membrane.is_none();
        if self.all_disks && simple {
            self.forces_disks(p, law, sys, h);
            return;
        }
        let (carm, cst) = (&self.carm, &self.cstate);
        // 1. Every pair, in parallel over fixed chunks of pairs: force on i, torques on i and j.
        {
            let pairs = &sys.contacts.pairs;
            let n = pairs.len();
            let hist = &mut sys.contacts.hist[..n];
            let fast = law.linear().and_then(|l| LinearPair::new(l, &dom, dt));
            let ch = PAIR_CHUNK;
            pairs
                .par_chunks(ch)
                .zip(hist.par_chunks_mut(ch))
                .zip(self.touch[..n].par_chunks_mut(ch))
                .zip(self.out[..n].par_chunks_mut(ch))
                .for_each(|(((pairs, hist), touch), out)| match &fast {
                    Some(k) => k.run(cst, pairs, hist, out, touch),
                    None => generic_pairs(law, &dom, dt, cst, pairs, hist, out, touch),
                });
        }
        // 2. Per body: each circle's own sum plus its reactions in ascending i. Without walls,
        //    bonds or membrane nothing else adds to the contact forces, so body forces, damping
        //    and the kick follow in the same pass.
        let g = p.gravity * p.gravity_factor;
        let fin = Finish {
            g,
            gv: p.viscous_damping,
            al: p.local_damping,
            h,
        };
        let (out, ps, js, jl) = (&self.out, &self.pair_start, &self.j_start, &self.j_list);
        // Circle c: its pairs as i in ascending j, then as j in ascending i (the reaction −f).
        let circle_sum = |c: usize| -> (Vec2, f64) {
            let (mut fc, mut tc) = (Vec2::ZERO, 0.0);
            for o in &out[ps[c] as usize..ps[c + 1] as usize] {
                fc.x += o.fx;
                fc.y += o.fy;
                tc += o.ti;
            }
            for &q in &jl[js[c] as usize..js[c + 1] as usize] {
                let o = &out[q as usize];
                fc.x -= o.fx;
                fc.y -= o.fy;
                tc += o.tj;
            }
            (fc, tc)
        };
        let disks = self.all_disks;
        let kick = &self.kick;
        let bodies = &mut sys.bodies;
        let Bodies5 {
            force,
            torque,
            vel,
            omega,
            mass,
            inertia,
            ext_force,
            ext_torque,
            cstart,
        } = Bodies5::of(bodies);
        force
            .par_iter_mut()
            .zip(torque.par_iter_mut())
            .zip(vel.par_iter_mut().zip(omega.par_iter_mut()))
            .enumerate()
            .with_min_len(512)
            .for_each(|(k, ((f, t), (v, w)))| {
                if disks {
                    (*f, *t) = circle_sum(k);
                } else {
                    let (mut fb, mut tb) = (Vec2::ZERO, 0.0);
                    let c0 = cstart[k];
                    for (c, arm) in (c0..).zip(&carm[c0..cstart[k + 1]]) {
                        let (fc, tc) = circle_sum(c);
                        fb += fc;
                        tb += tc + arm.cross(fc);
                    }
                    *f = fb;
                    *t = tb;
                }
                if simple {
                    fin.apply(
                        f,
                        t,
                        v,
                        w,
                        mass[k],
                        inertia[k],
                        &kick[k],
                        ext_force[k],
                        ext_torque[k],
                    );
                }
            });
        if simple {
            return;
        }
        // 3. Walls: per circle in parallel, then a sequential sum in circle order.
        let nw = sys.walls.len();
        if nw > 0 {
            let b = &sys.bodies;
            let walls = &sys.walls;
            self.wall_buf.resize(b.n_circles() * nw, (Vec2::ZERO, 0.0));
            self.wall_buf
                .par_chunks_mut(nw)
                .zip(sys.contacts.wall_hist.par_chunks_mut(nw))
                .enumerate()
                .with_min_len(256)
                .for_each(|(c, (buf, hist))| {
                    let k = b.circle_body[c] as usize;
                    let r = b.circle_r[c];
                    for w in 0..nw {
                        match walls[w].touch(cst[c].pos, r) {
                            None => {
                                hist[w] = History::default();
                                buf[w] = (Vec2::ZERO, 0.0);
                            }
                            Some((delta, n)) => {
                                let a = r - delta;
                                let arm = carm[c] + n * a;
                                let v = b.vel[k] + arm.spin(b.omega[k]);
                                let ci = ContactInput {
                                    delta,
                                    n,
                                    v_rel: v - walls[w].vel,
                                    w_rel: b.omega[k],
                                    r_eff: r,
                                    m_eff: b.mass[k],
                                    dt,
                                };
                                let o = wall_law.force(&ci, &mut hist[w]);
                                buf[w] = (o.f, arm.cross(o.f) + o.m_roll);
                            }
                        }
                    }
                });
            let mut wf = vec![Vec2::ZERO; nw];
            let mut wn = vec![0u32; nw];
            let bodies = &mut sys.bodies;
            for c in 0..bodies.n_circles() {
                let k = bodies.circle_body[c] as usize;
                for (w, wfw) in wf.iter_mut().enumerate() {
                    let (f, t) = self.wall_buf[c * nw + w];
                    bodies.force[k] += f;
                    bodies.torque[k] += t;
                    *wfw -= f;
                    wn[w] += u32::from(f != Vec2::ZERO);
                }
            }
            for ((w, f), n) in sys.walls.iter_mut().zip(wf).zip(wn) {
                w.force = f;
                w.n_contacts = n;
            }
        }
        // 4. Bonds, sequentially in bond order.
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
                    m_eff: 0.0,
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
        // 5. Body forces, drivers, damping.
        let kick = &self.kick;
        let bodies = &mut sys.bodies;
        if let Some(mem) = &sys.membrane {
            for (k, &bk) in mem.bodies.iter().enumerate() {
                let bk = bk as usize;
                let f = mem.force_on(k, bodies.pos[bk]);
                bodies.force[bk] += f;
            }
        }
        let Bodies5 {
            force,
            torque,
            vel,
            omega,
            mass,
            inertia,
            ext_force,
            ext_torque,
            ..
        } = Bodies5::of(bodies);
        force
            .par_iter_mut()
            .zip(torque.par_iter_mut())
            .zip(vel.par_iter_mut().zip(omega.par_iter_mut()))
            .enumerate()
            .with_min_len(1024)
            .for_each(|(k, ((f, t), (v, w)))| {
                fin.apply(
                    f,
                    t,
                    v,
                    w,
                    mass[k],
                    inertia[k],
                    &kick[k],
                    ext_force[k],
                    ext_torque[k],
                );
            });
    }
}

impl Stepper {
    /// Disks without walls, bonds or membrane: the pair pass and the per-body pass fused per
    /// chunk of circles, so each chunk's pair results are summed while still in cache. Circle
    /// c needs the reactions of all its partners i < c; those in the chunk are done before
    /// it, so every circle without a partner in an earlier chunk is finished in the same task
    /// (same summation order as the separate passes, hence the same bits); the rest
    /// (`deferred`) follow in a second pass.
    fn forces_disks<L: ContactLaw>(&mut self, p: &StepParams, law: &L, sys: &mut System, h: f64) {
        let (dt, dom) = (p.dt, sys.domain);
        let fin = Finish {
            g: p.gravity * p.gravity_factor,
            gv: p.viscous_damping,
            al: p.local_damping,
            h,
        };
        let fast = law.linear().and_then(|l| LinearPair::new(l, &dom, dt));
        let (cst, ps, js, jl, kick) = (
            &self.cstate,
            &self.pair_start,
            &self.j_start,
            &self.j_list,
            &self.kick,
        );
        let (deferred, dstart) = (&self.deferred, &self.deferred_start);
        let pairs = &sys.contacts.pairs;
        let Bodies5 {
            force,
            torque,
            vel,
            omega,
            mass,
            inertia,
            ext_force,
            ext_torque,
            ..
        } = Bodies5::of(&mut sys.bodies);
        let nc = force.len();
        // Sum of circle c and its finish; `out` holds the pairs from `base` on.
        let finish =
            |c: usize, out: &[PairOut], base: usize, f: &mut Vec2, t: &mut f64, v: &mut Vec2, w: &mut f64| {
                let (mut fc, mut tc) = (Vec2::ZERO, 0.0);
                for o in &out[ps[c] as usize - base..ps[c + 1] as usize - base] {
                    fc.x += o.fx;
                    fc.y += o.fy;
                    tc += o.ti;
                }
                for &q in &jl[js[c] as usize..js[c + 1] as usize] {
                    let o = &out[q as usize - base];
                    fc.x -= o.fx;
                    fc.y -= o.fy;
                    tc += o.tj;
                }
                (*f, *t) = (fc, tc);
                fin.apply(
                    f,
                    t,
                    v,
                    w,
                    mass[c],
                    inertia[c],
                    &kick[c],
                    ext_force[c],
                    ext_torque[c],
                );
            };
        {
            let mut tasks = Vec::with_capacity(nc.div_ceil(CIRCLE_CHUNK));
            let (mut hist, mut out, mut touch) =
                (&mut sys.contacts.hist[..], &mut self.out[..], &mut self.touch[..]);
            let body = force
                .chunks_mut(CIRCLE_CHUNK)
                .zip(torque.chunks_mut(CIRCLE_CHUNK))
                .zip(vel.chunks_mut(CIRCLE_CHUNK).zip(omega.chunks_mut(CIRCLE_CHUNK)));
            for (k, bk) in body.enumerate() {
                let c0 = k * CIRCLE_CHUNK;
                let c1 = (c0 + CIRCLE_CHUNK).min(nc);
                let len = (ps[c1] - ps[c0]) as usize;
                let (hk, hr) = std::mem::take(&mut hist).split_at_mut(len);
                let (ok, or) = std::mem::take(&mut out).split_at_mut(len);
                let (tk, tr) = std::mem::take(&mut touch).split_at_mut(len);
                (hist, out, touch) = (hr, or, tr);
                tasks.push((k, hk, ok, tk, bk));
            }
            tasks
                .into_par_iter()
                .for_each(|(k, hist, out, touch, ((f, t), (v, w)))| {
                    let c0 = k * CIRCLE_CHUNK;
                    let base = ps[c0] as usize;
                    let pr = &pairs[base..base + out.len()];
                    match &fast {
                        Some(kern) => kern.run(cst, pr, hist, out, touch),
                        None => generic_pairs(law, &dom, dt, cst, pr, hist, out, touch),
                    }
                    let mut skip = deferred[dstart[k] as usize..dstart[k + 1] as usize]
                        .iter()
                        .peekable();
                    for l in 0..f.len() {
                        let c = c0 + l;
                        if skip.peek().is_some_and(|&&d| d as usize == c) {
                            skip.next();
                            continue;
                        }
                        finish(c, out, base, &mut f[l], &mut t[l], &mut v[l], &mut w[l]);
                    }
                });
        }
        // Circles with a partner in an earlier chunk, now that every pair is done.
        let out = &self.out[..];
        force
            .par_chunks_mut(CIRCLE_CHUNK)
            .zip(torque.par_chunks_mut(CIRCLE_CHUNK))
            .zip(
                vel.par_chunks_mut(CIRCLE_CHUNK)
                    .zip(omega.par_chunks_mut(CIRCLE_CHUNK)),
            )
            .enumerate()
            .for_each(|(k, ((f, t), (v, w)))| {
                let c0 = k * CIRCLE_CHUNK;
                for &c in &deferred[dstart[k] as usize..dstart[k + 1] as usize] {
                    let l = c as usize - c0;
                    finish(c as usize, out, 0, &mut f[l], &mut t[l], &mut v[l], &mut w[l]);
                }
            });
    }
}

/// The pair pass for any law: force on i, torques on i and j, touching flag.
#[allow(clippy::too_many_arguments)]
fn generic_pairs<L: ContactLaw>(
    law: &L,
    dom: &Domain,
    dt: f64,
    cst: &[CircleState],
    pairs: &[[u32; 2]],
    hist: &mut [History],
    out: &mut [PairOut],
    touch: &mut [u8],
) {
    for (((pr, h), t), o) in pairs.iter().zip(hist).zip(touch).zip(out) {
        let (ci, cj) = (&cst[pr[0] as usize], &cst[pr[1] as usize]);
        let d = dom.min_image(cj.pos - ci.pos);
        let (ri, rj) = (ci.r, cj.r);
        let rs = ri + rj;
        let d2 = d.norm2();
        if d2 >= rs * rs {
            if *h != History::default() {
                *h = History::default();
            }
            *o = PairOut::default();
            *t = 0;
            continue;
        }
        let dist = d2.sqrt();
        let n = d * (1.0 / dist);
        let delta = rs - dist;
        let (ai, aj) = (ri - 0.5 * delta, rj - 0.5 * delta);
        let (wi, wj) = (ci.omega, cj.omega);
        let vi = ci.vel + (n * ai).spin(wi);
        let vj = cj.vel - (n * aj).spin(wj);
        let (mi, mj) = (ci.mass, cj.mass);
        let c = ContactInput {
            delta,
            n,
            v_rel: vi - vj,
            w_rel: wi - wj,
            r_eff: ri * rj / rs,
            m_eff: mi * mj / (mi + mj),
            dt,
        };
        let r = law.force(&c, h);
        let nxf = n.cross(r.f);
        *o = PairOut {
            fx: r.f.x,
            fy: r.f.y,
            ti: ai * nxf + r.m_roll,
            tj: aj * nxf - r.m_roll,
        };
        *t = 1;
    }
}

/// Body forces, damping and the closing half kick for one body.
struct Finish {
    g: Vec2,
    gv: f64,
    al: f64,
    h: f64,
}

impl Finish {
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn apply(
        &self,
        f: &mut Vec2,
        t: &mut f64,
        v: &mut Vec2,
        w: &mut f64,
        m: f64,
        i: f64,
        kick: &Kick,
        ef: Vec2,
        et: f64,
    ) {
        *f += self.g * m + ef;
        *t += et;
        if self.gv > 0.0 {
            *f -= *v * (self.gv * m);
            *t -= self.gv * i * *w;
        }
        if self.al > 0.0 {
            f.x -= self.al * f.x.abs() * sign(v.x);
            f.y -= self.al * f.y.abs() * sign(v.y);
            *t -= self.al * t.abs() * sign(*w);
        }
        if self.h != 0.0 {
            // The opening kick of this step refreshed `kick` for this h.
            *v += *f * kick.hm;
            *w += *t * kick.hi;
        }
    }
}

/// Maximum that propagates NaN (a non-finite position must stop the run).
#[inline]
pub(crate) fn nan_max(p: f64, q: f64) -> f64 {
    if p.is_nan() || q.is_nan() {
        f64::NAN
    } else {
        p.max(q)
    }
}

#[inline]
fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Split borrows of the fields the force passes need.
struct Bodies5<'a> {
    force: &'a mut Vec<Vec2>,
    torque: &'a mut Vec<f64>,
    vel: &'a mut Vec<Vec2>,
    omega: &'a mut Vec<f64>,
    mass: &'a [f64],
    inertia: &'a [f64],
    ext_force: &'a [Vec2],
    ext_torque: &'a [f64],
    cstart: &'a [usize],
}

impl<'a> Bodies5<'a> {
    fn of(b: &'a mut crate::body::Bodies) -> Self {
        Self {
            force: &mut b.force,
            torque: &mut b.torque,
            vel: &mut b.vel,
            omega: &mut b.omega,
            mass: &b.mass,
            inertia: &b.inertia,
            ext_force: &b.ext_force,
            ext_torque: &b.ext_torque,
            cstart: &b.circle_start,
        }
    }
}
