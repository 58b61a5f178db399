//! The fused all-disk path: disks without walls, bonds, membrane or user forces get the pair pass
//! and the finish pass per chunk of circles, so each chunk's pair records are summed while still
//! in cache. Circle c needs the reactions of all its partners i < c; those in the chunk are done
//! before it, so every circle without a partner in an earlier chunk is finished in the same task
//! (same summation order as the separate passes, hence the same bits); the rest (`deferred`)
//! follow in a second pass.

use super::finish::{Bodies5, Finish};
use super::pairs::{Generic, PairKernel, circle_sum};
use super::{CIRCLE_CHUNK, Stepper};
use crate::contact::{ContactLaw, History};
use crate::scratch::{CircleState, Kick, PairOut};
use crate::system::System;
use crate::vector::Vec2;
use lbdem_core::simd::{self, Simd, WithSimd};
use rayon::prelude::*;

impl Stepper {
    pub(super) fn forces_disks<L: ContactLaw>(&mut self, dt: f64, law: &L, sys: &mut System, fin: &Finish) {
        let dom = sys.domain;
        let n = sys.contacts.pairs.len();
        match crate::pair_batched::BatchedPair::of(law, &dom, dt) {
            Some(k) => {
                let hist = sys.contacts.hist.conform::<History>(n);
                fused(self, fin, &sys.contacts.pairs, hist, &mut sys.bodies, &k);
            }
            None => {
                let hist = sys.contacts.hist.conform::<L::History>(n);
                let k = Generic { law, dom, dt };
                fused(self, fin, &sys.contacts.pairs, hist, &mut sys.bodies, &k);
            }
        }
    }
}

/// What the finish of a circle reads: the pair tables and the bodies' constants.
#[derive(Clone, Copy)]
struct Tables<'a> {
    fin: &'a Finish,
    ps: &'a [u32],
    js: &'a [u32],
    jl: &'a [u32],
    kick: &'a [Kick],
    mass: &'a [f64],
    inertia: &'a [f64],
    ext_force: &'a [Vec2],
    ext_torque: &'a [f64],
}

impl Tables<'_> {
    /// Sum of circle c and its finish; `out` holds the pairs from `base` on.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn finish(
        &self,
        c: usize,
        out: &[PairOut],
        base: usize,
        f: &mut Vec2,
        t: &mut f64,
        v: &mut Vec2,
        w: &mut f64,
    ) {
        (*f, *t) = circle_sum(out, base, self.ps, self.js, self.jl, c);
        self.fin.apply(
            f,
            t,
            v,
            w,
            self.mass[c],
            self.inertia[c],
            &self.kick[c],
            self.ext_force[c],
            self.ext_torque[c],
        );
    }
}

/// One chunk of circles: its pairs, then the finish of every circle without a partner in an
/// earlier chunk; one op of `lbdem_core::simd::dispatch`.
struct Chunk<'a, K: PairKernel> {
    kernel: &'a K,
    tab: Tables<'a>,
    cst: &'a [CircleState],
    pairs: &'a [[u32; 2]],
    skip: &'a [u32],
    c0: usize,
    hist: &'a mut [K::H],
    out: &'a mut [PairOut],
    touch: &'a mut [u8],
    f: &'a mut [Vec2],
    t: &'a mut [f64],
    v: &'a mut [Vec2],
    w: &'a mut [f64],
}

impl<K: PairKernel> WithSimd for Chunk<'_, K> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        let Chunk {
            kernel,
            tab,
            cst,
            pairs,
            skip,
            c0,
            hist,
            out,
            touch,
            f,
            t,
            v,
            w,
        } = self;
        let base = tab.ps[c0] as usize;
        kernel.run::<S>(cst, pairs, hist, out, touch);
        let mut skip = skip.iter().peekable();
        for l in 0..f.len() {
            let c = c0 + l;
            if skip.peek().is_some_and(|&&d| d as usize == c) {
                skip.next();
                continue;
            }
            tab.finish(c, out, base, &mut f[l], &mut t[l], &mut v[l], &mut w[l]);
        }
    }
}

/// The deferred circles of one chunk, once every pair is done.
struct Deferred<'a> {
    tab: Tables<'a>,
    out: &'a [PairOut],
    list: &'a [u32],
    c0: usize,
    f: &'a mut [Vec2],
    t: &'a mut [f64],
    v: &'a mut [Vec2],
    w: &'a mut [f64],
}

impl WithSimd for Deferred<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        let Deferred {
            tab,
            out,
            list,
            c0,
            f,
            t,
            v,
            w,
        } = self;
        for &c in list {
            let l = c as usize - c0;
            tab.finish(c as usize, out, 0, &mut f[l], &mut t[l], &mut v[l], &mut w[l]);
        }
    }
}

fn fused<K: PairKernel>(
    st: &mut Stepper,
    fin: &Finish,
    pairs: &[[u32; 2]],
    hist: &mut [K::H],
    bodies: &mut crate::body::Bodies,
    kernel: &K,
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
    let tab = Tables {
        fin,
        ps,
        js,
        jl,
        kick,
        mass,
        inertia,
        ext_force,
        ext_torque,
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
                simd::dispatch(Chunk {
                    kernel,
                    tab,
                    cst,
                    pairs: &pairs[base..base + out.len()],
                    skip: &deferred[dstart[k] as usize..dstart[k + 1] as usize],
                    c0,
                    hist,
                    out,
                    touch,
                    f,
                    t,
                    v,
                    w,
                })
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
            simd::dispatch(Deferred {
                tab,
                out,
                list: &deferred[dstart[k] as usize..dstart[k + 1] as usize],
                c0: k * CIRCLE_CHUNK,
                f,
                t,
                v,
                w,
            })
        });
}
