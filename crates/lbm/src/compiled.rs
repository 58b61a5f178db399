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
//!
//! Each step also names a [`Place`]: the codegen unit its kernel copies are compiled in. rustc
//! puts every copy of a generic function in the unit of the module that defines it, so all the
//! kernels sat in two units (the AA and the two-array steppers' modules), about 70 MB of machine
//! code that LLVM optimised on one core: the crate's build, CI's longest, ran on one core for
//! most of its 11 minutes. A default method of [`Place`] goes to the unit of its `Self` type, and
//! each step's marker lives in a module of its own, so the kernels are spread over twelve units.

use crate::LbmError;
use crate::collision::Collider;
use crate::kernel::Ctx;
use crate::kernel_aa::{Bad, CtxAa};
use crate::lattice::{D2Q9, D3Q19, Lattice};
use crate::real::Real;
use crate::stepper::{Fluid, Macro, Stepper};
use crate::stepper_aa::StepperAa;
use crate::storage::{ShiftedF16, ShiftedF32, Storage};

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

/// The codegen unit of one step's kernels (module doc): implemented, with the default methods, by
/// one marker per step and lattice, each in a module of its own. The methods are the row tasks of
/// the two steppers; `#[inline(never)]` keeps each out of its caller (the pool's task closure, in
/// the stepper's module), so the kernels it inlines stay in this unit. One call per task of rows.
pub(crate) trait Place {
    #[inline(never)]
    fn rows_aa<L: Lattice, T: Real, St: Storage<T>, C: Collider<L, T>>(
        ctx: &CtxAa<T, C, St>,
        first: usize,
        flags: &mut [Bad],
        odd: bool,
        forced: bool,
    ) {
        crate::stepper_aa::rows_aa::<L, T, St, C>(ctx, first, flags, odd, forced)
    }

    #[inline(never)]
    fn rows_two<L: Lattice, T: Real, C: Collider<L, T>>(
        ctx: &Ctx<T, C>,
        first: usize,
        flags: &mut [bool],
        forced: bool,
    ) {
        crate::stepper::rows_two::<L, T, C>(ctx, first, flags, forced)
    }
}

/// One module per name, each holding a [`Place`] marker `Here`.
macro_rules! places {
    ($($step:ident),*) => {
        $(
            pub mod $step {
                pub struct Here;
                impl crate::compiled::Place for Here {}
            }
        )*
    };
}

/// `impl Compiled for $lattice`: each method calls the generic step of its stepper, so that the
/// variants are compiled here (not `#[inline]`: inlining would copy them into the caller). In
/// this crate's own unit-test build they are `#[inline]`, so that it compiles only the variants
/// its tests step, not the whole set a second time.
macro_rules! compiled {
    ($lattice:ty, $m:ident) => {
        /// The [`Place`] markers of this lattice's steps, a module each (one codegen unit each).
        mod $m {
            places!(two_f64, two_f32, aa_f64, aa_f32, aa_f32s, aa_f16s);
        }

        impl Compiled for $lattice {
            #[cfg_attr(test, inline)]
            fn step_two_f64(
                st: &mut Stepper<Self, f64>,
                fluid: &mut Fluid<Self, f64>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                st.step_generic::<$m::two_f64::Here>(fluid, out)
            }
            #[cfg_attr(test, inline)]
            fn step_two_f32(
                st: &mut Stepper<Self, f32>,
                fluid: &mut Fluid<Self, f32>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                st.step_generic::<$m::two_f32::Here>(fluid, out)
            }
            #[cfg_attr(test, inline)]
            fn step_aa_f64(
                st: &mut StepperAa<Self, f64>,
                fluid: &mut Fluid<Self, f64>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                st.step_generic::<$m::aa_f64::Here>(fluid, out)
            }
            #[cfg_attr(test, inline)]
            fn step_aa_f32(
                st: &mut StepperAa<Self, f32>,
                fluid: &mut Fluid<Self, f32>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                st.step_generic::<$m::aa_f32::Here>(fluid, out)
            }
            #[cfg_attr(test, inline)]
            fn step_aa_f32s(
                st: &mut StepperAa<Self, f64, ShiftedF32>,
                fluid: &mut Fluid<Self, f64>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                st.step_generic::<$m::aa_f32s::Here>(fluid, out)
            }
            #[cfg_attr(test, inline)]
            fn step_aa_f16s(
                st: &mut StepperAa<Self, f32, ShiftedF16>,
                fluid: &mut Fluid<Self, f32>,
                out: Option<&mut Macro>,
            ) -> Result<(), LbmError> {
                st.step_generic::<$m::aa_f16s::Here>(fluid, out)
            }
        }
    };
}

compiled!(D2Q9, d2q9);
compiled!(D3Q19, d3q19);
