//! Free surface by mass tracking (Leonardi et al. 2014 Sect. 5.2, Eqs. 23-26, after Körner et
//! al. 2005): liquid, interface and gas nodes ([`cells`]), the mass exchange ([`mass`]), the
//! populations from the gas at atmospheric density ([`reconstruct`]), the interface-to-liquid and
//! interface-to-gas conversions with the excess mass shared out ([`convert`]) and the step that
//! strings them together with gravity as a body force ([`stepper`]), and the nodes moving grains
//! cover and uncover (Sect. 5.1, [`solids`]). Generic over the lattice
//! (D2Q9 and D3Q19), f64. See `docs/free_surface.md`.

pub mod cases;
pub mod cells;
pub mod convert;
pub mod creep;
pub mod flips;
pub mod mass;
pub mod reconstruct;
pub mod solids;
pub mod stepper;

pub use cells::{FreeSurface, GAS, GRAIN, INTERFACE, LIQUID, WALL};
pub use convert::Conversions;
pub use creep::ClampCreep;
pub use flips::FlipFlops;
pub use solids::{Exchanged, cover, uncover};
pub use stepper::{FreeSurfaceParams, FreeSurfaceStepper};
