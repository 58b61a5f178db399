//! How the in-place AA kernel stores its populations, apart from the precision it computes in.
//!
//! A stream-collide step is bound by memory traffic on large lattices: each node update moves
//! 2Q stored values. Storing them in fewer bits moves fewer bytes, and the collision can still run
//! in the wider arithmetic type `T` (Lehmann et al. 2022, "Accuracy and performance of the lattice
//! Boltzmann method with 64-bit, 32-bit, and customized 16-bit number formats", Phys. Rev. E 106,
//! 015308: FP32 arithmetic on FP16 storage gave FP32 accuracy on most cases). The key to keeping
//! the answer is to store the *deviation* from the rest populations, f_i − w_i, instead of f_i: at
//! low Mach number f_i = w_i (1 + O(δρ, c·u)) and the stored number then carries only the small
//! part, so its relative rounding (2⁻²⁴ in f32, 2⁻¹¹ in f16) applies to δρ and c·u, not to 1
//! (Lehmann et al. Sec. II.B, "DDF-shifting"; Skordos 1993).
//!
//! [`Storage`] is that choice: `T` itself (unshifted, the kernels as before, bit for bit),
//! [`ShiftedF32`] (f32 storage of f − w, f64 arithmetic: about the f64 answer at the f32 bytes)
//! and [`ShiftedF16`] (IEEE binary16 storage of f − w, f32 arithmetic: a quarter of the f64
//! bytes). The storage converts to and from the arithmetic type only when a block is gathered and
//! scattered, so the collision is the same code for every storage.

use crate::LbmError;
use crate::lattice::{Lattice, QMAX};
use crate::real::Real;
use crate::stepper::{Fluid, Macro};
use crate::stepper_aa::StepperAa;

/// Element type of the AA stepper's population array, with arithmetic type `T`.
pub trait Storage<T: Real>: Copy + Send + Sync + Default + std::fmt::Debug + 'static {
    /// Name of the precision as users choose it ([`Precision`]).
    const NAME: &'static str;
    /// Whether the stored value is f_i − w_i (false: f_i itself).
    const SHIFTED: bool;
    /// Whether the kernels run in copies compiled with F16C where the CPU has it
    /// (`lbdem_core::simd::dispatch_f16c`), so that this storage's conversions inline.
    const F16C: bool = false;
    /// The stored form of `v` (already shifted when `SHIFTED`), rounded to nearest.
    fn encode(v: T) -> Self;
    /// The value in the arithmetic type (still shifted when `SHIFTED`).
    fn decode(self) -> T;

    /// Read population i of node `node` of `f`: f_i in the arithmetic type.
    ///
    /// # Safety
    /// `f.add(k)` must be a valid read.
    #[inline(always)]
    unsafe fn load<L: Lattice>(f: *const Self, k: usize, i: usize) -> T {
        let v = unsafe { *f.add(k) }.decode();
        if Self::SHIFTED {
            v + T::from_f64(L::W[i])
        } else {
            v
        }
    }

    /// Write f_i as population i at `f + k`.
    ///
    /// # Safety
    /// `f.add(k)` must be a valid, unshared write.
    #[inline(always)]
    unsafe fn store<L: Lattice>(f: *mut Self, k: usize, i: usize, v: T) {
        let v = if Self::SHIFTED {
            v - T::from_f64(L::W[i])
        } else {
            v
        };
        unsafe { *f.add(k) = Self::encode(v) };
    }

    /// Gather `B` consecutive values of each direction i < Q from `f + src[i] + x` into `out[i]`.
    ///
    /// # Safety
    /// Every read must be in bounds.
    #[inline(always)]
    unsafe fn gather<L: Lattice, const B: usize>(
        f: *const Self,
        src: &[usize; QMAX],
        x: usize,
        out: &mut [[T; B]; QMAX],
    ) {
        for (i, fi) in out.iter_mut().enumerate().take(L::Q) {
            let p = unsafe { f.add(src[i].wrapping_add(x)) };
            let w = T::from_f64(L::W[i]);
            for (k, v) in fi.iter_mut().enumerate() {
                let d = unsafe { *p.add(k) }.decode();
                *v = if Self::SHIFTED { d + w } else { d };
            }
        }
    }

    /// Scatter `B` values of each direction i < Q from `vals[i]` to `f + dst[i] + x`.
    ///
    /// # Safety
    /// Every write must be in bounds and unshared.
    #[inline(always)]
    unsafe fn scatter<L: Lattice, const B: usize>(
        f: *mut Self,
        dst: &[usize; QMAX],
        x: usize,
        vals: &[[T; B]; QMAX],
    ) {
        for (i, fi) in vals.iter().enumerate().take(L::Q) {
            let p = unsafe { f.add(dst[i].wrapping_add(x)) };
            let w = T::from_f64(L::W[i]);
            for (k, &v) in fi.iter().enumerate() {
                let s = if Self::SHIFTED { v - w } else { v };
                unsafe { *p.add(k) = Self::encode(s) };
            }
        }
    }

    /// One AA step of this storage (the lattice's compiled step: `compiled`).
    fn step_aa<L: Lattice>(
        st: &mut StepperAa<L, T, Self>,
        fluid: &mut Fluid<L, T>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError>;
}

/// The arithmetic type stored as itself: the kernels as they were (identical bits).
impl<T: Real> Storage<T> for T {
    const NAME: &'static str = T::NAME;
    const SHIFTED: bool = false;
    #[inline(always)]
    fn encode(v: T) -> Self {
        v
    }
    #[inline(always)]
    fn decode(self) -> T {
        self
    }
    #[inline(always)]
    unsafe fn gather<L: Lattice, const B: usize>(
        f: *const Self,
        src: &[usize; QMAX],
        x: usize,
        out: &mut [[T; B]; QMAX],
    ) {
        for (i, fi) in out.iter_mut().enumerate().take(L::Q) {
            unsafe { std::ptr::copy_nonoverlapping(f.add(src[i].wrapping_add(x)), fi.as_mut_ptr(), B) };
        }
    }
    #[inline(always)]
    unsafe fn scatter<L: Lattice, const B: usize>(
        f: *mut Self,
        dst: &[usize; QMAX],
        x: usize,
        vals: &[[T; B]; QMAX],
    ) {
        for (i, fi) in vals.iter().enumerate().take(L::Q) {
            unsafe { std::ptr::copy_nonoverlapping(fi.as_ptr(), f.add(dst[i].wrapping_add(x)), B) };
        }
    }
    #[inline(always)]
    fn step_aa<L: Lattice>(
        st: &mut StepperAa<L, T, Self>,
        fluid: &mut Fluid<L, T>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError> {
        T::step_aa(st, fluid, out)
    }
}

/// f_i − w_i stored in f32, arithmetic in f64: 4 bytes per population. The deviation is below
/// about 0.5 w_i at any admitted state (|u| < 0.4), so its f32 rounding, 2⁻²⁴ relative, is at
/// most about 3·10⁻⁸ w_i absolute, against 6·10⁻⁸ w_i for f_i itself in f32 and 1·10⁻¹⁶ in f64.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(transparent)]
pub struct ShiftedF32(pub f32);

impl Storage<f64> for ShiftedF32 {
    const NAME: &'static str = "f32s";
    const SHIFTED: bool = true;
    #[inline(always)]
    fn encode(v: f64) -> Self {
        ShiftedF32(v as f32)
    }
    #[inline(always)]
    fn decode(self) -> f64 {
        self.0 as f64
    }
    #[inline(always)]
    unsafe fn gather<L: Lattice, const B: usize>(
        f: *const Self,
        src: &[usize; QMAX],
        x: usize,
        out: &mut [[f64; B]; QMAX],
    ) {
        #[cfg(target_arch = "x86_64")]
        if B.is_multiple_of(4) && avx::available() {
            // SAFETY: the CPU has AVX; reads as the caller guarantees.
            return unsafe { avx::gather::<L, B>(f.cast(), src, x, out) };
        }
        for (i, fi) in out.iter_mut().enumerate().take(L::Q) {
            let p = unsafe { f.add(src[i].wrapping_add(x)) };
            for (k, v) in fi.iter_mut().enumerate() {
                *v = unsafe { *p.add(k) }.decode() + L::W[i];
            }
        }
    }
    #[inline(always)]
    unsafe fn scatter<L: Lattice, const B: usize>(
        f: *mut Self,
        dst: &[usize; QMAX],
        x: usize,
        vals: &[[f64; B]; QMAX],
    ) {
        #[cfg(target_arch = "x86_64")]
        if B.is_multiple_of(4) && avx::available() {
            // SAFETY: the CPU has AVX; writes as the caller guarantees.
            return unsafe { avx::scatter::<L, B>(f.cast(), dst, x, vals) };
        }
        for (i, fi) in vals.iter().enumerate().take(L::Q) {
            let p = unsafe { f.add(dst[i].wrapping_add(x)) };
            for (k, &v) in fi.iter().enumerate() {
                unsafe { *p.add(k) = Self::encode(v - L::W[i]) };
            }
        }
    }
    #[inline(always)]
    fn step_aa<L: Lattice>(
        st: &mut StepperAa<L, f64, Self>,
        fluid: &mut Fluid<L, f64>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError> {
        L::step_aa_f32s(st, fluid, out)
    }
}

/// f_i − w_i stored in IEEE binary16 (`half::f16`, 11 significant bits), arithmetic in f32: 2
/// bytes per population. Rounded to nearest even both in hardware (F16C, taken whenever the
/// CPU has it: every x86-64-v3 CPU) and in `half`'s software conversion, so both give the same
/// bits. Values below 2⁻¹⁴ are kept as subnormals (absolute step 2⁻²⁴ ≈ 6·10⁻⁸).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(transparent)]
pub struct ShiftedF16(pub half::f16);

impl ShiftedF16 {
    /// The stored bits (IEEE binary16).
    pub fn to_bits(self) -> u16 {
        self.0.to_bits()
    }
    pub fn from_bits(bits: u16) -> Self {
        ShiftedF16(half::f16::from_bits(bits))
    }
}

impl Storage<f32> for ShiftedF16 {
    const NAME: &'static str = "f16s";
    const SHIFTED: bool = true;
    const F16C: bool = true;
    #[inline(always)]
    fn encode(v: f32) -> Self {
        ShiftedF16(half::f16::from_f32(v))
    }
    #[inline(always)]
    fn decode(self) -> f32 {
        self.0.to_f32()
    }
    #[inline(always)]
    unsafe fn gather<L: Lattice, const B: usize>(
        f: *const Self,
        src: &[usize; QMAX],
        x: usize,
        out: &mut [[f32; B]; QMAX],
    ) {
        #[cfg(target_arch = "x86_64")]
        if B.is_multiple_of(8) && f16c::available() {
            // SAFETY: the CPU has F16C and AVX; reads as the caller guarantees.
            return unsafe { f16c::gather::<L, B>(f.cast(), src, x, out) };
        }
        for (i, fi) in out.iter_mut().enumerate().take(L::Q) {
            let p = unsafe { f.add(src[i].wrapping_add(x)) };
            let w = L::W[i] as f32;
            for (k, v) in fi.iter_mut().enumerate() {
                *v = unsafe { *p.add(k) }.decode() + w;
            }
        }
    }
    #[inline(always)]
    unsafe fn scatter<L: Lattice, const B: usize>(
        f: *mut Self,
        dst: &[usize; QMAX],
        x: usize,
        vals: &[[f32; B]; QMAX],
    ) {
        #[cfg(target_arch = "x86_64")]
        if B.is_multiple_of(8) && f16c::available() {
            // SAFETY: the CPU has F16C and AVX; writes as the caller guarantees.
            return unsafe { f16c::scatter::<L, B>(f.cast(), dst, x, vals) };
        }
        for (i, fi) in vals.iter().enumerate().take(L::Q) {
            let p = unsafe { f.add(dst[i].wrapping_add(x)) };
            let w = L::W[i] as f32;
            for (k, &v) in fi.iter().enumerate() {
                unsafe { *p.add(k) = Self::encode(v - w) };
            }
        }
    }
    #[inline(always)]
    fn step_aa<L: Lattice>(
        st: &mut StepperAa<L, f32, Self>,
        fluid: &mut Fluid<L, f32>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError> {
        L::step_aa_f16s(st, fluid, out)
    }
}

/// Whole-block conversions with the F16C instructions (8 values per instruction), a block of nodes
/// for all Q directions at a time. pulp's x86-64-v3 level does not enable F16C, so this storage's
/// kernels run in a v3 copy compiled with F16C as well (`Storage::F16C`,
/// `lbdem_core::simd::dispatch_f16c`; AVX-512 implies F16C) and these inline into it; from the
/// portable copy they are a call per block.
#[cfg(target_arch = "x86_64")]
mod f16c {
    use crate::lattice::{Lattice, QMAX};
    use std::arch::x86_64::*;

    /// The CPU has F16C and AVX (detected once; a cached load afterwards).
    #[inline(always)]
    pub(super) fn available() -> bool {
        cfg!(all(target_feature = "f16c", target_feature = "avx"))
            || (std::arch::is_x86_feature_detected!("f16c") && std::arch::is_x86_feature_detected!("avx"))
    }

    /// # Safety
    /// F16C and AVX present; `B` a multiple of 8; reads in bounds.
    #[target_feature(enable = "avx,f16c")]
    #[inline]
    pub(super) unsafe fn gather<L: Lattice, const B: usize>(
        f: *const u16,
        src: &[usize; QMAX],
        x: usize,
        out: &mut [[f32; B]; QMAX],
    ) {
        for i in 0..L::Q {
            let p = unsafe { f.add(src[i].wrapping_add(x)) };
            let w = _mm256_set1_ps(L::W[i] as f32);
            for k in (0..B).step_by(8) {
                // SAFETY: 8 values from p + k, in bounds (caller); `out[i][k..k + 8]` exists.
                unsafe {
                    let h = _mm_loadu_si128(p.add(k).cast());
                    let v = _mm256_add_ps(_mm256_cvtph_ps(h), w);
                    _mm256_storeu_ps(out[i].as_mut_ptr().add(k), v);
                }
            }
        }
    }

    /// # Safety
    /// F16C and AVX present; `B` a multiple of 8; writes in bounds and unshared.
    #[target_feature(enable = "avx,f16c")]
    #[inline]
    pub(super) unsafe fn scatter<L: Lattice, const B: usize>(
        f: *mut u16,
        dst: &[usize; QMAX],
        x: usize,
        vals: &[[f32; B]; QMAX],
    ) {
        for i in 0..L::Q {
            let p = unsafe { f.add(dst[i].wrapping_add(x)) };
            let w = _mm256_set1_ps(L::W[i] as f32);
            for k in (0..B).step_by(8) {
                // SAFETY: as in `gather`.
                unsafe {
                    let v = _mm256_sub_ps(_mm256_loadu_ps(vals[i].as_ptr().add(k)), w);
                    let h = _mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(v);
                    _mm_storeu_si128(p.add(k).cast(), h);
                }
            }
        }
    }
}

/// f32 ↔ f64 block conversions with AVX (4 values per instruction). Left to itself the compiler
/// converted the 16-node blocks of the AVX2 copy one value at a time (`vcvtss2sd`, 2026-11-29
/// `perf annotate`: f32s ran at 65 MLUPS against 100 for f64 at 4096² on one thread). Inlined into
/// the kernel's AVX2 and AVX-512 copies (their `#[target_feature]` includes AVX); taken only when
/// the kernels run at level v3 or above, so the portable copy stays portable. `vcvtpd2ps` rounds to
/// nearest even as `as f32` does: the same bits.
#[cfg(target_arch = "x86_64")]
mod avx {
    use crate::lattice::{Lattice, QMAX};
    use std::arch::x86_64::*;

    #[inline(always)]
    pub(super) fn available() -> bool {
        cfg!(target_feature = "avx") || lbdem_core::simd::level() >= lbdem_core::simd::Level::V3
    }

    /// # Safety
    /// AVX present; `B` a multiple of 4; reads in bounds.
    #[target_feature(enable = "avx")]
    #[inline]
    pub(super) unsafe fn gather<L: Lattice, const B: usize>(
        f: *const f32,
        src: &[usize; QMAX],
        x: usize,
        out: &mut [[f64; B]; QMAX],
    ) {
        for i in 0..L::Q {
            let p = unsafe { f.add(src[i].wrapping_add(x)) };
            let w = _mm256_set1_pd(L::W[i]);
            for k in (0..B).step_by(4) {
                // SAFETY: 4 values from p + k, in bounds (caller); `out[i][k..k + 4]` exists.
                unsafe {
                    let v = _mm256_add_pd(_mm256_cvtps_pd(_mm_loadu_ps(p.add(k))), w);
                    _mm256_storeu_pd(out[i].as_mut_ptr().add(k), v);
                }
            }
        }
    }

    /// # Safety
    /// AVX present; `B` a multiple of 4; writes in bounds and unshared.
    #[target_feature(enable = "avx")]
    #[inline]
    pub(super) unsafe fn scatter<L: Lattice, const B: usize>(
        f: *mut f32,
        dst: &[usize; QMAX],
        x: usize,
        vals: &[[f64; B]; QMAX],
    ) {
        for i in 0..L::Q {
            let p = unsafe { f.add(dst[i].wrapping_add(x)) };
            let w = _mm256_set1_pd(L::W[i]);
            for k in (0..B).step_by(4) {
                // SAFETY: as in `gather`.
                unsafe {
                    let v = _mm256_sub_pd(_mm256_loadu_pd(vals[i].as_ptr().add(k)), w);
                    _mm_storeu_ps(p.add(k), _mm256_cvtpd_ps(v));
                }
            }
        }
    }
}

/// The precisions a run may choose (`Precision::from_str` takes the names users write).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// f64 storage and arithmetic (8 bytes per population).
    F64,
    /// f32 storage and arithmetic (4 bytes).
    F32,
    /// f32 storage of f − w, f64 arithmetic (4 bytes; [`ShiftedF32`]); AA kernel only.
    F32s,
    /// binary16 storage of f − w, f32 arithmetic (2 bytes; [`ShiftedF16`]); AA kernel only.
    F16s,
}

impl Precision {
    pub const ALL: [Precision; 4] = [Precision::F64, Precision::F32, Precision::F32s, Precision::F16s];
    pub fn name(self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
            Precision::F32s => ShiftedF32::NAME,
            Precision::F16s => ShiftedF16::NAME,
        }
    }
    /// Bytes per stored population.
    pub fn bytes(self) -> usize {
        match self {
            Precision::F64 => 8,
            Precision::F32 | Precision::F32s => 4,
            Precision::F16s => 2,
        }
    }
    /// The arithmetic type's name ("f64" or "f32").
    pub fn arithmetic(self) -> &'static str {
        match self {
            Precision::F64 | Precision::F32s => "f64",
            Precision::F32 | Precision::F16s => "f32",
        }
    }
}

/// A precision name that is not one of [`Precision::ALL`].
#[derive(Debug, thiserror::Error)]
#[error(
    "precision {0:?} is not known; use \"f64\", \"f32\", \"f32s\" (f32 storage of f - w, f64 arithmetic, AA \
     kernel) or \"f16s\" (16-bit storage of f - w, f32 arithmetic, AA kernel)"
)]
pub struct UnknownPrecision(pub String);

impl std::str::FromStr for Precision {
    type Err = UnknownPrecision;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim().to_ascii_lowercase();
        Precision::ALL
            .into_iter()
            .find(|p| p.name() == t)
            .ok_or_else(|| UnknownPrecision(s.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::D2Q9;

    #[test]
    fn precision_names_round_trip_and_unknown_is_refused() {
        for p in Precision::ALL {
            assert_eq!(p.name().parse::<Precision>().unwrap(), p);
        }
        assert_eq!(" F16S ".parse::<Precision>().unwrap(), Precision::F16s);
        let e = "f16".parse::<Precision>().unwrap_err().to_string();
        assert!(e.contains("\"f16\"") && e.contains("f16s"), "{e}");
    }

    /// The F16C block conversion and `half`'s software conversion give the same bits on every
    /// value class the kernel stores (normal, subnormal, zero, both signs, ties).
    #[test]
    fn f16_block_conversion_matches_software() {
        const B: usize = 16;
        let mut vals = [[0f32; B]; QMAX];
        let mut seed = 12345u32;
        for i in 0..9 {
            for k in 0..B {
                seed = seed.wrapping_mul(1664525).wrapping_add(1013904223);
                let e = (seed >> 24) as i32 % 30 - 26; // 2^-26 .. 2^3
                let m = 1.0 + (seed & 0xffff) as f32 / 65536.0;
                let s = if seed & 0x10000 != 0 { -1.0 } else { 1.0 };
                // every fourth value sits exactly on a tie of binary16 rounding
                let v = if k % 4 == 0 {
                    s * (1.0 + (2 * (seed & 0x3ff) + 1) as f32 / 2048.0) * 2f32.powi(e)
                } else {
                    s * m * 2f32.powi(e)
                };
                vals[i][k] = v + D2Q9::W[i] as f32;
            }
        }
        vals[0][1] = D2Q9::W[0] as f32; // zero deviation
        let idx: [usize; QMAX] = std::array::from_fn(|i| i * B);
        let mut fast = vec![ShiftedF16::default(); 9 * B];
        let mut slow = vec![ShiftedF16::default(); 9 * B];
        let mut back_fast = [[0f32; B]; QMAX];
        let mut back_slow = [[0f32; B]; QMAX];
        unsafe {
            <ShiftedF16 as Storage<f32>>::scatter::<D2Q9, B>(fast.as_mut_ptr(), &idx, 0, &vals);
            <ShiftedF16 as Storage<f32>>::gather::<D2Q9, B>(fast.as_ptr(), &idx, 0, &mut back_fast);
        }
        for i in 0..9 {
            for k in 0..B {
                slow[i * B + k] = ShiftedF16::encode(vals[i][k] - D2Q9::W[i] as f32);
                back_slow[i][k] = slow[i * B + k].decode() + D2Q9::W[i] as f32;
            }
        }
        assert_eq!(fast, slow);
        assert_eq!(back_fast, back_slow);
    }
}
