//! The only place where SI, lattice-Boltzmann and DEM units meet.
//!
//! Scenes are written in SI; each solver asks this module for its own units and the
//! module refuses parameter sets that cannot be stable or accurate, with an error
//! naming the parameter, its value, the limit and the fix.

pub mod coupled;
pub mod dem;
pub mod lattice;
