//! Pair kernel of the linear spring-dashpot law with tangential history (no rolling spring), the
//! benchmark case: the same arithmetic as [`crate::contact::LinearSpringDashpot::force`] and
//! [`crate::contact::tangential`], operation for operation (so the bits are the same), written
//! without branches so the compiler evaluates eight pairs per instruction (AVX-512 with
//! `target-cpu=native`). Untouched pairs and the Coulomb cap become selects.

use crate::contact::{Damping, History, LinearSpringDashpot};
use crate::domain::Domain;
use crate::lanes::{F8, M8, W};
use crate::scratch::{CircleState, PairOut};

/// The law and box constants of one force evaluation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LinearPair {
    k_n: f64,
    k_t: f64,
    /// Tangential dashpot as a fraction of the normal one.
    t_frac: f64,
    mu: f64,
    clip: bool,
    /// γ (c_n = γ m*) or ζ (c_n = 2 ζ sqrt(k_n m*)).
    damp: f64,
    gamma: bool,
    dt: f64,
    /// Periodic box lengths and half lengths (infinite half length on open axes).
    l: [f64; 2],
    half: [f64; 2],
}

impl LinearPair {
    /// The kernel for `law`, if it applies (friction, no rolling spring).
    pub(crate) fn new(law: &LinearSpringDashpot, dom: &Domain, dt: f64) -> Option<Self> {
        if law.rolling.is_some() || law.mu <= 0.0 {
            return None;
        }
        let (damp, gamma) = match law.damping {
            Damping::Gamma(g) => (g, true),
            Damping::Ratio(z) => (z, false),
        };
        let l = dom.size();
        // `Domain::min_image` shifts when |d| > l/2 on periodic axes: an infinite threshold
        // never shifts.
        let half = |p: bool, v: f64| if p { 0.5 * v } else { f64::INFINITY };
        Some(Self {
            k_n: law.k_n,
            k_t: law.k_t,
            t_frac: law.tangential_damping,
            mu: law.mu,
            clip: law.clip,
            damp,
            gamma,
            dt,
            l: [l.x, l.y],
            half: [half(dom.periodic[0], l.x), half(dom.periodic[1], l.y)],
        })
    }

    /// Evaluate `pairs` (with their `hist`), writing each pair's force on i and torques on i
    /// and j to `out` and 1/0 (touching or not) to `touch`.
    pub(crate) fn run(
        &self,
        cst: &[CircleState],
        pairs: &[[u32; 2]],
        hist: &mut [History],
        out: &mut [PairOut],
        touch: &mut [u8],
    ) {
        if self.gamma {
            self.run_damp::<true>(cst, pairs, hist, out, touch);
        } else {
            self.run_damp::<false>(cst, pairs, hist, out, touch);
        }
    }

    #[inline(always)]
    fn run_damp<const GAMMA: bool>(
        &self,
        cst: &[CircleState],
        pairs: &[[u32; 2]],
        hist: &mut [History],
        out: &mut [PairOut],
        touch: &mut [u8],
    ) {
        let n = pairs.len();
        let out = &mut out[..n];
        let (hist, touch) = (&mut hist[..n], &mut touch[..n]);
        let nc = cst.len();
        let mut q = 0;
        while q < n {
            let m = (n - q).min(W);
            // Lanes past the end repeat the last pair; only the first m are stored.
            let lane = |k: usize| q + k.min(m - 1);
            let ix: [usize; W] = std::array::from_fn(|k| pairs[lane(k)][0] as usize);
            let jx: [usize; W] = std::array::from_fn(|k| pairs[lane(k)][1] as usize);
            assert!(ix.iter().chain(&jx).all(|&c| c < nc), "pair index out of range");
            let ci = Lanes::gather(cst, &ix);
            let cj = Lanes::gather(cst, &jx);
            if m == W {
                let h: &mut [History; W] = (&mut hist[q..q + W]).try_into().expect("eight histories");
                let (hx, hy, keep) = hist_load(h);
                let r = self.lanes::<GAMMA>(&ci, &cj, hx, hy);
                hist_store(h, r.xix, r.xiy, keep, r.touch);
                let o: &mut [PairOut; W] = (&mut out[q..q + W]).try_into().expect("eight records");
                store4(o, [r.fx, r.fy, r.ti, r.tj]);
                for k in 0..W {
                    touch[q + k] = u8::from(r.touch.bit(k));
                }
            } else {
                let hx = F8::from_array(std::array::from_fn(|k| hist[lane(k)].xi_t.x));
                let hy = F8::from_array(std::array::from_fn(|k| hist[lane(k)].xi_t.y));
                let r = self.lanes::<GAMMA>(&ci, &cj, hx, hy);
                let [xix, xiy, fx, fy, ti, tj] = [r.xix, r.xiy, r.fx, r.fy, r.ti, r.tj].map(F8::to_array);
                for k in 0..m {
                    let h = &mut hist[q + k];
                    let t = r.touch.bit(k);
                    h.xi_t.x = xix[k];
                    h.xi_t.y = xiy[k];
                    h.theta_r = if t { h.theta_r } else { 0.0 };
                    h.delta_p = if t { h.delta_p } else { 0.0 };
                    touch[q + k] = u8::from(t);
                    out[q + k] = PairOut {
                        fx: fx[k],
                        fy: fy[k],
                        ti: ti[k],
                        tj: tj[k],
                    };
                }
            }
            q += m;
        }
    }

    /// Eight pairs. Untouched lanes: zeros.
    #[inline(always)]
    fn lanes<const GAMMA: bool>(&self, ci: &Lanes, cj: &Lanes, hx: F8, hy: F8) -> LaneOut {
        let zero = F8::splat(0.0);
        let min_image = |d: F8, k: usize| {
            let shift = d.abs().gt(F8::splat(self.half[k]));
            shift.select(d - F8::splat(self.l[k]).copysign(d), d)
        };
        let dx = min_image(cj.x - ci.x, 0);
        let dy = min_image(cj.y - ci.y, 1);
        let (ri, rj) = (ci.r, cj.r);
        let rs = ri + rj;
        let d2 = dx * dx + dy * dy;
        let touching = d2.lt(rs * rs);
        let dist = d2.sqrt();
        let inv = F8::splat(1.0) / dist;
        let (nx, ny) = (dx * inv, dy * inv);
        let delta = rs - dist;
        let half = F8::splat(0.5);
        let (ai, aj) = (ri - half * delta, rj - half * delta);
        let (wi, wj) = (ci.w, cj.w);
        // v_i + (n a_i).spin(ω_i) − (v_j − (n a_j).spin(ω_j)), spin(w) = (−w y, w x)
        let vix = ci.vx + -wi * (ny * ai);
        let viy = ci.vy + wi * (nx * ai);
        let vjx = cj.vx - -wj * (ny * aj);
        let vjy = cj.vy - wj * (nx * aj);
        let (vx, vy) = (vix - vjx, viy - vjy);
        let (mi, mj) = (ci.m, cj.m);
        let m_eff = mi * mj / (mi + mj);
        let cn = if GAMMA {
            F8::splat(self.damp) * m_eff
        } else {
            F8::splat(2.0 * self.damp) * (F8::splat(self.k_n) * m_eff).sqrt()
        };
        let vn = vx * nx + vy * ny;
        let mut f_n = F8::splat(self.k_n) * delta + cn * vn;
        if self.clip {
            f_n = f_n.lt(zero).select(zero, f_n);
        }
        // Tangential spring (contact::tangential).
        let (kt, ct) = (F8::splat(self.k_t), cn * F8::splat(self.t_frac));
        let dt = F8::splat(self.dt);
        let (vtx, vty) = (vx - nx * vn, vy - ny * vn);
        let xd = hx * nx + hy * ny;
        let xix = (hx - nx * xd) + vtx * dt;
        let xiy = (hy - ny * xd) + vty * dt;
        let ftx = -(xix * kt) - vtx * ct;
        let fty = -(xiy * kt) - vty * ct;
        let lim = F8::splat(self.mu) * f_n.max0();
        let ftm2 = ftx * ftx + fty * fty;
        let slide = ftm2.gt(lim * lim);
        let ftm = ftm2.sqrt();
        let s = lim / ftm;
        let pos = ftm.gt(zero);
        let (sx, sy) = (pos.select(ftx * s, zero), pos.select(fty * s, zero));
        let ikt = F8::splat(1.0 / self.k_t);
        let kpos = kt.gt(zero);
        let ex = kpos.select(-(sx + vtx * ct) * ikt, zero);
        let ey = kpos.select(-(sy + vty * ct) * ikt, zero);
        let (ftx, fty) = (slide.select(sx, ftx), slide.select(sy, fty));
        let (xix, xiy) = (slide.select(ex, xix), slide.select(ey, xiy));
        let fx = ftx - nx * f_n;
        let fy = fty - ny * f_n;
        let nxf = nx * fy - ny * fx;
        let ti = ai * nxf + zero;
        let tj = aj * nxf - zero;
        LaneOut {
            touch: touching,
            xix: touching.select(xix, zero),
            xiy: touching.select(xiy, zero),
            fx: touching.select(fx, zero),
            fy: touching.select(fy, zero),
            ti: touching.select(ti, zero),
            tj: touching.select(tj, zero),
        }
    }
}

struct LaneOut {
    touch: M8,
    xix: F8,
    xiy: F8,
    fx: F8,
    fy: F8,
    ti: F8,
    tj: F8,
}

/// Circle state of eight lanes.
struct Lanes {
    x: F8,
    y: F8,
    vx: F8,
    vy: F8,
    w: F8,
    r: F8,
    m: F8,
}

impl Lanes {
    /// Eight circle states (one 64-byte line each) transposed into lanes. Every index must be
    /// in range (checked by the caller).
    #[inline(always)]
    fn gather(cst: &[CircleState], idx: &[usize; W]) -> Self {
        #[cfg(target_feature = "avx512f")]
        {
            let c = x86::transpose8(cst, idx);
            Self {
                x: c[0],
                y: c[1],
                vx: c[2],
                vy: c[3],
                w: c[4],
                r: c[5],
                m: c[6],
            }
        }
        #[cfg(not(target_feature = "avx512f"))]
        {
            let rows: [[f64; W]; W] = std::array::from_fn(|k| cst[idx[k]].line());
            let col = |f: usize| F8::from_array(std::array::from_fn(|k| rows[k][f]));
            Self {
                x: col(0),
                y: col(1),
                vx: col(2),
                vy: col(3),
                w: col(4),
                r: col(5),
                m: col(6),
            }
        }
    }
}

/// Tangential elongations of eight histories, and a mask of their other two fields.
#[inline(always)]
fn hist_load(h: &[History; W]) -> (F8, F8, [F8; 2]) {
    #[cfg(target_feature = "avx512f")]
    {
        x86::hist_load(h)
    }
    #[cfg(not(target_feature = "avx512f"))]
    {
        (
            F8::from_array(std::array::from_fn(|k| h[k].xi_t.x)),
            F8::from_array(std::array::from_fn(|k| h[k].xi_t.y)),
            [
                F8::from_array(std::array::from_fn(|k| h[k].theta_r)),
                F8::from_array(std::array::from_fn(|k| h[k].delta_p)),
            ],
        )
    }
}

/// Store eight histories: new elongations; the other fields kept where touching, else zero.
#[inline(always)]
fn hist_store(h: &mut [History; W], xix: F8, xiy: F8, other: [F8; 2], touch: M8) {
    let zero = F8::splat(0.0);
    let (t, p) = (touch.select(other[0], zero), touch.select(other[1], zero));
    #[cfg(target_feature = "avx512f")]
    {
        // SAFETY: History is repr(C): four f64, 32 bytes.
        x86::store4(
            unsafe { &mut *h.as_mut_ptr().cast::<[[f64; 4]; W]>() },
            [xix, xiy, t, p],
        );
    }
    #[cfg(not(target_feature = "avx512f"))]
    {
        let [xix, xiy, t, p] = [xix, xiy, t, p].map(F8::to_array);
        for k in 0..W {
            h[k] = History {
                xi_t: crate::Vec2::new(xix[k], xiy[k]),
                theta_r: t[k],
                delta_p: p[k],
            };
        }
    }
}

/// Store eight pair results (lanes to records).
#[inline(always)]
fn store4(o: &mut [PairOut; W], v: [F8; 4]) {
    #[cfg(target_feature = "avx512f")]
    {
        // SAFETY: PairOut is repr(C): four f64, 32 bytes.
        x86::store4(unsafe { &mut *o.as_mut_ptr().cast::<[[f64; 4]; W]>() }, v);
    }
    #[cfg(not(target_feature = "avx512f"))]
    {
        let v = v.map(F8::to_array);
        for k in 0..W {
            o[k] = PairOut {
                fx: v[0][k],
                fy: v[1][k],
                ti: v[2][k],
                tj: v[3][k],
            };
        }
    }
}

/// AVX-512 transposes: whole 64-byte lines in, lanes out (shuffles instead of 8 scalar loads
/// per field). Pure data movement: no arithmetic, so the bits are those of the portable path.
#[cfg(target_feature = "avx512f")]
mod x86 {
    use super::{F8, W};
    use crate::contact::History;
    use crate::scratch::CircleState;
    use std::arch::x86_64::*;

    #[inline(always)]
    fn f8(v: __m512d) -> F8 {
        F8(v)
    }
    #[inline(always)]
    fn m512(v: F8) -> __m512d {
        v.0
    }

    /// Columns 0..7 of the eight lines `cst[idx[k]]`.
    #[inline(always)]
    pub(super) fn transpose8(cst: &[CircleState], idx: &[usize; W]) -> [F8; 8] {
        let p = cst.as_ptr();
        // SAFETY: avx512f is enabled for the whole build (cfg above); every idx[k] < cst.len()
        // (asserted by the caller); CircleState is repr(C), 64 bytes, 64-byte aligned, eight f64.
        unsafe {
            let r: [__m512d; 8] = std::array::from_fn(|k| _mm512_load_pd(p.add(idx[k]).cast::<f64>()));
            crate::lanes::transpose_registers(r.map(f8))
        }
    }

    /// History k = [x y θ δp]: two histories per 512-bit line.
    #[inline(always)]
    pub(super) fn hist_load(h: &[History; W]) -> (F8, F8, [F8; 2]) {
        let p = h.as_ptr().cast::<f64>();
        // SAFETY: avx512f enabled for the build; eight repr(C) Histories = 32 f64, read as four
        // unaligned lines.
        unsafe {
            let l: [__m512d; 4] = std::array::from_fn(|k| _mm512_loadu_pd(p.add(8 * k)));
            let (xy, tp) = (
                _mm512_setr_epi64(0, 4, 8, 12, 1, 5, 9, 13),
                _mm512_setr_epi64(2, 6, 10, 14, 3, 7, 11, 15),
            );
            // a: x0..x3 y0..y3, b: x4..x7 y4..y7; c, d: θ, δp likewise.
            let a = _mm512_permutex2var_pd(l[0], xy, l[1]);
            let b = _mm512_permutex2var_pd(l[2], xy, l[3]);
            let c = _mm512_permutex2var_pd(l[0], tp, l[1]);
            let d = _mm512_permutex2var_pd(l[2], tp, l[3]);
            (
                f8(_mm512_shuffle_f64x2::<0x44>(a, b)),
                f8(_mm512_shuffle_f64x2::<0xEE>(a, b)),
                [
                    f8(_mm512_shuffle_f64x2::<0x44>(c, d)),
                    f8(_mm512_shuffle_f64x2::<0xEE>(c, d)),
                ],
            )
        }
    }

    /// Eight records of four f64 from four lane vectors (the inverse of [`hist_load`]).
    #[inline(always)]
    pub(super) fn store4(h: &mut [[f64; 4]; W], v: [F8; 4]) {
        let [x, y, t, dp] = v.map(m512);
        // SAFETY: avx512f enabled for the build; writes the 32 f64 of `h`.
        unsafe {
            let idx = [
                _mm512_setr_epi64(0, 4, 8, 12, 1, 5, 9, 13),
                _mm512_setr_epi64(2, 6, 10, 14, 3, 7, 11, 15),
            ];
            let (a, b) = (
                _mm512_shuffle_f64x2::<0x44>(x, y),
                _mm512_shuffle_f64x2::<0xEE>(x, y),
            );
            let (c, d) = (
                _mm512_shuffle_f64x2::<0x44>(t, dp),
                _mm512_shuffle_f64x2::<0xEE>(t, dp),
            );
            let l = [
                _mm512_permutex2var_pd(a, idx[0], c),
                _mm512_permutex2var_pd(a, idx[1], c),
                _mm512_permutex2var_pd(b, idx[0], d),
                _mm512_permutex2var_pd(b, idx[1], d),
            ];
            let p = h.as_mut_ptr().cast::<f64>();
            for (k, v) in l.into_iter().enumerate() {
                _mm512_storeu_pd(p.add(8 * k), v);
            }
        }
    }
}
