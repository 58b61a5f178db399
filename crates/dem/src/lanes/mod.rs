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

/// The whole build targets x86-64-v4 (`-C target-cpu=native` here): the AVX-512 copies are
/// called directly, without a `#[target_feature]` call in between.
pub(crate) const NATIVE_AVX512: bool = lbdem_core::simd::NATIVE_V4;

/// Whether the AVX-512 copies may run: `lbdem_core::simd` runs this process at x86-64-v4
/// (the CPU has every feature the copies' `#[target_feature]` entries enable). `LBDEM_ISA`
/// below v4 turns them off, except in a native build (`NATIVE_AVX512`), where every function
/// is compiled for v4 anyway.
///
/// The functions of `avx512` and of `crate::on_avx512` are safe to call only under this (or
/// `NATIVE_AVX512`); they are reached only through `pair_linear.rs` and `kick_disks.rs`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn avx512_ok() -> bool {
    lbdem_core::simd::level() == lbdem_core::simd::Level::V4
}
