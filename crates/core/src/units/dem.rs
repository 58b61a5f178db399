//! DEM time and stiffness scales: the critical time step (issue 4).
//! Owned by the DEM engine (issue 4).
