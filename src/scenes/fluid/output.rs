//! What a fluid scene writes: `series.csv` / `series.json` (one row per sample), VTK snapshots
//! `fields/fluid_<step>.vti` with `fluid.pvd`, and `summary.json`. All in SI units.

use super::Setup;
use crate::scenes::SimContext;
use crate::stages::{StageOutput, Table};
use anyhow::{Context, Result};
use lbdem_core::atomic::write_atomic;
use lbdem_core::units::lattice::LatticeUnits;
use lbdem_core::vtk::{Array, Values, write_pvd, write_vti};
use lbdem_lbm::domain::FLUID;
use lbdem_lbm::{Face, Fluid, ForceTorque, Lattice, Macro, Real};
use serde::Serialize;
use std::path::PathBuf;

/// One time-series row.
#[derive(Debug, Serialize)]
pub struct Sample {
    pub step: u64,
    pub time: f64,
    /// Mean fluid velocity (m/s).
    pub mean_u: [f64; 3],
    /// Mean pressure on the x_min face nodes minus on the x_max face nodes (Pa).
    pub pressure_drop: f64,
    /// Force (N, or N/m in 2D) and torque (N m, or N m/m) on each obstacle.
    pub force: Vec<[f64; 3]>,
    pub torque: Vec<[f64; 3]>,
    pub max_mach: f64,
}

impl Sample {
    pub fn take<L: Lattice, T: Real>(
        fluid: &Fluid<L, T>,
        forces: &[ForceTorque],
        m: &Macro,
        u: &LatticeUnits,
        dim: usize,
        n: [usize; 3],
    ) -> Self {
        let dom = &fluid.domain;
        let (mut sum, mut cnt, mut umax2) = ([0.0; 3], 0usize, 0.0f64);
        let (mut p_in, mut n_in, mut p_out, mut n_out) = (0.0, 0usize, 0.0, 0usize);
        for idx in 0..dom.len() {
            if dom.kind[idx] != FLUID {
                continue;
            }
            let v = [m.u[3 * idx], m.u[3 * idx + 1], m.u[3 * idx + 2]];
            for a in 0..3 {
                sum[a] += v[a];
            }
            umax2 = umax2.max(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            cnt += 1;
            let x = idx % n[0];
            if x == 0 {
                p_in += m.rho[idx];
                n_in += 1;
            } else if x + 1 == n[0] {
                p_out += m.rho[idx];
                n_out += 1;
            }
        }
        let n_obst = fluid.obstacles.len();
        let fs = &forces[..n_obst];
        let drop = if n_in > 0 && n_out > 0 {
            u.density_to_pressure(1.0 + p_in / n_in as f64 - p_out / n_out as f64)
        } else {
            0.0
        };
        Self {
            step: fluid.step,
            time: fluid.step as f64 * u.dt,
            mean_u: sum.map(|s| u.velocity_to_si(s / cnt.max(1) as f64)),
            pressure_drop: drop,
            force: fs
                .iter()
                .map(|f| f.force.map(|x| u.force_to_si(x, dim)))
                .collect(),
            torque: fs
                .iter()
                .map(|f| f.torque.map(|x| u.torque_to_si(x, dim)))
                .collect(),
            max_mach: umax2.sqrt() / (1.0f64 / 3.0).sqrt(),
        }
    }
}

pub struct Writer {
    out_dir: PathBuf,
    names: Vec<String>,
    samples: Vec<Sample>,
    snapshots: Vec<(f64, String)>,
    files: Vec<PathBuf>,
}

impl Writer {
    pub fn new(ctx: &SimContext, _su: &Setup, names: Vec<String>) -> Result<Self> {
        std::fs::create_dir_all(ctx.out_dir.join("fields"))
            .with_context(|| format!("cannot create output directory {}", ctx.out_dir.display()))?;
        Ok(Self {
            out_dir: ctx.out_dir.clone(),
            names,
            samples: Vec::new(),
            snapshots: Vec::new(),
            files: Vec::new(),
        })
    }

    pub fn push(&mut self, s: Sample) {
        self.samples.push(s);
    }

    /// Write the fields of the last step as VTK image data (point data, SI units).
    pub fn snapshot<L: Lattice, T: Real>(
        &mut self,
        fluid: &Fluid<L, T>,
        m: &Macro,
        u: &LatticeUnits,
        step: u64,
    ) -> Result<()> {
        let dom = &fluid.domain;
        let fluid_node = |i: usize| dom.kind[i] == FLUID;
        let vel: Vec<f64> = (0..3 * dom.len())
            .map(|k| {
                if fluid_node(k / 3) {
                    u.velocity_to_si(m.u[k])
                } else {
                    0.0
                }
            })
            .collect();
        let p: Vec<f64> = (0..dom.len())
            .map(|i| {
                if fluid_node(i) {
                    u.density_to_pressure(m.rho[i])
                } else {
                    0.0
                }
            })
            .collect();
        let kind: Vec<i32> = dom.kind.iter().map(|&k| k as i32).collect();
        let rel = format!("fields/fluid_{step:08}.vti");
        let path = self.out_dir.join(&rel);
        write_vti(
            &path,
            dom.n,
            [
                0.5 * u.dx,
                0.5 * u.dx,
                if dom.n[2] > 1 { 0.5 * u.dx } else { 0.0 },
            ],
            [u.dx; 3],
            &[
                Array::vector("velocity", Values::F64(&vel)),
                Array::scalar("pressure", Values::F64(&p)),
                Array::scalar("node_kind", Values::I32(&kind)),
            ],
        )
        .with_context(|| format!("cannot write {}", path.display()))?;
        self.snapshots.push((step as f64 * u.dt, rel.clone()));
        self.files.push(PathBuf::from(rel));
        Ok(())
    }

    /// A failed run: remove the snapshots written so far.
    pub fn discard(&mut self) {
        for f in self.files.drain(..) {
            let _ = std::fs::remove_file(self.out_dir.join(f));
        }
    }

    pub fn finish<L: Lattice, T: Real>(
        mut self,
        su: &Setup,
        fluid: &Fluid<L, T>,
        steady: bool,
        wall: f64,
    ) -> Result<StageOutput> {
        let mut header = vec![
            "step".to_string(),
            "time_s".into(),
            "mean_ux_m_s".into(),
            "mean_uy_m_s".into(),
            "mean_uz_m_s".into(),
            "pressure_drop_pa".into(),
            "max_mach".into(),
        ];
        for n in &self.names {
            for c in ["fx", "fy", "fz", "tx", "ty", "tz"] {
                header.push(format!("{n}_{c}"));
            }
        }
        let mut csv = header.join(",") + "\n";
        for s in &self.samples {
            let mut row = vec![
                s.step.to_string(),
                format!("{:e}", s.time),
                format!("{:e}", s.mean_u[0]),
                format!("{:e}", s.mean_u[1]),
                format!("{:e}", s.mean_u[2]),
                format!("{:e}", s.pressure_drop),
                format!("{:e}", s.max_mach),
            ];
            for (f, t) in s.force.iter().zip(&s.torque) {
                row.extend(f.iter().chain(t).map(|v| format!("{v:e}")));
            }
            csv += &(row.join(",") + "\n");
        }
        let put = |w: &mut Self, rel: &str, bytes: &[u8]| -> Result<()> {
            let p = w.out_dir.join(rel);
            write_atomic(&p, bytes).with_context(|| format!("cannot write {}", p.display()))?;
            w.files.push(rel.into());
            Ok(())
        };
        put(&mut self, "series.csv", csv.as_bytes())?;
        let series = serde_json::json!({ "obstacles": self.names, "samples": self.samples });
        put(&mut self, "series.json", &serde_json::to_vec_pretty(&series)?)?;
        let pvd = self.out_dir.join("fluid.pvd");
        write_pvd(&pvd, &self.snapshots).with_context(|| format!("cannot write {}", pvd.display()))?;
        self.files.push("fluid.pvd".into());
        let last = self.samples.last();
        let faces: Vec<String> = su.faces.iter().map(|f| format!("{f:?}")).collect();
        let summary = serde_json::json!({
            "kind": "fluid",
            "lattice": L::NAME,
            "precision": T::NAME,
            "nodes": su.n,
            "fluid_nodes": fluid.domain.fluid_count(),
            "units": su.units,
            "collision": su.collision,
            "kernel": su.kernel,
            "faces": faces,
            "steps": fluid.step,
            "time_s": fluid.step as f64 * su.units.dt,
            "steady": steady,
            "wall_time_s": wall,
            "mlups": fluid.domain.fluid_count() as f64 * fluid.step as f64 / wall / 1e6,
            "final": last,
            "periodic_x": matches!(su.faces[0], Face::Periodic),
        });
        put(&mut self, "summary.json", &serde_json::to_vec_pretty(&summary)?)?;
        Ok(StageOutput {
            summary,
            figures: Vec::new(),
            tables: vec![Table {
                path: "series.csv".into(),
                caption:
                    "fluid time series: mean velocity, pressure drop, force and torque per obstacle (SI)"
                        .into(),
            }],
            files: self.files,
        })
    }
}
