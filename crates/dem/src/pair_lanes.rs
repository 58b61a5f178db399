//! The lane code of the batched pair kernel (`crate::pair_batched`), written once against a
//! lane type `super::lanes` and compiled for each (`crate::on_avx512`, `crate::on_arrays`).

use super::lanes::{self, F8, M8};
use crate::contact::{BatchedNormal, History};
use crate::lanes::W;
use crate::pair_batched::BatchedPair;
use crate::scratch::{CircleState, PairOut};

/// Every pair of `pairs`, the damping form and the normal law chosen once per call.
#[inline(always)]
pub(crate) fn run(
    kp: &BatchedPair,
    cst: &[CircleState],
    pairs: &[[u32; 2]],
    hist: &mut [History],
    out: &mut [PairOut],
    touch: &mut [u8],
) {
    let plastic = matches!(kp.normal, BatchedNormal::Plastic { .. });
    match (kp.gamma, plastic) {
        (true, false) => run_law::<true, false>(kp, cst, pairs, hist, out, touch),
        (false, false) => run_law::<false, false>(kp, cst, pairs, hist, out, touch),
        (true, true) => run_law::<true, true>(kp, cst, pairs, hist, out, touch),
        (false, true) => run_law::<false, true>(kp, cst, pairs, hist, out, touch),
    }
}

#[inline(always)]
fn run_law<const GAMMA: bool, const PLASTIC: bool>(
    kp: &BatchedPair,
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
        let (m, ix, jx) = crate::lanes::batch(pairs, q, nc);
        let lane = |k: usize| q + k.min(m - 1);
        let ci = Lanes::gather(cst, &ix);
        let cj = Lanes::gather(cst, &jx);
        if m == W {
            let h: &mut [History; W] = (&mut hist[q..q + W]).try_into().expect("eight histories");
            let (hx, hy, other) = lanes::hist_load(h);
            let r = eight::<GAMMA, PLASTIC>(kp, &ci, &cj, [hx, hy, other[0], other[1]]);
            hist_store(h, r.hist);
            let o: &mut [PairOut; W] = (&mut out[q..q + W]).try_into().expect("eight records");
            store4(o, [r.fx, r.fy, r.ti, r.tj]);
            for k in 0..W {
                touch[q + k] = u8::from(r.touch.bit(k));
            }
        } else {
            let field = |f: fn(&History) -> f64| F8::from_array(std::array::from_fn(|k| f(&hist[lane(k)])));
            let h0 = [
                field(|h| h.xi_t.x),
                field(|h| h.xi_t.y),
                field(|h| h.theta_r),
                field(|h| h.delta_p),
            ];
            let r = eight::<GAMMA, PLASTIC>(kp, &ci, &cj, h0);
            let [h0, h1, h2, h3] = r.hist;
            let [xix, xiy, th, dp] = [h0.to_array(), h1.to_array(), h2.to_array(), h3.to_array()];
            let (fx, fy) = (r.fx.to_array(), r.fy.to_array());
            let (ti, tj) = (r.ti.to_array(), r.tj.to_array());
            for k in 0..m {
                hist[q + k] = History {
                    xi_t: crate::Vec2::new(xix[k], xiy[k]),
                    theta_r: th[k],
                    delta_p: dp[k],
                };
                touch[q + k] = u8::from(r.touch.bit(k));
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

/// Eight pairs, their histories `h` as lanes (ξ_x, ξ_y, θ_r, δ_p). Untouched lanes: zeros.
#[inline(always)]
fn eight<const GAMMA: bool, const PLASTIC: bool>(
    kp: &BatchedPair,
    ci: &Lanes,
    cj: &Lanes,
    h: [F8; 4],
) -> LaneOut {
    let zero = F8::splat(0.0);
    let [hx, hy, theta, dp] = h;
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
    let k_n = F8::splat(kp.k_damp());
    let cn = if GAMMA {
        F8::splat(kp.damp) * m_eff
    } else {
        F8::splat(2.0 * kp.damp) * (k_n * m_eff).sqrt()
    };
    let vn = vx * nx + vy * ny;
    let (f_n, dp) = match kp.normal {
        // Su et al. 2020 Eq. 6 (contact::ElasticPlastic::normal): elastic to the yield
        // envelope F_y + k_p (δ − F_y/k_e), plastic along it, the dashpot only while loaded.
        BatchedNormal::Plastic { k_e, k_p, f_y } if PLASTIC => {
            let f = k_n * (delta - dp);
            let env = F8::splat(f_y) + F8::splat(k_p) * (delta - F8::splat(f_y / k_e));
            let yields = f.gt(env);
            let dp = yields.select(delta - env / k_n, dp);
            let f_el = yields.select(env, f).max0();
            (f_el.gt(zero).select((f_el + cn * vn).max0(), zero), dp)
        }
        BatchedNormal::Linear { clip, .. } if !PLASTIC => {
            let f_n = k_n * delta + cn * vn;
            (if clip { f_n.lt(zero).select(zero, f_n) } else { f_n }, dp)
        }
        _ => unreachable!("run picks PLASTIC from the law"),
    };
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
    // Rolling spring with its limit μ_r r* F_n (contact::Rolling::torque).
    let (m_roll, theta) = match kp.rolling {
        Some([k_r, mu_r]) => {
            let th = theta + (wi - wj) * dt;
            let m = F8::splat(-k_r) * th;
            let lim = F8::splat(mu_r) * (ri * rj / rs) * f_n.max0();
            let over = m.abs().gt(lim);
            let m = over.select(lim.copysign(m), m);
            (m, over.select(-m / F8::splat(k_r), th))
        }
        None => (zero, theta),
    };
    let fx = ftx - nx * f_n;
    let fy = fty - ny * f_n;
    let nxf = nx * fy - ny * fx;
    let ti = ai * nxf + m_roll;
    let tj = aj * nxf - m_roll;
    // No `map` with a closure here: a closure is compiled without the lane copy's target
    // features, and its selects stayed calls (16 % of the AVX2 step's samples).
    LaneOut {
        touch: touching,
        hist: [
            touching.select(xix, zero),
            touching.select(xiy, zero),
            touching.select(theta, zero),
            touching.select(dp, zero),
        ],
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
    /// The new history (ξ_x, ξ_y, θ_r, δ_p), zero where untouched.
    hist: [F8; 4],
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

/// Store eight histories (lanes ξ_x, ξ_y, θ_r, δ_p, already zero where untouched).
#[inline(always)]
fn hist_store(h: &mut [History; W], v: [F8; 4]) {
    // SAFETY: History is repr(C): four f64, 32 bytes.
    lanes::store4(unsafe { &mut *h.as_mut_ptr().cast::<[[f64; 4]; W]>() }, v);
}

/// Store eight pair results (lanes to records).
#[inline(always)]
fn store4(o: &mut [PairOut; W], v: [F8; 4]) {
    // SAFETY: PairOut is repr(C): four f64, 32 bytes.
    lanes::store4(unsafe { &mut *o.as_mut_ptr().cast::<[[f64; 4]; W]>() }, v);
}
