//! The batched pair kernel of the Hertz-Mindlin law with a tangential spring
//! ([`super::law::HertzMindlinSpring`]): eight sphere pairs per instruction, with the same IEEE
//! operations in the same order as the stepper's scalar path (`pair_response`, the law's
//! `hertz_mindlin_force` and `tangential_spring`), so the bits are the scalar path's. Branches
//! become selects (out of range, the spring carried onto the tangent plane, the Coulomb cap),
//! and the law's constants (E*, G*, the restitution's β with its `ln`) are taken once per pass
//! instead of once per pair. Used for the pair pass when no contact records are kept.
//!
//! The spheres' state is packed once per force evaluation into one 128-byte line per sphere
//! ([`SphereLine`]), so the lane code loads two aligned lines per sphere and transposes them
//! (`crate::lanes`), as the 2D kernel does with its circle lines.

use super::domain::Domain3;
use super::law::hertz_mindlin::Coeffs;
use crate::vector::Vec3;
use lbdem_core::simd::{Simd, WithSimd};
use rayon::prelude::*;

/// One sphere as the lane kernel reads it: x, y, z, v (3), ω (3), r, the mass of the body it
/// moves with, 1 if frozen (else 0), padding to two 64-byte lines.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
pub(crate) struct SphereLine(pub(crate) [f64; 16]);

/// Field indices of a [`SphereLine`].
pub(crate) mod field {
    pub(crate) const X: usize = 0;
    pub(crate) const V: usize = 3;
    pub(crate) const W: usize = 6;
    pub(crate) const R: usize = 9;
    pub(crate) const M: usize = 10;
    pub(crate) const FROZEN: usize = 11;
}

/// Force on i and torques on i and j of one pair (the reaction −f acts on j).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub(crate) struct PairRecord {
    pub(crate) f: [f64; 3],
    pub(crate) ti: [f64; 3],
    pub(crate) tj: [f64; 3],
}

/// The law and box constants of one force evaluation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct HmPair {
    /// 2 E* (S_n = this × √(R* δ)).
    pub(crate) two_e: f64,
    /// 8 G* (k_t = this × √(R* δ)).
    pub(crate) eight_g: f64,
    /// (4/3) E* (F_n's elastic part = this × √(R* δ) × δ).
    pub(crate) four_thirds_e: f64,
    pub(crate) damp: f64,
    pub(crate) mu: f64,
    pub(crate) dt: f64,
    /// Box lengths.
    pub(crate) l: [f64; 3],
    /// Which axes are periodic.
    pub(crate) periodic: [bool; 3],
    /// Lees-Edwards offset and shear rate, if the box is sheared.
    pub(crate) shear: Option<[f64; 2]>,
}

impl HmPair {
    /// The kernel's constants from the law's sphere-sphere coefficients, written as the scalar
    /// law forms them (`2.0 * e_star`, `8.0 * g_star`, `4.0 / 3.0 * e_star`).
    pub(crate) fn new(k: &Coeffs, dom: &Domain3, dt: f64) -> Self {
        let l = dom.size();
        Self {
            two_e: 2.0 * k.e_star,
            eight_g: 8.0 * k.g_star,
            four_thirds_e: 4.0 / 3.0 * k.e_star,
            damp: k.damp,
            mu: k.mu,
            dt,
            l: [l.x, l.y, l.z],
            periodic: dom.periodic,
            shear: dom.shear.map(|le| [le.offset, le.rate]),
        }
    }

    /// Evaluate `pairs` with their springs `hist` into `out`. Runs inside an op of
    /// `lbdem_core::simd::dispatch` at level `S`: the AVX-512 lanes in the v4 copy, the AVX2
    /// lanes in the v3 copy, the array lanes in the baseline copy.
    #[inline(always)]
    pub(crate) fn run_in<S: Simd>(
        &self,
        lines: &[SphereLine],
        pairs: &[[u32; 2]],
        hist: &mut [Vec3],
        out: &mut [PairRecord],
    ) {
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::avx512_in::<S>() {
            return crate::on_avx512::sphere::run(self, lines, pairs, hist, out);
        }
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::avx2_in::<S>() {
            return crate::on_avx2::sphere::run(self, lines, pairs, hist, out);
        }
        crate::on_arrays::sphere::run(self, lines, pairs, hist, out)
    }
}

/// The lines of every sphere: position, velocity, spin, radius, the mass of its body
/// (`body_mass`), frozen or not; on rayon's threads if `parallel` (each line on its own).
#[allow(clippy::too_many_arguments)]
pub(crate) fn pack(
    lines: &mut Vec<SphereLine>,
    pos: &[Vec3],
    vel: &[Vec3],
    omega: &[Vec3],
    radius: &[f64],
    frozen: &[bool],
    body_mass: impl Fn(usize) -> f64 + Sync,
    parallel: bool,
) {
    let line = |k: usize| {
        let mut l = [0.0; 16];
        let (p, v, w) = (pos[k], vel[k], omega[k]);
        l[field::X..field::X + 3].copy_from_slice(&[p.x, p.y, p.z]);
        l[field::V..field::V + 3].copy_from_slice(&[v.x, v.y, v.z]);
        l[field::W..field::W + 3].copy_from_slice(&[w.x, w.y, w.z]);
        l[field::R] = radius[k];
        l[field::M] = body_mass(k);
        l[field::FROZEN] = if frozen[k] { 1.0 } else { 0.0 };
        SphereLine(l)
    };
    lines.resize(pos.len(), SphereLine::default());
    if parallel {
        lines
            .par_iter_mut()
            .enumerate()
            .with_min_len(4096)
            .for_each(|(k, l)| *l = line(k));
    } else {
        for (k, l) in lines.iter_mut().enumerate() {
            *l = line(k);
        }
    }
}

/// One chunk of the pair pass as an op of `lbdem_core::simd::dispatch`.
pub(crate) struct HmChunk<'a> {
    pub(crate) kernel: &'a HmPair,
    pub(crate) lines: &'a [SphereLine],
    pub(crate) pairs: &'a [[u32; 2]],
    pub(crate) hist: &'a mut [Vec3],
    pub(crate) out: &'a mut [PairRecord],
}

impl WithSimd for HmChunk<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        self.kernel
            .run_in::<S>(self.lines, self.pairs, self.hist, self.out)
    }
}
