//! The time step of the sphere engine: velocity Verlet for translation and rotation (Verlet
//! 1967; Allen & Tildesley, "Computer Simulation of Liquids", Sect. 3.2), the same scheme as the
//! 2D engine: half kick with the last forces, drift, Verlet-list check, forces at the new
//! positions with the half-step velocities, closing half kick. Generic over the contact law
//! ([`SphereLaw`], monomorphised: its `force` inlines into the pair loop); user forces through a
//! [`SphereForceHook`].
//!
//! Parallel where the time goes: the pair laws run on rayon's threads (each pair reads the
//! spheres and writes only its own history; the Hertz-Mindlin spring law eight pairs at a time,
//! `super::hm_batched`), and their forces are then summed in list order (the force and torque
//! sums side by side on two threads, each serial), so results do not depend on the thread count; the kicks and the per-sphere checks run
//! on the threads too (each sphere on its own). Walls, gravity, clumps and the list's rebuild
//! bookkeeping are serial.
//! Determinism: the pair list is sorted (i < j), every pair beyond the law's range is skipped
//! (adds nothing) and wall contacts follow in wall order, so each sphere's force is summed in an
//! order fixed by the set of interactions alone; and the list's reference positions live in the
//! state, so a resumed run rebuilds the list at the same steps and continues bit for bit.

use super::cells::CellList3;
use super::clump::{Clumps, free_rotation, quat_array};
use super::error::SphereError;
use super::hm_batched::{HmChunk, HmPair, PairRecord, SphereLine, pack};
use super::hook::{NoHook, SphereForceHook, user_forces};
use super::kick_batched::{KickChunk, KickInput};
use super::law::{Interaction, Response, SphereLaw, TimeStepLimit};
use super::stress::{ContactForce, Partner};
use super::system::{FREE, SphereSystem, Spheres};
use crate::history::{Histories, stride_of};
use crate::neighbor::carry_history_into;
use crate::vector::{Vec3, Vector};
use rayon::prelude::*;
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

/// Scratch for stepping a [`SphereSystem`] under the law `L` (nothing here is state).
#[derive(Debug)]
pub struct SphereStepper<L: SphereLaw> {
    cells: CellList3,
    new_pairs: Vec<[u32; 2]>,
    new_hist: Histories,
    /// The (dt, law, sphere count, frozen count) last checked.
    checked: Option<(f64, L, usize, usize)>,
    /// Interactions of the last force evaluation ([`Self::contacts`]), kept only when
    /// `record` is on.
    records: Vec<ContactForce>,
    /// Whether force evaluations fill `records` ([`Self::record_contacts`]; off by default).
    record: bool,
    /// The pair pass's per-pair results when recording (scratch, list order; empty otherwise).
    hits: Vec<Option<PairHit>>,
    /// The pair pass's per-pair sums when not recording (scratch, list order).
    sums: Vec<Option<PairSum>>,
    /// The spheres packed for the batched Hertz-Mindlin kernel, and its per-pair results
    /// (scratch; used when the law has that kernel and no records are kept).
    lines: Vec<SphereLine>,
    batched: Vec<PairRecord>,
    /// 1.0 per mobile sphere for the kicks (scratch).
    mobile: Vec<f64>,
    /// List rebuilds so far (diagnostic).
    pub rebuilds: u64,
}

impl<L: SphereLaw> Default for SphereStepper<L> {
    fn default() -> Self {
        Self {
            cells: CellList3::default(),
            new_pairs: Vec::new(),
            new_hist: Histories::default(),
            checked: None,
            records: Vec::new(),
            record: false,
            hits: Vec::new(),
            sums: Vec::new(),
            lines: Vec::new(),
            batched: Vec::new(),
            mobile: Vec::new(),
            rebuilds: 0,
        }
    }
}

/// The smallest time-step limit of `law` over the mobile spheres of `sys` (frozen ones are not
/// integrated; against a frozen grain m* is the mobile sphere's mass, above the m/2 of two equal
/// spheres the laws bound), and the sphere that sets it (`None` with no mobile spheres).
pub fn max_time_step<L: SphereLaw>(law: &L, sys: &SphereSystem) -> Option<(usize, TimeStepLimit)> {
    let s = &sys.spheres;
    (0..s.len())
        .filter(|&k| !sys.is_frozen(k))
        .map(|k| (k, law.max_time_step(s.radius[k], s.mass[k])))
        .reduce(|a, b| if b.1.dt < a.1.dt { b } else { a })
}

impl<L: SphereLaw> SphereStepper<L> {
    pub fn new() -> Self {
        Self::default()
    }

    /// Turn the contact records of [`Self::contacts`] on or off (off by default: recording
    /// costs a comparison and a push per interaction every step). Turning it off drops the
    /// records held.
    pub fn record_contacts(&mut self, on: bool) {
        self.record = on;
        if !on {
            self.records.clear();
        }
    }

    /// Every interaction that exerted a force in the last force evaluation (pairs in list
    /// order, then sphere-wall contacts; the end of the last step, or the priming at step 0),
    /// with its contact point, branch vector and force, for stress sums
    /// ([`super::dipole_stress`]). Only while recording is on ([`Self::record_contacts`]):
    /// with recording off (the default) this is always empty. Empty before this stepper's
    /// first step and after a step that returned an error.
    pub fn contacts(&self) -> &[ContactForce] {
        &self.records
    }

    fn check(&mut self, p: &SphereStepParams, law: &L, sys: &SphereSystem) -> Result<(), SphereError> {
        let n = sys.spheres.len();
        let nf = sys.spheres.frozen.iter().filter(|&&f| f).count();
        if self
            .checked
            .as_ref()
            .is_some_and(|(dt, l, m, f)| *dt == p.dt && l == law && *m == n && *f == nf)
        {
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
        sys.validate()?;
        if let Some((sphere, limit)) = max_time_step(law, sys)
            && p.dt > limit.dt
        {
            return Err(SphereError::TimeStepTooLarge {
                dt: p.dt,
                limit: limit.dt,
                sphere,
                bound: limit.bound,
            });
        }
        self.checked = Some((p.dt, law.clone(), n, nf));
        Ok(())
    }

    /// Advance `sys` by one step of `p.dt` under `law`.
    ///
    /// # Errors
    ///
    /// Parameters and state are checked before anything moves: such an error leaves `sys`
    /// untouched. An error from later in the step (the cell list refusing the drifted
    /// positions, or a non-finite state after the step) leaves `sys` part way through it —
    /// positions, velocities, time and Lees-Edwards offset advanced, forces stale — so it is
    /// not fit to step on: restore it from a checkpoint. The contact records are empty after
    /// any error.
    pub fn step(&mut self, p: &SphereStepParams, law: &L, sys: &mut SphereSystem) -> Result<(), SphereError> {
        self.step_with(p, law, sys, &mut NoHook)
    }

    /// Advance `sys` by one step of `p.dt` under `law`, with the user forces of `hook`. Errors
    /// as for [`Self::step`].
    pub fn step_with(
        &mut self,
        p: &SphereStepParams,
        law: &L,
        sys: &mut SphereSystem,
        hook: &mut impl SphereForceHook,
    ) -> Result<(), SphereError> {
        // Records of a step that fails are never left to look current.
        self.records.clear();
        self.check(p, law, sys)?;
        if sys.step == 0 {
            // Prime F(0): the opening half kick needs the forces of the initial state.
            self.refresh_list(p.skin, law, sys)?;
            self.forces(p, law, sys, hook);
        }
        let dt = p.dt;
        let h = 0.5 * dt;
        // The Lees-Edwards images move first: positions at t + dt wrap with the offset of t + dt.
        sys.domain.advance(dt);
        let dom = sys.domain;
        // Opening half kick and drift: mobile spheres (frozen ones stay), then clumps (members
        // placed on them).
        // Which spheres move: fixed for the step (the force hook sees the system read-only).
        mobile_mask(&sys.spheres, &mut self.mobile);
        kick(&mut sys.spheres, h, Some((dt, &dom)), &self.mobile);
        let c = &mut sys.clumps;
        for k in 0..c.len() {
            c.vel[k] += c.force[k] * (h / c.mass[k]);
            c.ang_mom[k] += c.torque[k] * h;
            (c.pos[k], c.vel[k]) = dom.wrap_moving(c.pos[k] + c.vel[k] * dt, c.vel[k]);
            let q = free_rotation(c.orientation(k), c.ang_mom[k], c.inertia[k], dt);
            c.quat[k] = quat_array(&q);
        }
        place_members(sys, true);
        for w in &mut sys.walls {
            w.point += w.vel * dt;
        }
        sys.time += dt;
        if let Err(e) = self.refresh_list(p.skin, law, sys) {
            // The priming's records (step 0) are not this step's.
            self.records.clear();
            return Err(e);
        }
        self.forces(p, law, sys, hook);
        // Closing half kick.
        kick(&mut sys.spheres, h, None, &self.mobile);
        let c = &mut sys.clumps;
        for k in 0..c.len() {
            c.vel[k] += c.force[k] * (h / c.mass[k]);
            c.ang_mom[k] += c.torque[k] * h;
        }
        place_members(sys, false);
        sys.step += 1;
        if let Some(k) = first_non_finite(&sys.spheres) {
            self.records.clear();
            return Err(SphereError::NonFinite {
                sphere: k,
                step: sys.step - 1,
            });
        }
        Ok(())
    }

    /// Rebuild the Verlet list if it is missing or a sphere has moved more than skin/2 since
    /// it was built, carrying each pair's history onto the new list.
    fn refresh_list(&mut self, skin: f64, law: &L, sys: &mut SphereSystem) -> Result<(), SphereError> {
        let dom = sys.domain;
        let s = &sys.spheres;
        let c = &mut sys.contacts;
        let n = s.len();
        // Each sphere may move skin/2 (two of them: skin); on a Lees-Edwards box a pair across
        // the sheared faces also slides by the change of the offset, taken off the skin first.
        let slide = match dom.shear {
            Some(le) => {
                let lx = dom.size().x;
                let ds = le.offset - c.list_offset;
                (ds - lx * (ds / lx).round()).abs()
            }
            None => 0.0,
        };
        let fresh = c.list_ref.len() == n && c.hist.len() == c.pairs.len() && slide <= skin && {
            let half = 0.5 * (skin - slide);
            let lim = half * half;
            let near = |(&p, &q): (&Vec3, &Vec3)| dom.min_image(p - q).norm2() <= lim;
            if n < PARALLEL_SPHERES {
                s.pos.iter().zip(&c.list_ref).all(near)
            } else {
                s.pos
                    .par_iter()
                    .zip(&c.list_ref)
                    .with_min_len(SPHERE_CHUNK)
                    .all(near)
            }
        };
        if !fresh {
            self.cells.build_pairs(
                &dom,
                &s.pos,
                &s.radius,
                &s.owner,
                skin,
                |a, b| law.range(a, b),
                &mut self.new_pairs,
            )?;
            // Two frozen grains never move relative to each other: no pair.
            let frozen = &s.frozen;
            self.new_pairs
                .retain(|p| !(frozen[p[0] as usize] && frozen[p[1] as usize]));
            let new = self.new_hist.conform::<L::History>(self.new_pairs.len());
            new.fill(L::History::default());
            let old = c.hist.as_slice::<L::History>().unwrap_or(&[]);
            let keep = c.pairs.len().min(old.len());
            carry_history_into(&c.pairs[..keep], &old[..keep], &self.new_pairs, new);
            std::mem::swap(&mut c.pairs, &mut self.new_pairs);
            std::mem::swap(&mut c.hist, &mut self.new_hist);
            c.list_ref.clear();
            c.list_ref.extend_from_slice(&s.pos);
            c.list_offset = dom.shear_offset();
            self.rebuilds += 1;
        }
        Ok(())
    }

    /// Interaction forces (pairs in list order, then walls), gravity, the user's forces; then
    /// each clump's total.
    fn forces(
        &mut self,
        p: &SphereStepParams,
        law: &L,
        sys: &mut SphereSystem,
        hook: &mut impl SphereForceHook,
    ) {
        let dom = sys.domain;
        let s = &mut sys.spheres;
        let c = &mut sys.contacts;
        let cl = &sys.clumps;
        let n = s.len();
        s.force.fill(Vec3::ZERO);
        s.torque.fill(Vec3::ZERO);
        self.records.clear();
        // The laws in parallel (each pair reads the spheres and writes only its own history),
        // then the sums in list order (each array serially): the same additions in the same
        // order whatever the thread count, so the bits do not depend on it. The Hertz-Mindlin
        // spring law takes the batched kernel, whose springs are its `Vec3` histories.
        let hm = law
            .hertz_mindlin_pairs()
            .filter(|_| !self.record && stride_of::<L::History>() == stride_of::<Vec3>());
        if let Some(k) = hm {
            // The batched kernel (same bits as the generic pass below; spheres::hm_batched).
            self.hits.clear();
            let kp = HmPair::new(&k, &dom, p.dt);
            pack(
                &mut self.lines,
                &s.pos,
                &s.vel,
                &s.omega,
                &s.radius,
                &s.frozen,
                |k| body_mass(s, cl, k),
                n >= PARALLEL_SPHERES,
            );
            let springs = c.hist.conform::<Vec3>(c.pairs.len());
            self.batched.resize(c.pairs.len(), PairRecord::default());
            let lines = &self.lines;
            c.pairs
                .par_chunks(PAIR_CHUNK)
                .zip(springs.par_chunks_mut(PAIR_CHUNK))
                .zip(self.batched.par_chunks_mut(PAIR_CHUNK))
                .for_each(|((pairs, hist), out)| {
                    lbdem_core::simd::dispatch(HmChunk {
                        kernel: &kp,
                        lines,
                        pairs,
                        hist,
                        out,
                    })
                });
            // Forces and torques are separate sums, each in list order: on two threads they run
            // side by side, on one in a single pass; the same bits either way.
            let (pairs, recs) = (&c.pairs, &self.batched);
            let (force, torque) = (&mut s.force, &mut s.torque);
            if n < PARALLEL_SPHERES || rayon::current_num_threads() < 2 {
                for (pair, r) in pairs.iter().zip(recs) {
                    let (i, j) = (pair[0] as usize, pair[1] as usize);
                    let f = Vec3::new(r.f[0], r.f[1], r.f[2]);
                    force[i] += f;
                    force[j] -= f;
                    torque[i] += Vec3::new(r.ti[0], r.ti[1], r.ti[2]);
                    torque[j] += Vec3::new(r.tj[0], r.tj[1], r.tj[2]);
                }
            } else {
                rayon::join(
                    || {
                        for (pair, r) in pairs.iter().zip(recs) {
                            let f = Vec3::new(r.f[0], r.f[1], r.f[2]);
                            force[pair[0] as usize] += f;
                            force[pair[1] as usize] -= f;
                        }
                    },
                    || {
                        for (pair, r) in pairs.iter().zip(recs) {
                            torque[pair[0] as usize] += Vec3::new(r.ti[0], r.ti[1], r.ti[2]);
                            torque[pair[1] as usize] += Vec3::new(r.tj[0], r.tj[1], r.tj[2]);
                        }
                    },
                );
            }
        } else if !self.record {
            let hist = c.hist.conform::<L::History>(c.pairs.len());
            // No stale records' hits summed below.
            self.hits.clear();
            // Only what the sums need (the force on i, the torques on i and j): 80 bytes a
            // pair against a full hit's 168; the pass writes and the sums read it every step.
            pair_pass(law, &dom, s, cl, p.dt, &c.pairs, hist, &mut self.sums, |hit| {
                let tq = hit.nrm.cross(hit.out.f);
                PairSum {
                    f: hit.out.f,
                    ti: tq * hit.ai + hit.out.torque_i,
                    tj: tq * hit.aj + hit.out.torque_j,
                }
            });
            for (pair, sum) in c.pairs.iter().zip(&self.sums) {
                let Some(PairSum { f, ti, tj }) = *sum else {
                    continue;
                };
                let (i, j) = (pair[0] as usize, pair[1] as usize);
                s.force[i] += f;
                s.force[j] -= f;
                s.torque[i] += ti;
                s.torque[j] += tj;
            }
        } else {
            let hist = c.hist.conform::<L::History>(c.pairs.len());
            pair_pass(law, &dom, s, cl, p.dt, &c.pairs, hist, &mut self.hits, |hit| hit);
        }
        for (pair, hit) in c.pairs.iter().zip(&self.hits) {
            let Some(PairHit { out, nrm, ai, aj, d }) = *hit else {
                continue;
            };
            let (i, j) = (pair[0] as usize, pair[1] as usize);
            if self.record && out != Response::default() {
                self.records.push(ContactForce {
                    i: pair[0],
                    j: Partner::Sphere(pair[1]),
                    point: s.pos[i] + nrm * ai,
                    branch: d,
                    force: out.f,
                    hydro: out.f_hydro,
                });
            }
            s.force[i] += out.f;
            s.force[j] -= out.f;
            let tq = nrm.cross(out.f);
            s.torque[i] += tq * ai + out.torque_i;
            s.torque[j] += tq * aj + out.torque_j;
        }
        let nw = sys.walls.len();
        // Spheres appended since the last evaluation get fresh records, the others keep theirs
        // (sphere-major layout); a changed wall count resets them all.
        let laid_out = c.wall_count == nw || (c.wall_count == 0 && c.wall_hist.len() == n * nw);
        if laid_out {
            c.wall_hist.resize::<L::History>(n * nw);
        } else {
            c.wall_hist.reset::<L::History>(n * nw);
        }
        c.wall_count = nw;
        let wall_hist = c.wall_hist.conform::<L::History>(n * nw);
        if nw > 0 {
            for k in 0..n {
                for (w, wall) in sys.walls.iter().enumerate() {
                    let h = &mut wall_hist[k * nw + w];
                    let r = s.radius[k];
                    let gap = (s.pos[k] - wall.point).dot(wall.normal);
                    if gap >= r + law.wall_range(r) {
                        *h = L::History::default();
                        continue;
                    }
                    let nrm = -wall.normal;
                    let delta = r - gap;
                    let a = r - 0.5 * delta;
                    let it = Interaction {
                        n: nrm,
                        delta,
                        r_i: r,
                        r_j: f64::INFINITY,
                        r_eff: r,
                        m_eff: body_mass(s, cl, k),
                        v_rel: s.vel[k] + s.omega[k].cross(nrm * a) - wall.vel,
                        dv: s.vel[k] - wall.vel,
                        dw: s.omega[k],
                        wall: true,
                        frozen: false,
                        dt: p.dt,
                    };
                    let out = law.force(&it, h);
                    if self.record && out != Response::default() {
                        self.records.push(ContactForce {
                            i: k as u32,
                            j: Partner::Wall(w as u32),
                            point: s.pos[k] + nrm * a,
                            branch: nrm * a,
                            force: out.f,
                            hydro: out.f_hydro,
                        });
                    }
                    s.force[k] += out.f;
                    s.torque[k] += nrm.cross(out.f) * a + out.torque_i;
                }
            }
        }
        if p.gravity != Vec3::ZERO {
            for k in 0..n {
                if s.owner[k] == FREE && !s.frozen[k] {
                    s.force[k] += p.gravity * s.mass[k];
                }
            }
        }
        user_forces(hook, sys.time, sys);
        gather_clumps(sys, p.gravity);
    }
}

/// Pairs per parallel task of the pair pass (a pair's law is ~100 ns: a task of this many
/// amortises rayon's hand-off).
const PAIR_CHUNK: usize = 512;

/// Spheres per parallel task of the per-sphere passes (kicks, list check, finiteness).
const SPHERE_CHUNK: usize = 4096;

/// Sphere count below which the per-sphere passes run on the calling thread: a rayon hand-off
/// costs more than such a pass (the reduced extruder, ~2,600 spheres at 0.2 ms a step, ran 1.2
/// times slower with its four per-sphere passes handed to the pool).
const PARALLEL_SPHERES: usize = 2 * SPHERE_CHUNK;

/// A half kick of the mobile spheres (v += F h/m, ω += T h/I) and, with `drift = Some((dt,
/// domain))`, the drift x += v dt wrapped into the box, eight spheres at a time
/// (`super::kick_batched`, the bits of the scalar form [`kick_scalar`]). Each sphere on its own:
/// parallel for large systems, and the same bits on any thread count. `mobile` from
/// [`mobile_mask`].
fn kick(s: &mut Spheres, h: f64, drift: Option<(f64, &super::domain::Domain3)>, mobile: &[f64]) {
    let Spheres {
        pos,
        vel,
        omega,
        force,
        torque,
        mass,
        inertia,
        ..
    } = s;
    let inp = KickInput {
        force,
        torque,
        mass,
        inertia,
        mobile,
        h,
        drift,
    };
    if pos.len() < PARALLEL_SPHERES {
        lbdem_core::simd::dispatch(KickChunk {
            inp: &inp,
            first: 0,
            pos,
            vel,
            omega,
        });
    } else {
        pos.par_chunks_mut(SPHERE_CHUNK)
            .zip(vel.par_chunks_mut(SPHERE_CHUNK))
            .zip(omega.par_chunks_mut(SPHERE_CHUNK))
            .enumerate()
            .for_each(|(c, ((pos, vel), omega))| {
                lbdem_core::simd::dispatch(KickChunk {
                    inp: &inp,
                    first: c * SPHERE_CHUNK,
                    pos,
                    vel,
                    omega,
                })
            });
    }
}

/// 1.0 for each mobile sphere, free (no clump) and not frozen (as `SphereSystem::is_mobile`),
/// else 0.0: the kick's lanes select on it.
fn mobile_mask(s: &Spheres, out: &mut Vec<f64>) {
    out.clear();
    out.extend((0..s.len()).map(|k| {
        let fixed = s.owner.get(k).is_some_and(|&o| o != FREE) || s.frozen.get(k).is_some_and(|&f| f);
        if fixed { 0.0 } else { 1.0 }
    }));
}

/// The kick one sphere at a time: the reference the batched kick is tested against.
#[cfg(test)]
fn kick_scalar(s: &mut Spheres, h: f64, drift: Option<(f64, &super::domain::Domain3)>) {
    for k in 0..s.len() {
        if s.owner.get(k).is_some_and(|&o| o != FREE) || s.frozen.get(k).is_some_and(|&f| f) {
            continue;
        }
        s.vel[k] += s.force[k] * (h / s.mass[k]);
        s.omega[k] += s.torque[k] * (h / s.inertia[k]);
        if let Some((dt, dom)) = drift {
            (s.pos[k], s.vel[k]) = dom.wrap_moving(s.pos[k] + s.vel[k] * dt, s.vel[k]);
        }
    }
}

/// The first sphere whose position, velocity or spin is not finite.
fn first_non_finite(s: &Spheres) -> Option<usize> {
    let bad = |k: usize| !(s.pos[k].is_finite() && s.vel[k].is_finite() && s.omega[k].is_finite());
    if s.len() < PARALLEL_SPHERES {
        (0..s.len()).find(|&k| bad(k))
    } else {
        (0..s.len())
            .into_par_iter()
            .with_min_len(SPHERE_CHUNK)
            .position_first(bad)
    }
}

/// What the sums need of one pair when no records are kept.
#[derive(Clone, Copy, Debug)]
struct PairSum {
    /// Force on i (−f on j).
    f: Vec3,
    /// Torque on i and on j.
    ti: Vec3,
    tj: Vec3,
}

/// The pair laws of `pairs` on rayon's threads, in tasks of at least `PAIR_CHUNK` pairs (each
/// pair reads the spheres and writes only its own history), each hit mapped by `keep` into
/// `out` (list order; `None` beyond the law's range).
#[allow(clippy::too_many_arguments)]
fn pair_pass<L: SphereLaw, T: Send>(
    law: &L,
    dom: &super::domain::Domain3,
    s: &Spheres,
    cl: &Clumps,
    dt: f64,
    pairs: &[[u32; 2]],
    hist: &mut [L::History],
    out: &mut Vec<Option<T>>,
    keep: impl Fn(PairHit) -> T + Sync,
) {
    pairs
        .par_iter()
        .zip(hist.par_iter_mut())
        .with_min_len(PAIR_CHUNK)
        .map(|(pair, h)| pair_response(law, dom, s, cl, dt, *pair, h).map(&keep))
        .collect_into_vec(out);
}

/// What one pair's law returned, with what the sums need: the unit normal, the arms to the
/// contact point and the branch vector.
#[derive(Clone, Copy, Debug)]
struct PairHit {
    out: Response,
    nrm: Vec3,
    ai: f64,
    aj: f64,
    d: Vec3,
}

/// The law of the pair `pair` (i < j) at the spheres' present state, updating its history; None
/// (and a fresh history) beyond the law's range. Inlined, with the law and the minimum image,
/// into the pair pass's loop (1.13x on `bench dem3d`); the law's per-call constants, such
/// as the Hertz-Mindlin restitution's β and its `ln`, are still computed per pair.
#[inline(always)]
fn pair_response<L: SphereLaw>(
    law: &L,
    dom: &super::domain::Domain3,
    s: &Spheres,
    cl: &Clumps,
    dt: f64,
    pair: [u32; 2],
    h: &mut L::History,
) -> Option<PairHit> {
    let (i, j) = (pair[0] as usize, pair[1] as usize);
    // On a Lees-Edwards box the image of j across a y face moves at v_j + dv_j.
    let (d, dv_j) = dom.min_image_moving(s.pos[j] - s.pos[i]);
    let (ri, rj) = (s.radius[i], s.radius[j]);
    let dist2 = d.norm2();
    let reach = ri + rj + law.range(ri, rj);
    if dist2 >= reach * reach || dist2 == 0.0 {
        *h = L::History::default();
        return None;
    }
    let dist = dist2.sqrt();
    let nrm = d * (1.0 / dist);
    let delta = ri + rj - dist;
    // Arms to the contact point, halfway into the overlap (or across the gap): a_i + a_j
    // = distance, so the pair conserves angular momentum.
    let (ai, aj) = (ri - 0.5 * delta, rj - 0.5 * delta);
    let v_j = s.vel[j] + dv_j;
    let v_rel = (s.vel[i] + s.omega[i].cross(nrm * ai)) - (v_j + s.omega[j].cross(nrm * -aj));
    let (fi, fj) = (s.frozen[i], s.frozen[j]);
    // m* of a mobile-frozen pair is the mobile body's mass: the frozen one is immovable.
    let m_eff = match (fi, fj) {
        (false, true) => body_mass(s, cl, i),
        (true, false) => body_mass(s, cl, j),
        _ => {
            let (mi, mj) = (body_mass(s, cl, i), body_mass(s, cl, j));
            mi * mj / (mi + mj)
        }
    };
    let it = Interaction {
        n: nrm,
        delta,
        r_i: ri,
        r_j: rj,
        r_eff: ri * rj / (ri + rj),
        m_eff,
        v_rel,
        dv: s.vel[i] - v_j,
        dw: s.omega[i] - s.omega[j],
        wall: false,
        frozen: fi || fj,
        dt,
    };
    Some(PairHit {
        out: law.force(&it, h),
        nrm,
        ai,
        aj,
        d,
    })
}

/// The mass that moves with sphere `k`: its own, or its clump's.
#[inline]
fn body_mass(s: &Spheres, cl: &Clumps, k: usize) -> f64 {
    match s.owner[k] {
        FREE => s.mass[k],
        o => cl.mass[o as usize],
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
            let arm = b.rotated_by(&q);
            // A member placed across a Lees-Edwards face takes that image's velocity.
            let (p, v) = dom.wrap_moving(c.pos[k] + arm, c.vel[k] + w.cross(arm));
            if positions {
                s.pos[m] = p;
            }
            s.vel[m] = v;
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
            let arm = b.rotated_by(&q);
            f += s.force[m];
            t += arm.cross(s.force[m]) + s.torque[m];
        }
        c.force[k] = f + gravity * c.mass[k];
        c.torque[k] = t;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spheres::domain::Domain3;
    use crate::vector::Vec3;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// The batched kick against the scalar one, to the bit: random spheres (some frozen, some
    /// owned by a clump, some pushed out of the box through every face, the Lees-Edwards y
    /// faces included), counts that leave a tail of fewer than eight and one above the size
    /// from which chunks run on the pool, with and without the drift.
    #[test]
    fn the_batched_kick_gives_the_scalar_kicks_bits() {
        for (n, sheared) in [(37, false), (203, true), (PARALLEL_SPHERES + 13, true)] {
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(n as u64);
            let mut dom = Domain3::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0), [true, true, false]).unwrap();
            if sheared {
                dom = dom.with_lees_edwards(0.7).unwrap();
                dom.advance(0.3);
            }
            let mut sys = SphereSystem::new(dom);
            let mut u = |a: f64| a * (2.0 * rng.random::<f64>() - 1.0);
            for _ in 0..n {
                let p = Vec3::new(0.5 + u(0.49), 1.0 + u(0.99), 1.5 + u(1.4));
                let k = sys
                    .add_sphere(
                        p,
                        Vec3::new(u(3.0), u(3.0), u(3.0)),
                        Vec3::new(u(9.0), u(9.0), u(9.0)),
                        0.01 + u(0.005),
                        2500.0,
                    )
                    .unwrap();
                sys.spheres.force[k] = Vec3::new(u(1e3), u(1e3), u(1e3));
                sys.spheres.torque[k] = Vec3::new(u(1.0), u(1.0), u(1.0));
            }
            for k in (0..n).step_by(7) {
                sys.set_frozen(k, true).unwrap();
            }
            for k in (3..n).step_by(11) {
                sys.spheres.owner[k] = 0;
            }
            for dt in [None, Some(0.2)] {
                let (mut a, mut b) = (sys.spheres.clone(), sys.spheres.clone());
                let mut mobile = Vec::new();
                mobile_mask(&a, &mut mobile);
                kick(&mut a, 0.1, dt.map(|t| (t, &dom)), &mobile);
                kick_scalar(&mut b, 0.1, dt.map(|t| (t, &dom)));
                assert!(
                    a == b,
                    "n = {n}, drift {dt:?}: the batched kick parts from the scalar one"
                );
                if dt.is_some() {
                    let moved = (0..n).filter(|&k| a.pos[k] != sys.spheres.pos[k]).count();
                    let wrapped = (0..n)
                        .filter(|&k| (a.pos[k] - sys.spheres.pos[k]).norm2() > 0.5)
                        .count();
                    assert!(
                        moved > n / 2 && wrapped > 0,
                        "n = {n}: {moved} moved, {wrapped} wrapped"
                    );
                }
            }
        }
    }
}
