//! The lane code of the batched Hertz-Mindlin pair kernel (`crate::spheres::hm_batched`),
//! written once against a lane type `super::lanes` and compiled for each (`crate::on_avx512`,
//! `crate::on_arrays`). Every line mirrors the scalar path operation for operation
//! (`spheres::stepper::pair_response`, `law::hertz_mindlin::hertz_mindlin_force`,
//! `law::tangential_spring`, `Domain3::min_image_moving`): the comments name the scalar line.

use super::lanes::{self, F8, M8};
use crate::lanes::W;
use crate::spheres::hm_batched::{HmPair, PairRecord, SphereLine, field};
use crate::vector::Vec3;

/// Every pair of `pairs` with its spring in `hist` (updated), into `out`.
#[inline(always)]
pub(crate) fn run(
    kp: &HmPair,
    lines: &[SphereLine],
    pairs: &[[u32; 2]],
    hist: &mut [Vec3],
    out: &mut [PairRecord],
) {
    let n = pairs.len();
    let (hist, out) = (&mut hist[..n], &mut out[..n]);
    let nl = lines.len();
    let mut q = 0;
    while q < n {
        let (m, ix, jx) = crate::lanes::batch(pairs, q, nl);
        let lane = |k: usize| q + k.min(m - 1);
        let si = lanes::transpose16(lines, &ix);
        let sj = lanes::transpose16(lines, &jx);
        if m == W {
            let h: &mut [Vec3; W] = (&mut hist[q..q + W]).try_into().expect("eight springs");
            let h: &mut [[f64; 3]; W] = bytemuck::cast_mut(h);
            let r = eight(kp, &si, &sj, lanes::load3(h));
            lanes::store3(h, r.hist);
            store_records(&mut out[q..q + W], &r);
        } else {
            let h0 = [
                F8::from_array(std::array::from_fn(|k| hist[lane(k)].x)),
                F8::from_array(std::array::from_fn(|k| hist[lane(k)].y)),
                F8::from_array(std::array::from_fn(|k| hist[lane(k)].z)),
            ];
            let r = eight(kp, &si, &sj, h0);
            let [hx, hy, hz] = arrays3(r.hist);
            for k in 0..m {
                hist[q + k] = Vec3::new(hx[k], hy[k], hz[k]);
            }
            store_records(&mut out[q..q + m], &r);
        }
        q += m;
    }
}

/// The first `out.len()` lanes of `r` as pair records.
#[inline(always)]
fn store_records(out: &mut [PairRecord], r: &LaneOut) {
    let (f, ti, tj) = (arrays3(r.f), arrays3(r.ti), arrays3(r.tj));
    for (k, o) in out.iter_mut().enumerate() {
        *o = PairRecord {
            f: [f[0][k], f[1][k], f[2][k]],
            ti: [ti[0][k], ti[1][k], ti[2][k]],
            tj: [tj[0][k], tj[1][k], tj[2][k]],
        };
    }
}

/// The three lane vectors as arrays (a function, not `map` with a closure: a closure is
/// compiled without the lane copy's target features).
#[inline(always)]
fn arrays3(v: [F8; 3]) -> [[f64; W]; 3] {
    [v[0].to_array(), v[1].to_array(), v[2].to_array()]
}

struct LaneOut {
    /// The new spring ξ, zero where the pair does not touch.
    hist: [F8; 3],
    f: [F8; 3],
    ti: [F8; 3],
    tj: [F8; 3],
}

/// a × b per lane (`Vec3::cross`).
#[inline(always)]
fn cross(a: [F8; 3], b: [F8; 3]) -> [F8; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// a · b per lane (`Vec3::dot`).
#[inline(always)]
fn dot(a: [F8; 3], b: [F8; 3]) -> F8 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// a × s per lane (`Vec3 * f64`).
#[inline(always)]
fn scale(a: [F8; 3], s: F8) -> [F8; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline(always)]
fn add(a: [F8; 3], b: [F8; 3]) -> [F8; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline(always)]
fn sub(a: [F8; 3], b: [F8; 3]) -> [F8; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn neg(a: [F8; 3]) -> [F8; 3] {
    [-a[0], -a[1], -a[2]]
}

#[inline(always)]
fn select(m: M8, a: [F8; 3], b: [F8; 3]) -> [F8; 3] {
    [m.select(a[0], b[0]), m.select(a[1], b[1]), m.select(a[2], b[2])]
}

/// `Domain3::min_image_moving` per lane: the separation and the velocity of j's image.
#[inline(always)]
fn min_image(kp: &HmPair, d: [F8; 3]) -> ([F8; 3], F8) {
    let [mut dx, mut dy, mut dz] = d;
    let zero = F8::splat(0.0);
    let [lx, ly, lz] = kp.l;
    let dvx = match kp.shear {
        Some([offset, rate]) => {
            // if d.y.abs() > 0.5 * l.y { k = ±1; d.y += k l.y; d.x += k offset; dv.x = k rate l.y }
            let cross_y = dy.abs().gt(F8::splat(0.5 * ly));
            let k = dy.gt(zero).select(F8::splat(-1.0), F8::splat(1.0));
            dy = cross_y.select(dy + k * F8::splat(ly), dy);
            dx = cross_y.select(dx + k * F8::splat(offset), dx);
            let dvx = cross_y.select(k * F8::splat(rate) * F8::splat(ly), zero);
            // Up to two exact shifts of L_x each way (the scalar if / else if).
            let (half, l) = (F8::splat(0.5 * lx), F8::splat(lx));
            let up = dx.ge(half);
            dx = up.select(dx - l, dx);
            dx = up.and(dx.ge(half)).select(dx - l, dx);
            let down = up.not().and(dx.le(-half));
            dx = down.select(dx + l, dx);
            dx = down.and(dx.le(-half)).select(dx + l, dx);
            if kp.periodic[2] {
                let s = dz.abs().gt(F8::splat(0.5 * lz));
                dz = s.select(dz - F8::splat(lz).copysign(dz), dz);
            }
            dvx
        }
        None => {
            // `Domain3::min_image`: one shift on each periodic axis.
            for (k, dk) in [&mut dx, &mut dy, &mut dz].into_iter().enumerate() {
                if kp.periodic[k] {
                    let lk = kp.l[k];
                    let s = dk.abs().gt(F8::splat(0.5 * lk));
                    *dk = s.select(*dk - F8::splat(lk).copysign(*dk), *dk);
                }
            }
            zero
        }
    };
    ([dx, dy, dz], dvx)
}

/// Eight pairs: sphere lines `si`, `sj` as columns, springs `h`.
#[inline(always)]
fn eight(kp: &HmPair, si: &[F8; 16], sj: &[F8; 16], h: [F8; 3]) -> LaneOut {
    let zero = F8::splat(0.0);
    let v3 = |s: &[F8; 16], at: usize| [s[at], s[at + 1], s[at + 2]];
    let (xi_, xj) = (v3(si, field::X), v3(sj, field::X));
    let (ri, rj) = (si[field::R], sj[field::R]);
    // let (d, dv_j) = dom.min_image_moving(s.pos[j] - s.pos[i]);
    let (d, dvx) = min_image(kp, sub(xj, xi_));
    // let dist2 = d.norm2(); let reach = ri + rj + law.range(ri, rj) (0 for this law);
    let dist2 = dot(d, d);
    let reach = ri + rj + zero;
    // in range: !(dist2 >= reach * reach || dist2 == 0.0)
    let in_range = dist2.ge(reach * reach).or(dist2.ne(zero).not()).not();
    let dist = dist2.sqrt();
    let nrm = scale(d, F8::splat(1.0) / dist);
    let delta = ri + rj - dist;
    let half = F8::splat(0.5);
    let (ai, aj) = (ri - half * delta, rj - half * delta);
    // let v_j = s.vel[j] + dv_j;
    let vj = {
        let v = v3(sj, field::V);
        [v[0] + dvx, v[1] + zero, v[2] + zero]
    };
    let (vi, wi, wj) = (v3(si, field::V), v3(si, field::W), v3(sj, field::W));
    // (s.vel[i] + s.omega[i].cross(nrm * ai)) - (v_j + s.omega[j].cross(nrm * -aj))
    let v_rel = sub(
        add(vi, cross(wi, scale(nrm, ai))),
        add(vj, cross(wj, scale(nrm, -aj))),
    );
    // m* of a mobile-frozen pair is the mobile body's mass.
    let (mi, mj) = (si[field::M], sj[field::M]);
    let one = F8::splat(1.0);
    let (fi, fj) = (si[field::FROZEN].ge(one), sj[field::FROZEN].ge(one));
    let both = mi * mj / (mi + mj);
    let m_eff = fj.and(fi.not()).select(mi, fi.and(fj.not()).select(mj, both));
    let r_eff = ri * rj / (ri + rj);
    // hertz_mindlin_force: nothing (and the spring zeroed) unless delta > 0.
    let touch = in_range.and(delta.gt(zero));
    let sqrt_rd = (r_eff * delta).sqrt();
    let s_n = F8::splat(kp.two_e) * sqrt_rd;
    let k_t = F8::splat(kp.eight_g) * sqrt_rd;
    let damp = F8::splat(kp.damp);
    let c_n = damp * (s_n * m_eff).sqrt();
    let c_t = damp * (k_t * m_eff).sqrt();
    let vn = dot(v_rel, nrm);
    let f_n = F8::splat(kp.four_thirds_e) * sqrt_rd * delta + c_n * vn;
    let vt = sub(v_rel, scale(nrm, vn));
    // tangential_spring(xi, n, vt, dt, k_t, c_t, mu * f_n.max(0.0))
    let cap = F8::splat(kp.mu) * f_n.max0();
    let xn = dot(h, nrm);
    let old2 = dot(h, h);
    let p = sub(h, scale(nrm, xn));
    let p2 = dot(p, p);
    let rotated = select(p2.gt(zero), scale(p, (old2 / p2).sqrt()), [zero; 3]);
    let xi = select(xn.ne(zero), rotated, h);
    let dt = F8::splat(kp.dt);
    let xi = add(xi, scale(vt, dt));
    let f_t = sub(neg(scale(xi, k_t)), scale(vt, c_t));
    let ft2 = dot(f_t, f_t);
    let slide = ft2.gt(cap * cap);
    let capped = select(ft2.gt(zero), scale(f_t, cap / ft2.sqrt()), [zero; 3]);
    let reset = select(
        k_t.gt(zero),
        scale(neg(add(capped, scale(vt, c_t))), one / k_t),
        [zero; 3],
    );
    let f_t = select(slide, capped, f_t);
    let xi = select(slide, reset, xi);
    // f_t - k.n * f_n
    let f = sub(f_t, scale(nrm, f_n));
    // PairSum: tq = nrm.cross(f); ti = tq * ai + torque_i (0); tj = tq * aj + torque_j (0)
    let tq = cross(nrm, f);
    let ti = add(scale(tq, ai), [zero; 3]);
    let tj = add(scale(tq, aj), [zero; 3]);
    LaneOut {
        hist: select(touch, xi, [zero; 3]),
        f: select(touch, f, [zero; 3]),
        ti: select(touch, ti, [zero; 3]),
        tj: select(touch, tj, [zero; 3]),
    }
}
