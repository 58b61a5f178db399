//! The DEM validations and engine checks: one test binary for the crate (one file per case beside this one).
//!
//! One binary instead of one per file: each file used to link its own copy of the
//! crate's generic kernels, compiled at opt-level 3, which made most of CI's build time.
//! Run one file's tests with `cargo test -p lbdem-dem --test dem <file>::` (e.g. `chung_ooi::`).

mod common;
mod suspension;

mod chung_ooi;
mod clumps;
mod contact_laws;
mod determinism;
mod extruder;
mod frozen;
mod law_seams;
mod lees_edwards;
mod lubrication;
mod motion;
mod packing;
mod pair_kernel;
mod removal;
mod shear_rheology;
mod spheres;
mod stress;
