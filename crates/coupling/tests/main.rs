//! The LBM-DEM coupling validations: one test binary for the crate (one file per case beside this one).
//!
//! One binary instead of one per file: each file used to link its own copy of the
//! crate's generic kernels, compiled at opt-level 3, which made most of CI's build time.
//! Run one file's tests with `cargo test -p lbdem-coupling --test coupling <file>::` (e.g. `added_mass::`).

mod common;

mod added_mass;
mod darcy;
mod dkt;
mod dkt_uhlmann;
mod incline;
mod low_resolution;
mod momentum;
mod psm_3d;
mod resume;
mod sangani_psm;
mod settling_disk;
mod solid_zone;
mod surface_grains;
mod torque;
