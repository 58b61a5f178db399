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
    }

    impl M8 {
        /// `a` where the mask is set, else `b`.
        #[inline(always)]
        pub(crate) fn select(self, a: F8, b: F8) -> F8 {
            F8(unsafe { _mm512_mask_blend_pd(self.0, b.0, a.0) })
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
    }
}

pub(crate) use imp::{F8, M8};
