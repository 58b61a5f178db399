//! The fused all-disk path: disks without walls, bonds, membrane or user forces get the pair pass
//! and the finish pass per chunk of circles, so each chunk's pair records are summed while still
//! in cache. Circle c needs the reactions of all its partners i < c; those in the chunk are done
//! before it, so every circle without a partner in an earlier chunk is finished in the same task
//! (same summation order as the separate passes, hence the same bits); the rest (`deferred`)
//! follow in a second pass.

use super::finish::{Bodies5, Finish};
use super::pairs::{circle_sum, generic_pairs, linear_kernel};
use super::{CIRCLE_CHUNK, Stepper};
use crate::contact::{ContactLaw, History};
use crate::scratch::{CircleState, PairOut};
use crate::system::System;
use crate::vector::Vec2;
use rayon::prelude::*;

impl Stepper {
    pub(super) fn forces_disks<L: ContactLaw>(&mut self, dt: f64, law: &L, sys: &mut System, fin: &Finish) {
        let dom = sys.domain;
        let n = sys.contacts.pairs.len();
        match linear_kernel(law, &dom, dt) {
            Some(k) => {
                let hist = sys.contacts.hist.conform::<History>(n);
                fused(
                    self,
                    fin,
                    &sys.contacts.pairs,
                    hist,
                    &mut sys.bodies,
                    |cst, pr, h, o, t| k.run(cst, pr, h, o, t),
                );
            }
            None => {
                let hist = sys.contacts.hist.conform::<L::History>(n);
                fused(
                    self,
                    fin,
                    &sys.contacts.pairs,
                    hist,
                    &mut sys.bodies,
                    |cst, pr, h, o, t| generic_pairs(law, &dom, dt, cst, pr, h, o, t),
                );
            }
        }
    }
}

fn fused<H: Send>(
    st: &mut Stepper,
    fin: &Finish,
    pairs: &[[u32; 2]],
    hist: &mut [H],
    bodies: &mut crate::body::Bodies,
    kernel: impl Fn(&[CircleState], &[[u32; 2]], &mut [H], &mut [PairOut], &mut [u8]) + Sync,
) {
    let (cst, ps, js, jl, kick) = (&st.cstate, &st.pair_start, &st.j_start, &st.j_list, &st.kick);
    let (deferred, dstart) = (&st.deferred, &st.deferred_start);
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
    let nc = force.len();
    // Sum of circle c and its finish; `out` holds the pairs from `base` on.
    let finish =
        |c: usize, out: &[PairOut], base: usize, f: &mut Vec2, t: &mut f64, v: &mut Vec2, w: &mut f64| {
            (*f, *t) = circle_sum(out, base, ps, js, jl, c);
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
        let (mut hist, mut out, mut touch) = (hist, &mut st.out[..], &mut st.touch[..]);
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
                kernel(cst, pr, hist, out, touch);
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
    let out = &st.out[..];
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
