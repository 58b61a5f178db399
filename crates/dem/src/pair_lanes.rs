//! The lane code of the linear pair kernel (`crate::pair_linear`), written once against a lane
//! type `super::lanes` and compiled for each (`crate::on_avx512`, `crate::on_arrays`).

use super::lanes::{self, F8, M8};
use crate::contact::History;
use crate::lanes::W;
use crate::pair_linear::LinearPair;
use crate::scratch::{CircleState, PairOut};

/// Every pair of `pairs`, the damping form chosen once per call.
#[inline(always)]
pub(crate) fn run(
    kp: &LinearPair,
    cst: &[CircleState],
    pairs: &[[u32; 2]],
    hist: &mut [History],
    out: &mut [PairOut],
    touch: &mut [u8],
) {
    if kp.gamma {
        run_damp::<true>(kp, cst, pairs, hist, out, touch);
    } else {
        run_damp::<false>(kp, cst, pairs, hist, out, touch);
    }
}

#[inline(always)]
fn run_damp<const GAMMA: bool>(
    kp: &LinearPair,
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
            let (hx, hy, keep) = lanes::hist_load(h);
            let r = eight::<GAMMA>(kp, &ci, &cj, hx, hy);
            hist_store(h, r.xix, r.xiy, keep, r.touch);
            let o: &mut [PairOut; W] = (&mut out[q..q + W]).try_into().expect("eight records");
            store4(o, [r.fx, r.fy, r.ti, r.tj]);
            for k in 0..W {
                touch[q + k] = u8::from(r.touch.bit(k));
            }
        } else {
            let hx = F8::from_array(std::array::from_fn(|k| hist[lane(k)].xi_t.x));
            let hy = F8::from_array(std::array::from_fn(|k| hist[lane(k)].xi_t.y));
            let r = eight::<GAMMA>(kp, &ci, &cj, hx, hy);
            let (xix, xiy, fx, fy) = (
                r.xix.to_array(),
                r.xiy.to_array(),
                r.fx.to_array(),
                r.fy.to_array(),
            );
            let (ti, tj) = (r.ti.to_array(), r.tj.to_array());
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
fn eight<const GAMMA: bool>(kp: &LinearPair, ci: &Lanes, cj: &Lanes, hx: F8, hy: F8) -> LaneOut {
    let zero = F8::splat(0.0);
    let dx = min_image(cj.x - ci.x, kp.half[0], kp.l[0]);
    let dy = min_image(cj.y - ci.y, kp.half[1], kp.l[1]);
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
        F8::splat(kp.damp) * m_eff
    } else {
        F8::splat(2.0 * kp.damp) * (F8::splat(kp.k_n) * m_eff).sqrt()
    };
    let vn = vx * nx + vy * ny;
    let mut f_n = F8::splat(kp.k_n) * delta + cn * vn;
    if kp.clip {
        f_n = f_n.lt(zero).select(zero, f_n);
    }
    // Tangential spring (contact::tangential).
    let (kt, ct) = (F8::splat(kp.k_t), cn * F8::splat(kp.t_frac));
    let dt = F8::splat(kp.dt);
    let (vtx, vty) = (vx - nx * vn, vy - ny * vn);
    let xd = hx * nx + hy * ny;
    let xix = (hx - nx * xd) + vtx * dt;
    let xiy = (hy - ny * xd) + vty * dt;
    let ftx = -(xix * kt) - vtx * ct;
    let fty = -(xiy * kt) - vty * ct;
    let lim = F8::splat(kp.mu) * f_n.max0();
    let ftm2 = ftx * ftx + fty * fty;
    let slide = ftm2.gt(lim * lim);
    let ftm = ftm2.sqrt();
    let s = lim / ftm;
    let pos = ftm.gt(zero);
    let (sx, sy) = (pos.select(ftx * s, zero), pos.select(fty * s, zero));
    let ikt = F8::splat(1.0 / kp.k_t);
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

/// `Domain::min_image` along one axis: d shifted by one box length `l` when |d| > `half`.
/// A function, not a closure: a closure would be compiled without the features of the
/// `#[target_feature]` entry, and the AVX-512 intrinsics would stay calls.
#[inline(always)]
fn min_image(d: F8, half: f64, l: f64) -> F8 {
    let shift = d.abs().gt(F8::splat(half));
    shift.select(d - F8::splat(l).copysign(d), d)
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
        let c = lanes::transpose8(cst, idx);
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
}

/// Store eight histories: new elongations; the other fields kept where touching, else zero.
#[inline(always)]
fn hist_store(h: &mut [History; W], xix: F8, xiy: F8, other: [F8; 2], touch: M8) {
    let zero = F8::splat(0.0);
    let (t, p) = (touch.select(other[0], zero), touch.select(other[1], zero));
    // SAFETY: History is repr(C): four f64, 32 bytes.
    lanes::store4(
        unsafe { &mut *h.as_mut_ptr().cast::<[[f64; 4]; W]>() },
        [xix, xiy, t, p],
    );
}

/// Store eight pair results (lanes to records).
#[inline(always)]
fn store4(o: &mut [PairOut; W], v: [F8; 4]) {
    // SAFETY: PairOut is repr(C): four f64, 32 bytes.
    lanes::store4(unsafe { &mut *o.as_mut_ptr().cast::<[[f64; 4]; W]>() }, v);
}
