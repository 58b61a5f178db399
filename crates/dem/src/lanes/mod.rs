//! Eight f64 lanes for the batched kernels (pairs of the linear and elastic-plastic laws, the
//! all-disk kick). Every operation is the scalar IEEE operation per lane (no fused multiply-add,
//! same rounding), so a lane's bits equal the scalar code's, whichever lane type runs.
//!
//! Three lane types with the same interface: [`avx512`] (one register per value, one mask
//! register per mask), [`avx2`] (two registers of four per value and per mask) and
//! [`portable`] (arrays the compiler vectorises). The kernels that use them are written once
//! and compiled for each (`crate::on_avx512`, `crate::on_avx2`, `crate::on_arrays`). Whole
//! passes (a chunk of disks, a chunk of pairs) are dispatched once by `lbdem_core::simd`; the
//! v4 copy takes the AVX-512 lanes ([`avx512_in`]), the v3 copy the AVX2 lanes ([`avx2_in`]),
//! the baseline copy the array lanes.

#[cfg(target_arch = "x86_64")]
pub(crate) mod avx2;
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx512;
pub(crate) mod portable;

/// Lanes per batch (eight f64 = one AVX-512 register).
pub(crate) const W: usize = 8;

/// Inside an op run by `lbdem_core::simd::dispatch`, compiled for level `S`: whether this copy
/// takes the AVX-512 lanes ([`avx512`], `crate::on_avx512`) instead of the array lanes. True in
/// the v4 copy (entered only where the CPU has AVX-512 and `LBDEM_ISA` allows it) and in every
/// copy of a build for an AVX-512 CPU; a constant in each copy, so a copy holds one lane type.
///
/// The functions of `avx512` and of `crate::on_avx512` are safe to run only under this.
#[inline(always)]
pub(crate) fn avx512_in<S: lbdem_core::simd::Simd>() -> bool {
    cfg!(target_arch = "x86_64") && lbdem_core::simd::is_v4::<S>()
}

/// Inside an op run by `lbdem_core::simd::dispatch`, compiled for level `S`: whether this copy
/// takes the AVX2 lanes ([`avx2`], `crate::on_avx2`): true in the v3 copy and in every copy of
/// a build for an AVX2 CPU without AVX-512; never where [`avx512_in`] is.
///
/// The functions of `avx2` and of `crate::on_avx2` are safe to run only under this.
#[inline(always)]
pub(crate) fn avx2_in<S: lbdem_core::simd::Simd>() -> bool {
    cfg!(target_arch = "x86_64") && lbdem_core::simd::is_v3::<S>()
}

/// The batch of `pairs` from `q`: how many are real (`m` ≤ W) and the i and j index of each
/// lane (lanes past the end repeat the last pair; the kernels store the first `m` only), every
/// index checked below `bodies`.
#[inline(always)]
pub(crate) fn batch(pairs: &[[u32; 2]], q: usize, bodies: usize) -> (usize, [usize; W], [usize; W]) {
    let m = (pairs.len() - q).min(W);
    let lane = |k: usize| q + k.min(m - 1);
    let ix: [usize; W] = std::array::from_fn(|k| pairs[lane(k)][0] as usize);
    let jx: [usize; W] = std::array::from_fn(|k| pairs[lane(k)][1] as usize);
    assert!(
        ix.iter().chain(&jx).all(|&c| c < bodies),
        "pair index out of range"
    );
    (m, ix, jx)
}

#[cfg(test)]
mod tests;
