//! The `lbdem` crate's integration tests in one binary: one link instead of one per file.
//! Each file's binary linked polars and the engines, about 165 MB in the test profile, 3.5 GB
//! for the 23 of them; a CI run's linker died of SIGBUS, which lld does when the disk fills. Run one file's tests with `cargo test --test it FILE::`. The fuzz
//! harness stays in its own binary (`tests/fuzz.rs`): it installs a counting global allocator.

mod common;

mod analysis_errors;
mod digitise_bad_input;
mod digitise_photo;
mod digitise_stage;
mod layers;
mod pipeline_errors;
mod pipeline_quickstart;
mod radiograph_determinism;
mod radiograph_edge_flag;
mod radiograph_errors;
mod radiograph_io;
mod radiograph_meniscus;
mod radiograph_quickstart;
mod radiograph_real;
mod radiograph_stepwedge;
mod resume_after_kill;
mod self_contained;
mod simd_level;
mod strain_operators;
mod su2020_ci_pipeline;
mod su2020_pipeline_wiring;
mod sweep_cli;
mod synth_recovery;
