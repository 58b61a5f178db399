//! An extruder run as the `extrusion` stage reads it: the geometry, paste and liquid its
//! manifest records (the engine's `spec` and `law` in the summary), its `spheres` snapshots
//! with the time of each, and its `series.csv`. Everything from the files a run writes.

use super::super::run_data::SNAPSHOT_INDEX;
use crate::contract::{MANIFEST, StageRecord};
use crate::report::table::{f64_column, read_table, u64_column};
use crate::scenes::sphere_table::{SphereTable, read_spheres};
use anyhow::{Context, Result, bail};
use lbdem_analysis::coarse::Particle;
use lbdem_dem::spheres::extruder::ExtruderSpec;
use polars::prelude::DataFrame;
use std::path::{Path, PathBuf};

pub struct ExtruderRun {
    pub dir: PathBuf,
    pub spec: ExtruderSpec,
    /// Liquid viscosity η_f (Pa s).
    pub viscosity: f64,
    /// The contact and lubrication law as the run recorded it.
    pub law: serde_json::Value,
    /// When the run's mass balance first held (s), if it did.
    pub first_steady: Option<f64>,
    /// Simulated time at the run's end (s).
    pub end_time: f64,
    /// (time, file) of each sphere snapshot, by time.
    pub snapshots: Vec<(f64, PathBuf)>,
    pub series_path: PathBuf,
    pub series: DataFrame,
}

impl ExtruderRun {
    pub fn open(dir: &Path) -> Result<Self> {
        let manifest = dir.join(MANIFEST);
        let text = std::fs::read_to_string(&manifest).with_context(|| {
            format!(
                "{} is not a finished run: it has no {MANIFEST} (give the output directory of `lbdem \
                 simulate` on an extruder scene, or the name of an earlier simulate stage)",
                dir.display()
            )
        })?;
        let rec: StageRecord = serde_json::from_str(&text)
            .with_context(|| format!("{} is not a stage manifest", manifest.display()))?;
        let s = &rec.output.summary;
        if rec.kind != "simulate" || s["physics"].as_str() != Some("extruder") {
            bail!(
                "{} is not an extruder run (stage '{}', physics {}): give the output of `lbdem simulate` on a \
                 scene with [extruder]",
                dir.display(),
                rec.kind,
                s["physics"]
            );
        }
        let engine = &s["engine"];
        let spec: ExtruderSpec = serde_json::from_value(engine["spec"].clone()).with_context(|| {
            format!(
                "{}: summary.engine.spec is not an extruder spec",
                manifest.display()
            )
        })?;
        let viscosity = engine["law"]["lubrication"]["viscosity"]
            .as_f64()
            .with_context(|| {
                format!(
                    "{}: no summary.engine.law.lubrication.viscosity",
                    manifest.display()
                )
            })?;
        let index = dir.join(SNAPSHOT_INDEX);
        let df = read_table(&index).with_context(|| format!("run {}: no snapshot index", dir.display()))?;
        let steps = u64_column(&df, "step", &index)?;
        let times = f64_column(&df, "time", &index)?;
        let kinds = df.column("kind")?.str()?.clone();
        let files = df.column("file")?.str()?.clone();
        let mut snapshots = Vec::new();
        for k in (0..steps.len()).filter(|&k| kinds.get(k) == Some("spheres")) {
            let file = files.get(k).with_context(|| {
                format!(
                    "{}: row {} (step {}) names no file",
                    index.display(),
                    k + 1,
                    steps[k]
                )
            })?;
            snapshots.push((times[k], dir.join(file)));
        }
        snapshots.sort_by(|a, b| a.0.total_cmp(&b.0));
        let series_path = dir.join(crate::scenes::observers::SERIES_FILE);
        let series = read_table(&series_path)?;
        Ok(Self {
            dir: dir.to_path_buf(),
            spec,
            viscosity,
            law: engine["law"].clone(),
            first_steady: engine["first_steady"].as_f64(),
            end_time: s["time"].as_f64().unwrap_or(f64::NAN),
            snapshots,
            series_path,
            series,
        })
    }

    /// ρ d² / η_f (s), d the smaller diameter: times a velocity gradient, the Stokes number of
    /// Ness's Fig. 4.
    pub fn stokes_scale(&self) -> f64 {
        let d = self.spec.paste.range()[0];
        self.spec.paste.density * d * d / self.viscosity
    }

    /// Start of the averaging window: `from` if given, else when the mass balance first held,
    /// else the second half of the run.
    pub fn window_start(&self, from: Option<f64>) -> f64 {
        from.or(self.first_steady).unwrap_or(0.5 * self.end_time)
    }

    /// Mean of series column `name` over the rows at or after `from`.
    pub fn series_mean(&self, name: &str, from: f64) -> Result<f64> {
        let t = f64_column(&self.series, "time", &self.series_path)?;
        let v = f64_column(&self.series, name, &self.series_path)?;
        let (s, n) = t
            .iter()
            .zip(&v)
            .filter(|(t, v)| **t >= from && v.is_finite())
            .fold((0.0, 0usize), |(s, n), (_, v)| (s + v, n + 1));
        if n == 0 {
            bail!(
                "{}: no row of '{name}' at or after t = {from:e} s (the run ends at {:e} s): give an earlier 'from'",
                self.series_path.display(),
                self.end_time
            );
        }
        Ok(s / n as f64)
    }
}

/// The paste grains of a sphere snapshot (wall grains left out: they carry no dipole share,
/// `lbdem_dem::spheres::sphere_dipoles`, and no velocity), refused if it has no dipoles.
pub fn paste_particles(path: &Path) -> Result<Vec<Particle>> {
    let t: SphereTable = read_spheres(path)?;
    if !t.has_dipoles() {
        bail!(
            "{} has no dipole columns (w_xx ...): it was written before snapshots carried them; rerun the \
             simulation to analyse its stress",
            path.display()
        );
    }
    Ok((0..t.x.len())
        .filter(|&k| t.frozen[k] == 0)
        .map(|k| Particle {
            x: t.x[k],
            y: t.y[k],
            r: t.r[k],
            v: [t.vx[k], t.vy[k], t.vz[k]],
            w: std::array::from_fn(|c| t.w[c][k]),
            wh: std::array::from_fn(|c| t.wh[c][k]),
        })
        .collect())
}
