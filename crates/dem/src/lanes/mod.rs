//! Eight f64 lanes for the batched kernels (pairs of the linear law, the all-disk kick). Every
//! operation is the scalar IEEE operation per lane (no fused multiply-add, same rounding), so a
//! lane's bits equal the scalar code's, whichever lane type runs.
//!
//! Two lane types with the same interface: [`avx512`] (one register per value, one mask
//! register per mask) and [`portable`] (arrays the compiler vectorises). The kernels that use
//! them are written once and compiled for each (`crate::on_avx512`, `crate::on_arrays`); the
//! AVX-512 copy runs when [`avx512_ok`], the array copy otherwise, itself compiled for every
//! level of `lbdem_core::simd`.

#[cfg(target_arch = "x86_64")]
pub(crate) mod avx512;
pub(crate) mod portable;

/// Lanes per batch (eight f64 = one AVX-512 register).
pub(crate) const W: usize = 8;

/// The whole build targets a CPU with AVX-512 F and DQ (`-C target-cpu=native` here): the
/// AVX-512 copies are called directly, without a `#[target_feature]` call in between.
pub(crate) const NATIVE_AVX512: bool = cfg!(all(target_feature = "avx512f", target_feature = "avx512dq"));

/// Whether the AVX-512 copies may run: the build targets such a CPU, or `lbdem_core::simd`
/// runs this process at x86-64-v4 (detected on the CPU, not capped by `LBDEM_ISA`).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn avx512_ok() -> bool {
    NATIVE_AVX512 || lbdem_core::simd::level() == lbdem_core::simd::Level::V4
}
