//! Opening half kick and drift; world positions, arms and packed lines of the circles.

use super::{BODY_CHUNK, Stepper};
use crate::domain::Domain;
use crate::kick_disks::{DiskKick, Eight};
use crate::lanes::W;
use crate::scratch::{CircleState, Kick, nan_max};
use crate::system::System;
use crate::vector::{Vec2, Vector};
use lbdem_core::simd::{self, Simd, WithSimd};
use rayon::prelude::*;

impl Stepper {
    /// [`Stepper::kick_drift`] and [`Stepper::update_circles`] in one pass when every body is a
    /// single centred circle (circle k = body k). Each chunk is one op of
    /// `lbdem_core::simd::dispatch`: the AVX-512 lanes at v4, the AVX2 lanes at v3, the array lanes
    /// at the baseline.
    pub(super) fn kick_drift_disks(&mut self, sys: &mut System, h: f64, dt: f64) -> f64 {
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
                simd::dispatch(KickChunk {
                    dom: &dom,
                    dk: &dk,
                    h,
                    dt,
                    x,
                    v,
                    a,
                    w,
                    st,
                    kc,
                    f: &force[r.clone()],
                    t: &torque[r.clone()],
                    m: &mass[r.clone()],
                    i: &inertia[r.clone()],
                    rad: &rad[r.clone()],
                    refp: &refp[r],
                })
            })
            .reduce(|| 0.0, nan_max)
    }

    /// Half kick, drift and the world state of every circle, in one pass over chunks of bodies
    /// (each chunk writes its bodies' circles, contiguous in circle order); returns the largest
    /// squared displacement since the last list build (NaN if any position is not finite). The
    /// same arithmetic as a kick-drift pass followed by [`Stepper::update_circles`], hence the
    /// same bits, with one fork-join instead of three: on two threads the DEM step of Su's
    /// shear cell is short enough (about 0.3 ms) that each join's wake-up shows.
    pub(super) fn kick_drift_clumps(&mut self, sys: &mut System, h: f64, dt: f64) -> f64 {
        let dom = sys.domain;
        let b = &mut sys.bodies;
        let nc = b.n_circles();
        self.cpos.resize(nc, Vec2::ZERO);
        self.carm.resize(nc, Vec2::ZERO);
        self.cstate.resize(nc, CircleState::default());
        self.turn.resize(b.len(), (0.0, 1.0));
        let have_ref = self.ref_pos.len() == nc;
        let consts = Circles {
            dom,
            start: &b.circle_start,
            offset: &b.circle_offset,
            radius: &b.circle_r,
            mass: &b.mass,
            refp: if have_ref { &self.ref_pos } else { &[] },
        };
        let (force, torque, inertia) = (&b.force, &b.torque, &b.inertia);
        // Each chunk's circles: split the circle arrays at the chunks' first circles.
        let ch = BODY_CHUNK;
        let mut tasks = Vec::with_capacity(b.len().div_ceil(ch));
        {
            let (mut cpos, mut carm, mut cst) =
                (&mut self.cpos[..], &mut self.carm[..], &mut self.cstate[..]);
            let mut c0 = 0;
            for k0 in (0..b.len()).step_by(ch) {
                let c1 = b.circle_start[(k0 + ch).min(b.len())];
                let (p, pr) = std::mem::take(&mut cpos).split_at_mut(c1 - c0);
                let (a, ar) = std::mem::take(&mut carm).split_at_mut(c1 - c0);
                let (s, sr) = std::mem::take(&mut cst).split_at_mut(c1 - c0);
                tasks.push((k0, p, a, s));
                (cpos, carm, cst) = (pr, ar, sr);
                c0 = c1;
            }
        }
        b.pos
            .par_chunks_mut(ch)
            .zip(b.vel.par_chunks_mut(ch))
            .zip(b.angle.par_chunks_mut(ch).zip(b.omega.par_chunks_mut(ch)))
            .zip(self.kick.par_chunks_mut(ch).zip(self.turn.par_chunks_mut(ch)))
            .zip(tasks)
            .map(|((((x, v), (a, w)), (kc, turn)), (k0, cpos, carm, cst))| {
                let mut worst = 0.0;
                let c0 = consts.start[k0];
                for l in 0..x.len() {
                    let k = k0 + l;
                    let kk = &mut kc[l];
                    kk.refresh(h, consts.mass[k], inertia[k]);
                    v[l] += force[k] * kk.hm;
                    w[l] += torque[k] * kk.hi;
                    x[l] = dom.wrap(x[l] + v[l] * dt);
                    a[l] += w[l] * dt;
                    turn[l] = a[l].sin_cos();
                    for c in consts.start[k]..consts.start[k + 1] {
                        let i = c - c0;
                        let d2 = consts.place(
                            c,
                            k,
                            x[l],
                            v[l],
                            w[l],
                            turn[l],
                            &mut cpos[i],
                            &mut carm[i],
                            &mut cst[i],
                        );
                        worst = nan_max(worst, d2);
                    }
                }
                worst
            })
            .reduce(|| 0.0, nan_max)
    }

    /// World positions, arms and packed pair-loop state of every circle; returns the largest
    /// squared displacement since the last list build (NaN if any position is not finite).
    pub(super) fn update_circles(&mut self, sys: &System) -> f64 {
        let b = &sys.bodies;
        let dom = sys.domain;
        let nc = b.n_circles();
        self.cpos.resize(nc, Vec2::ZERO);
        self.carm.resize(nc, Vec2::ZERO);
        self.cstate.resize(nc, CircleState::default());
        let have_ref = self.ref_pos.len() == nc;
        let consts = Circles {
            dom,
            start: &b.circle_start,
            offset: &b.circle_offset,
            radius: &b.circle_r,
            mass: &b.mass,
            refp: if have_ref { &self.ref_pos } else { &[] },
        };
        self.turn.resize(b.len(), (0.0, 1.0));
        b.angle
            .par_iter()
            .zip(self.turn.par_iter_mut())
            .with_min_len(1024)
            .for_each(|(a, t)| *t = a.sin_cos());
        let turn = &self.turn;
        self.cpos
            .par_iter_mut()
            .zip(self.carm.par_iter_mut())
            .zip(self.cstate.par_iter_mut())
            .enumerate()
            .with_min_len(1024)
            .map(|(c, ((x, a), st))| {
                let k = b.circle_body[c] as usize;
                consts.place(c, k, b.pos[k], b.vel[k], b.omega[k], turn[k], x, a, st)
            })
            .reduce(|| 0.0, nan_max)
    }
}

/// What placing a circle reads besides its body's motion.
struct Circles<'a> {
    dom: Domain,
    start: &'a [usize],
    offset: &'a [Vec2],
    radius: &'a [f64],
    mass: &'a [f64],
    /// Positions at the last list build (empty before the first).
    refp: &'a [Vec2],
}

impl Circles<'_> {
    /// Circle c of body k (at `pos` with velocity `vel`, spin `omega`, and (sin, cos) of its
    /// angle `turn`): its world position, arm and pair-loop state; returns its squared
    /// displacement since the last list build (0 before the first, NaN if not finite).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn place(
        &self,
        c: usize,
        k: usize,
        pos: Vec2,
        vel: Vec2,
        omega: f64,
        turn: (f64, f64),
        x: &mut Vec2,
        a: &mut Vec2,
        st: &mut CircleState,
    ) -> f64 {
        let off = self.offset[c];
        *a = if off.x == 0.0 && off.y == 0.0 {
            Vec2::ZERO
        } else {
            let (s, cs) = turn;
            off.rotated_sc(s, cs)
        };
        *x = pos + *a;
        *st = CircleState {
            pos: *x,
            vel: vel + a.spin(omega),
            omega,
            r: self.radius[c],
            mass: self.mass[k],
            pad: 0.0,
        };
        if self.refp.is_empty() {
            x.norm2() * 0.0
        } else {
            self.dom.min_image(*x - self.refp[c]).norm2()
        }
    }
}

/// One chunk of the all-disk kick and drift.
struct KickChunk<'a> {
    dom: &'a Domain,
    dk: &'a DiskKick,
    h: f64,
    dt: f64,
    x: &'a mut [Vec2],
    v: &'a mut [Vec2],
    a: &'a mut [f64],
    w: &'a mut [f64],
    st: &'a mut [CircleState],
    kc: &'a mut [Kick],
    f: &'a [Vec2],
    t: &'a [f64],
    m: &'a [f64],
    i: &'a [f64],
    rad: &'a [f64],
    refp: &'a [Vec2],
}

impl WithSimd for KickChunk<'_> {
    type Output = f64;
    /// Eight disks at a time, then the scalar loop for the rest (and for a batch with a disk
    /// that must take the far wrap).
    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) -> f64 {
        let KickChunk {
            dom,
            dk,
            h,
            dt,
            x,
            v,
            a,
            w,
            st,
            kc,
            f,
            t,
            m,
            i,
            rad,
            refp,
        } = self;
        let mut worst = 0.0;
        let mut l0 = 0;
        while l0 + W <= x.len() {
            let lanes = l0..l0 + W;
            let mut hm = [0.0; W];
            let mut hi = [0.0; W];
            for (k, kk) in kc[lanes.clone()].iter_mut().enumerate() {
                kk.refresh(h, m[l0 + k], i[l0 + k]);
                hm[k] = kk.hm;
                hi[k] = kk.hi;
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
                refp: refp[lanes].try_into().expect("8"),
                hm,
                hi,
            };
            match dk.eight_in::<S>(e) {
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
    }
}
