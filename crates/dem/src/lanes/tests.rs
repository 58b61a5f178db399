//! Every lane type gives the array lanes' bits, operation by operation: the batched kernels'
//! "same bits on every CPU" rests on this (the kernels' own tests check only the lane type of
//! the machine they run on, through the stepper).

use super::W;
use crate::contact::History;
use crate::scratch::CircleState;
use crate::spheres::hm_batched::SphereLine;

/// Inputs with the values where lane types could part: ±0, ±∞, NaN, subnormals, ties.
fn inputs() -> Vec<[f64; W]> {
    let special = [
        0.0,
        -0.0,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        f64::MIN_POSITIVE / 8.0,
        -1.5,
        2.0,
    ];
    let mut s = 0x9e37_79b9_7f4a_7c15_u64;
    let mut rnd = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
    };
    let mut v = vec![special, [1.0, -1.0, 0.5, -0.0, 0.0, 3.0, f64::NAN, -2.0]];
    for _ in 0..30 {
        let mut a: [f64; W] = std::array::from_fn(|_| rnd());
        // Some lanes copied from the special values, so they meet ordinary ones.
        let k = (rnd().abs() * 3.9) as usize;
        a[k] = special[(k * 3) % W];
        v.push(a);
    }
    v
}

/// The bits every operation of one lane type gives on `a`, `b` (as f64 bits, masks as 0/1),
/// and of every line move on records built from them. Written once as a macro and expanded
/// per lane type, like the kernels.
macro_rules! digest {
    ($name:ident, $lanes:path $(, $attr:meta)?) => {
        $(#[$attr])?
        #[allow(unused_unsafe)]
        unsafe fn $name(a: [f64; W], b: [f64; W], c: [f64; W]) -> Vec<u64> {
            use $lanes as l;
            let (x, y, z) = (l::F8::from_array(a), l::F8::from_array(b), l::F8::from_array(c));
            // Lane vectors in `vs`, everything else as bits in `d`.
            let mut vs: Vec<l::F8> = Vec::new();
            let mut d: Vec<u64> = Vec::new();
            let mut f = |v: l::F8| vs.push(v);
            f(x + y);
            f(x - y);
            f(x * y);
            f(x / y);
            f(-x);
            f(x.sqrt());
            f(x.abs());
            f(x.max0());
            f(x.copysign(y));
            f(l::F8::splat(a[3]));
            let zero = l::F8::splat(0.0);
            let one = l::F8::splat(1.0);
            let masks = [
                x.lt(y),
                x.gt(y),
                x.ge(y),
                x.le(y),
                x.ne(y),
                x.outside(y, z),
                x.lt(y).and(x.ne(z)),
                x.gt(y).or(x.lt(z)),
                x.le(z).not(),
            ];
            for m in masks {
                f(m.select(one, zero));
                f(m.select(x, y));
                d.push(u64::from(m.any()));
                d.extend((0..W).map(|k| u64::from(m.bit(k))));
            }
            // Line moves.
            let rows = l::transpose([x, y, z, x + y, x - z, y * z, -x, z]);
            d.extend(rows.iter().flatten().map(|v| v.to_bits()));
            let pairs: [[f64; 2]; W] = std::array::from_fn(|k| [a[k], b[k]]);
            let (px, py) = l::deinterleave(&pairs);
            f(px);
            f(py);
            let mut back = [[0.0; 2]; W];
            l::interleave(y, z, &mut back);
            d.extend(back.iter().flatten().map(|v| v.to_bits()));
            let lines: Vec<CircleState> = (0..11)
                .map(|k| CircleState {
                    pos: crate::Vec2::new(a[k % W], b[k % W]),
                    vel: crate::Vec2::new(c[k % W], a[(k + 1) % W]),
                    omega: b[(k + 2) % W],
                    r: c[(k + 3) % W],
                    mass: a[(k + 4) % W],
                    pad: k as f64,
                })
                .collect();
            let idx = [3, 0, 10, 7, 7, 1, 9, 4];
            for v in l::transpose8(&lines, &idx) {
                f(v);
            }
            let spheres: Vec<SphereLine> = (0..10)
                .map(|k| SphereLine(std::array::from_fn(|q| [a, b, c][q % 3][(k + q) % W] + q as f64)))
                .collect();
            for v in l::transpose16(&spheres, &[9, 2, 2, 0, 5, 6, 8, 1]) {
                f(v);
            }
            let mut rec3: [[f64; 3]; W] = std::array::from_fn(|k| [a[k], b[k], c[k]]);
            for v in l::load3(&rec3) {
                f(v);
            }
            l::store3(&mut rec3, [z, x, y]);
            d.extend(rec3.iter().flatten().map(|v| v.to_bits()));
            let hist: [History; W] = std::array::from_fn(|k| History {
                xi_t: crate::Vec2::new(a[k], b[k]),
                theta_r: c[k],
                delta_p: a[(k + 5) % W],
            });
            let (hx, hy, [ht, hd]) = l::hist_load(&hist);
            for v in [hx, hy, ht, hd] {
                f(v);
            }
            let mut rec4 = [[0.0; 4]; W];
            l::store4(&mut rec4, [z, y, x, x * z]);
            d.extend(rec4.iter().flatten().map(|v| v.to_bits()));
            d.extend(vs.iter().flat_map(|v| v.to_array().map(f64::to_bits)));
            d
        }
    };
}

digest!(arrays, crate::lanes::portable);
#[cfg(target_arch = "x86_64")]
digest!(avx2, crate::lanes::avx2, target_feature(enable = "avx,avx2,fma"));
#[cfg(target_arch = "x86_64")]
digest!(
    avx512,
    crate::lanes::avx512,
    target_feature(enable = "avx512f,avx512dq")
);

#[test]
fn every_lane_type_gives_the_array_lanes_bits() {
    let v = inputs();
    let mut checked = 0;
    for (k, a) in v.iter().enumerate() {
        let (b, c) = (v[(k + 1) % v.len()], v[(k + 7) % v.len()]);
        // SAFETY: the array lanes need no CPU feature.
        let want = unsafe { arrays(*a, b, c) };
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                // SAFETY: the features were just detected.
                assert_eq!(unsafe { avx2(*a, b, c) }, want, "AVX2 lanes, input {k}");
                checked += 1;
            }
            if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx512dq") {
                // SAFETY: the features were just detected.
                assert_eq!(unsafe { avx512(*a, b, c) }, want, "AVX-512 lanes, input {k}");
            }
        }
    }
    // Every x86-64 CPU of this project's machines has AVX2 (the test would check nothing
    // otherwise).
    #[cfg(target_arch = "x86_64")]
    assert!(
        checked > 0,
        "this CPU has no AVX2: the AVX2 lanes were not checked"
    );
}
