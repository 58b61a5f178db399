//! Pair kernel of the linear spring-dashpot law with tangential history (no rolling spring), the
//! benchmark case: the same arithmetic as [`crate::contact::LinearSpringDashpot::force`] and
//! [`crate::contact::tangential`], operation for operation (so the bits are the same), written
//! without branches so the compiler evaluates eight pairs per instruction (AVX-512 registers where the CPU has them: `crate::lanes`). Untouched pairs and the Coulomb cap become selects.

use crate::contact::{Damping, History, LinearSpringDashpot};
use crate::domain::Domain;
use crate::scratch::{CircleState, PairOut};
use lbdem_core::simd::Simd;

/// The law and box constants of one force evaluation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LinearPair {
    pub(crate) k_n: f64,
    pub(crate) k_t: f64,
    /// Tangential dashpot as a fraction of the normal one.
    pub(crate) t_frac: f64,
    pub(crate) mu: f64,
    pub(crate) clip: bool,
    /// γ (c_n = γ m*) or ζ (c_n = 2 ζ sqrt(k_n m*)).
    pub(crate) damp: f64,
    pub(crate) gamma: bool,
    pub(crate) dt: f64,
    /// Periodic box lengths and half lengths (infinite half length on open axes).
    pub(crate) l: [f64; 2],
    pub(crate) half: [f64; 2],
}

impl LinearPair {
    /// The kernel for `law`, if it applies (friction, no rolling spring).
    pub(crate) fn new(law: &LinearSpringDashpot, dom: &Domain, dt: f64) -> Option<Self> {
        if law.rolling.is_some() || law.mu <= 0.0 {
            return None;
        }
        let (damp, gamma) = match law.damping {
            Damping::Gamma(g) => (g, true),
            Damping::Ratio(z) => (z, false),
        };
        let l = dom.size();
        // `Domain::min_image` shifts when |d| > l/2 on periodic axes: an infinite threshold
        // never shifts.
        let half = |p: bool, v: f64| if p { 0.5 * v } else { f64::INFINITY };
        Some(Self {
            k_n: law.k_n,
            k_t: law.k_t,
            t_frac: law.tangential_damping,
            mu: law.mu,
            clip: law.clip,
            damp,
            gamma,
            dt,
            l: [l.x, l.y],
            half: [half(dom.periodic[0], l.x), half(dom.periodic[1], l.y)],
        })
    }

    /// Evaluate `pairs` (with their `hist`), writing each pair's force on i and torques on i
    /// and j to `out` and 1/0 (touching or not) to `touch`. Runs inside an op of
    /// `lbdem_core::simd::dispatch` at level `S` (the stepper's passes): the AVX-512 lanes in
    /// the v4 copy, the array lanes in the others.
    #[inline(always)]
    pub(crate) fn run_in<S: Simd>(
        &self,
        cst: &[CircleState],
        pairs: &[[u32; 2]],
        hist: &mut [History],
        out: &mut [PairOut],
        touch: &mut [u8],
    ) {
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::avx512_in::<S>() {
            return crate::on_avx512::pair::run(self, cst, pairs, hist, out, touch);
        }
        crate::on_arrays::pair::run(self, cst, pairs, hist, out, touch)
    }
}
