//! Errors of the coupling; each names the parameter, its value, the limit and the fix.

#[derive(Debug, thiserror::Error)]
pub enum CouplingError {
    #[error(
        "relaxation time tau = {tau} must be > 0.5 (zero or negative viscosity, Su et al. 2020 Eq. 15); \
         increase the viscosity or the LBM time step, or refine dx"
    )]
    Tau { tau: f64 },
    #[error("unsupported set-up: {0}")]
    Unsupported(String),
    /// Unit conversion refused (e.g. a DEM step that is not a whole fraction of the LBM step,
    /// `UnitsError::Ratio`).
    #[error(transparent)]
    Units(#[from] lbdem_core::units::lattice::UnitsError),
    #[error(transparent)]
    Dem(#[from] lbdem_dem::DemError),
    /// The 3D sphere engine's errors (`surface_grains`).
    #[error(transparent)]
    Spheres(#[from] lbdem_dem::spheres::SphereError),
    /// Every lattice failure, the instability of the PSM lattice included
    /// (`LbmError::Unstable`: step, node, state and likely cause, from `lbdem_lbm::diagnosis`).
    #[error(transparent)]
    Lbm(#[from] lbdem_lbm::LbmError),
}
