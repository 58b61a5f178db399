//! The batched pair kernel: the laws that describe themselves as [`Batched`] (the linear
//! spring-dashpot, Su et al. 2020's elastic-plastic law; tangential history, optional rolling
//! spring) with the same arithmetic as their [`crate::contact::ContactLaw::force`], operation for
//! operation (so the bits are the same), written without branches so the compiler evaluates
//! eight pairs per instruction (AVX-512 registers where the CPU has them: `crate::lanes`).
//! Untouched pairs, the yield envelope and the Coulomb and rolling caps become selects.

use crate::contact::{Batched, BatchedNormal, Damping};
use crate::domain::Domain;
use crate::history::stride_of;
use crate::scratch::{CircleState, PairOut};
use crate::{ContactLaw, History};
use lbdem_core::simd::Simd;

/// The law and box constants of one force evaluation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BatchedPair {
    pub(crate) normal: BatchedNormal,
    pub(crate) k_t: f64,
    /// Tangential dashpot as a fraction of the normal one.
    pub(crate) t_frac: f64,
    pub(crate) mu: f64,
    /// γ (c_n = γ m*) or ζ (c_n = 2 ζ sqrt(k_n m*)).
    pub(crate) damp: f64,
    pub(crate) gamma: bool,
    /// Rolling spring k_r and its limit μ_r, if any.
    pub(crate) rolling: Option<[f64; 2]>,
    pub(crate) dt: f64,
    /// Periodic box lengths and half lengths (infinite half length on open axes).
    pub(crate) l: [f64; 2],
    pub(crate) half: [f64; 2],
}

impl BatchedPair {
    /// The kernel for `law`, if it has one (see [`ContactLaw::batched`]).
    pub(crate) fn of<L: ContactLaw>(law: &L, dom: &Domain, dt: f64) -> Option<Self> {
        if stride_of::<L::History>() != stride_of::<History>() {
            return None;
        }
        law.batched().and_then(|b| Self::new(&b, dom, dt))
    }

    /// The kernel for `law`, if it applies (Coulomb friction).
    pub(crate) fn new(law: &Batched, dom: &Domain, dt: f64) -> Option<Self> {
        if law.mu <= 0.0 {
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
            normal: law.normal,
            k_t: law.k_t,
            t_frac: law.t_frac,
            mu: law.mu,
            damp,
            gamma,
            rolling: law.rolling.map(|r| [r.k_r, r.mu_r]),
            dt,
            l: [l.x, l.y],
            half: [half(dom.periodic[0], l.x), half(dom.periodic[1], l.y)],
        })
    }

    /// The stiffness the normal dashpot is scaled on (k_n, or k_n,e for the plastic law).
    pub(crate) fn k_damp(&self) -> f64 {
        match self.normal {
            BatchedNormal::Linear { k_n, .. } => k_n,
            BatchedNormal::Plastic { k_e, .. } => k_e,
        }
    }

    /// Evaluate `pairs` (with their `hist`), writing each pair's force on i and torques on i
    /// and j to `out` and 1/0 (touching or not) to `touch`. Runs inside an op of
    /// `lbdem_core::simd::dispatch` at level `S` (the stepper's passes): the AVX-512 lanes in
    /// the v4 copy, the AVX2 lanes in the v3 copy, the array lanes in the baseline copy.
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
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::avx2_in::<S>() {
            return crate::on_avx2::pair::run(self, cst, pairs, hist, out, touch);
        }
        crate::on_arrays::pair::run(self, cst, pairs, hist, out, touch)
    }
}
