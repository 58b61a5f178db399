//! Eight f64 lanes for the batched pair kernel. Every operation is the scalar IEEE operation
//! per lane (no fused multiply-add, same rounding), so a lane's bits equal the scalar code's.
//! With AVX-512 (`target-cpu=native` on this project's machines) a value is one register and
//! a mask one mask register; otherwise plain arrays the compiler may vectorise.

/// Lanes per batch (eight f64 = one AVX-512 register).
pub(crate) const W: usize = 8;

#[cfg(target_feature = "avx512f")]
mod imp {
    use super::W;
    use std::arch::x86_64::*;

    #[derive(Clone, Copy)]
    #[repr(transparent)]
    pub(crate) struct F8(pub(crate) __m512d);

    #[derive(Clone, Copy)]
    pub(crate) struct M8(__mmask8);

    // SAFETY (every `unsafe` below): avx512f is enabled for the whole build (the cfg above);
    // the intrinsics only touch registers except `from_array`/`to_array`, which read/write
    // one local [f64; 8].
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
        /// Lanes that are not in [lo, hi) (NaN included).
        #[inline(always)]
        pub(crate) fn outside(self, lo: F8, hi: F8) -> M8 {
            M8(unsafe {
                _mm512_cmp_pd_mask::<_CMP_NGE_UQ>(self.0, lo.0)
                    | _mm512_cmp_pd_mask::<_CMP_NLT_UQ>(self.0, hi.0)
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
        transpose_registers(r).map(F8::to_array)
    }

    /// 8 x 8 transpose kept in registers: lane k of result j is lane j of input k.
    #[inline(always)]
    pub(crate) fn transpose_registers(r: [F8; W]) -> [F8; W] {
        unsafe {
            let r = r.map(|v| v.0);
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
            c.map(F8)
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
    }
}

#[cfg(not(target_feature = "avx512f"))]
mod imp {
    use super::W;

    #[derive(Clone, Copy)]
    #[repr(C, align(64))]
    pub(crate) struct F8([f64; W]);

    /// Lane mask: all ones (true) or zero.
    #[derive(Clone, Copy)]
    #[repr(C, align(64))]
    pub(crate) struct M8([u64; W]);

    macro_rules! lanewise {
        ($tr:ident, $f:ident, $op:tt) => {
            impl std::ops::$tr for F8 {
                type Output = F8;
                #[inline(always)]
                fn $f(self, o: F8) -> F8 {
                    F8(std::array::from_fn(|k| self.0[k] $op o.0[k]))
                }
            }
        };
    }
    lanewise!(Add, add, +);
    lanewise!(Sub, sub, -);
    lanewise!(Mul, mul, *);
    lanewise!(Div, div, /);

    impl std::ops::Neg for F8 {
        type Output = F8;
        #[inline(always)]
        fn neg(self) -> F8 {
            F8(self.0.map(|v| -v))
        }
    }

    impl F8 {
        #[inline(always)]
        pub(crate) fn splat(v: f64) -> F8 {
            F8([v; W])
        }
        #[inline(always)]
        pub(crate) fn from_array(a: [f64; W]) -> F8 {
            F8(a)
        }
        #[inline(always)]
        pub(crate) fn to_array(self) -> [f64; W] {
            self.0
        }
        #[inline(always)]
        pub(crate) fn sqrt(self) -> F8 {
            F8(self.0.map(f64::sqrt))
        }
        #[inline(always)]
        pub(crate) fn abs(self) -> F8 {
            F8(self.0.map(f64::abs))
        }
        /// `f64::max(self, 0.0)` per lane.
        #[inline(always)]
        pub(crate) fn max0(self) -> F8 {
            F8(self.0.map(|v| v.max(0.0)))
        }
        /// Magnitude of self with the sign of `s`.
        #[inline(always)]
        pub(crate) fn copysign(self, s: F8) -> F8 {
            F8(std::array::from_fn(|k| self.0[k].copysign(s.0[k])))
        }
        #[inline(always)]
        pub(crate) fn lt(self, o: F8) -> M8 {
            M8(std::array::from_fn(|k| if self.0[k] < o.0[k] { !0 } else { 0 }))
        }
        #[inline(always)]
        pub(crate) fn gt(self, o: F8) -> M8 {
            M8(std::array::from_fn(|k| if self.0[k] > o.0[k] { !0 } else { 0 }))
        }
        #[inline(always)]
        pub(crate) fn ge(self, o: F8) -> M8 {
            M8(std::array::from_fn(|k| if self.0[k] >= o.0[k] { !0 } else { 0 }))
        }
        /// Lanes that are not in [lo, hi) (NaN included).
        #[inline(always)]
        pub(crate) fn outside(self, lo: F8, hi: F8) -> M8 {
            M8(std::array::from_fn(|k| {
                if !(self.0[k] >= lo.0[k] && self.0[k] < hi.0[k]) {
                    !0
                } else {
                    0
                }
            }))
        }
    }

    /// x and y lanes of eight (x, y) pairs.
    #[inline(always)]
    pub(crate) fn deinterleave(p: &[[f64; 2]; W]) -> (F8, F8) {
        (F8(p.map(|q| q[0])), F8(p.map(|q| q[1])))
    }

    /// Inverse of [`deinterleave`].
    #[inline(always)]
    pub(crate) fn interleave(x: F8, y: F8, p: &mut [[f64; 2]; W]) {
        for k in 0..W {
            p[k] = [x.0[k], y.0[k]];
        }
    }

    /// 8 x 8 transpose (lanes of column k become row k).
    #[inline(always)]
    pub(crate) fn transpose(r: [F8; W]) -> [[f64; W]; W] {
        std::array::from_fn(|k| std::array::from_fn(|f| r[f].0[k]))
    }

    impl M8 {
        /// `a` where the mask is set, else `b`.
        #[inline(always)]
        pub(crate) fn select(self, a: F8, b: F8) -> F8 {
            F8(std::array::from_fn(|k| {
                f64::from_bits((a.0[k].to_bits() & self.0[k]) | (b.0[k].to_bits() & !self.0[k]))
            }))
        }
        #[inline(always)]
        pub(crate) fn bit(self, k: usize) -> bool {
            self.0[k] != 0
        }
        /// Any lane set.
        #[inline(always)]
        pub(crate) fn any(self) -> bool {
            self.0.iter().any(|&m| m != 0)
        }
    }
}

#[cfg(target_feature = "avx512f")]
pub(crate) use imp::transpose_registers;
pub(crate) use imp::{F8, M8, deinterleave, interleave, transpose};
