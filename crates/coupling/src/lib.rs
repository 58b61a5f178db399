//! LBM-DEM coupling by partially saturated cells (Noble & Torczynski 1998; Su et al.
//! 2020 Eqs. 9-14). This crate holds the geometry and weighting that do not depend on
//! either engine's data layout: the exact overlap of lattice cells with circles, the
//! per-cell solid fraction of a set of clumped grains, and the weighting B of Eq. 10.
//! The collision term (Eq. 11) and the force and moment sums (Eq. 14) come with the
//! engines' coupling (issue 6).

pub mod overlap;
pub mod solid_fraction;
pub mod weighting;
