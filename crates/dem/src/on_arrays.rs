//! The lane kernels compiled with array lanes (`crate::lanes::portable`): every CPU, and
//! inside each instruction-set level of `lbdem_core::simd`.

use crate::lanes::portable as lanes;

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
