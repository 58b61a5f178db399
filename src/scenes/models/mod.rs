//! The engines as the time loop sees them ([`crate::scenes::timeloop::Model`]): grains only
//! (`dry`), liquid only (`fluid`), grains in a liquid (`coupled`). Each is built from the
//! scene's sections, steps its engine, samples the series, writes snapshots and saves its
//! whole state for `--resume`.

pub mod coupled;
pub mod dry;
pub mod fluid;
pub mod packed_zone;
pub mod shear_cell;

use crate::scenes::snapshot::ContactForce;
use lbdem_dem::{Stepper, System};

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
