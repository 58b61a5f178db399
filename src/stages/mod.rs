//! Stages: units of work that read files and write files, run alone from the CLI or as steps of
//! a pipeline, always through the runner (`crate::pipeline`). Each implements
//! [`crate::contract::Stage`] and is listed once in [`crate::registry::STAGES`]. Stages know the
//! kernels only through their public APIs, and never call the runner or the CLI.

pub mod analyse;
pub mod assemble;
pub mod compare;
pub mod digitise;
pub mod extrusion;
pub mod incline_outlines;
pub mod matrix;
pub mod mechanism_map;
pub mod minimal_models;
pub mod radiograph;
pub mod report;
pub mod run_data;
pub mod settling_study;
pub mod simulate;
pub mod stability_map;
pub mod strain_fields;
pub mod synth;
pub mod synth_run;
pub mod tradeoffs;
