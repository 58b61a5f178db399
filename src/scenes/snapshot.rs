//! Snapshot tables that can be read back, beside the VTK files for ParaView:
//! - `particles_<step>.csv`: one row per circle: `body`, `circle`, `tag` (1 = membrane), the
//!   circle's `x`, `y`, `r`, and its body's `body_x`, `body_y`, `angle`, `vx`, `vy`, `omega`,
//!   and the body's total force and torque of the last evaluation `fx`, `fy`, `torque`;
//! - `contacts_<step>.csv`: one row per touching pair of circles: `i`, `j`, `body_i`,
//!   `body_j` and the contact force on i, `fx`, `fy` (j receives the opposite);
//! - `fluid_<step>.csv`: one row per node: `i`, `j`, `k`, the node's `x`, `y`, `z`, velocity
//!   `ux`, `uy`, `uz` (m/s), `pressure` (Pa, relative to the reference density; coupled, Su
//!   Eq. 19's Δp on the liquid nodes only, cells less than half solid) and, coupled, the
//!   `solid_fraction`; NaN on nodes that hold no liquid.
//!
//! Every number reads back to the same bits (`crate::report::table`). [`read_particles`],
//! [`read_contacts`] and [`read_fluid`] read them, e.g. for the analysis of a run.

use crate::report::table::{Col, f64_column, read_table, u64_column, write_table};
use anyhow::{Context, Result};
use lbdem_core::vtk::{Array, Values, write_vti, write_vtp_points};
use lbdem_dem::System;
use std::path::{Path, PathBuf};

/// A touching pair of circles and the contact force on the first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactForce {
    pub i: u32,
    pub j: u32,
    pub force: [f64; 2],
}

/// The particle table of one snapshot, column by column (one entry per circle).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParticleTable {
    pub body: Vec<u64>,
    pub circle: Vec<u64>,
    pub tag: Vec<u64>,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub r: Vec<f64>,
    pub body_x: Vec<f64>,
    pub body_y: Vec<f64>,
    pub angle: Vec<f64>,
    pub vx: Vec<f64>,
    pub vy: Vec<f64>,
    pub omega: Vec<f64>,
    pub fx: Vec<f64>,
    pub fy: Vec<f64>,
    pub torque: Vec<f64>,
}

impl ParticleTable {
    pub fn of(sys: &System) -> Self {
        let b = &sys.bodies;
        let mut t = ParticleTable::default();
        for c in 0..b.n_circles() {
            let k = b.circle_body[c] as usize;
            let p = b.circle_pos(c);
            t.body.push(k as u64);
            t.circle.push(c as u64);
            t.tag.push(u64::from(b.tag[k]));
            t.x.push(p.x);
            t.y.push(p.y);
            t.r.push(b.circle_r[c]);
            t.body_x.push(b.pos[k].x);
            t.body_y.push(b.pos[k].y);
            t.angle.push(b.angle[k]);
            t.vx.push(b.vel[k].x);
            t.vy.push(b.vel[k].y);
            t.omega.push(b.omega[k]);
            t.fx.push(b.force[k].x);
            t.fy.push(b.force[k].y);
            t.torque.push(b.torque[k]);
        }
        t
    }

    fn columns(&self) -> Vec<(&'static str, Col<'_>)> {
        vec![
            ("body", Col::U64(&self.body)),
            ("circle", Col::U64(&self.circle)),
            ("tag", Col::U64(&self.tag)),
            ("x", Col::F64(&self.x)),
            ("y", Col::F64(&self.y)),
            ("r", Col::F64(&self.r)),
            ("body_x", Col::F64(&self.body_x)),
            ("body_y", Col::F64(&self.body_y)),
            ("angle", Col::F64(&self.angle)),
            ("vx", Col::F64(&self.vx)),
            ("vy", Col::F64(&self.vy)),
            ("omega", Col::F64(&self.omega)),
            ("fx", Col::F64(&self.fx)),
            ("fy", Col::F64(&self.fy)),
            ("torque", Col::F64(&self.torque)),
        ]
    }
}

/// Write the particle and contact tables and the VTK points of `sys` under `dir/snapshots/`,
/// named by the scene's `step` (a coupled scene counts LBM steps, the DEM its sub-steps);
/// returns (kind, path relative to `dir`).
pub fn write_particles(
    dir: &Path,
    step: u64,
    sys: &System,
    contacts: &[ContactForce],
) -> Result<Vec<(&'static str, PathBuf)>> {
    let t = ParticleTable::of(sys);
    let rel = |kind: &str, ext: &str| PathBuf::from(format!("snapshots/{kind}_{step:09}.{ext}"));
    let p = rel("particles", "csv");
    write_table(&dir.join(&p), &t.columns())?;
    let c = rel("contacts", "csv");
    let b = &sys.bodies;
    let (mut i, mut j, mut bi, mut bj, mut fx, mut fy) = (vec![], vec![], vec![], vec![], vec![], vec![]);
    for cf in contacts {
        i.push(u64::from(cf.i));
        j.push(u64::from(cf.j));
        bi.push(u64::from(b.circle_body[cf.i as usize]));
        bj.push(u64::from(b.circle_body[cf.j as usize]));
        fx.push(cf.force[0]);
        fy.push(cf.force[1]);
    }
    write_table(
        &dir.join(&c),
        &[
            ("i", Col::U64(&i)),
            ("j", Col::U64(&j)),
            ("body_i", Col::U64(&bi)),
            ("body_j", Col::U64(&bj)),
            ("fx", Col::F64(&fx)),
            ("fy", Col::F64(&fy)),
        ],
    )?;
    let v = rel("particles", "vtp");
    write_vtp(&dir.join(&v), sys)?;
    Ok(vec![("particles", p), ("contacts", c), ("particles_vtk", v)])
}

/// One point per circle: radius, body id, body velocity and angular velocity.
fn write_vtp(path: &Path, sys: &System) -> Result<()> {
    let b = &sys.bodies;
    let nc = b.n_circles();
    let pos: Vec<[f64; 3]> = (0..nc)
        .map(|c| {
            let p = b.circle_pos(c);
            [p.x, p.y, 0.0]
        })
        .collect();
    let body: Vec<i32> = b.circle_body.iter().map(|&k| k as i32).collect();
    let vel: Vec<f64> = (0..nc)
        .flat_map(|c| {
            let v = b.vel[b.circle_body[c] as usize];
            [v.x, v.y, 0.0]
        })
        .collect();
    let omega: Vec<f64> = (0..nc).map(|c| b.omega[b.circle_body[c] as usize]).collect();
    write_vtp_points(
        path,
        &pos,
        &[
            Array::scalar("radius", Values::F64(&b.circle_r)),
            Array::scalar("body", Values::I32(&body)),
            Array::vector("velocity", Values::F64(&vel)),
            Array::scalar("omega", Values::F64(&omega)),
        ],
    )
    .with_context(|| format!("cannot write {}", path.display()))
}

/// Read a particle table written by [`write_particles`].
pub fn read_particles(path: &Path) -> Result<ParticleTable> {
    let df = read_table(path)?;
    let f = |n: &str| f64_column(&df, n, path);
    let u = |n: &str| u64_column(&df, n, path);
    Ok(ParticleTable {
        body: u("body")?,
        circle: u("circle")?,
        tag: u("tag")?,
        x: f("x")?,
        y: f("y")?,
        r: f("r")?,
        body_x: f("body_x")?,
        body_y: f("body_y")?,
        angle: f("angle")?,
        vx: f("vx")?,
        vy: f("vy")?,
        omega: f("omega")?,
        fx: f("fx")?,
        fy: f("fy")?,
        torque: f("torque")?,
    })
}

/// Read a contact table written by [`write_particles`].
pub fn read_contacts(path: &Path) -> Result<Vec<ContactForce>> {
    let df = read_table(path)?;
    let (i, j) = (u64_column(&df, "i", path)?, u64_column(&df, "j", path)?);
    let (fx, fy) = (f64_column(&df, "fx", path)?, f64_column(&df, "fy", path)?);
    Ok((0..i.len())
        .map(|k| ContactForce {
            i: i[k] as u32,
            j: j[k] as u32,
            force: [fx[k], fy[k]],
        })
        .collect())
}

/// The liquid on the lattice at one step, node by node (SI), for the tables and VTK.
pub struct FluidFields {
    pub n: [usize; 3],
    /// Origin (m): node (i, j, k) sits at lo + (i + ½, j + ½, k + ½) dx.
    pub lo: [f64; 3],
    pub dx: f64,
    /// Interleaved xyz, m/s; NaN where no liquid.
    pub velocity: Vec<f64>,
    /// Pa relative to the reference density; NaN where no liquid (coupled: on nodes at least
    /// half solid too).
    pub pressure: Vec<f64>,
    /// Coupled scenes: the solid fraction of every node (Su Eqs. 9-10).
    pub solid_fraction: Option<Vec<f64>>,
    /// Node kind of the lattice (0 = liquid), liquid-only scenes.
    pub node_kind: Option<Vec<i32>>,
}

/// Write the fluid table and the VTK image of `f` at `step`; returns (kind, path).
pub fn write_fluid(dir: &Path, step: u64, f: &FluidFields) -> Result<Vec<(&'static str, PathBuf)>> {
    let rel = |ext: &str| PathBuf::from(format!("snapshots/fluid_{step:09}.{ext}"));
    let [nx, ny, nz] = f.n;
    let nodes = nx * ny * nz;
    let (mut i, mut j, mut k) = (
        Vec::with_capacity(nodes),
        Vec::with_capacity(nodes),
        Vec::with_capacity(nodes),
    );
    let (mut x, mut y, mut z) = (
        Vec::with_capacity(nodes),
        Vec::with_capacity(nodes),
        Vec::with_capacity(nodes),
    );
    for idx in 0..nodes {
        let (a, b, c) = (idx % nx, (idx / nx) % ny, idx / (nx * ny));
        i.push(a as u64);
        j.push(b as u64);
        k.push(c as u64);
        x.push(f.lo[0] + (a as f64 + 0.5) * f.dx);
        y.push(f.lo[1] + (b as f64 + 0.5) * f.dx);
        z.push(if nz > 1 {
            f.lo[2] + (c as f64 + 0.5) * f.dx
        } else {
            0.0
        });
    }
    let comp = |a: usize| -> Vec<f64> { (0..nodes).map(|n| f.velocity[3 * n + a]).collect() };
    let (ux, uy, uz) = (comp(0), comp(1), comp(2));
    let mut cols = vec![
        ("i", Col::U64(&i)),
        ("j", Col::U64(&j)),
        ("k", Col::U64(&k)),
        ("x", Col::F64(&x)),
        ("y", Col::F64(&y)),
        ("z", Col::F64(&z)),
        ("ux", Col::F64(&ux)),
        ("uy", Col::F64(&uy)),
        ("uz", Col::F64(&uz)),
        ("pressure", Col::F64(&f.pressure)),
    ];
    if let Some(s) = &f.solid_fraction {
        cols.push(("solid_fraction", Col::F64(s)));
    }
    let table = rel("csv");
    write_table(&dir.join(&table), &cols)?;
    let vti = rel("vti");
    // VTK readers choke on NaN less than on holes: write 0 where there is no liquid.
    let zero_nan = |v: &[f64]| -> Vec<f64> { v.iter().map(|x| if x.is_nan() { 0.0 } else { *x }).collect() };
    let (vel, p) = (zero_nan(&f.velocity), zero_nan(&f.pressure));
    let mut arrays = vec![
        Array::vector("velocity", Values::F64(&vel)),
        Array::scalar("pressure", Values::F64(&p)),
    ];
    if let Some(s) = &f.solid_fraction {
        arrays.push(Array::scalar("solid_fraction", Values::F64(s)));
    }
    if let Some(kk) = &f.node_kind {
        arrays.push(Array::scalar("node_kind", Values::I32(kk)));
    }
    let half = 0.5 * f.dx;
    write_vti(
        &dir.join(&vti),
        f.n,
        [
            f.lo[0] + half,
            f.lo[1] + half,
            if nz > 1 { f.lo[2] + half } else { 0.0 },
        ],
        [f.dx; 3],
        &arrays,
    )
    .with_context(|| format!("cannot write {}", dir.join(&vti).display()))?;
    Ok(vec![("fluid", table), ("fluid_vtk", vti)])
}

/// The fluid table of one snapshot, read back.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FluidTable {
    pub i: Vec<u64>,
    pub j: Vec<u64>,
    pub k: Vec<u64>,
    pub ux: Vec<f64>,
    pub uy: Vec<f64>,
    pub uz: Vec<f64>,
    pub pressure: Vec<f64>,
    pub solid_fraction: Option<Vec<f64>>,
}

/// Read a fluid table written by [`write_fluid`].
pub fn read_fluid(path: &Path) -> Result<FluidTable> {
    let df = read_table(path)?;
    let f = |n: &str| f64_column(&df, n, path);
    let u = |n: &str| u64_column(&df, n, path);
    Ok(FluidTable {
        i: u("i")?,
        j: u("j")?,
        k: u("k")?,
        ux: f("ux")?,
        uy: f("uy")?,
        uz: f("uz")?,
        pressure: f("pressure")?,
        solid_fraction: df
            .column("solid_fraction")
            .is_ok()
            .then(|| f("solid_fraction"))
            .transpose()?,
    })
}
