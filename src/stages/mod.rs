//! Stages: units of work that read files and write files, run alone from the CLI or as steps of
//! a pipeline, always through the runner (`crate::pipeline`). Each implements
//! [`crate::contract::Stage`] and is listed once in [`crate::registry::STAGES`]. Stages know the
//! kernels only through their public APIs, and never call the runner or the CLI.

pub mod assemble;
pub mod digitise;
pub mod radiograph;
pub mod report;
pub mod settling_study;
pub mod simulate;
pub mod synth;
