//! The eight lanes as AVX-512 registers and masks, and the line transposes of the pair kernel.
//!
//! No closure holds an intrinsic (a closure is compiled without its caller's target features,
//! so the intrinsic would stay a call): loops and explicit arrays instead of `map`/`from_fn`.
//!
//! Every function here is `#[inline(always)]` without `#[target_feature]`: it is compiled only
//! into callers that enable AVX-512 F and DQ, the lane kernels' AVX-512 copy
//! (`crate::on_avx512`), taken only in the v4 copy of a pass dispatched by `lbdem_core::simd`
//! (`crate::lanes::avx512_in`), or a whole `target-cpu=native` build for such a CPU. Data
//! movement and the scalar IEEE operations per lane: the bits are those of `super::portable`.

use super::W;
use crate::contact::History;
use crate::scratch::CircleState;
use std::arch::x86_64::*;

#[derive(Clone, Copy)]
#[repr(transparent)]
pub(crate) struct F8(pub(crate) __m512d);

#[derive(Clone, Copy)]
pub(crate) struct M8(__mmask8);

// SAFETY (every `unsafe` below): this code runs only where the CPU has AVX-512 F and DQ (the
// module doc); the intrinsics only touch registers except `from_array`/`to_array`, which
// read/write one local [f64; 8].
macro_rules! binop {
    ($tr:ident, $f:ident, $intr:ident) => {
        impl std::ops::$tr for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: F8) -> F8 {
                F8(unsafe { $intr(self.0, o.0) })
            }
        }
    };
}
binop!(Add, add, _mm512_add_pd);
binop!(Sub, sub, _mm512_sub_pd);
binop!(Mul, mul, _mm512_mul_pd);
binop!(Div, div, _mm512_div_pd);

impl std::ops::Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        F8(unsafe { _mm512_xor_pd(self.0, _mm512_set1_pd(-0.0)) })
    }
}

impl F8 {
    #[inline(always)]
    pub(crate) fn splat(v: f64) -> F8 {
        F8(unsafe { _mm512_set1_pd(v) })
    }
    #[inline(always)]
    pub(crate) fn from_array(a: [f64; W]) -> F8 {
        F8(unsafe { _mm512_loadu_pd(a.as_ptr()) })
    }
    #[inline(always)]
    pub(crate) fn to_array(self) -> [f64; W] {
        let mut a = [0.0; W];
        unsafe { _mm512_storeu_pd(a.as_mut_ptr(), self.0) };
        a
    }
    #[inline(always)]
    pub(crate) fn sqrt(self) -> F8 {
        F8(unsafe { _mm512_sqrt_pd(self.0) })
    }
    #[inline(always)]
    pub(crate) fn abs(self) -> F8 {
        F8(unsafe { _mm512_abs_pd(self.0) })
    }
    /// max(self, 0): 0 for NaN, like `f64::max(self, 0.0)` (which may return either zero
    /// for −0; this returns +0).
    #[inline(always)]
    pub(crate) fn max0(self) -> F8 {
        F8(unsafe { _mm512_max_pd(self.0, _mm512_setzero_pd()) })
    }
    /// Magnitude of self with the sign of `s`.
    #[inline(always)]
    pub(crate) fn copysign(self, s: F8) -> F8 {
        unsafe {
            let sign = _mm512_set1_pd(-0.0);
            F8(_mm512_or_pd(
                _mm512_andnot_pd(sign, self.0),
                _mm512_and_pd(sign, s.0),
            ))
        }
    }
    #[inline(always)]
    pub(crate) fn lt(self, o: F8) -> M8 {
        M8(unsafe { _mm512_cmp_pd_mask::<_CMP_LT_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    pub(crate) fn gt(self, o: F8) -> M8 {
        M8(unsafe { _mm512_cmp_pd_mask::<_CMP_GT_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    pub(crate) fn ge(self, o: F8) -> M8 {
        M8(unsafe { _mm512_cmp_pd_mask::<_CMP_GE_OQ>(self.0, o.0) })
    }
    #[inline(always)]
    pub(crate) fn le(self, o: F8) -> M8 {
        M8(unsafe { _mm512_cmp_pd_mask::<_CMP_LE_OQ>(self.0, o.0) })
    }
    /// Lanes where self != o, NaN included (Rust's `!=`).
    #[inline(always)]
    pub(crate) fn ne(self, o: F8) -> M8 {
        M8(unsafe { _mm512_cmp_pd_mask::<_CMP_NEQ_UQ>(self.0, o.0) })
    }
    /// Lanes that are not in [lo, hi) (NaN included).
    #[inline(always)]
    pub(crate) fn outside(self, lo: F8, hi: F8) -> M8 {
        M8(unsafe {
            _mm512_cmp_pd_mask::<_CMP_NGE_UQ>(self.0, lo.0) | _mm512_cmp_pd_mask::<_CMP_NLT_UQ>(self.0, hi.0)
        })
    }
}

/// x and y lanes of eight (x, y) pairs.
#[inline(always)]
pub(crate) fn deinterleave(p: &[[f64; 2]; W]) -> (F8, F8) {
    unsafe {
        let q = p.as_ptr().cast::<f64>();
        let (a, b) = (_mm512_loadu_pd(q), _mm512_loadu_pd(q.add(8)));
        let ix = _mm512_setr_epi64(0, 2, 4, 6, 8, 10, 12, 14);
        let iy = _mm512_setr_epi64(1, 3, 5, 7, 9, 11, 13, 15);
        (
            F8(_mm512_permutex2var_pd(a, ix, b)),
            F8(_mm512_permutex2var_pd(a, iy, b)),
        )
    }
}

/// Inverse of [`deinterleave`].
#[inline(always)]
pub(crate) fn interleave(x: F8, y: F8, p: &mut [[f64; 2]; W]) {
    unsafe {
        let lo = _mm512_setr_epi64(0, 8, 1, 9, 2, 10, 3, 11);
        let hi = _mm512_setr_epi64(4, 12, 5, 13, 6, 14, 7, 15);
        let q = p.as_mut_ptr().cast::<f64>();
        _mm512_storeu_pd(q, _mm512_permutex2var_pd(x.0, lo, y.0));
        _mm512_storeu_pd(q.add(8), _mm512_permutex2var_pd(x.0, hi, y.0));
    }
}

/// 8 x 8 transpose (lanes of column k become row k).
#[inline(always)]
pub(crate) fn transpose(r: [F8; W]) -> [[f64; W]; W] {
    let t = transpose_registers(r);
    let mut rows = [[0.0; W]; W];
    for (row, v) in rows.iter_mut().zip(t) {
        *row = v.to_array();
    }
    rows
}

/// 8 x 8 transpose kept in registers: lane k of result j is lane j of input k.
#[inline(always)]
pub(crate) fn transpose_registers(r: [F8; W]) -> [F8; W] {
    unsafe {
        let r = [r[0].0, r[1].0, r[2].0, r[3].0, r[4].0, r[5].0, r[6].0, r[7].0];
        let t = [
            _mm512_unpacklo_pd(r[0], r[1]),
            _mm512_unpackhi_pd(r[0], r[1]),
            _mm512_unpacklo_pd(r[2], r[3]),
            _mm512_unpackhi_pd(r[2], r[3]),
            _mm512_unpacklo_pd(r[4], r[5]),
            _mm512_unpackhi_pd(r[4], r[5]),
            _mm512_unpacklo_pd(r[6], r[7]),
            _mm512_unpackhi_pd(r[6], r[7]),
        ];
        let u = [
            _mm512_shuffle_f64x2::<0x88>(t[0], t[2]),
            _mm512_shuffle_f64x2::<0xDD>(t[0], t[2]),
            _mm512_shuffle_f64x2::<0x88>(t[1], t[3]),
            _mm512_shuffle_f64x2::<0xDD>(t[1], t[3]),
            _mm512_shuffle_f64x2::<0x88>(t[4], t[6]),
            _mm512_shuffle_f64x2::<0xDD>(t[4], t[6]),
            _mm512_shuffle_f64x2::<0x88>(t[5], t[7]),
            _mm512_shuffle_f64x2::<0xDD>(t[5], t[7]),
        ];
        let c = [
            _mm512_shuffle_f64x2::<0x88>(u[0], u[4]),
            _mm512_shuffle_f64x2::<0x88>(u[2], u[6]),
            _mm512_shuffle_f64x2::<0x88>(u[1], u[5]),
            _mm512_shuffle_f64x2::<0x88>(u[3], u[7]),
            _mm512_shuffle_f64x2::<0xDD>(u[0], u[4]),
            _mm512_shuffle_f64x2::<0xDD>(u[2], u[6]),
            _mm512_shuffle_f64x2::<0xDD>(u[1], u[5]),
            _mm512_shuffle_f64x2::<0xDD>(u[3], u[7]),
        ];
        [
            F8(c[0]),
            F8(c[1]),
            F8(c[2]),
            F8(c[3]),
            F8(c[4]),
            F8(c[5]),
            F8(c[6]),
            F8(c[7]),
        ]
    }
}

impl M8 {
    /// `a` where the mask is set, else `b`.
    #[inline(always)]
    pub(crate) fn select(self, a: F8, b: F8) -> F8 {
        F8(unsafe { _mm512_mask_blend_pd(self.0, b.0, a.0) })
    }
    /// Any lane set.
    #[inline(always)]
    pub(crate) fn any(self) -> bool {
        self.0 != 0
    }
    #[inline(always)]
    pub(crate) fn bit(self, k: usize) -> bool {
        (self.0 >> k) & 1 != 0
    }
    #[inline(always)]
    pub(crate) fn and(self, o: M8) -> M8 {
        M8(self.0 & o.0)
    }
    #[inline(always)]
    pub(crate) fn or(self, o: M8) -> M8 {
        M8(self.0 | o.0)
    }
    #[inline(always)]
    pub(crate) fn not(self) -> M8 {
        M8(!self.0)
    }
}

// The line moves of the pair kernel: shuffles instead of eight scalar loads per field.

/// Columns 0..7 of the eight lines `cst[idx[k]]`.
#[inline(always)]
pub(crate) fn transpose8(cst: &[CircleState], idx: &[usize; W]) -> [F8; 8] {
    let p = cst.as_ptr();
    // SAFETY: AVX-512 code runs only where the CPU has it (module doc); every idx[k] < cst.len()
    // (asserted by the caller); CircleState is repr(C), 64 bytes, 64-byte aligned, eight f64.
    unsafe {
        let mut r = [F8(_mm512_setzero_pd()); W];
        for (v, &i) in r.iter_mut().zip(idx) {
            *v = F8(_mm512_load_pd(p.add(i).cast::<f64>()));
        }
        transpose_registers(r)
    }
}

/// The sixteen columns of the eight sphere lines `lines[idx[k]]` (two 64-byte lines each).
#[inline(always)]
pub(crate) fn transpose16(lines: &[crate::spheres::hm_batched::SphereLine], idx: &[usize; W]) -> [F8; 16] {
    let p = lines.as_ptr();
    // SAFETY: AVX-512 code runs only where the CPU has it (module doc); every idx[k] <
    // lines.len() (asserted by the caller); SphereLine is repr(C), 128 bytes, 64-byte aligned.
    unsafe {
        let mut a = [F8(_mm512_setzero_pd()); W];
        let mut b = [F8(_mm512_setzero_pd()); W];
        for k in 0..W {
            let q = p.add(idx[k]).cast::<f64>();
            a[k] = F8(_mm512_load_pd(q));
            b[k] = F8(_mm512_load_pd(q.add(8)));
        }
        let (a, b) = (transpose_registers(a), transpose_registers(b));
        let mut r = [F8(_mm512_setzero_pd()); 16];
        r[..W].copy_from_slice(&a);
        r[W..].copy_from_slice(&b);
        r
    }
}

/// x, y and z lanes of eight packed (x, y, z) records (24 f64).
#[inline(always)]
pub(crate) fn load3(p: &[[f64; 3]; W]) -> [F8; 3] {
    // SAFETY: as above; reads the 24 f64 of `p` as three unaligned lines.
    unsafe {
        let q = p.as_ptr().cast::<f64>();
        let (l0, l1, l2) = (
            _mm512_loadu_pd(q),
            _mm512_loadu_pd(q.add(8)),
            _mm512_loadu_pd(q.add(16)),
        );
        let x = _mm512_permutex2var_pd(l0, _mm512_setr_epi64(0, 3, 6, 9, 12, 15, 0, 0), l1);
        let x = _mm512_permutex2var_pd(x, _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 10, 13), l2);
        let y = _mm512_permutex2var_pd(l0, _mm512_setr_epi64(1, 4, 7, 10, 13, 0, 0, 0), l1);
        let y = _mm512_permutex2var_pd(y, _mm512_setr_epi64(0, 1, 2, 3, 4, 8, 11, 14), l2);
        let z = _mm512_permutex2var_pd(l0, _mm512_setr_epi64(2, 5, 8, 11, 14, 0, 0, 0), l1);
        let z = _mm512_permutex2var_pd(z, _mm512_setr_epi64(0, 1, 2, 3, 4, 9, 12, 15), l2);
        [F8(x), F8(y), F8(z)]
    }
}

/// The inverse of [`load3`].
#[inline(always)]
pub(crate) fn store3(p: &mut [[f64; 3]; W], v: [F8; 3]) {
    let [x, y, z] = [v[0].0, v[1].0, v[2].0];
    // SAFETY: as above; writes the 24 f64 of `p`.
    unsafe {
        let a = _mm512_permutex2var_pd(x, _mm512_setr_epi64(0, 8, 0, 1, 9, 0, 2, 10), y);
        let l0 = _mm512_permutex2var_pd(a, _mm512_setr_epi64(0, 1, 8, 3, 4, 9, 6, 7), z);
        let b = _mm512_permutex2var_pd(x, _mm512_setr_epi64(0, 3, 11, 0, 4, 12, 0, 5), y);
        let l1 = _mm512_permutex2var_pd(b, _mm512_setr_epi64(10, 1, 2, 11, 4, 5, 12, 7), z);
        let c = _mm512_permutex2var_pd(x, _mm512_setr_epi64(13, 0, 6, 14, 0, 7, 15, 0), y);
        let l2 = _mm512_permutex2var_pd(c, _mm512_setr_epi64(0, 13, 2, 3, 14, 5, 6, 15), z);
        let q = p.as_mut_ptr().cast::<f64>();
        _mm512_storeu_pd(q, l0);
        _mm512_storeu_pd(q.add(8), l1);
        _mm512_storeu_pd(q.add(16), l2);
    }
}

/// History k = [x y θ δp]: two histories per 512-bit line.
#[inline(always)]
pub(crate) fn hist_load(h: &[History; W]) -> (F8, F8, [F8; 2]) {
    let p = h.as_ptr().cast::<f64>();
    // SAFETY: as above; eight repr(C) Histories = 32 f64, read as four
    // unaligned lines.
    unsafe {
        let l = [
            _mm512_loadu_pd(p),
            _mm512_loadu_pd(p.add(8)),
            _mm512_loadu_pd(p.add(16)),
            _mm512_loadu_pd(p.add(24)),
        ];
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
            F8(_mm512_shuffle_f64x2::<0x44>(a, b)),
            F8(_mm512_shuffle_f64x2::<0xEE>(a, b)),
            [
                F8(_mm512_shuffle_f64x2::<0x44>(c, d)),
                F8(_mm512_shuffle_f64x2::<0xEE>(c, d)),
            ],
        )
    }
}

/// Eight records of four f64 from four lane vectors (the inverse of [`hist_load`]).
#[inline(always)]
pub(crate) fn store4(h: &mut [[f64; 4]; W], v: [F8; 4]) {
    let [x, y, t, dp] = [v[0].0, v[1].0, v[2].0, v[3].0];
    // SAFETY: as above; writes the 32 f64 of `h`.
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
