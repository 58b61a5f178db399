//! The pair pass: the pair law over every pair of the Verlet list (in parallel over fixed chunks
//! of pairs), one record per pair; then the per-body gather of those records in canonical order.
//! The generic loop serves any [`ContactLaw`] (monomorphised, the law inlined); the linear law
//! takes the batched kernel of `pair_linear.rs` (same bits).

use super::finish::{Bodies5, Finish};
use super::{PAIR_CHUNK, Stepper};
use crate::contact::{ContactInput, ContactLaw, History};
use crate::domain::Domain;
use crate::history::stride_of;
use crate::pair_linear::LinearPair;
use crate::scratch::{CircleState, PairOut};
use crate::system::System;
use crate::vector::{Vec2, Vector};
use rayon::prelude::*;

/// The batched linear kernel for `law`, if it applies (see [`ContactLaw::linear`]).
#[inline]
pub(super) fn linear_kernel<L: ContactLaw>(law: &L, dom: &Domain, dt: f64) -> Option<LinearPair> {
    if stride_of::<L::History>() != stride_of::<History>() {
        return None;
    }
    law.linear().and_then(|l| LinearPair::new(l, dom, dt))
}

impl Stepper {
    /// Every pair, in parallel over fixed chunks of pairs: force on i, torques on i and j.
    pub(super) fn pair_pass<L: ContactLaw>(&mut self, dt: f64, law: &L, sys: &mut System) {
        let dom = sys.domain;
        let pairs = &sys.contacts.pairs;
        let n = pairs.len();
        match linear_kernel(law, &dom, dt) {
            Some(k) => {
                let hist = sys.contacts.hist.conform::<History>(n);
                self.chunked(pairs, hist, |cst, pr, h, o, t| k.run(cst, pr, h, o, t));
            }
            None => {
                let hist = sys.contacts.hist.conform::<L::History>(n);
                self.chunked(pairs, hist, |cst, pr, h, o, t| {
                    generic_pairs(law, &dom, dt, cst, pr, h, o, t)
                });
            }
        }
    }

    fn chunked<H: Send>(
        &mut self,
        pairs: &[[u32; 2]],
        hist: &mut [H],
        kernel: impl Fn(&[CircleState], &[[u32; 2]], &mut [H], &mut [PairOut], &mut [u8]) + Sync,
    ) {
        let n = pairs.len();
        let cst = &self.cstate;
        let ch = PAIR_CHUNK;
        pairs
            .par_chunks(ch)
            .zip(hist.par_chunks_mut(ch))
            .zip(self.touch[..n].par_chunks_mut(ch))
            .zip(self.out[..n].par_chunks_mut(ch))
            .for_each(|(((pairs, hist), touch), out)| kernel(cst, pairs, hist, out, touch));
    }

    /// Per body: each circle's own records (as i, ascending j) plus its reactions (as j,
    /// ascending i), over its circles in order. With `fin` (nothing else adds to the contact
    /// forces) the finish pass follows in the same pass.
    pub(super) fn gather(&mut self, sys: &mut System, fin: Option<&Finish>) {
        let (out, ps, js, jl) = (&self.out, &self.pair_start, &self.j_start, &self.j_list);
        let circle_sum = |c: usize| -> (Vec2, f64) { circle_sum(out, 0, ps, js, jl, c) };
        let (disks, kick, carm) = (self.all_disks, &self.kick, &self.carm);
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
        } = Bodies5::of(&mut sys.bodies);
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
                if let Some(fin) = fin {
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
    }
}

/// Sum of circle c's records: its pairs as i in ascending j, then as j in ascending i (the
/// reaction −f). `out` holds the records from pair `base` on.
#[inline(always)]
pub(super) fn circle_sum(
    out: &[PairOut],
    base: usize,
    ps: &[u32],
    js: &[u32],
    jl: &[u32],
    c: usize,
) -> (Vec2, f64) {
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
    (fc, tc)
}

/// The pair pass for any law: force on i, torques on i and j, and whether the law acted (the
/// pair overlaps, or its gap is below the law's range). Pairs out of range get a fresh history.
#[allow(clippy::too_many_arguments)]
pub(super) fn generic_pairs<L: ContactLaw>(
    law: &L,
    dom: &Domain,
    dt: f64,
    cst: &[CircleState],
    pairs: &[[u32; 2]],
    hist: &mut [L::History],
    out: &mut [PairOut],
    touch: &mut [u8],
) {
    for (((pr, h), t), o) in pairs.iter().zip(hist).zip(touch).zip(out) {
        let (ci, cj) = (&cst[pr[0] as usize], &cst[pr[1] as usize]);
        let d = dom.min_image(cj.pos - ci.pos);
        let (ri, rj) = (ci.r, cj.r);
        let rs = ri + rj;
        let rc = rs + law.range(ri, rj);
        let d2 = d.norm2();
        if d2 >= rc * rc {
            if *h != L::History::default() {
                *h = L::History::default();
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
