//! The sphere engine's half kick and drift eight spheres at a time (`crate::sphere_kick_lanes`,
//! AVX-512 registers, AVX2 registers or arrays, chosen per chunk by `lbdem_core::simd::dispatch`), with the
//! scalar kick's bits; `spheres::stepper::kick` hands it chunks of spheres.

use super::domain::Domain3;
use crate::vector::Vec3;
use lbdem_core::simd::{Simd, WithSimd};

/// What the kick reads besides the state it updates.
pub(crate) struct KickInput<'a> {
    pub(crate) force: &'a [Vec3],
    pub(crate) torque: &'a [Vec3],
    pub(crate) mass: &'a [f64],
    pub(crate) inertia: &'a [f64],
    /// 1.0 for a mobile sphere (free and not frozen), else 0.0.
    pub(crate) mobile: &'a [f64],
    pub(crate) h: f64,
    pub(crate) drift: Option<(f64, &'a Domain3)>,
}

/// The spheres `first..first + pos.len()` as an op of `lbdem_core::simd::dispatch`.
pub(crate) struct KickChunk<'a> {
    pub(crate) inp: &'a KickInput<'a>,
    pub(crate) first: usize,
    pub(crate) pos: &'a mut [Vec3],
    pub(crate) vel: &'a mut [Vec3],
    pub(crate) omega: &'a mut [Vec3],
}

impl WithSimd for KickChunk<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::avx512_in::<S>() {
            return crate::on_avx512::sphere_kick::run(self.inp, self.first, self.pos, self.vel, self.omega);
        }
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::avx2_in::<S>() {
            return crate::on_avx2::sphere_kick::run(self.inp, self.first, self.pos, self.vel, self.omega);
        }
        crate::on_arrays::sphere_kick::run(self.inp, self.first, self.pos, self.vel, self.omega)
    }
}
