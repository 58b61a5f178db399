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
    #[error(
        "LBM-DEM time-step ratio dt_lbm / dt_dem = {ratio} must be a whole number >= 1 \
         (Su et al. 2020 Table 3); set dt_dem = dt_lbm / N for a whole N"
    )]
    Ratio { ratio: f64 },
    #[error(transparent)]
    Dem(#[from] lbdem_dem::DemError),
    /// Every lattice failure, the instability of the PSM lattice included
    /// (`LbmError::Unstable`: step, node, state and likely cause, from `lbdem_lbm::diagnosis`).
    #[error(transparent)]
    Lbm(#[from] lbdem_lbm::LbmError),
}
