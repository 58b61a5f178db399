//! The atlas's studies. Each runs (or reads) the runs of one knob and returns its points; the
//! caption of each (in the `tradeoffs` stage) states the case, the reference and the error
//! measure.

use super::Point;
use crate::report::table::{f64_column, read_table, str_column};
use anyhow::{Context, Result, bail};
use lbdem_coupling::Method;
use lbdem_coupling::cases::resolution::{Steady, disk_array, offsets, offsets_at, sangani_acrivos};
use lbdem_coupling::cases::settling::{self, SettlingSpec};
use lbdem_lbm::cases::poiseuille::poiseuille;
use lbdem_lbm::cases::taylor_green::{self, StoredRun};
use lbdem_lbm::{Collision, ShiftedF16, ShiftedF32};
use std::path::Path;

/// Lattice resolution: Stokes drag of a square array of disks at solid fraction `phi` against
/// Sangani & Acrivos (1982) Table 1, PSM with BGK at τ = 1, at each number of cells per
/// diameter; below 10 cells the answer depends on where the disk sits on the lattice, so it is
/// the mean over 3 × 3 sub-cell offsets (2 × 2 up to 20 cells), and the wall time is per run.
pub fn resolution(cells: &[f64], phi: f64) -> Result<Vec<Point>> {
    let published = sangani_acrivos(phi).with_context(|| {
        format!("solid fraction {phi} is not in Sangani & Acrivos's table (0.05, 0.1, 0.2 ... 0.5)")
    })?;
    let steady = Steady {
        tol: 1e-7,
        ..Steady::default()
    };
    cells
        .iter()
        .map(|&n| {
            let runs = offsets(offsets_at(n))
                .into_iter()
                .map(|o| disk_array(phi, n, o, 1.0, &steady))
                .collect::<Result<Vec<_>, _>>()
                .with_context(|| format!("disk array at {n} cells per diameter"))?;
            let m = runs.len() as f64;
            let drag = runs.iter().map(|r| r.drag).sum::<f64>() / m;
            Ok(Point {
                study: "resolution".into(),
                setting: "PSM, BGK τ = 1".into(),
                value: n,
                error: (drag - published).abs() / published,
                wall_seconds: runs.iter().map(|r| r.seconds).sum::<f64>() / m,
            })
        })
        .collect()
}

/// Coupling method and storage precision: the settling disk (`lbdem_coupling::cases::settling`)
/// against Faxén's wall-corrected Stokes drag, PSM and moving bounce-back, populations in f64 and
/// f32, at each resolution. Returns the "method" points (f64, both methods) and the "precision"
/// points (both precisions, both methods).
pub fn coupling(resolutions: &[usize], duration: f64) -> Result<(Vec<Point>, Vec<Point>)> {
    let (mut method, mut precision) = (Vec::new(), Vec::new());
    for m in [Method::Psm, Method::BounceBack] {
        let name = if m == Method::Psm { "PSM" } else { "bounce-back" };
        for f32 in [false, true] {
            for &n in resolutions {
                let spec = SettlingSpec {
                    cells_per_diameter: n,
                    method: m,
                    duration,
                    ..Default::default()
                };
                let r = if f32 {
                    settling::run::<f32>(&spec)
                } else {
                    settling::run::<f64>(&spec)
                }
                .with_context(|| format!("settling disk, {name}, {n} cells per diameter"))?;
                let p = Point {
                    study: "precision".into(),
                    setting: format!("{name} {}", if f32 { "f32" } else { "f64" }),
                    value: n as f64,
                    error: r.error.abs(),
                    wall_seconds: r.wall_seconds,
                };
                if !f32 {
                    method.push(Point {
                        study: "method".into(),
                        setting: name.into(),
                        ..p.clone()
                    });
                }
                precision.push(p);
            }
        }
    }
    Ok((method, precision))
}

/// The populations' storage in the in-place AA kernel (`lbdem_lbm::storage`): f64 and f32 as
/// themselves, f32s (f32 storage of f − w_i, f64 arithmetic) and f16s (binary16 storage of
/// f − w_i, f32 arithmetic), on the decaying Taylor-Green vortex (`taylor_green::stored`) of
/// each box side in `sizes` and each amplitude in `u0s`, `steps` steps, against the analytic
/// field. One study per amplitude ([`storage_study`]: the two are different cases, each with its
/// own front); `value` is the box side; the wall time is the stepping's.
pub fn storage(sizes: &[usize], u0s: &[f64], steps: usize) -> Result<Vec<Point>> {
    type Run = fn(usize, f64, usize) -> Result<StoredRun, lbdem_lbm::LbmError>;
    let kinds: [(&str, Run); 4] = [
        ("f64", taylor_green::stored::<f64, f64>),
        ("f32", taylor_green::stored::<f32, f32>),
        ("f32s", taylor_green::stored::<f64, ShiftedF32>),
        ("f16s", taylor_green::stored::<f32, ShiftedF16>),
    ];
    let mut out = Vec::new();
    for &u0 in u0s {
        for (name, run) in kinds {
            for &l in sizes {
                let r = run(l, u0, steps)
                    .with_context(|| format!("Taylor-Green vortex, {name} storage, {l} x {l}, u0 = {u0}"))?;
                out.push(Point {
                    study: storage_study(u0),
                    setting: name.into(),
                    value: l as f64,
                    error: r.error,
                    wall_seconds: r.seconds,
                });
            }
        }
    }
    Ok(out)
}

/// The storage study's name at vortex amplitude `u0`.
pub fn storage_study(u0: f64) -> String {
    format!("storage-u0-{u0:e}")
}

/// BGK against TRT: plane Poiseuille flow between halfway bounce-back walls ([`poiseuille`]),
/// the largest deviation from the parabola over u_max, at each τ and channel height. TRT at the
/// former default Λ = 1/4 slips as BGK at τ = 1 at every τ; at Λ = 3/16 (the default now) it
/// does not slip.
pub fn collision(taus: &[f64], heights: &[usize]) -> Result<Vec<Point>> {
    let mut out = Vec::new();
    for &tau in taus {
        let cs = [
            (format!("BGK τ = {tau}"), Collision::Bgk { tau }),
            (
                format!("TRT Λ = 1/4 (scene default), τ = {tau}"),
                Collision::Trt { tau, magic: 0.25 },
            ),
            (
                format!("TRT Λ = 3/16, τ = {tau}"),
                Collision::Trt {
                    tau,
                    magic: 3.0 / 16.0,
                },
            ),
        ];
        for (name, c) in cs {
            for &h in heights {
                let r = poiseuille(c, h).with_context(|| format!("channel of {h} rows, {name}"))?;
                out.push(Point {
                    study: "collision".into(),
                    setting: name.clone(),
                    value: h as f64,
                    error: r.error,
                    wall_seconds: r.seconds,
                });
            }
        }
    }
    Ok(out)
}

/// The tables a study reads from each finished sweep directory (the inputs of a stage that
/// reads sweeps: a rerun sweep changes its key).
pub fn sweep_tables(dirs: impl Iterator<Item = std::path::PathBuf>) -> Vec<std::path::PathBuf> {
    dirs.flat_map(|d| [d.join("results.csv"), d.join("cases.csv")])
        .filter(|f| f.is_file())
        .collect()
}

/// The paired shifts of one value of a swept knob against the reference value, replica by
/// replica, with the mean wall time of a case at that value.
#[derive(Clone, Debug)]
pub struct Shift<T> {
    pub at: T,
    pub shifts: Vec<f64>,
    /// Replicas that finished at the reference but not here (blown up).
    pub failed: usize,
    /// Replicas that finished at the reference.
    pub of: usize,
    pub wall_seconds: f64,
    /// Per replica, its wall time over the reference case's of the same replica.
    pub wall_ratios: Vec<f64>,
}

impl<T> Shift<T> {
    pub fn mean(&self) -> f64 {
        self.shifts.iter().sum::<f64>() / self.shifts.len() as f64
    }
    /// Standard error of the mean shift (NaN below two replicas).
    pub fn standard_error(&self) -> f64 {
        let n = self.shifts.len() as f64;
        if n < 2.0 {
            return f64::NAN;
        }
        let m = self.mean();
        (self.shifts.iter().map(|s| (s - m).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt()
    }
    /// 1 − the median of the paired wall-time ratios: the fraction of time saved, robust to a
    /// machine whose load changes between the pairs (run them close in time: `[sweep] interleave`).
    pub fn time_saved(&self) -> f64 {
        let mut r = self.wall_ratios.clone();
        if r.is_empty() {
            return f64::NAN;
        }
        r.sort_by(f64::total_cmp);
        let m = r.len() / 2;
        let median = if r.len() % 2 == 1 {
            r[m]
        } else {
            0.5 * (r[m - 1] + r[m])
        };
        1.0 - median
    }
    /// |mean| + 2 standard errors; |shift| for one realisation; infinite where replicas failed.
    pub fn bound(&self) -> f64 {
        if self.failed > 0 || self.shifts.is_empty() {
            f64::INFINITY
        } else if self.shifts.len() == 1 {
            self.shifts[0].abs()
        } else {
            self.mean().abs() + 2.0 * self.standard_error()
        }
    }
}

/// Per value of the `axis` column of a finished sweep (values in order of first appearance),
/// the shifts of `result` against the same replica's case at `reference`. `column` reads the
/// axis column as `T` (numbers or names); `wall_result` names a result column to time cases by
/// instead of their whole wall time.
pub fn paired_shifts<T: PartialEq + Clone>(
    study: &str,
    sweep: &Path,
    axis: &str,
    reference: &T,
    result: &str,
    column: impl Fn(&polars::prelude::DataFrame, &str, &Path) -> Result<Vec<T>>,
    wall_result: Option<&str>,
) -> Result<Vec<Shift<T>>> {
    let (res_path, cases_path) = (sweep.join("results.csv"), sweep.join("cases.csv"));
    for p in [&res_path, &cases_path] {
        if !p.is_file() {
            bail!(
                "sweep study '{study}': {} is missing; run `lbdem sweep` on the sweep file whose out is {} first, or \
                 leave the study out",
                p.display(),
                sweep.display()
            );
        }
    }
    let res = read_table(&res_path)?;
    let cases = read_table(&cases_path)?;
    let (case, knob, value) = (
        str_column(&res, "case", &res_path)?,
        column(&res, axis, &res_path)?,
        f64_column(&res, result, &res_path)?,
    );
    // Without replicas every case is replica 0: one realisation per value.
    let replica = match res.column("replica") {
        Ok(_) => str_column(&res, "replica", &res_path)?,
        Err(_) => vec![String::new(); case.len()],
    };
    // A case's wall time: the whole case (cases.csv), or one of its results (e.g. one stage's
    // `wall_seconds`, leaving out stages every case shares).
    let (wall_case, wall) = match wall_result {
        None => (
            str_column(&cases, "case", &cases_path)?,
            f64_column(&cases, "wall_s", &cases_path)?,
        ),
        Some(w) => (case.clone(), f64_column(&res, w, &res_path)?),
    };
    let wall_of = |c: &str| wall_case.iter().position(|w| w == c).map(|k| wall[k]);
    // A case that finished without the result (a packed zone never formed) counts as failed.
    let base: Vec<usize> = (0..case.len())
        .filter(|&k| knob[k] == *reference && value[k].is_finite())
        .collect();
    if base.is_empty() {
        bail!(
            "{}: no finished case at the reference of study '{study}' in column {axis}",
            res_path.display()
        );
    }
    let mut values: Vec<T> = Vec::new();
    for k in &knob {
        if !values.contains(k) {
            values.push(k.clone());
        }
    }
    Ok(values
        .into_iter()
        .map(|f| {
            let mut shifts = Vec::new();
            let mut walls = Vec::new();
            let mut wall_ratios = Vec::new();
            for k in (0..case.len()).filter(|&k| knob[k] == f && value[k].is_finite()) {
                walls.extend(wall_of(&case[k]));
                if let Some(&b) = base.iter().find(|&&b| replica[b] == replica[k]) {
                    shifts.push(value[k] - value[b]);
                    if let (Some(w), Some(wb)) = (wall_of(&case[k]), wall_of(&case[b])) {
                        wall_ratios.push(w / wb);
                    }
                }
            }
            Shift {
                wall_ratios,
                failed: base.len().saturating_sub(walls.len()),
                of: base.len(),
                wall_seconds: walls.iter().sum::<f64>() / walls.len().max(1) as f64,
                at: f,
                shifts,
            }
        })
        .collect())
}

/// A setting's error in a sweep study's chart: 0 at the reference, |mean paired shift| + 2
/// standard errors elsewhere, infinite where replicas failed (a setting with failed replicas is
/// not an answer, whatever its finished ones say).
fn chart_error<T>(s: &Shift<T>, reference: bool) -> f64 {
    if s.failed > 0 {
        f64::INFINITY
    } else if reference {
        0.0
    } else {
        s.mean().abs() + 2.0 * s.standard_error()
    }
}

/// A knob swept by a finished `lbdem sweep` with replicas (e.g. sweeps/su2020-mass-scaling.toml):
/// per value of the `axis` column, the mean wall time of a case (cases.csv) and the bound
/// |mean paired shift| + 2 standard errors of the `result` column against the replica's case at
/// the `reference` value (0 for the reference itself; infinite where replicas that finished at
/// the reference failed).
pub fn paired(
    study: &str,
    sweep: &Path,
    axis: &str,
    reference: f64,
    result: &str,
    time: Option<&str>,
) -> Result<Vec<Point>> {
    let mut shifts = paired_shifts(study, sweep, axis, &reference, result, f64_column, time)
        .map_err(|e| anyhow::anyhow!("{e} (reference {axis} = {reference}; docs/atlas.md)"))?;
    shifts.sort_by(|a, b| a.at.total_cmp(&b.at));
    Ok(shifts
        .into_iter()
        .map(|s| Point {
            study: study.into(),
            setting: if s.failed > 0 {
                format!("{axis} {} ({} of {} failed)", s.at, s.failed, s.of)
            } else {
                format!("{axis} {}", s.at)
            },
            value: s.at,
            error: chart_error(&s, s.at == reference),
            wall_seconds: s.wall_seconds,
        })
        .collect())
}

/// As [`paired`] for an axis of names (e.g. a sweep over `scene.simplify`: "none",
/// "monolayer"): the points in the order the names first appear, `value` their index; `time`
/// names a result column to time cases by (e.g. the simulation's own wall time) instead of the
/// whole case's.
pub fn paired_named(
    study: &str,
    sweep: &Path,
    axis: &str,
    reference: &str,
    result: &str,
    time: Option<&str>,
) -> Result<Vec<Point>> {
    let shifts = paired_shifts(
        study,
        sweep,
        axis,
        &reference.to_string(),
        result,
        str_column,
        time,
    )
    .map_err(|e| anyhow::anyhow!("{e} (reference {axis} = {reference}; docs/atlas.md)"))?;
    Ok(shifts
        .into_iter()
        .enumerate()
        .map(|(k, s)| Point {
            study: study.into(),
            setting: if s.failed > 0 {
                format!("{} ({} of {} failed)", s.at, s.failed, s.of)
            } else {
                s.at.clone()
            },
            value: k as f64,
            error: chart_error(&s, s.at == reference),
            wall_seconds: s.wall_seconds,
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three replicas at the reference, three at f = 2 with shifts 1, 2, 3 (mean 2, standard
    /// error 1/√3), one at f = 3 (two failed).
    #[test]
    fn paired_shifts_give_the_bound_and_name_failed_replicas() {
        let d = tempfile::tempdir().unwrap();
        std::fs::write(
            d.path().join("results.csv"),
            "case,f,replica,eps_vol_end\na0,1,0,0.0\na1,1,1,1.0\na2,1,2,2.0\nb0,2,0,1.0\nb1,2,1,3.0\nb2,2,2,5.0\nc0,3,0,0.5\n",
        )
        .unwrap();
        std::fs::write(
            d.path().join("cases.csv"),
            "case,wall_s\na0,4\na1,4\na2,4\nb0,2\nb1,2\nb2,2\nc0,1\nc1,1\nc2,1\n",
        )
        .unwrap();
        let p = paired("s", d.path(), "f", 1.0, "eps_vol_end", None).unwrap();
        assert_eq!(p.len(), 3);
        assert_eq!((p[0].error, p[0].wall_seconds), (0.0, 4.0));
        assert!(
            (p[1].error - (2.0 + 2.0 / 3f64.sqrt())).abs() < 1e-12,
            "{:?}",
            p[1]
        );
        assert_eq!(p[2].setting, "f 3 (2 of 3 failed)");
        assert!(p[2].error.is_infinite());
        let e = paired("s", d.path(), "f", 9.0, "eps_vol_end", None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("f = 9"), "{e}");
    }

    /// Named settings, paired by replica, timed by a result column: "none" the reference,
    /// "cut" shifted by 1, 2, 3 (bound 2 + 2/√3), "flat" by −4 on one replica of two (the other
    /// failed: infinite).
    #[test]
    fn named_settings_pair_by_replica_and_time_by_a_result_column() {
        let d = tempfile::tempdir().unwrap();
        std::fs::write(
            d.path().join("results.csv"),
            "case,simplify,replica,v,sim_wall\na0,none,0,0.0,10\na1,none,1,1.0,10\na2,none,2,2.0,10\n\
             b0,cut,0,1.0,6\nb1,cut,1,3.0,6\nb2,cut,2,5.0,6\nc0,flat,0,-4.0,1\n",
        )
        .unwrap();
        std::fs::write(d.path().join("cases.csv"), "case,wall_s\na0,99\n").unwrap();
        let p = paired_named("s", d.path(), "simplify", "none", "v", Some("sim_wall")).unwrap();
        let got: Vec<(&str, f64, f64)> = p
            .iter()
            .map(|q| (q.setting.as_str(), q.value, q.wall_seconds))
            .collect();
        assert_eq!(
            got,
            [
                ("none", 0.0, 10.0),
                ("cut", 1.0, 6.0),
                ("flat (2 of 3 failed)", 2.0, 1.0)
            ]
        );
        assert_eq!(p[0].error, 0.0);
        assert!(
            (p[1].error - (2.0 + 2.0 / 3f64.sqrt())).abs() < 1e-12,
            "{:?}",
            p[1]
        );
        assert!(p[2].error.is_infinite());
        let e = paired_named("s", d.path(), "simplify", "full", "v", None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("simplify = full"), "{e}");
    }
}
