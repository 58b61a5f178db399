//! The pair pass: the pair law over every pair of the Verlet list (in parallel over fixed chunks
//! of pairs), one record per pair; then the per-body gather of those records in canonical order.
//! The generic loop serves any [`ContactLaw`] (monomorphised, the law inlined); the laws with a
//! [`ContactLaw::batched`] form (linear, elastic-plastic) take the batched kernel of
//! `pair_batched.rs` (same bits).

use super::finish::{Bodies5, Finish};
use super::{PAIR_CHUNK, Stepper};
use crate::contact::{ContactInput, ContactLaw, History};
use crate::domain::Domain;
use crate::pair_batched::BatchedPair;
use crate::scratch::{CircleState, Kick, PairOut};
use crate::system::System;
use crate::vector::{Vec2, Vector};
use lbdem_core::simd::{self, Simd, WithSimd};
use rayon::prelude::*;

/// A pair kernel: every pair of a slice, compiled into an op of `lbdem_core::simd::dispatch`
/// at level `S` (so it must inline: `#[inline(always)]`).
pub(super) trait PairKernel: Sync {
    type H: Send;
    fn run<S: Simd>(
        &self,
        cst: &[CircleState],
        pairs: &[[u32; 2]],
        hist: &mut [Self::H],
        out: &mut [PairOut],
        touch: &mut [u8],
    );
}

impl PairKernel for BatchedPair {
    type H = History;
    #[inline(always)]
    fn run<S: Simd>(
        &self,
        cst: &[CircleState],
        pairs: &[[u32; 2]],
        hist: &mut [History],
        out: &mut [PairOut],
        touch: &mut [u8],
    ) {
        self.run_in::<S>(cst, pairs, hist, out, touch)
    }
}

/// Any law through [`generic_pairs`].
pub(super) struct Generic<'a, L> {
    pub(super) law: &'a L,
    pub(super) dom: Domain,
    pub(super) dt: f64,
}

impl<L: ContactLaw> PairKernel for Generic<'_, L> {
    type H = L::History;
    #[inline(always)]
    fn run<S: Simd>(
        &self,
        cst: &[CircleState],
        pairs: &[[u32; 2]],
        hist: &mut [L::History],
        out: &mut [PairOut],
        touch: &mut [u8],
    ) {
        generic_pairs(self.law, &self.dom, self.dt, cst, pairs, hist, out, touch)
    }
}

/// One chunk of the pair pass.
struct PairChunk<'a, K: PairKernel> {
    kernel: &'a K,
    cst: &'a [CircleState],
    pairs: &'a [[u32; 2]],
    hist: &'a mut [K::H],
    out: &'a mut [PairOut],
    touch: &'a mut [u8],
}

impl<K: PairKernel> WithSimd for PairChunk<'_, K> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        self.kernel
            .run::<S>(self.cst, self.pairs, self.hist, self.out, self.touch)
    }
}

impl Stepper {
    /// Every pair, in parallel over fixed chunks of pairs: force on i, torques on i and j.
    pub(super) fn pair_pass<L: ContactLaw>(&mut self, dt: f64, law: &L, sys: &mut System) {
        let dom = sys.domain;
        let pairs = &sys.contacts.pairs;
        let n = pairs.len();
        match BatchedPair::of(law, &dom, dt) {
            Some(k) => {
                let hist = sys.contacts.hist.conform::<History>(n);
                self.chunked(pairs, hist, &k);
            }
            None => {
                let hist = sys.contacts.hist.conform::<L::History>(n);
                self.chunked(pairs, hist, &Generic { law, dom, dt });
            }
        }
    }

    /// Each chunk of pairs is one op of `lbdem_core::simd::dispatch`.
    fn chunked<K: PairKernel>(&mut self, pairs: &[[u32; 2]], hist: &mut [K::H], kernel: &K) {
        let n = pairs.len();
        let cst = &self.cstate;
        let ch = PAIR_CHUNK;
        pairs
            .par_chunks(ch)
            .zip(hist.par_chunks_mut(ch))
            .zip(self.touch[..n].par_chunks_mut(ch))
            .zip(self.out[..n].par_chunks_mut(ch))
            .for_each(|(((pairs, hist), touch), out)| {
                simd::dispatch(PairChunk {
                    kernel,
                    cst,
                    pairs,
                    hist,
                    out,
                    touch,
                })
            });
    }

    /// Per body: each circle's own records (as i, ascending j) plus its reactions (as j,
    /// ascending i), over its circles in order. With `fin` (nothing else adds to the contact
    /// forces) the finish pass follows in the same pass. Each chunk of bodies is one op of
    /// `lbdem_core::simd::dispatch`.
    pub(super) fn gather(&mut self, sys: &mut System, fin: Option<&Finish>) {
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
        let g = Gather {
            out: &self.out,
            ps: &self.pair_start,
            js: &self.j_start,
            jl: &self.j_list,
            disks: self.all_disks,
            kick: &self.kick,
            carm: &self.carm,
            fin,
            mass,
            inertia,
            ext_force,
            ext_torque,
            cstart,
        };
        let ch = super::BODY_CHUNK;
        force
            .par_chunks_mut(ch)
            .zip(torque.par_chunks_mut(ch))
            .zip(vel.par_chunks_mut(ch).zip(omega.par_chunks_mut(ch)))
            .enumerate()
            .for_each(|(c, ((f, t), (v, w)))| {
                simd::dispatch(GatherChunk {
                    g: &g,
                    k0: c * ch,
                    f,
                    t,
                    v,
                    w,
                })
            });
    }
}

/// What the gather reads.
struct Gather<'a> {
    out: &'a [PairOut],
    ps: &'a [u32],
    js: &'a [u32],
    jl: &'a [u32],
    disks: bool,
    kick: &'a [Kick],
    carm: &'a [Vec2],
    fin: Option<&'a Finish>,
    mass: &'a [f64],
    inertia: &'a [f64],
    ext_force: &'a [Vec2],
    ext_torque: &'a [f64],
    cstart: &'a [usize],
}

/// The gather of bodies `k0..k0 + f.len()`.
struct GatherChunk<'a, 'b> {
    g: &'b Gather<'a>,
    k0: usize,
    f: &'b mut [Vec2],
    t: &'b mut [f64],
    v: &'b mut [Vec2],
    w: &'b mut [f64],
}

impl WithSimd for GatherChunk<'_, '_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        let g = self.g;
        for (l, (((f, t), v), w)) in self
            .f
            .iter_mut()
            .zip(self.t.iter_mut())
            .zip(self.v.iter_mut())
            .zip(self.w.iter_mut())
            .enumerate()
        {
            let k = self.k0 + l;
            if g.disks {
                (*f, *t) = circle_sum(g.out, 0, g.ps, g.js, g.jl, k);
            } else {
                let (mut fb, mut tb) = (Vec2::ZERO, 0.0);
                let c0 = g.cstart[k];
                for (c, arm) in (c0..).zip(&g.carm[c0..g.cstart[k + 1]]) {
                    let (fc, tc) = circle_sum(g.out, 0, g.ps, g.js, g.jl, c);
                    fb += fc;
                    tb += tc + arm.cross(fc);
                }
                *f = fb;
                *t = tb;
            }
            if let Some(fin) = g.fin {
                fin.apply(
                    f,
                    t,
                    v,
                    w,
                    g.mass[k],
                    g.inertia[k],
                    &g.kick[k],
                    g.ext_force[k],
                    g.ext_torque[k],
                );
            }
        }
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
#[inline(always)]
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
