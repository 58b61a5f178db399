//! `[fluid] initial`: the liquid's velocity and pressure at step 0, read from a fluid table
//! (the format of a run's `fields/fluid_*` snapshots, through `snapshot::read_fluid`, polars)
//! and checked node by node before anything runs: every liquid node exactly once, indices
//! inside the lattice, finite values, speeds within `[fluid] u_max` (the speed the Mach check,
//! Su Eq. 16, was made for) and a positive density. Solid nodes may be absent or NaN (a run's
//! snapshot writes NaN there); they start at rest.

use crate::scenes::snapshot::read_fluid;
use anyhow::{Context, Result, bail};
use lbdem_core::units::lattice::LatticeUnits;
use lbdem_lbm::domain::FLUID;
use std::path::Path;

/// (density, velocity) in lattice units, one per node in the lattice's index order.
pub type NodeStates = Vec<(f64, [f64; 3])>;

/// Read and check `path` for a lattice of `n` nodes whose node kinds are `kind`.
pub fn read(
    path: &Path,
    n: [usize; 3],
    dim: usize,
    kind: &[u8],
    units: &LatticeUnits,
    u_max: f64,
) -> Result<NodeStates> {
    let t = read_fluid(path).with_context(|| {
        format!(
            "[fluid] initial = {}: not a fluid table (columns i, j, k, ux, uy, uz in m/s, pressure in Pa)",
            path.display()
        )
    })?;
    let nodes = n[0] * n[1] * n[2];
    let mut out: Vec<Option<(f64, [f64; 3])>> = vec![None; nodes];
    let at = |row: usize| format!("[fluid] initial = {}, data row {}", path.display(), row + 1);
    for r in 0..t.i.len() {
        let ijk = [t.i[r], t.j[r], t.k[r]];
        if let Some(a) = (0..3).find(|&a| ijk[a] >= n[a] as u64) {
            bail!(
                "{}: {} = {} is outside the lattice (0..{} on that axis, from [domain] and [lattice] dx); \
                 write the table for this lattice, or change dx",
                at(r),
                ["i", "j", "k"][a],
                ijk[a],
                n[a] - 1
            );
        }
        let idx = ijk[0] as usize + n[0] * (ijk[1] as usize + n[1] * ijk[2] as usize);
        if out[idx].is_some() {
            bail!(
                "{}: node (i, j, k) = ({}, {}, {}) is given twice; give each node once",
                at(r),
                ijk[0],
                ijk[1],
                ijk[2]
            );
        }
        let u = [t.ux[r], t.uy[r], t.uz[r]];
        let p = t.pressure[r];
        if kind[idx] != FLUID {
            // A solid node: whatever the table says, it starts at rest.
            out[idx] = Some((1.0, [0.0; 3]));
            continue;
        }
        if let Some((name, v)) = [("ux", u[0]), ("uy", u[1]), ("uz", u[2]), ("pressure", p)]
            .into_iter()
            .find(|(_, v)| !v.is_finite())
        {
            bail!(
                "{}: {name} = {v} at the liquid node ({}, {}, {}); every liquid node needs a finite velocity (m/s) \
                 and pressure (Pa)",
                at(r),
                ijk[0],
                ijk[1],
                ijk[2]
            );
        }
        if dim == 2 && u[2] != 0.0 {
            bail!(
                "{}: uz = {} in a 2D scene; the liquid moves in the plane only, write uz = 0",
                at(r),
                u[2]
            );
        }
        let speed = u.iter().map(|v| v * v).sum::<f64>().sqrt();
        if speed > u_max {
            bail!(
                "{}: speed {speed:e} m/s is above [fluid] u_max = {u_max:e} m/s, the speed the Mach check was \
                 made for; raise u_max (and check [lattice] dt or tau) or lower the initial velocity",
                at(r)
            );
        }
        let rho = 1.0 + units.pressure_to_density(p);
        if rho <= 0.0 {
            bail!(
                "{}: pressure = {p} Pa gives a lattice density {rho} (must be above 0); the pressure is relative \
                 to the reference, so it cannot be below -rho c_s^2 (about {:e} Pa)",
                at(r),
                units.density_to_pressure(0.0)
            );
        }
        out[idx] = Some((rho, u.map(|v| units.velocity_to_lattice(v))));
    }
    let mut states = Vec::with_capacity(nodes);
    for (idx, s) in out.into_iter().enumerate() {
        match s {
            Some(s) => states.push(s),
            None if kind[idx] != FLUID => states.push((1.0, [0.0; 3])),
            None => {
                let (x, y, z) = (idx % n[0], (idx / n[0]) % n[1], idx / (n[0] * n[1]));
                bail!(
                    "[fluid] initial = {}: the liquid node (i, j, k) = ({x}, {y}, {z}) has no row; the table must \
                     give every liquid node of the {}x{}x{} lattice",
                    path.display(),
                    n[0],
                    n[1],
                    n[2]
                );
            }
        }
    }
    Ok(states)
}
