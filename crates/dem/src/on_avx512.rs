//! The lane kernels compiled with AVX-512 registers (`crate::lanes::avx512`); entered only
//! from `#[target_feature]` functions called where the CPU has the features.

use crate::lanes::avx512 as lanes;

#[allow(clippy::duplicate_mod)] // compiled once per lane type, on purpose
#[path = "kick_lanes.rs"]
pub(crate) mod kick;
#[allow(clippy::duplicate_mod)]
#[path = "pair_lanes.rs"]
pub(crate) mod pair;
