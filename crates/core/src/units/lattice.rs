//! SI <-> lattice units for the LBM (Su et al. 2020 Eqs. 15-16).
//! Owned by the LBM engine (issue 3).
