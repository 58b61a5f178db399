//! Snapshot table of a 3D sphere system (the extruder), readable back to the bits:
//! `spheres_<step>.csv`, one row per sphere: `id` (index in the system at that step), `frozen`
//! (1 = wall grain), centre `x`, `y`, `z`, radius `r`, velocity `vx`, `vy`, `vz`, spin `wx`,
//! `wy`, `wz`, and the total force of the last evaluation `fx`, `fy`, `fz` (on a wall grain:
//! the paste's load on it), and the sphere's share of the force dipoles of Ness et al. (2017)
//! Eq. 7, `w_ab` = −Σ r_a F_b (N m, compression positive; a pair's dipole split half to each
//! sphere, the paste grain's arm's share at a wall grain, `lbdem_dem::spheres::sphere_dipoles`) with
//! its hydrodynamic part `wh_ab` (Eq. 7a),
//! NaN in a snapshot taken before any recorded force evaluation; beside it `spheres_<step>.vtp`
//! for ParaView.

use crate::report::table::{Col, f64_column, read_table, u64_column, write_table};
use anyhow::{Context, Result};
use lbdem_core::vtk::{Array, Values, write_vtp_points};
use lbdem_dem::spheres::{SphereDipole, SphereSystem};
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
    /// Dipole shares, component ab at index 3a + b (empty when the table has none).
    pub w: [Vec<f64>; 9],
    pub wh: [Vec<f64>; 9],
}

/// Names of the dipole columns, component ab at index 3a + b.
pub const DIPOLE: [&str; 9] = [
    "w_xx", "w_xy", "w_xz", "w_yx", "w_yy", "w_yz", "w_zx", "w_zy", "w_zz",
];
pub const DIPOLE_HYDRO: [&str; 9] = [
    "wh_xx", "wh_xy", "wh_xz", "wh_yx", "wh_yy", "wh_yz", "wh_zx", "wh_zy", "wh_zz",
];

const F64: [&str; 13] = [
    "x", "y", "z", "r", "vx", "vy", "vz", "wx", "wy", "wz", "fx", "fy", "fz",
];

impl SphereTable {
    /// The table of `sys`, with each sphere's dipole share from `dipoles` (one per sphere) or
    /// NaN when `None` (no recorded force evaluation).
    pub fn of(sys: &SphereSystem, dipoles: Option<&[SphereDipole]>) -> Self {
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
            let share = dipoles.and_then(|d| d.get(k));
            for a in 0..3 {
                for b in 0..3 {
                    t.w[3 * a + b].push(share.map_or(f64::NAN, |d| d.total[a][b]));
                    t.wh[3 * a + b].push(share.map_or(f64::NAN, |d| d.hydro[a][b]));
                }
            }
        }
        t
    }

    /// Whether the table carries dipole shares (snapshots written before they existed do not).
    pub fn has_dipoles(&self) -> bool {
        self.w.iter().chain(&self.wh).all(|c| c.len() == self.x.len())
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
pub fn write_spheres(
    dir: &Path,
    step: u64,
    sys: &SphereSystem,
    dipoles: Option<&[SphereDipole]>,
) -> Result<Vec<(&'static str, PathBuf)>> {
    let t = SphereTable::of(sys, dipoles);
    let csv = PathBuf::from(format!("snapshots/spheres_{step:09}.csv"));
    let mut cols = vec![("id", Col::U64(&t.id)), ("frozen", Col::U64(&t.frozen))];
    cols.extend(F64.iter().zip(t.f64_ref()).map(|(n, v)| (*n, Col::F64(v))));
    cols.extend(DIPOLE.iter().zip(&t.w).map(|(n, v)| (*n, Col::F64(v))));
    cols.extend(DIPOLE_HYDRO.iter().zip(&t.wh).map(|(n, v)| (*n, Col::F64(v))));
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
    // The dipole columns are newer than the table: read when all are there.
    if DIPOLE.iter().chain(&DIPOLE_HYDRO).all(|n| df.column(n).is_ok()) {
        for (name, col) in DIPOLE.iter().zip(&mut t.w) {
            *col = f64_column(&df, name, path)?;
        }
        for (name, col) in DIPOLE_HYDRO.iter().zip(&mut t.wh) {
            *col = f64_column(&df, name, path)?;
        }
    }
    Ok(t)
}
