//! lbdem: radiographs in, solid-fraction and strain maps, grain assemblies, coupled
//! LBM-DEM simulations and side-by-side reports out.
//!
//! The physics lives in the kernel crates (`lbdem-imaging`, `lbdem-lbm`, `lbdem-dem`,
//! `lbdem-grains`), which never touch files. This crate holds what does: the CLI, the
//! pipeline runner with its content-hash cache and provenance, the stages that read and
//! write files, the scene loaders, the report writer and the benchmarks.

pub mod bench;
pub mod cli;
pub mod io;
pub mod pipeline;
pub mod report;
pub mod scenes;
pub mod stages;
