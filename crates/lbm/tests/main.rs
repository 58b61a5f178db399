//! The lattice-Boltzmann validations and kernel checks: one test binary for the crate (one file per case beside this one).
//!
//! One binary instead of one per file: each file used to link its own copy of the
//! crate's generic kernels, compiled at opt-level 3, which made most of CI's build time.
//! Run one file's tests with `cargo test -p lbdem-lbm --test lbm <file>::` (e.g. `aa_kernel::`).

mod common;

mod aa_kernel;
mod bingham;
mod cavity;
mod free_surface;
mod local_tau;
mod poiseuille;
mod sangani_acrivos;
mod stability;
mod storage;
mod taylor_green;
