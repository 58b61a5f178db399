//! Stage `tradeoffs`: the speed-against-accuracy atlas (issue 16 item 1). One Pareto chart per
//! knob (error against wall time on this machine in this run, the non-dominated settings joined),
//! each on a case with a published or exact answer, and every point in one table.

use crate::atlas::chart::{Axes, pareto_png};
use crate::atlas::pareto::non_dominated;
use crate::atlas::{Point, studies};
use crate::contract::{Figure, Stage, StageContext, StageOutput, Table};
use crate::report::table::{Col, write_table};
use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// Cells per disk diameter of the resolution study ([] leaves it out). Su et al. 2020 run at
    /// 2.4 cells across a hydrodynamic diameter.
    #[serde(default = "resolution")]
    pub resolution: Vec<f64>,
    /// Solid fraction of the disk array (a row of Sangani & Acrivos's table).
    #[serde(default = "phi")]
    pub phi: f64,
    /// Cells per diameter of the settling disk (method and precision studies; [] leaves them out).
    #[serde(default = "settling")]
    pub settling: Vec<usize>,
    /// Settling time in viscous times W²/ν (0.6 reaches the terminal velocity to 0.1 %).
    #[serde(default = "duration")]
    pub duration: f64,
    /// τ values of the BGK-against-TRT study ([] leaves it out).
    #[serde(default = "taus")]
    pub taus: Vec<f64>,
    /// Channel heights (fluid rows) of the BGK-against-TRT study.
    #[serde(default = "heights")]
    pub heights: Vec<usize>,
    /// Box sides of the storage study (the Taylor-Green vortex; [] leaves it out).
    #[serde(default = "storage")]
    pub storage: Vec<usize>,
    /// Vortex amplitudes (lattice units) of the storage study: the smaller shows the stored form.
    #[serde(default = "storage_u0")]
    pub storage_u0: Vec<f64>,
    /// Steps of each storage run.
    #[serde(default = "storage_steps")]
    pub storage_steps: usize,
    /// Knobs read from finished sweeps with replicas (mass scaling, the DEM step).
    #[serde(default)]
    pub sweeps: Vec<SweepStudy>,
    /// rayon threads for every run, 0 = all.
    #[serde(default)]
    pub threads: usize,
}

/// A study read from a finished sweep: the paired shift of `result` against the case at
/// `reference` of `axis`, per value of the axis ([`studies::paired`]).
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepStudy {
    /// Its name in the table and its chart's file name (tradeoff_<study>.png).
    pub study: String,
    /// One sentence for the caption: the case and the knob.
    pub what: String,
    /// The sweep's out directory.
    pub dir: PathBuf,
    pub axis: String,
    /// The axis value the others are compared with: a number (a mass scale, a step) or a name
    /// (a `scene.simplify` value such as "none").
    pub reference: Reference,
    #[serde(default = "eps_vol_end")]
    pub result: String,
    /// A result column to time cases by (e.g. the simulation's own wall time) instead of the
    /// whole case's wall time in cases.csv.
    #[serde(default)]
    pub time: Option<String>,
}

/// A study's reference setting.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Reference {
    Value(f64),
    Name(String),
}

impl std::fmt::Display for Reference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Reference::Value(v) => write!(f, "{v}"),
            Reference::Name(n) => f.write_str(n),
        }
    }
}

fn eps_vol_end() -> String {
    "eps_vol_end".into()
}

fn resolution() -> Vec<f64> {
    vec![2.0, 2.4, 3.0, 5.0, 10.0, 20.0]
}
fn phi() -> f64 {
    0.3
}
fn settling() -> Vec<usize> {
    vec![8, 12, 16, 24]
}
fn duration() -> f64 {
    0.6
}
fn taus() -> Vec<f64> {
    vec![0.6, 1.0, 1.5]
}
fn heights() -> Vec<usize> {
    vec![8, 16, 32]
}
fn storage() -> Vec<usize> {
    vec![64, 256, 1024]
}
fn storage_u0() -> Vec<f64> {
    vec![1e-2, 1e-4]
}
fn storage_steps() -> usize {
    1000
}

/// A study's chart: file, title, error label, caption, log axes.
struct Chart {
    study: String,
    file: String,
    title: String,
    error: String,
    caption: String,
    log: bool,
}

pub struct Tradeoffs;

impl Stage for Tradeoffs {
    const KIND: &'static str = "tradeoffs";
    const ABOUT: &'static str = "Speed against accuracy: a Pareto chart per knob (resolution, precision, method, collision, storage, mass scaling)";
    type Params = Params;

    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        studies::sweep_tables(p.sweeps.iter().map(|s| ctx.resolve(&s.dir)))
    }

    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        check(p)?;
        let pool = rayon::ThreadPoolBuilder::new().num_threads(p.threads).build()?;
        let work = [
            !p.resolution.is_empty(),
            !p.settling.is_empty(),
            !p.taus.is_empty(),
            !p.storage.is_empty(),
        ];
        let bar = ctx.progress_bar(
            (work.iter().filter(|w| **w).count() + p.sweeps.len()) as u64,
            "studies",
        );
        let mut points: Vec<Point> = Vec::new();
        let mut charts: Vec<Chart> = Vec::new();
        if work[0] {
            points.extend(pool.install(|| studies::resolution(&p.resolution, p.phi))?);
            charts.push(Chart {
                study: "resolution".into(),
                file: "tradeoff_resolution.png".into(),
                title: "lattice resolution: disk-array drag".into(),
                error: "|F - F_SA| / F_SA".into(),
                caption: format!(
                    "Lattice resolution. Stokes drag F/(μU) of a square array of disks at solid fraction {} (PSM, BGK τ = 1) \
                     against Sangani & Acrivos (1982) Table 1, at {:?} cells per diameter (Su et al. 2020 run at 2.4); \
                     below 10 cells the mean over 3 × 3 sub-cell positions of the disk. x: wall time per run on this \
                     machine in this run.",
                    p.phi, p.resolution
                ),
                log: true,
            });
            bar.inc(1);
        }
        if work[1] {
            let (method, precision) = pool.install(|| studies::coupling(&p.settling, p.duration))?;
            points.extend(method);
            points.extend(precision);
            let case = format!(
                "the terminal velocity of a disk settling between walls 4 d apart (Re ≈ 0.06) against Faxén's \
                 wall-corrected Stokes drag, at {:?} cells per diameter; x: wall time per run.",
                p.settling
            );
            charts.push(Chart {
                study: "method".into(),
                file: "tradeoff_method.png".into(),
                title: "coupling: PSM against moving bounce-back".into(),
                error: "|U - U_Faxén| / U_Faxén".into(),
                caption: format!("Coupling method, f64 populations: {case}"),
                log: true,
            });
            charts.push(Chart {
                study: "precision".into(),
                file: "tradeoff_precision.png".into(),
                title: "storage: f64 against f32 populations".into(),
                error: "|U - U_Faxén| / U_Faxén".into(),
                caption: format!("Population storage, f64 and f32, both coupling methods: {case}"),
                log: true,
            });
            bar.inc(1);
        }
        if work[2] {
            points.extend(pool.install(|| studies::collision(&p.taus, &p.heights))?);
            charts.push(Chart {
                study: "collision".into(),
                file: "tradeoff_collision.png".into(),
                title: "collision: BGK against TRT".into(),
                error: "max |u - u_exact| / u_max".into(),
                caption: format!(
                    "Collision operator. Plane Poiseuille flow between halfway bounce-back walls, {:?} fluid rows, \
                     τ = {:?}: the largest deviation from the parabola over the peak velocity. TRT at Λ = 3/16 is exact at \
                     every τ up to what the steady-state criterion leaves (1e-14 to 6e-9, growing with the height); \
                     BGK slips by (g/ν)(16(τ-½)² - 3)/24.",
                    p.heights, p.taus
                ),
                log: true,
            });
            bar.inc(1);
        }
        if work[3] {
            points.extend(pool.install(|| studies::storage(&p.storage, &p.storage_u0, p.storage_steps))?);
            for &u0 in &p.storage_u0 {
                let study = studies::storage_study(u0);
                charts.push(Chart {
                    file: format!("tradeoff_{study}.png"),
                    study,
                    title: format!("storage: f64, f32, f32s, f16s populations, vortex u0 = {u0:e}"),
                    error: "max |u - u_exact| / u_max".into(),
                    caption: format!(
                        "Population storage in the in-place AA kernel: f64 and f32 as themselves, f32s (f32 storage \
                         of f - w_i, f64 arithmetic), f16s (binary16 storage of f - w_i, f32 arithmetic). The \
                         decaying Taylor-Green vortex (BGK τ = 0.8) of amplitude u0 = {u0:e} on periodic boxes of \
                         {:?} nodes a side, {} steps: the largest deviation of the velocity field from the analytic \
                         one over its amplitude. x: wall time of the stepping.",
                        p.storage, p.storage_steps
                    ),
                    log: true,
                });
            }
            bar.inc(1);
        }
        for s in &p.sweeps {
            let dir = ctx.resolve(&s.dir);
            points.extend(match &s.reference {
                Reference::Value(r) => {
                    studies::paired(&s.study, &dir, &s.axis, *r, &s.result, s.time.as_deref())?
                }
                Reference::Name(r) => {
                    studies::paired_named(&s.study, &dir, &s.axis, r, &s.result, s.time.as_deref())?
                }
            });
            charts.push(Chart {
                study: s.study.clone(),
                file: format!("tradeoff_{}.png", s.study),
                title: format!("{}: paired shift of {} against {} = {}", s.study, s.result, s.axis, s.reference),
                error: format!("|mean Δ{}| + 2 SE", s.result),
                caption: format!(
                    "{} From the sweep in {}: per value of {}, the mean wall time of a case ({}) and the bound on the \
                     shift of {} against {} = {} on the same replicas (mean paired shift plus two standard errors; 0 for \
                     the reference itself).",
                    s.what,
                    s.dir.display(),
                    s.axis,
                    s.time.as_deref().map_or_else(|| "cases.csv's wall_s".to_string(), |t| format!("its {t}")),
                    s.result,
                    s.axis,
                    s.reference
                ),
                log: false,
            });
            bar.inc(1);
        }
        bar.finish_and_clear();
        let mut front = vec![false; points.len()];
        for c in &charts {
            let idx: Vec<usize> = (0..points.len())
                .filter(|&k| points[k].study == c.study)
                .collect();
            let e: Vec<f64> = idx.iter().map(|&k| points[k].error).collect();
            let t: Vec<f64> = idx.iter().map(|&k| points[k].wall_seconds).collect();
            for (k, f) in idx.iter().zip(non_dominated(&e, &t)) {
                front[*k] = f;
            }
            let sel: Vec<Point> = idx.iter().map(|&k| points[k].clone()).collect();
            let on: Vec<bool> = idx.iter().map(|&k| front[k]).collect();
            pareto_png(
                &ctx.out_dir.join(&c.file),
                &sel,
                &on,
                &Axes {
                    title: &c.title,
                    error_label: &c.error,
                    log: c.log,
                },
            )?;
        }
        let text = |f: fn(&Point) -> &String| points.iter().map(|q| f(q).clone()).collect::<Vec<_>>();
        let num = |f: fn(&Point) -> f64| points.iter().map(f).collect::<Vec<_>>();
        let (study, setting) = (text(|q| &q.study), text(|q| &q.setting));
        let (value, error, wall) = (num(|q| q.value), num(|q| q.error), num(|q| q.wall_seconds));
        let nd: Vec<u64> = front.iter().map(|&f| u64::from(f)).collect();
        write_table(
            &ctx.out_dir.join("tradeoffs.csv"),
            &[
                ("study", Col::Str(&study)),
                ("setting", Col::Str(&setting)),
                ("value", Col::F64(&value)),
                ("error", Col::F64(&error)),
                ("wall_seconds", Col::F64(&wall)),
                ("non_dominated", Col::U64(&nd)),
            ],
        )?;
        let summary: Vec<serde_json::Value> = points
            .iter()
            .zip(&front)
            .map(|(q, f)| serde_json::json!({ "point": q, "non_dominated": f }))
            .collect();
        let mut files: Vec<PathBuf> = charts.iter().map(|c| PathBuf::from(&c.file)).collect();
        files.push("tradeoffs.csv".into());
        Ok(StageOutput {
            summary: serde_json::json!({ "points": summary }),
            figures: charts
                .into_iter()
                .map(|c| Figure {
                    path: c.file.into(),
                    caption: format!("{} The line joins the non-dominated settings.", c.caption),
                })
                .collect(),
            tables: vec![Table {
                path: "tradeoffs.csv".into(),
                caption: "Every run of the atlas: study, setting, value along the series, error, wall time (s), and \
                          whether no other setting of its study is both at least as accurate and as fast"
                    .into(),
            }],
            files,
        })
    }
}

fn check(p: &Params) -> Result<()> {
    if let Some(n) = p.resolution.iter().find(|n| !(**n >= 1.5 && n.is_finite())) {
        bail!(
            "tradeoffs: resolution = {:?} holds {n}; give cells per diameter of at least 1.5, e.g. [2.4, 5, 10]",
            p.resolution
        );
    }
    if let Some(n) = p.settling.iter().find(|n| **n < 4) {
        bail!(
            "tradeoffs: settling = {:?} holds {n}; give cells per diameter of at least 4, e.g. [8, 12]",
            p.settling
        );
    }
    if !(p.duration > 0.0 && p.duration.is_finite()) {
        bail!(
            "tradeoffs: duration = {} must be a positive number of viscous times (0.6 reaches the terminal velocity)",
            p.duration
        );
    }
    if let Some(t) = p.taus.iter().find(|t| !(**t > 0.5 && t.is_finite())) {
        bail!(
            "tradeoffs: taus = {:?} holds {t}; every τ must be above 1/2, e.g. [0.6, 1.0, 1.5]",
            p.taus
        );
    }
    if !p.taus.is_empty() && (p.heights.is_empty() || p.heights.iter().any(|h| *h < 4)) {
        bail!(
            "tradeoffs: heights = {:?}; give channel heights of at least 4 rows, e.g. [8, 16, 32]",
            p.heights
        );
    }
    if let Some(l) = p.storage.iter().find(|l| **l < 8) {
        bail!(
            "tradeoffs: storage = {:?} holds {l}; give box sides of at least 8 nodes, e.g. [64, 256, 1024]",
            p.storage
        );
    }
    if !p.storage.is_empty() {
        if let Some(u) = p.storage_u0.iter().find(|u| !(**u > 0.0 && **u <= 0.1)) {
            bail!(
                "tradeoffs: storage_u0 = {:?} holds {u}; give vortex amplitudes in (0, 0.1] lattice units (Mach \
                 below 0.17), e.g. [1e-2, 1e-4]",
                p.storage_u0
            );
        }
        if p.storage_u0.is_empty() || p.storage_steps == 0 {
            bail!(
                "tradeoffs: the storage study needs amplitudes (storage_u0 = {:?}) and steps (storage_steps = {}); \
                 e.g. [1e-2, 1e-4] and 1000, or storage = [] to leave it out",
                p.storage_u0,
                p.storage_steps
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pts<'a>(out: &'a StageOutput, study: &str) -> Vec<&'a serde_json::Value> {
        out.summary["points"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|p| p["point"]["study"] == study)
            .collect()
    }
    fn num(p: &serde_json::Value, k: &str) -> f64 {
        p["point"][k].as_f64().unwrap()
    }

    /// The reduced atlas CI runs (about 5 s): the orderings a reduced run can show.
    #[test]
    fn the_reduced_atlas_shows_the_orderings_of_each_knob() {
        let dir = tempfile::tempdir().unwrap();
        let ctx = StageContext::new(
            dir.path().to_path_buf(),
            "tradeoffs".into(),
            dir.path().to_path_buf(),
        );
        let p = Params {
            resolution: vec![2.4, 10.0],
            phi: 0.3,
            settling: vec![6, 8],
            duration: 0.6,
            taus: vec![0.8, 1.5],
            heights: vec![8, 16],
            storage: vec![64],
            storage_u0: vec![1e-2, 1e-4],
            storage_steps: 200,
            sweeps: Vec::new(),
            threads: 0,
        };
        let out = Tradeoffs::run(&p, &ctx).unwrap();
        for f in [
            "tradeoff_resolution.png",
            "tradeoff_method.png",
            "tradeoff_precision.png",
            "tradeoff_collision.png",
            "tradeoff_storage-u0-1e-2.png",
            "tradeoff_storage-u0-1e-4.png",
            "tradeoffs.csv",
        ] {
            assert!(dir.path().join(f).is_file(), "{f}");
        }
        // Resolution: the disk-array drag error falls from the paper's 2.4 cells to 10
        // (measured 0.81 and 0.20 against Sangani & Acrivos at Φ = 0.3).
        let r = pts(&out, "resolution");
        assert!(num(r[1], "error") < 0.5 * num(r[0], "error"), "{r:?}");
        // Precision: f32 populations change the settling error by far less than the lattice
        // does (measured at most 4.7e-5; the errors are 7e-3 to 0.13).
        let pr = pts(&out, "precision");
        for m in ["PSM", "bounce-back"] {
            for n in [6.0, 8.0] {
                let e = |s: &str| {
                    pr.iter()
                        .find(|p| p["point"]["setting"] == format!("{m} {s}") && num(p, "value") == n)
                        .map(|p| num(p, "error"))
                        .unwrap()
                };
                assert!(
                    (e("f64") - e("f32")).abs() < 1e-4,
                    "{m} at {n}: {} vs {}",
                    e("f64"),
                    e("f32")
                );
            }
        }
        // Collision: BGK (Λ = (τ - ½)²) and TRT at Λ = 1/4 slip by (16Λ - 3)/(3h²) of u_max, TRT at Λ = 3/16 not
        // at all (measured at most 4.3e-11, the steady-state tolerance's trace).
        for p in pts(&out, "collision") {
            let (h, e) = (num(p, "value"), num(p, "error"));
            let setting = p["point"]["setting"].as_str().unwrap();
            let lambda = if let Some(tau) = setting.strip_prefix("BGK τ = ") {
                let tau: f64 = tau.parse().unwrap();
                Some((tau - 0.5).powi(2))
            } else {
                setting.starts_with("TRT Λ = 1/4").then_some(0.25)
            };
            if let Some(lambda) = lambda {
                let want = (16.0 * lambda - 3.0).abs() / (3.0 * h * h);
                assert!(
                    (e - want).abs() < 1e-6 * want.max(1e-3),
                    "{setting}, h {h}: {e} vs {want}"
                );
            } else {
                assert!(e < 1e-10, "{setting}, h {h}: {e}");
            }
        }
        // Storage (Taylor-Green, 64 x 64, 200 steps; measured errors over the amplitude, u0 = 1e-2 and
        // 1e-4: f64 1.1816e-3, 1.1403e-3; f32 1.1842e-3, 5.39e-3; f32s 1.1816e-3, 1.1403e-3; f16s
        // 1.82e-3, 6.22e-3): f32s stays with f64 (measured within 3.8e-8), f32 stored as itself
        // loses the slow vortex (4.7 times f32s's error), f16s within twice its error.
        let e = |kind: &str, u0: &str| {
            pts(&out, &format!("storage-u0-{u0}"))
                .iter()
                .find(|p| p["point"]["setting"] == kind)
                .map(|p| num(p, "error"))
                .unwrap()
        };
        for u0 in ["1e-2", "1e-4"] {
            assert!((e("f32s", u0) - e("f64", u0)).abs() < 8e-8, "u0 {u0}");
        }
        assert!(e("f32", "1e-4") > 3.0 * e("f32s", "1e-4"));
        assert!(e("f16s", "1e-2") < 3.7e-3 && e("f16s", "1e-4") < 1.3e-2);
        // The front: every study has one, and holds its most accurate setting.
        for s in [
            "resolution",
            "method",
            "precision",
            "collision",
            "storage-u0-1e-2",
            "storage-u0-1e-4",
        ] {
            let v = pts(&out, s);
            let best = v
                .iter()
                .min_by(|a, b| num(a, "error").total_cmp(&num(b, "error")))
                .unwrap();
            assert!(best["non_dominated"].as_bool().unwrap(), "{s}: {best:?}");
        }
    }

    #[test]
    fn bad_settings_are_refused_with_the_fix() {
        let dir = tempfile::tempdir().unwrap();
        let ctx = StageContext::new(
            dir.path().to_path_buf(),
            "tradeoffs".into(),
            dir.path().to_path_buf(),
        );
        let mut p: Params = toml::from_str("taus = [0.5]").unwrap();
        let e = Tradeoffs::run(&p, &ctx).unwrap_err().to_string();
        assert!(e.contains("taus") && e.contains("above 1/2"), "{e}");
        p = toml::from_str(
            "resolution = []\nsettling = []\ntaus = []\nstorage = []\n[[sweeps]]\nstudy = \"mass-scaling\"\nwhat = \"x\"\ndir = \"nowhere\"\naxis = \"mass_scale\"\nreference = 1.0",
        )
        .unwrap();
        let e = Tradeoffs::run(&p, &ctx).unwrap_err().to_string();
        assert!(e.contains("nowhere") && e.contains("lbdem sweep"), "{e}");
        p = toml::from_str("resolution = []\nsettling = []\ntaus = []\nstorage = [64]\nstorage_u0 = [0.5]")
            .unwrap();
        let e = Tradeoffs::run(&p, &ctx).unwrap_err().to_string();
        assert!(e.contains("storage_u0") && e.contains("(0, 0.1]"), "{e}");
    }
}
