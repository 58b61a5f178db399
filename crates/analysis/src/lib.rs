//! lbdem-analysis: what Su et al. (2020) compute from a deformed grain assembly, as pure kernels
//! (no file I/O; the `analyse` and `compare` stages of the `lbdem` binary read the snapshots):
//!
//! - strain by triangulation of the grain centroids (Sect. 2.5, refs. [104-106]): the
//!   displacement gradient of every Delaunay triangle, ε_xx, ε_yy, ε_xy = γ_xy/2 and the rotation,
//!   rasterised and averaged over the same √10 d̄ REV as the radiographs ([`mesh`], [`strain`],
//!   [`raster`]);
//! - the three volumetric strains a reader meets — Eq. 5 (area ratio minus one, what intensity
//!   measures), Eq. 18 (logarithmic area strain) and ε_xx + ε_yy — and how they differ
//!   ([`volume`]);
//! - the cracking criterion Δp < Δp_c = −0.03 Pa (Sect. 3.5, Fig. 10), where it first happens
//!   relative to the push-plate's corners ([`cracking`]);
//! - the net mechanism of a run (suspension, shear-induced contraction or dilation, shear
//!   cracking; Sect. 3.1), the dynamic-dilatancy law (Eq. 21), the experimental datasets of
//!   Fig. 3j and the transition lines between classes ([`mechanism`]);
//! - whether the contact network percolates ([`network`]).
//!
//! And what Ness et al. (2017) compute from an extruder's spheres: binned coarse-grained
//! velocity, gradients, stress, dissipation and static zones ([`coarse`]), and the
//! Benbow-Bridgwater fit of pressure drops against die velocity ([`benbow`]).

pub mod benbow;
pub mod coarse;
pub mod cracking;
pub mod error;
pub mod mechanism;
pub mod mesh;
pub mod network;
pub mod raster;
pub mod strain;
pub mod volume;

pub use error::AnalysisError;
pub type Result<T> = std::result::Result<T, AnalysisError>;

/// A point in the plane (m, or any consistent length unit), y up.
pub type P2 = [f64; 2];
