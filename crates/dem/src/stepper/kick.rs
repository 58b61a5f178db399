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
    /// `lbdem_core::simd::dispatch`: the AVX-512 lanes at v4, the array lanes at the other levels.
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

    /// Half kick then drift, fused in one pass over the bodies.
    pub(super) fn kick_drift(&mut self, sys: &mut System, h: f64, dt: f64) {
        let dom = sys.domain;
        let b = &mut sys.bodies;
        let (force, mass, torque, inertia) = (&b.force, &b.mass, &b.torque, &b.inertia);
        b.pos
            .par_iter_mut()
            .zip(b.vel.par_iter_mut())
            .zip(b.angle.par_iter_mut().zip(b.omega.par_iter_mut()))
            .zip(self.kick.par_iter_mut())
            .enumerate()
            .with_min_len(1024)
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
    pub(super) fn update_circles(&mut self, sys: &System) -> f64 {
        let b = &sys.bodies;
        let dom = sys.domain;
        let nc = b.n_circles();
        self.cpos.resize(nc, Vec2::ZERO);
        self.carm.resize(nc, Vec2::ZERO);
        self.cstate.resize(nc, CircleState::default());
        let have_ref = self.ref_pos.len() == nc;
        let refp = &self.ref_pos;
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
                let off = b.circle_offset[c];
                *a = if off.x == 0.0 && off.y == 0.0 {
                    Vec2::ZERO
                } else {
                    let (s, cs) = turn[k];
                    off.rotated_sc(s, cs)
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
