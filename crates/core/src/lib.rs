//! Shared, dependency-light pieces every lbdem crate uses: unit conversion (the one
//! place where SI, lattice and DEM units meet), atomic file output and the VTK writers
//! that ParaView reads.
//!
//! Physics kernels live in their own crates (`lbdem-lbm`, `lbdem-dem`, ...) and never
//! do I/O; the writers here are called by stages and scenes, not by kernels.

pub mod atomic;
pub mod simd;
pub mod units;
pub mod vtk;
