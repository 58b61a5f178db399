//! The eight lanes as two AVX2 registers of four, masks as two all-ones/zero registers, and the
//! line transposes of the pair kernel as 4 × 4 shuffles.
//!
//! Why not the array lanes on these CPUs: compiled for v3, the arrays of `super::portable`
//! gather each field of a circle line with a scalar load and an insert (eight per field) and
//! keep masks as integer arrays, so the pair kernel of a v3 CPU spent most of its
//! instructions moving data (docs/dem.md, "AVX2 lanes").
//!
//! As in `super::avx512`: no closure holds an intrinsic (a closure is compiled without its
//! caller's target features), and every function is `#[inline(always)]` without
//! `#[target_feature]`, compiled only into callers that enable AVX2 (the lane kernels' AVX2 copy
//! `crate::on_avx2`, taken only in the v3 copy of a pass dispatched by `lbdem_core::simd`,
//! `crate::lanes::avx2_in`). Data movement and the scalar IEEE operations per lane (no fused
//! multiply-add): the bits are those of `super::portable`.

use super::W;
use crate::contact::History;
use crate::scratch::CircleState;
use std::arch::x86_64::*;

/// Lanes 0-3 and 4-7.
#[derive(Clone, Copy)]
pub(crate) struct F8(__m256d, __m256d);

/// Lanes 0-3 and 4-7, each all ones (set) or zero.
#[derive(Clone, Copy)]
pub(crate) struct M8(__m256d, __m256d);

// SAFETY (every `unsafe` below): this code runs only where the CPU has AVX2 (the module doc);
// the intrinsics touch registers only, except the loads and stores, whose bounds each
// function states.
macro_rules! binop {
    ($tr:ident, $f:ident, $intr:ident) => {
        impl std::ops::$tr for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: F8) -> F8 {
                unsafe { F8($intr(self.0, o.0), $intr(self.1, o.1)) }
            }
        }
    };
}
binop!(Add, add, _mm256_add_pd);
binop!(Sub, sub, _mm256_sub_pd);
binop!(Mul, mul, _mm256_mul_pd);
binop!(Div, div, _mm256_div_pd);

impl std::ops::Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        unsafe {
            let s = _mm256_set1_pd(-0.0);
            F8(_mm256_xor_pd(self.0, s), _mm256_xor_pd(self.1, s))
        }
    }
}

/// A comparison per half (`$p`: the `_CMP_*` predicate).
macro_rules! cmp {
    ($f:ident, $p:ident) => {
        #[inline(always)]
        pub(crate) fn $f(self, o: F8) -> M8 {
            unsafe {
                M8(
                    _mm256_cmp_pd::<$p>(self.0, o.0),
                    _mm256_cmp_pd::<$p>(self.1, o.1),
                )
            }
        }
    };
}

impl F8 {
    #[inline(always)]
    pub(crate) fn splat(v: f64) -> F8 {
        unsafe { F8(_mm256_set1_pd(v), _mm256_set1_pd(v)) }
    }
    #[inline(always)]
    pub(crate) fn from_array(a: [f64; W]) -> F8 {
        // Reads the eight f64 of `a`.
        unsafe { F8(_mm256_loadu_pd(a.as_ptr()), _mm256_loadu_pd(a.as_ptr().add(4))) }
    }
    #[inline(always)]
    pub(crate) fn to_array(self) -> [f64; W] {
        let mut a = [0.0; W];
        // Writes the eight f64 of `a`.
        unsafe {
            _mm256_storeu_pd(a.as_mut_ptr(), self.0);
            _mm256_storeu_pd(a.as_mut_ptr().add(4), self.1);
        }
        a
    }
    #[inline(always)]
    pub(crate) fn sqrt(self) -> F8 {
        unsafe { F8(_mm256_sqrt_pd(self.0), _mm256_sqrt_pd(self.1)) }
    }
    #[inline(always)]
    pub(crate) fn abs(self) -> F8 {
        unsafe {
            let s = _mm256_set1_pd(-0.0);
            F8(_mm256_andnot_pd(s, self.0), _mm256_andnot_pd(s, self.1))
        }
    }
    /// max(self, 0): 0 for NaN and +0 for −0, as the AVX-512 lanes.
    #[inline(always)]
    pub(crate) fn max0(self) -> F8 {
        unsafe {
            let z = _mm256_setzero_pd();
            F8(_mm256_max_pd(self.0, z), _mm256_max_pd(self.1, z))
        }
    }
    /// Magnitude of self with the sign of `s`.
    #[inline(always)]
    pub(crate) fn copysign(self, s: F8) -> F8 {
        unsafe {
            let m = _mm256_set1_pd(-0.0);
            F8(
                _mm256_or_pd(_mm256_andnot_pd(m, self.0), _mm256_and_pd(m, s.0)),
                _mm256_or_pd(_mm256_andnot_pd(m, self.1), _mm256_and_pd(m, s.1)),
            )
        }
    }
    cmp!(lt, _CMP_LT_OQ);
    cmp!(gt, _CMP_GT_OQ);
    cmp!(ge, _CMP_GE_OQ);
    cmp!(le, _CMP_LE_OQ);
    // Lanes where self != o, NaN included (Rust's `!=`).
    cmp!(ne, _CMP_NEQ_UQ);
    /// Lanes that are not in [lo, hi) (NaN included).
    #[inline(always)]
    pub(crate) fn outside(self, lo: F8, hi: F8) -> M8 {
        self.lt_or_nan(lo).or(self.ge_or_nan(hi))
    }
    cmp!(lt_or_nan, _CMP_NGE_UQ);
    cmp!(ge_or_nan, _CMP_NLT_UQ);
}

impl M8 {
    /// `a` where the mask is set, else `b`.
    #[inline(always)]
    pub(crate) fn select(self, a: F8, b: F8) -> F8 {
        unsafe {
            F8(
                _mm256_blendv_pd(b.0, a.0, self.0),
                _mm256_blendv_pd(b.1, a.1, self.1),
            )
        }
    }
    /// The eight lanes as bits 0-7.
    #[inline(always)]
    fn bits(self) -> u32 {
        unsafe { (_mm256_movemask_pd(self.0) | (_mm256_movemask_pd(self.1) << 4)) as u32 }
    }
    #[inline(always)]
    pub(crate) fn bit(self, k: usize) -> bool {
        (self.bits() >> k) & 1 != 0
    }
    /// Any lane set.
    #[inline(always)]
    pub(crate) fn any(self) -> bool {
        self.bits() != 0
    }
    #[inline(always)]
    pub(crate) fn and(self, o: M8) -> M8 {
        unsafe { M8(_mm256_and_pd(self.0, o.0), _mm256_and_pd(self.1, o.1)) }
    }
    #[inline(always)]
    pub(crate) fn or(self, o: M8) -> M8 {
        unsafe { M8(_mm256_or_pd(self.0, o.0), _mm256_or_pd(self.1, o.1)) }
    }
    #[inline(always)]
    pub(crate) fn not(self) -> M8 {
        unsafe {
            let ones = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
            M8(_mm256_xor_pd(self.0, ones), _mm256_xor_pd(self.1, ones))
        }
    }
}

/// 4 × 4 transpose: lane k of result j is lane j of input k.
#[inline(always)]
fn transpose4(r: [__m256d; 4]) -> [__m256d; 4] {
    unsafe {
        let t0 = _mm256_unpacklo_pd(r[0], r[1]);
        let t1 = _mm256_unpackhi_pd(r[0], r[1]);
        let t2 = _mm256_unpacklo_pd(r[2], r[3]);
        let t3 = _mm256_unpackhi_pd(r[2], r[3]);
        [
            _mm256_permute2f128_pd::<0x20>(t0, t2),
            _mm256_permute2f128_pd::<0x20>(t1, t3),
            _mm256_permute2f128_pd::<0x31>(t0, t2),
            _mm256_permute2f128_pd::<0x31>(t1, t3),
        ]
    }
}

/// Eight lines of eight f64 (`lo[k]`: fields 0-3 of line k, `hi[k]`: fields 4-7) into eight
/// lane vectors, field f of line k in lane k of result f.
#[inline(always)]
fn transpose_lines(lo: [__m256d; W], hi: [__m256d; W]) -> [F8; W] {
    let a = transpose4([lo[0], lo[1], lo[2], lo[3]]);
    let b = transpose4([lo[4], lo[5], lo[6], lo[7]]);
    let c = transpose4([hi[0], hi[1], hi[2], hi[3]]);
    let d = transpose4([hi[4], hi[5], hi[6], hi[7]]);
    [
        F8(a[0], b[0]),
        F8(a[1], b[1]),
        F8(a[2], b[2]),
        F8(a[3], b[3]),
        F8(c[0], d[0]),
        F8(c[1], d[1]),
        F8(c[2], d[2]),
        F8(c[3], d[3]),
    ]
}

/// 8 × 8 transpose kept in registers: lane k of result j is lane j of input k.
#[inline(always)]
fn transpose_registers(r: [F8; W]) -> [F8; W] {
    let mut lo = [r[0].0; W];
    let mut hi = [r[0].1; W];
    for k in 0..W {
        lo[k] = r[k].0;
        hi[k] = r[k].1;
    }
    transpose_lines(lo, hi)
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

/// x and y lanes of eight (x, y) pairs.
#[inline(always)]
pub(crate) fn deinterleave(p: &[[f64; 2]; W]) -> (F8, F8) {
    let q = p.as_ptr().cast::<f64>();
    // SAFETY: reads the sixteen f64 of `p`, eight from each of the two offsets.
    let ((x0, y0), (x1, y1)) = unsafe { (deinterleave4(q), deinterleave4(q.add(8))) };
    (F8(x0, x1), F8(y0, y1))
}

/// x and y of the four (x, y) pairs at `q`.
///
/// # Safety
/// `q` points at eight readable f64.
#[inline(always)]
unsafe fn deinterleave4(q: *const f64) -> (__m256d, __m256d) {
    unsafe {
        // [x0 y0 x1 y1], [x2 y2 x3 y3] → [x0 x2 x1 x3], [y0 y2 y1 y3] → in order.
        let (a, b) = (_mm256_loadu_pd(q), _mm256_loadu_pd(q.add(4)));
        (
            _mm256_permute4x64_pd::<0xD8>(_mm256_unpacklo_pd(a, b)),
            _mm256_permute4x64_pd::<0xD8>(_mm256_unpackhi_pd(a, b)),
        )
    }
}

/// Inverse of [`deinterleave`].
#[inline(always)]
pub(crate) fn interleave(x: F8, y: F8, p: &mut [[f64; 2]; W]) {
    // Writes the sixteen f64 of `p`.
    unsafe {
        let q = p.as_mut_ptr().cast::<f64>();
        for (o, xs, ys) in [(0, x.0, y.0), (8, x.1, y.1)] {
            // [x0 y0 x2 y2], [x1 y1 x3 y3] → [x0 y0 x1 y1], [x2 y2 x3 y3].
            let (u0, u1) = (_mm256_unpacklo_pd(xs, ys), _mm256_unpackhi_pd(xs, ys));
            _mm256_storeu_pd(q.add(o), _mm256_permute2f128_pd::<0x20>(u0, u1));
            _mm256_storeu_pd(q.add(o + 4), _mm256_permute2f128_pd::<0x31>(u0, u1));
        }
    }
}

/// Columns 0..7 of the eight lines `cst[idx[k]]`.
#[inline(always)]
pub(crate) fn transpose8(cst: &[CircleState], idx: &[usize; W]) -> [F8; 8] {
    let p = cst.as_ptr();
    // SAFETY: every idx[k] < cst.len() (asserted by the caller); CircleState is repr(C), 64
    // bytes, 64-byte aligned, eight f64.
    unsafe {
        let z = _mm256_setzero_pd();
        let (mut lo, mut hi) = ([z; W], [z; W]);
        for k in 0..W {
            let q = p.add(idx[k]).cast::<f64>();
            lo[k] = _mm256_load_pd(q);
            hi[k] = _mm256_load_pd(q.add(4));
        }
        transpose_lines(lo, hi)
    }
}

/// The sixteen columns of the eight sphere lines `lines[idx[k]]` (two 64-byte lines each).
#[inline(always)]
pub(crate) fn transpose16(lines: &[crate::spheres::hm_batched::SphereLine], idx: &[usize; W]) -> [F8; 16] {
    let p = lines.as_ptr();
    // SAFETY: every idx[k] < lines.len() (asserted by the caller); SphereLine is repr(C), 128
    // bytes, 64-byte aligned.
    unsafe {
        let z = _mm256_setzero_pd();
        let mut r = [F8(z, z); 16];
        for part in 0..2 {
            let (mut lo, mut hi) = ([z; W], [z; W]);
            for k in 0..W {
                let q = p.add(idx[k]).cast::<f64>().add(8 * part);
                lo[k] = _mm256_load_pd(q);
                hi[k] = _mm256_load_pd(q.add(4));
            }
            r[8 * part..8 * part + 8].copy_from_slice(&transpose_lines(lo, hi));
        }
        r
    }
}

/// x, y and z lanes of eight packed (x, y, z) records.
#[inline(always)]
pub(crate) fn load3(p: &[[f64; 3]; W]) -> [F8; 3] {
    let mut c = [[0.0; W]; 3];
    for (k, rec) in p.iter().enumerate() {
        for (col, &v) in c.iter_mut().zip(rec) {
            col[k] = v;
        }
    }
    [F8::from_array(c[0]), F8::from_array(c[1]), F8::from_array(c[2])]
}

/// The inverse of [`load3`].
#[inline(always)]
pub(crate) fn store3(p: &mut [[f64; 3]; W], v: [F8; 3]) {
    let c = [v[0].to_array(), v[1].to_array(), v[2].to_array()];
    for (k, rec) in p.iter_mut().enumerate() {
        *rec = [c[0][k], c[1][k], c[2][k]];
    }
}

/// History k = [x y θ δp]: one register per history.
#[inline(always)]
pub(crate) fn hist_load(h: &[History; W]) -> (F8, F8, [F8; 2]) {
    let p = h.as_ptr().cast::<f64>();
    // SAFETY: eight repr(C) Histories = 32 f64, read as eight unaligned registers.
    unsafe {
        let mut r = [_mm256_setzero_pd(); W];
        for (k, v) in r.iter_mut().enumerate() {
            *v = _mm256_loadu_pd(p.add(4 * k));
        }
        let a = transpose4([r[0], r[1], r[2], r[3]]);
        let b = transpose4([r[4], r[5], r[6], r[7]]);
        (F8(a[0], b[0]), F8(a[1], b[1]), [F8(a[2], b[2]), F8(a[3], b[3])])
    }
}

/// Eight records of four f64 from four lane vectors (the inverse of [`hist_load`]).
#[inline(always)]
pub(crate) fn store4(h: &mut [[f64; 4]; W], v: [F8; 4]) {
    let a = transpose4([v[0].0, v[1].0, v[2].0, v[3].0]);
    let b = transpose4([v[0].1, v[1].1, v[2].1, v[3].1]);
    let p = h.as_mut_ptr().cast::<f64>();
    // SAFETY: writes the 32 f64 of `h`.
    unsafe {
        for k in 0..4 {
            _mm256_storeu_pd(p.add(4 * k), a[k]);
            _mm256_storeu_pd(p.add(16 + 4 * k), b[k]);
        }
    }
}
