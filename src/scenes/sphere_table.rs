//! Snapshot table of a 3D sphere system (the extruder), readable back to the bits:
//! `spheres_<step>.csv`, one row per sphere: `id` (index in the system at that step), `frozen`
//! (1 = wall grain), centre `x`, `y`, `z`, radius `r`, velocity `vx`, `vy`, `vz`, spin `wx`,
//! `wy`, `wz`, and the total force of the last evaluation `fx`, `fy`, `fz` (on a wall grain:
//! the paste's load on it); beside it `spheres_<step>.vtp` for ParaView.

use crate::report::table::{Col, f64_column, read_table, u64_column, write_table};
use anyhow::{Context, Result};
use lbdem_core::vtk::{Array, Values, write_vtp_points};
use lbdem_dem::spheres::SphereSystem;
use std::path::{Path, PathBuf};

/// The sphere table, column by column.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SphereTable {
    pub id: Vec<u64>,
    pub frozen: Vec<u64>,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
    pub r: Vec<f64>,
    pub vx: Vec<f64>,
    pub vy: Vec<f64>,
    pub vz: Vec<f64>,
    pub wx: Vec<f64>,
    pub wy: Vec<f64>,
    pub wz: Vec<f64>,
    pub fx: Vec<f64>,
    pub fy: Vec<f64>,
    pub fz: Vec<f64>,
}

const F64: [&str; 13] = [
    "x", "y", "z", "r", "vx", "vy", "vz", "wx", "wy", "wz", "fx", "fy", "fz",
];

impl SphereTable {
    pub fn of(sys: &SphereSystem) -> Self {
        let s = &sys.spheres;
        let mut t = Self::default();
        for k in 0..s.len() {
            t.id.push(k as u64);
            t.frozen.push(u64::from(s.frozen[k]));
            let (p, v, w, f) = (s.pos[k], s.vel[k], s.omega[k], s.force[k]);
            for (col, x) in t.f64_mut().into_iter().zip([
                p.x,
                p.y,
                p.z,
                s.radius[k],
                v.x,
                v.y,
                v.z,
                w.x,
                w.y,
                w.z,
                f.x,
                f.y,
                f.z,
            ]) {
                col.push(x);
            }
        }
        t
    }

    fn f64_mut(&mut self) -> [&mut Vec<f64>; 13] {
        [
            &mut self.x,
            &mut self.y,
            &mut self.z,
            &mut self.r,
            &mut self.vx,
            &mut self.vy,
            &mut self.vz,
            &mut self.wx,
            &mut self.wy,
            &mut self.wz,
            &mut self.fx,
            &mut self.fy,
            &mut self.fz,
        ]
    }

    fn f64_ref(&self) -> [&Vec<f64>; 13] {
        [
            &self.x, &self.y, &self.z, &self.r, &self.vx, &self.vy, &self.vz, &self.wx, &self.wy, &self.wz,
            &self.fx, &self.fy, &self.fz,
        ]
    }
}

/// Write `spheres_<step>.csv` and `.vtp` under `dir/snapshots/`; returns (kind, path relative
/// to `dir`).
pub fn write_spheres(dir: &Path, step: u64, sys: &SphereSystem) -> Result<Vec<(&'static str, PathBuf)>> {
    let t = SphereTable::of(sys);
    let csv = PathBuf::from(format!("snapshots/spheres_{step:09}.csv"));
    let mut cols = vec![("id", Col::U64(&t.id)), ("frozen", Col::U64(&t.frozen))];
    cols.extend(F64.iter().zip(t.f64_ref()).map(|(n, v)| (*n, Col::F64(v))));
    write_table(&dir.join(&csv), &cols)?;
    let vtp = PathBuf::from(format!("snapshots/spheres_{step:09}.vtp"));
    let s = &sys.spheres;
    let pos: Vec<[f64; 3]> = s.pos.iter().map(|p| [p.x, p.y, p.z]).collect();
    let vel: Vec<f64> = s.vel.iter().flat_map(|v| [v.x, v.y, v.z]).collect();
    let frozen: Vec<f64> = s.frozen.iter().map(|&f| f64::from(u8::from(f))).collect();
    write_vtp_points(
        &dir.join(&vtp),
        &pos,
        &[
            Array::scalar("radius", Values::F64(&s.radius)),
            Array::scalar("frozen", Values::F64(&frozen)),
            Array::vector("velocity", Values::F64(&vel)),
        ],
    )
    .with_context(|| format!("cannot write {}", dir.join(&vtp).display()))?;
    Ok(vec![("spheres", csv), ("spheres_vtk", vtp)])
}

/// Read a sphere table written by [`write_spheres`].
pub fn read_spheres(path: &Path) -> Result<SphereTable> {
    let df = read_table(path)?;
    let mut t = SphereTable {
        id: u64_column(&df, "id", path)?,
        frozen: u64_column(&df, "frozen", path)?,
        ..SphereTable::default()
    };
    for (name, col) in F64.iter().zip(t.f64_mut()) {
        *col = f64_column(&df, name, path)?;
    }
    Ok(t)
}
