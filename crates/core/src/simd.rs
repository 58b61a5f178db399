//! The instruction set the kernels run with, chosen once at run time, so that one binary runs
//! on any x86-64 and still takes AVX-512 (x86-64-v4) or AVX2 + FMA (v3) where the CPU has them.
//!
//! A kernel is written once, as portable Rust the compiler auto-vectorises, and called through
//! [`dispatch`]: `pulp` compiles it once per level inside a `#[target_feature]` function and
//! picks the best level the CPU reports. Every level gives the same bits: Rust never contracts
//! `a * b + c` into a fused multiply-add on its own (the kernels' explicit `mul_add` is
//! correctly rounded on every level, in hardware or in libm) and never reorders a
//! floating-point sum, so vector width changes how fast a kernel runs, not what it computes.
//! `LBDEM_ISA=portable` forces the baseline path in a portable build (for users who suspect a
//! miscompiled path, and for bit comparisons); a level above what the CPU has is never taken.
//! A native build compiles every function for its CPU already: there the cap changes nothing,
//! and the command line says so.
//!
//! A pass with hand-written AVX-512 code (the DEM lane kernels) asks [`is_v4`] inside its op,
//! a constant in each compiled copy, and takes that code only in the v4 copy.
//!
//! The default build (`.cargo/config.toml`, no `target-cpu`) is this portable one: within a few
//! per cent of a native build on the LBM and DEM benches (docs/performance.md, "Portable
//! binaries"). A native build compiles every level alike ([`NATIVE_V4`]).

use std::sync::OnceLock;

pub use pulp::{Arch, Simd, WithSimd};

/// The environment variable that caps the level: `portable`, `v3` or `v4` (case-insensitive).
pub const ISA_ENV: &str = "LBDEM_ISA";

/// A level of the x86-64 psABI the kernels are compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// x86-64 baseline (SSE2), or any non-x86 target.
    Portable,
    /// x86-64-v3: AVX2, FMA, BMI2.
    V3,
    /// x86-64-v4: AVX-512 F/BW/CD/DQ/VL.
    V4,
}

impl Level {
    pub fn name(self) -> &'static str {
        match self {
            Level::Portable => "portable",
            Level::V3 => "x86-64-v3 (AVX2, FMA)",
            Level::V4 => "x86-64-v4 (AVX-512)",
        }
    }

    fn of(arch: Arch) -> Level {
        match arch {
            #[cfg(target_arch = "x86_64")]
            Arch::V4(_) => Level::V4,
            #[cfg(target_arch = "x86_64")]
            Arch::V3(_) => Level::V3,
            _ => Level::Portable,
        }
    }
}

/// `LBDEM_ISA` holds a value that names no level.
#[derive(Debug, thiserror::Error)]
#[error(
    "environment variable {ISA_ENV} = {value:?} names no instruction-set level; use `portable`, `v3` or `v4`, \
     or unset it to take the best level this CPU has"
)]
pub struct UnknownLevel {
    pub value: String,
}

/// The cap `LBDEM_ISA` sets, if any. The command line calls this first, so a typo is refused
/// before anything runs; [`arch`] ignores a value this refuses.
pub fn requested() -> Result<Option<Level>, UnknownLevel> {
    match std::env::var(ISA_ENV) {
        Err(std::env::VarError::NotPresent) => Ok(None),
        Err(std::env::VarError::NotUnicode(raw)) => Err(UnknownLevel {
            value: raw.to_string_lossy().into_owned(),
        }),
        Ok(v) => match v.trim().to_ascii_lowercase().as_str() {
            "portable" | "scalar" | "baseline" => Ok(Some(Level::Portable)),
            "v3" | "avx2" => Ok(Some(Level::V3)),
            "v4" | "avx512" | "avx-512" => Ok(Some(Level::V4)),
            _ => Err(UnknownLevel { value: v }),
        },
    }
}

/// The best level the CPU has, capped by `LBDEM_ISA`; detected once per process.
#[inline]
pub fn arch() -> Arch {
    static ARCH: OnceLock<Arch> = OnceLock::new();
    *ARCH.get_or_init(|| {
        let best = Arch::new();
        match requested().ok().flatten() {
            Some(cap) if cap < Level::of(best) => capped(cap),
            _ => best,
        }
    })
}

/// The best level at or under `cap` (the CPU has every level under its best).
fn capped(cap: Level) -> Arch {
    #[cfg(target_arch = "x86_64")]
    if cap == Level::V3
        && let Some(v3) = pulp::x86::V3::try_new()
    {
        return Arch::V3(v3);
    }
    let _ = cap;
    Arch::Scalar
}

/// The level [`dispatch`] runs kernels with in this process.
#[inline]
pub fn level() -> Level {
    if NATIVE_V4 { Level::V4 } else { Level::of(arch()) }
}

/// Run `op` compiled for the level of [`arch`]. `op.with_simd` must be `#[inline(always)]`
/// and call only `#[inline(always)]` code on its hot path: what it calls out of line is
/// compiled for the baseline.
///
/// A build for the native CPU (`-C target-cpu=native` on an AVX-512 machine) compiles every
/// function at that level already: it runs `op` once, without copies.
#[inline(always)]
pub fn dispatch<Op: WithSimd>(op: Op) -> Op::Output {
    if NATIVE_V4 {
        return op.with_simd(pulp::Scalar::new());
    }
    arch().dispatch(op)
}

/// As [`dispatch`], but where the level taken is v3 and the CPU also has F16C, `op` runs in a copy
/// compiled with F16C as well, so that half-precision conversions (`#[target_feature(enable =
/// "f16c")]` and `#[inline]`) inline into it: pulp's v3 level leaves F16C out, so the binary16
/// LBM storage called them once per block (12.6 % of its samples beside 28.6 % for the kernel;
/// inlined, the speed-up was within the noise, docs/lbm.md "Binary16 conversions inlined"). The
/// other levels are [`dispatch`]'s. Same bits: the same instructions, inlined or not.
#[inline(always)]
pub fn dispatch_f16c<Op: WithSimd>(op: Op) -> Op::Output {
    #[cfg(target_arch = "x86_64")]
    if !NATIVE_V4
        && let Arch::V3(v3) = arch()
        && std::arch::is_x86_feature_detected!("f16c")
    {
        // SAFETY: the V3 token proves pulp's v3 features, and F16C was just detected.
        return unsafe { v3_f16c(v3, op) };
    }
    dispatch(op)
}

/// `op` in a copy compiled for pulp's v3 features and F16C ([`dispatch_f16c`]).
///
/// # Safety
/// The CPU has every feature enabled here.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse3,ssse3,sse4.1,sse4.2,popcnt,avx,avx2,bmi1,bmi2,fma,lzcnt,f16c")]
#[inline]
unsafe fn v3_f16c<Op: WithSimd>(v3: pulp::x86::V3, op: Op) -> Op::Output {
    op.with_simd(v3)
}

/// Inside an op run by [`dispatch`]: whether this copy (`S`) runs with AVX-512 (the v4 copy,
/// or any copy of a build for an AVX-512 CPU), so it may take hand-written AVX-512 code. A
/// constant in each copy: the other branch is not compiled into it.
#[inline(always)]
pub fn is_v4<S: Simd>() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        NATIVE_V4 || std::any::TypeId::of::<S>() == std::any::TypeId::of::<pulp::x86::V4>()
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Inside an op run by [`dispatch`]: whether this copy (`S`) runs with AVX2 and FMA but not
/// AVX-512 (the v3 copy, or any copy of a build for such a CPU), so it may take hand-written
/// AVX2 code. A constant in each copy, false wherever [`is_v4`] is true.
#[inline(always)]
pub fn is_v3<S: Simd>() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        !is_v4::<S>() && (NATIVE_V3 || std::any::TypeId::of::<S>() == std::any::TypeId::of::<pulp::x86::V3>())
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// The whole build targets AVX2 and FMA (x86-64-v3) at least.
pub const NATIVE_V3: bool = cfg!(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma"
));

/// The whole build targets AVX-512 (x86-64-v4) already.
pub const NATIVE_V4: bool = cfg!(all(
    target_arch = "x86_64",
    target_feature = "avx512f",
    target_feature = "avx512dq",
    target_feature = "avx512vl",
    target_feature = "avx512bw",
    target_feature = "avx512cd",
    target_feature = "fma"
));

#[cfg(test)]
mod tests {
    use super::*;

    struct Sum<'a>(&'a [f64]);
    impl WithSimd for Sum<'_> {
        type Output = f64;
        #[inline(always)]
        fn with_simd<S: Simd>(self, _: S) -> f64 {
            self.0
                .iter()
                .fold(0.0, |a, &x| x.mul_add(1.000_000_1, a) * 0.999_999_9)
        }
    }

    #[test]
    fn every_level_this_cpu_has_gives_the_same_bits() {
        let v: Vec<f64> = (0..1000).map(|k| (k as f64 * 0.37).sin() * 1e3).collect();
        let scalar = Arch::Scalar.dispatch(Sum(&v));
        let best = Arch::new();
        assert_eq!(
            scalar.to_bits(),
            best.dispatch(Sum(&v)).to_bits(),
            "level {:?}",
            Level::of(best)
        );
        assert_eq!(scalar.to_bits(), capped(Level::V3).dispatch(Sum(&v)).to_bits());
    }

    struct V4Here;
    impl WithSimd for V4Here {
        type Output = bool;
        #[inline(always)]
        fn with_simd<S: Simd>(self, _: S) -> bool {
            is_v4::<S>()
        }
    }

    /// `is_v4` is true in exactly the copy that runs with AVX-512.
    #[test]
    fn is_v4_names_the_avx512_copy() {
        assert_eq!(dispatch(V4Here), level() == Level::V4);
        assert_eq!(Arch::Scalar.dispatch(V4Here), NATIVE_V4);
        assert_eq!(capped(Level::V3).dispatch(V4Here), NATIVE_V4);
    }

    struct V3Here;
    impl WithSimd for V3Here {
        type Output = bool;
        #[inline(always)]
        fn with_simd<S: Simd>(self, _: S) -> bool {
            is_v3::<S>()
        }
    }

    /// `is_v3` is true in exactly the copy that runs with AVX2 and without AVX-512.
    #[test]
    fn is_v3_names_the_avx2_copy() {
        assert_eq!(
            dispatch(V3Here),
            level() == Level::V3 || (NATIVE_V3 && !NATIVE_V4)
        );
        assert_eq!(Arch::Scalar.dispatch(V3Here), NATIVE_V3 && !NATIVE_V4);
        if let Some(v3) = pulp::x86::V3::try_new() {
            assert_eq!(Arch::V3(v3).dispatch(V3Here), !NATIVE_V4);
        }
    }

    #[test]
    fn a_cap_never_raises_the_level() {
        assert_eq!(Level::of(capped(Level::Portable)), Level::Portable);
        assert!(Level::of(capped(Level::V3)) <= Level::V3);
    }
}
