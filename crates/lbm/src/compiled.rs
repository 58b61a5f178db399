//! The step of each stepper, compiled here once per lattice and precision.
//!
//! The kernels are generic (lattice × precision × collision × forcing × instruction-set level),
//! and Rust compiles a generic function in the crate that names its concrete types. Left to
//! itself, every crate that steps a lattice (the `lbdem` crate, each test binary) compiled its
//! own copy of every variant, at its own optimisation level: most of the LLVM work of the `lbdem`
//! crate, at opt-level 1 in the test profile. [`Compiled`] names the concrete steps instead: its
//! methods are plain functions of `D2Q9` and `D3Q19`, compiled in this crate (at opt-level 3 in
//! every profile) and only called from outside. `Stepper::step` and `StepperAa::step` reach them
//! through [`Real`], so generic code downstream needs no bound beyond `L: Lattice, T: Real`.

use crate::LbmError;
use crate::lattice::{D2Q9, D3Q19};
use crate::stepper::{Fluid, Macro, Stepper};
use crate::stepper_aa::StepperAa;
use crate::storage::{ShiftedF16, ShiftedF32};

/// One step of each stepper, per precision (and, for the AA stepper, storage); implemented for every lattice of the crate by
/// [`compiled!`]. A supertrait of [`crate::Lattice`].
pub trait Compiled: Sized {
    fn step_two_f64(
        st: &mut Stepper<Self, f64>,
        fluid: &mut Fluid<Self, f64>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError>;
    fn step_two_f32(
        st: &mut Stepper<Self, f32>,
        fluid: &mut Fluid<Self, f32>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError>;
    fn step_aa_f64(
        st: &mut StepperAa<Self, f64>,
        fluid: &mut Fluid<Self, f64>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError>;
    fn step_aa_f32(
        st: &mut StepperAa<Self, f32>,
        fluid: &mut Fluid<Self, f32>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError>;
    /// f64 arithmetic on f32 storage of f − w (`storage::ShiftedF32`).
    fn step_aa_f32s(
        st: &mut StepperAa<Self, f64, ShiftedF32>,
        fluid: &mut Fluid<Self, f64>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError>;
    /// f32 arithmetic on binary16 storage of f − w (`storage::ShiftedF16`).
    fn step_aa_f16s(
        st: &mut StepperAa<Self, f32, ShiftedF16>,
        fluid: &mut Fluid<Self, f32>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError>;
}

/// `impl Compiled for $lattice`: each method calls the generic step of its stepper, so that the
/// variants are compiled here (not `#[inline]`: inlining would copy them into the caller). In
/// this crate's own unit-test build they are `#[inline]`, so that it compiles only the variants
/// its tests step, not the whole set a second time.
macro_rules! compiled {
    ($lattice:ty) => {
        impl Compiled for $lattice {
            #[cfg_attr(test, inline)]
            fn step_two_f64(
                st: &mut Stepper<Self, f64>,
                fluid: &mut Fluid<Self, f64>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                st.step_generic(fluid, out)
            }
            #[cfg_attr(test, inline)]
            fn step_two_f32(
                st: &mut Stepper<Self, f32>,
                fluid: &mut Fluid<Self, f32>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                st.step_generic(fluid, out)
            }
            #[cfg_attr(test, inline)]
            fn step_aa_f64(
                st: &mut StepperAa<Self, f64>,
                fluid: &mut Fluid<Self, f64>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                st.step_generic(fluid, out)
            }
            #[cfg_attr(test, inline)]
            fn step_aa_f32(
                st: &mut StepperAa<Self, f32>,
                fluid: &mut Fluid<Self, f32>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                st.step_generic(fluid, out)
            }
            #[cfg_attr(test, inline)]
            fn step_aa_f32s(
                st: &mut StepperAa<Self, f64, ShiftedF32>,
                fluid: &mut Fluid<Self, f64>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                st.step_generic(fluid, out)
            }
            #[cfg_attr(test, inline)]
            fn step_aa_f16s(
                st: &mut StepperAa<Self, f32, ShiftedF16>,
                fluid: &mut Fluid<Self, f32>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                st.step_generic(fluid, out)
            }
        }
    };
}

compiled!(D2Q9);
compiled!(D3Q19);
