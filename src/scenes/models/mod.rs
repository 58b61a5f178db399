//! The engines as the time loop sees them ([`crate::scenes::timeloop::Model`]): grains only
//! (`dry`), liquid only (`fluid`), grains in a liquid (`coupled`). Each is built from the
//! scene's sections, steps its engine, samples the series, writes snapshots and saves its
//! whole state for `--resume`.

pub mod coupled;
pub mod dry;
pub mod extruder;
pub mod fluid;
pub mod incline;
pub mod mass_control;
pub mod packed_zone;
pub mod shear_cell;

use crate::scenes::snapshot::ContactForce;
use lbdem_dem::{Stepper, System, Vector as _};

/// The touching pairs of the last force evaluation, for the contact table.
pub fn contact_list(st: &Stepper, sys: &System) -> Vec<ContactForce> {
    st.contact_forces(sys)
        .map(|(i, j, f)| ContactForce {
            i,
            j,
            force: [f.x, f.y],
        })
        .collect()
}

/// Every body's centroid, for [`crate::scenes::timeloop::Model::grain_centroids`].
pub fn centroids(sys: &System) -> Vec<[f64; 2]> {
    sys.bodies.pos.iter().map(|p| [p.x, p.y]).collect()
}

/// The largest distance a body moved since `then` (from [`centroids`]), the minimum image on
/// periodic axes (a window is short against the time to cross a box); `None` when the bodies
/// are not the same number.
pub fn max_displacement(sys: &System, then: &[[f64; 2]]) -> Option<f64> {
    (then.len() == sys.bodies.len()).then(|| {
        sys.bodies
            .pos
            .iter()
            .zip(then)
            .map(|(p, &[x, y])| sys.domain.min_image(*p - lbdem_dem::Vec2::new(x, y)).norm())
            .fold(0.0, f64::max)
    })
}

/// The grains of the scene as the DEM steps them: `build_system`, then `[particles]
/// area_factor` and `[dem] mass_scale`.
pub fn grains(s: &crate::scenes::schema::Scene, base: &std::path::Path) -> anyhow::Result<System> {
    let mut sys = crate::scenes::build::dem::build_system(s, base)?;
    if let Some(p) = &s.particles {
        let f = p.area_factor;
        if !(f > 0.0 && f.is_finite()) {
            anyhow::bail!("[particles] area_factor = {f}: give a positive factor (0.9 = 10 % smaller)");
        }
        if f != 1.0 {
            sys.bodies.scale_sizes(f.sqrt());
            sys.contacts = Default::default();
        }
        // The initial condition of the grains (checked finite with the scene's values).
        if let Some([vx, vy]) = p.velocity {
            sys.bodies.vel.fill(lbdem_dem::Vec2::new(vx, vy));
        }
        if let Some(w) = p.omega {
            sys.bodies.omega.fill(w);
        }
    }
    if let Some(d) = &s.dem {
        let f = d.mass_scale;
        if !(f > 0.0 && f.is_finite()) {
            anyhow::bail!("[dem] mass_scale = {f}: give a positive factor (1 = real masses)");
        }
        if f != 1.0 {
            sys.bodies.scale_mass(f);
        }
    }
    Ok(sys)
}
