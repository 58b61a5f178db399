//! The membrane driver (Su et al. 2020 Sect. 2.4): an inward force on each member grain that has
//! moved outward past the threshold.

use crate::system::System;

pub(super) fn membrane_forces(sys: &mut System) {
    let bodies = &mut sys.bodies;
    if let Some(mem) = &sys.membrane {
        for (k, &bk) in mem.bodies.iter().enumerate() {
            let bk = bk as usize;
            let f = mem.force_on(k, bodies.pos[bk]);
            bodies.force[bk] += f;
        }
    }
}
