//! From sections to engine objects: the DEM system (`dem`), the lattice units and faces
//! (`lattice`). Shared by every scene that has the section, so a grain assembly is built the
//! same way in a dry and in a coupled scene.

pub mod assembly_file;
pub mod dem;
pub mod initial_fluid;
pub mod lattice;
pub mod particles_csv;
