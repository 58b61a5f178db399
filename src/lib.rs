//! lbdem: radiographs in, solid-fraction and strain maps, grain assemblies, coupled
//! LBM-DEM simulations and side-by-side reports out.
//!
//! The physics lives in the kernel crates (`lbdem-imaging`, `lbdem-lbm`, `lbdem-dem`,
//! `lbdem-grains`, `lbdem-coupling`), which never touch files. This crate holds what does, in
//! layers that import only downwards (docs/architecture.md):
//! `cli` → `pipeline` (the runner) → `registry` → `stages` → `scenes` → engine crates, with
//! `contract` (the stage, output, manifest and provenance types) at the bottom for all of them,
//! and `report` (plots, tables) and `io` (TIFF) as libraries the stages use.

pub mod atlas;
pub mod bench;
pub mod cli;
pub mod contract;
pub mod io;
pub mod pipeline;
pub mod registry;
pub mod report;
pub mod scenes;
pub mod stages;
pub mod sweep;
