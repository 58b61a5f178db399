//! Storage precision of the populations, chosen per run (f64 by default, f32 for speed).

use crate::LbmError;
use crate::lattice::Lattice;
use crate::stepper::{Fluid, Macro, Stepper};
use crate::stepper_aa::StepperAa;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

/// Floating-point type the populations are stored and updated in.
pub trait Real:
    Copy
    + Send
    + Sync
    + Default
    + PartialOrd
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + serde::Serialize
    + serde::de::DeserializeOwned
    + 'static
{
    const NAME: &'static str;
    fn from_f64(x: f64) -> Self;
    fn to_f64(self) -> f64;
    /// Fused `self * a + b`, one rounding (one FMA instruction with `target-cpu=native`). Used
    /// explicitly where the kernels want it, so every code path (blocks of nodes, single nodes,
    /// both kernels) rounds the same way: results stay bitwise reproducible.
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// Square root (IEEE, correctly rounded: the same bits on every code path).
    fn sqrt(self) -> Self;
    /// Bit w set unless `lo < rho[w] < hi` and `usq[w] < um` (so NaN sets it): the kernels' range
    /// check of a block of B nodes. With AVX-512 it is three masked vector compares; left to
    /// itself the compiler split this reduction into scalar and part-width pieces that cost as
    /// much as the collision.
    fn bad_block<const B: usize>(rho: &[Self; B], usq: &[Self; B], lo: Self, hi: Self, um: Self) -> u32 {
        bad_scalar(rho, usq, lo, hi, um)
    }
    /// One two-array step: the lattice's compiled step of this precision (`compiled`).
    fn step_two<L: Lattice>(
        st: &mut Stepper<L, Self>,
        fluid: &mut Fluid<L, Self>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError>;
    /// One AA step: the lattice's compiled step of this precision (`compiled`).
    fn step_aa<L: Lattice>(
        st: &mut StepperAa<L, Self>,
        fluid: &mut Fluid<L, Self>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError>;
}

/// Mask of the low `b` bits (b <= 32).
#[inline(always)]
pub const fn lanes(b: usize) -> u32 {
    if b >= 32 { u32::MAX } else { (1u32 << b) - 1 }
}

/// Portable form of `Real::bad_block` (B <= 32).
#[inline(always)]
pub fn bad_scalar<T: Real, const B: usize>(rho: &[T; B], usq: &[T; B], lo: T, hi: T, um: T) -> u32 {
    let mut bits = 0u32;
    for w in 0..B {
        let ok = (rho[w] > lo) & (rho[w] < hi) & (usq[w] < um);
        bits |= u32::from(!ok) << w;
    }
    bits
}

/// The two precisions differ only in which compiled kernels they forward to (`compiled.rs`
/// instantiates each once) and which AVX-512 range check they use.
macro_rules! real_impl {
    ($t:ident, $step_two:ident, $step_aa:ident, $bad_block:ident, $lanes_v3:literal) => {
        impl Real for $t {
            const NAME: &'static str = stringify!($t);
            #[inline(always)]
            fn step_two<L: Lattice>(
                st: &mut Stepper<L, Self>,
                fluid: &mut Fluid<L, Self>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                L::$step_two(st, fluid, out)
            }
            #[inline(always)]
            fn step_aa<L: Lattice>(
                st: &mut StepperAa<L, Self>,
                fluid: &mut Fluid<L, Self>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                L::$step_aa(st, fluid, out)
            }
            #[inline(always)]
            fn from_f64(x: f64) -> Self {
                x as $t
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline(always)]
            fn mul_add(self, a: Self, b: Self) -> Self {
                $t::mul_add(self, a, b)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $t::sqrt(self)
            }
            #[inline(always)]
            fn bad_block<const B: usize>(
                rho: &[Self; B],
                usq: &[Self; B],
                lo: Self,
                hi: Self,
                um: Self,
            ) -> u32 {
                #[cfg(target_arch = "x86_64")]
                if avx512() {
                    // SAFETY: the CPU has AVX-512F (`avx512`).
                    return unsafe { v4::$bad_block(rho, usq, lo, hi, um) };
                }
                #[cfg(target_arch = "x86_64")]
                if avx2() && B.is_multiple_of($lanes_v3) && B <= 32 {
                    // SAFETY: the CPU has AVX2 (`avx2`).
                    return unsafe { v3::$bad_block(rho, usq, lo, hi, um) };
                }
                bad_scalar(rho, usq, lo, hi, um)
            }
        }
    };
}

real_impl!(f64, step_two_f64, step_aa_f64, bad_block_f64, 4);
real_impl!(f32, step_two_f32, step_aa_f32, bad_block_f32, 8);

/// Whether the AVX-512 range check may run: always in a `target-cpu=native` build for an
/// AVX-512 CPU, else when `lbdem_core::simd` runs the kernels at that level (a `OnceLock` read
/// per block of 16 or 32 nodes; in the other levels' copies the branch is never taken).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn avx512() -> bool {
    cfg!(target_feature = "avx512f") || lbdem_core::simd::level() == lbdem_core::simd::Level::V4
}

/// Whether the AVX2 range check may run (as [`avx512`]: a build for such a CPU, or the kernels
/// run at level v3 or above).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn avx2() -> bool {
    cfg!(target_feature = "avx2") || lbdem_core::simd::level() >= lbdem_core::simd::Level::V3
}

/// The range check as three vector compares and a sign-mask extraction per 256-bit register:
/// what `bad_scalar` should compile to with AVX2 but did not (it split the reduction into scalar
/// compares; on a CPU without AVX-512 every kernel took that path). Inlined into the AVX2 copy of
/// a kernel (`#[target_feature]` on the copy includes AVX).
#[cfg(target_arch = "x86_64")]
mod v3 {
    use super::lanes;
    use std::arch::x86_64::*;

    /// # Safety
    /// AVX present; B a multiple of 4, at most 32.
    #[target_feature(enable = "avx")]
    #[inline]
    pub(super) unsafe fn bad_block_f64<const B: usize>(
        rho: &[f64; B],
        usq: &[f64; B],
        lo: f64,
        hi: f64,
        um: f64,
    ) -> u32 {
        let mut ok = 0u32;
        for k in 0..B / 4 {
            // SAFETY: 4 values from offset 4k < B; the caller checked AVX.
            let m = unsafe {
                let r = _mm256_loadu_pd(rho.as_ptr().add(4 * k));
                let u = _mm256_loadu_pd(usq.as_ptr().add(4 * k));
                let a = _mm256_cmp_pd::<_CMP_GT_OQ>(r, _mm256_set1_pd(lo));
                let b = _mm256_cmp_pd::<_CMP_LT_OQ>(r, _mm256_set1_pd(hi));
                let c = _mm256_cmp_pd::<_CMP_LT_OQ>(u, _mm256_set1_pd(um));
                _mm256_movemask_pd(_mm256_and_pd(_mm256_and_pd(a, b), c)) as u32
            };
            ok |= m << (4 * k);
        }
        !ok & lanes(B)
    }

    /// # Safety
    /// AVX present; B a multiple of 8, at most 32.
    #[target_feature(enable = "avx")]
    #[inline]
    pub(super) unsafe fn bad_block_f32<const B: usize>(
        rho: &[f32; B],
        usq: &[f32; B],
        lo: f32,
        hi: f32,
        um: f32,
    ) -> u32 {
        let mut ok = 0u32;
        for k in 0..B / 8 {
            // SAFETY: 8 values from offset 8k < B; the caller checked AVX.
            let m = unsafe {
                let r = _mm256_loadu_ps(rho.as_ptr().add(8 * k));
                let u = _mm256_loadu_ps(usq.as_ptr().add(8 * k));
                let a = _mm256_cmp_ps::<_CMP_GT_OQ>(r, _mm256_set1_ps(lo));
                let b = _mm256_cmp_ps::<_CMP_LT_OQ>(r, _mm256_set1_ps(hi));
                let c = _mm256_cmp_ps::<_CMP_LT_OQ>(u, _mm256_set1_ps(um));
                _mm256_movemask_ps(_mm256_and_ps(_mm256_and_ps(a, b), c)) as u32
            };
            ok |= m << (8 * k);
        }
        !ok & lanes(B)
    }
}

/// The range check as three masked vector compares per register. Callable from any code
/// (`#[target_feature]`); inlined into the AVX-512 copy of a kernel.
#[cfg(target_arch = "x86_64")]
mod v4 {
    use super::{bad_scalar, lanes};
    use std::arch::x86_64::*;

    #[target_feature(enable = "avx512f")]
    #[inline]
    pub(super) unsafe fn bad_block_f64<const B: usize>(
        rho: &[f64; B],
        usq: &[f64; B],
        lo: f64,
        hi: f64,
        um: f64,
    ) -> u32 {
        if !B.is_multiple_of(8) || B > 32 {
            return bad_scalar(rho, usq, lo, hi, um);
        }
        let mut ok = 0u32;
        for k in 0..B / 8 {
            // SAFETY: 8 values from offset 8k < B; the caller checked AVX-512F.
            let m = unsafe {
                let r = _mm512_loadu_pd(rho.as_ptr().add(8 * k));
                let u = _mm512_loadu_pd(usq.as_ptr().add(8 * k));
                let m = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(r, _mm512_set1_pd(lo));
                let m = _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(m, r, _mm512_set1_pd(hi));
                _mm512_mask_cmp_pd_mask::<_CMP_LT_OQ>(m, u, _mm512_set1_pd(um))
            };
            ok |= u32::from(m) << (8 * k);
        }
        !ok & lanes(B)
    }

    #[target_feature(enable = "avx512f")]
    #[inline]
    pub(super) unsafe fn bad_block_f32<const B: usize>(
        rho: &[f32; B],
        usq: &[f32; B],
        lo: f32,
        hi: f32,
        um: f32,
    ) -> u32 {
        if !B.is_multiple_of(16) || B > 32 {
            return bad_scalar(rho, usq, lo, hi, um);
        }
        let mut ok = 0u32;
        for k in 0..B / 16 {
            // SAFETY: 16 values from offset 16k < B; the caller checked AVX-512F.
            let m = unsafe {
                let r = _mm512_loadu_ps(rho.as_ptr().add(16 * k));
                let u = _mm512_loadu_ps(usq.as_ptr().add(16 * k));
                let m = _mm512_cmp_ps_mask::<_CMP_GT_OQ>(r, _mm512_set1_ps(lo));
                let m = _mm512_mask_cmp_ps_mask::<_CMP_LT_OQ>(m, r, _mm512_set1_ps(hi));
                _mm512_mask_cmp_ps_mask::<_CMP_LT_OQ>(m, u, _mm512_set1_ps(um))
            };
            ok |= u32::from(m) << (16 * k);
        }
        !ok & lanes(B)
    }
}
