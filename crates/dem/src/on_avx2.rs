//! The lane kernels compiled with AVX2 registers (`crate::lanes::avx2`); taken only inside the
//! v3 copy of a pass dispatched by `lbdem_core::simd` (`crate::lanes::avx2_in`), where the CPU
//! has AVX2 and not AVX-512, or in a native build for such a CPU.

use crate::lanes::avx2 as lanes;

#[allow(clippy::duplicate_mod)] // compiled once per lane type, on purpose
#[path = "kick_lanes.rs"]
pub(crate) mod kick;
#[allow(clippy::duplicate_mod)]
#[path = "pair_lanes.rs"]
pub(crate) mod pair;
#[allow(clippy::duplicate_mod)]
#[path = "sphere_lanes.rs"]
pub(crate) mod sphere;
#[allow(clippy::duplicate_mod)]
#[path = "sphere_kick_lanes.rs"]
pub(crate) mod sphere_kick;
