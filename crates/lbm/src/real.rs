//! Storage precision of the populations, chosen per run (f64 by default, f32 for speed).

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
    /// Bit w set unless `lo < rho[w] < hi` and `usq[w] < um` (so NaN sets it): the kernels' range
    /// check of a block of B nodes. With AVX-512 it is three masked vector compares; left to
    /// itself the compiler split this reduction into scalar and part-width pieces that cost as
    /// much as the collision.
    fn bad_block<const B: usize>(rho: &[Self; B], usq: &[Self; B], lo: Self, hi: Self, um: Self) -> u32 {
        bad_scalar(rho, usq, lo, hi, um)
    }
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

impl Real for f64 {
    const NAME: &'static str = "f64";
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f64::mul_add(self, a, b)
    }
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
    #[inline(always)]
    fn bad_block<const B: usize>(rho: &[Self; B], usq: &[Self; B], lo: Self, hi: Self, um: Self) -> u32 {
        use std::arch::x86_64::*;
        if !B.is_multiple_of(8) || B > 32 {
            return bad_scalar(rho, usq, lo, hi, um);
        }
        let mut ok = 0u32;
        for k in 0..B / 8 {
            // SAFETY: 8 values from offset 8k < B; the target has AVX-512F (cfg).
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
}

impl Real for f32 {
    const NAME: &'static str = "f32";
    #[inline(always)]
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        f32::mul_add(self, a, b)
    }
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
    #[inline(always)]
    fn bad_block<const B: usize>(rho: &[Self; B], usq: &[Self; B], lo: Self, hi: Self, um: Self) -> u32 {
        use std::arch::x86_64::*;
        if !B.is_multiple_of(16) || B > 32 {
            return bad_scalar(rho, usq, lo, hi, um);
        }
        let mut ok = 0u32;
        for k in 0..B / 16 {
            // SAFETY: 16 values from offset 16k < B; the target has AVX-512F (cfg).
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
