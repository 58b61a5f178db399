//! Stage `minimal-models`: model no more than a scene needs (issue 16 item 3). From finished
//! sweeps that run a scene once per simplification (`[scene] simplify`, on the same replicas),
//! the table of what each simplification changes in the scene's result and what it saves in
//! wall time, with the verdict harmless or not against the tolerance stated for that result.
//! `[scene] minimal = true` applies what this table shows harmless (src/scenes/schema/simplify.rs).

use crate::atlas::chart::markers_and_line;
use crate::atlas::run_pairs::run_shifts;
use crate::atlas::studies::{Shift, paired_shifts, sweep_tables};
use crate::contract::{Figure, Stage, StageContext, StageOutput, Table};
use crate::report::plot::{XyPlot, xy_png};
use crate::report::table::{Col, str_column, write_table};
use crate::scenes::schema::simplify;
use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    pub studies: Vec<Study>,
    /// Also write the table here (e.g. scenes/su2020/minimal.csv, which `minimal = true` reads).
    #[serde(default)]
    pub publish: Option<PathBuf>,
}

/// One finished sweep: a scene of `family` run with `axis` (a `scene.simplify` key) over
/// simplifications, `reference` the full model.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Study {
    /// "shear-cell", "float" or "extruder": which scenes the rows speak for ([`simplify::family`]).
    pub family: String,
    /// The case, in a few words (a column of the table).
    pub study: String,
    /// The sweep's out directory...
    #[serde(default)]
    pub sweep: Option<PathBuf>,
    /// ...or one finished simulate stage per simplification (`reference` among them), for runs
    /// too long for a sweep: the result is the last value of that series column
    /// (`atlas::run_pairs`).
    #[serde(default)]
    pub runs: Option<BTreeMap<String, PathBuf>>,
    /// The sweep's axis holding the simplifications (default "simplify"); sweeps only: with
    /// `runs` each key names its simplification.
    #[serde(default)]
    pub axis: Option<String>,
    #[serde(default = "none")]
    pub reference: String,
    /// The result column of the sweep (of the runs' series), and the change in it a user accepts.
    pub result: String,
    pub tolerance: f64,
    /// Where the tolerance comes from (a sentence for the caption).
    pub why: String,
    /// A result column holding the time of the part each simplification acts on (e.g. the
    /// shear stage's `wall_seconds`, without the assembly every case repeats); default: the
    /// case's whole wall time. Sweeps only: a run's time is its stage.json's `wall_s`.
    #[serde(default)]
    pub time: Option<String>,
}

/// The axis a sweep varies simplifications along unless `axis` says otherwise.
const SIMPLIFY_AXIS: &str = "simplify";
fn none() -> String {
    "none".into()
}

/// The families a table row may speak for.
const FAMILIES: [&str; 3] = ["shear-cell", "float", "extruder"];

/// One row: a simplification in a study, its change and its saving.
struct Row<'a> {
    study: &'a Study,
    shift: Shift<String>,
    full_wall: f64,
}

impl Row<'_> {
    fn harmless(&self) -> bool {
        self.shift.bound() <= self.study.tolerance
    }
    fn time_saved(&self) -> f64 {
        self.shift.time_saved()
    }
}

pub struct MinimalModels;

impl Stage for MinimalModels {
    const KIND: &'static str = "minimal-models";
    const ABOUT: &'static str =
        "Model no more than a scene needs: the change and the time saved of each simplification, from sweeps";
    type Params = Params;

    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        let mut v = sweep_tables(
            p.studies
                .iter()
                .filter_map(|s| s.sweep.as_ref())
                .map(|d| ctx.resolve(d)),
        );
        for runs in p.studies.iter().filter_map(|s| s.runs.as_ref()) {
            for d in runs.values() {
                v.extend(["series.csv", "stage.json"].map(|f| ctx.resolve(d).join(f)));
            }
        }
        v
    }

    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        check(p)?;
        let mut rows: Vec<Row> = Vec::new();
        for s in &p.studies {
            let (shifts, source) = match (&s.sweep, &s.runs) {
                (Some(sweep), _) => {
                    let dir = ctx.resolve(sweep);
                    let shifts = paired_shifts(
                        &s.study,
                        &dir,
                        s.axis.as_deref().unwrap_or(SIMPLIFY_AXIS),
                        &s.reference,
                        &s.result,
                        str_column,
                        s.time.as_deref(),
                    )?;
                    (shifts, dir.display().to_string())
                }
                (None, Some(runs)) => (
                    run_shifts(&s.study, runs, &s.reference, &s.result, |d| ctx.resolve(d))?,
                    "the runs".to_string(),
                ),
                (None, None) => unreachable!("check() refuses a study with neither"),
            };
            let full_wall = shifts
                .iter()
                .find(|x| x.at == s.reference)
                .map(|x| x.wall_seconds)
                .context("internal: the reference has no shift")?;
            for shift in shifts.into_iter().filter(|x| x.at != s.reference) {
                for name in shift.at.split('+') {
                    if simplify::find(name.trim()).is_none() {
                        bail!(
                            "minimal-models: study '{}': {source} holds '{name}', not a simplification",
                            s.study
                        );
                    }
                }
                rows.push(Row {
                    study: s,
                    shift,
                    full_wall,
                });
            }
        }
        let out = ctx.out_dir.join("minimal.csv");
        write(&out, &rows)?;
        if let Some(dest) = &p.publish {
            let dest = ctx.resolve(dest);
            write(&dest, &rows).with_context(|| format!("minimal-models: publish = {}", dest.display()))?;
        }
        let mut figures = Vec::new();
        let mut files = vec![PathBuf::from("minimal.csv")];
        for s in &p.studies {
            // A chart needs a point: a shift with a bound and a measured time saved.
            if !rows.iter().any(|r| std::ptr::eq(r.study, s) && drawable(r)) {
                continue;
            }
            let file = format!("minimal_{}.png", slug(&s.study));
            chart(&ctx.out_dir.join(&file), s, &rows)?;
            figures.push(Figure {
                path: file.clone().into(),
                caption: format!(
                    "{} ({}): per simplification, the change in {} against the full model on the same replicas \
                     (|mean paired shift| + 2 standard errors; the shift itself for one realisation) over the \
                     tolerance {} ({}), against the wall time it saves (1 - the median over replicas of its wall \
                     time over the full model's on the same replica, from {}). Below the line: harmless. A simplification with failed replicas, \
                     or without a measured wall time (a run resumed across sessions), is not drawn; the first is not harmless.",
                    s.study,
                    s.family,
                    s.result,
                    s.tolerance,
                    s.why,
                    match (&s.sweep, &s.runs) {
                        (Some(d), _) => d.display().to_string(),
                        _ => "finished simulate stages, one per simplification".to_string(),
                    }
                ),
            });
            files.push(file.into());
        }
        let summary: Vec<serde_json::Value> = rows
            .iter()
            .map(|r| {
                serde_json::json!({
                    "family": r.study.family, "study": r.study.study, "simplification": r.shift.at,
                    "bound": finite(r.shift.bound()), "tolerance": r.study.tolerance,
                    "harmless": r.harmless(), "failed": r.shift.failed, "time_saved": r.time_saved(),
                })
            })
            .collect();
        Ok(StageOutput {
            summary: serde_json::json!({ "rows": summary }),
            figures,
            tables: vec![Table {
                path: "minimal.csv".into(),
                caption: "Per family of scenes, study and simplification: the replicas compared, how many failed, the \
                          mean paired shift of the result and its bound, the tolerance, the verdict, the mean wall \
                          times and the fraction of time saved (1 - the median paired wall-time ratio). `minimal = true` applies a simplification where \
                          every row of the scene's family says harmless."
                    .into(),
            }],
            files,
        })
    }
}

/// A row the chart can place: a finite bound and a measured time saved.
fn drawable(r: &Row) -> bool {
    r.shift.bound().is_finite() && r.time_saved().is_finite()
}

fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect::<String>()
        .split('-')
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("-")
}

fn write(path: &std::path::Path, rows: &[Row]) -> Result<()> {
    let text = |f: &dyn Fn(&Row) -> String| rows.iter().map(f).collect::<Vec<String>>();
    let num = |f: &dyn Fn(&Row) -> f64| rows.iter().map(f).collect::<Vec<f64>>();
    let int = |f: &dyn Fn(&Row) -> usize| rows.iter().map(|r| f(r) as u64).collect::<Vec<u64>>();
    let (family, study, simp, result) = (
        text(&|r| r.study.family.clone()),
        text(&|r| r.study.study.clone()),
        text(&|r| r.shift.at.clone()),
        text(&|r| r.study.result.clone()),
    );
    let (n, failed) = (int(&|r| r.shift.shifts.len()), int(&|r| r.shift.failed));
    let (mean, bound, tol) = (
        num(&|r| {
            if r.shift.shifts.is_empty() {
                f64::NAN
            } else {
                r.shift.mean()
            }
        }),
        num(&|r| r.shift.bound()),
        num(&|r| r.study.tolerance),
    );
    let harmless = text(&|r| r.harmless().to_string());
    let (wall, full, saved) = (
        num(&|r| r.shift.wall_seconds),
        num(&|r| r.full_wall),
        num(&|r| r.time_saved()),
    );
    write_table(
        path,
        &[
            ("family", Col::Str(&family)),
            ("study", Col::Str(&study)),
            ("simplification", Col::Str(&simp)),
            ("result", Col::Str(&result)),
            ("replicas", Col::U64(&n)),
            ("failed", Col::U64(&failed)),
            ("mean_shift", Col::F64(&mean)),
            ("bound", Col::F64(&bound)),
            ("tolerance", Col::F64(&tol)),
            ("harmless", Col::Str(&harmless)),
            ("wall_s", Col::F64(&wall)),
            ("full_wall_s", Col::F64(&full)),
            ("time_saved", Col::F64(&saved)),
        ],
    )
}

fn chart(path: &std::path::Path, s: &Study, rows: &[Row]) -> Result<()> {
    let mine: Vec<&Row> = rows
        .iter()
        .filter(|r| std::ptr::eq(r.study, s) && drawable(r))
        .collect();
    let data: Vec<(String, Vec<f64>, Vec<f64>)> = mine
        .iter()
        .map(|r| {
            (
                r.shift.at.clone(),
                vec![100.0 * r.time_saved()],
                vec![r.shift.bound() / s.tolerance],
            )
        })
        .collect();
    let lo = data.iter().map(|p| p.1[0]).fold(0.0f64, f64::min);
    let hi = data.iter().map(|p| p.1[0]).fold(1.0f64, f64::max);
    let (lx, ly) = ([lo, hi], [1.0, 1.0]);
    xy_png(
        path,
        &markers_and_line(&data, ("tolerance", &lx, &ly)),
        &XyPlot {
            title: &format!("{}: what each simplification changes and saves", s.study),
            x_label: "wall time saved (%)",
            y_label: &format!("change in {} / tolerance", s.result),
            log_x: false,
            log_y: false,
        },
    )
}

fn check(p: &Params) -> Result<()> {
    if p.studies.is_empty() {
        bail!("minimal-models: studies = []: give at least one [[stage.params.studies]] (docs/minimal.md)");
    }
    for s in &p.studies {
        if !FAMILIES.contains(&s.family.as_str()) {
            bail!(
                "minimal-models: study '{}': family = {:?}; give one of {FAMILIES:?} (the scenes a row speaks for)",
                s.study,
                s.family
            );
        }
        if s.sweep.is_some() == s.runs.is_some() {
            bail!(
                "minimal-models: study '{}': give either sweep = \"DIR\" (a finished sweep) or runs = {{ none = \"DIR\", ... }} \
                 (one finished simulate stage per simplification), not {}",
                s.study,
                if s.sweep.is_some() { "both" } else { "neither" }
            );
        }
        if s.runs.is_some() {
            // Keys of a sweep that mean nothing for runs are refused rather than ignored.
            let given = [
                (
                    "time",
                    s.time.as_ref(),
                    "a run's wall time is its stage.json's wall_s",
                ),
                (
                    "axis",
                    s.axis.as_ref(),
                    "each key of runs names its simplification",
                ),
            ];
            for (key, value, why) in given {
                if let Some(v) = value {
                    bail!(
                        "minimal-models: study '{}': {key} = {v:?} is for a sweep, and this study gives runs ({why}); \
                         remove {key}, or give sweep = \"DIR\" instead of runs",
                        s.study
                    );
                }
            }
        }
        if !(s.tolerance > 0.0 && s.tolerance.is_finite()) {
            bail!(
                "minimal-models: study '{}': tolerance = {}; give the change in {} a user accepts, a positive number",
                s.study,
                s.tolerance,
                s.result
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contract::StageContext;

    /// Three replicas: "none" at 0, 1, 2; "no-rolling" shifted by 0.001, 0.002, 0.003 (bound
    /// 0.002 + 2 × 0.001/√3 = 0.00315 under a tolerance of 0.004: harmless) and twice as fast;
    /// "no-liquid" shifted by 0.01 each (bound 0.01: not harmless); "f32" with a failed replica.
    #[test]
    fn each_simplification_gets_its_change_saving_and_verdict() {
        let d = tempfile::tempdir().unwrap();
        let sweep = d.path().join("sweep");
        std::fs::create_dir_all(&sweep).unwrap();
        std::fs::write(
            sweep.join("results.csv"),
            "case,simplify,replica,eps\n\
             a0,none,1,0.0\na1,none,2,1.0\na2,none,3,2.0\n\
             b0,no-rolling,1,0.001\nb1,no-rolling,2,1.002\nb2,no-rolling,3,2.003\n\
             c0,no-liquid,1,0.01\nc1,no-liquid,2,1.01\nc2,no-liquid,3,2.01\n\
             e0,f32,1,0.0\ne1,f32,2,1.0\n",
        )
        .unwrap();
        std::fs::write(
            sweep.join("cases.csv"),
            "case,wall_s\na0,4\na1,4\na2,4\nb0,2\nb1,2\nb2,2\nc0,1\nc1,1\nc2,1\ne0,3\ne1,3\n",
        )
        .unwrap();
        let p = Params {
            studies: vec![Study {
                family: "shear-cell".into(),
                study: "test cell".into(),
                sweep: Some(sweep.clone()),
                runs: None,
                axis: None,
                reference: none(),
                result: "eps".into(),
                tolerance: 0.004,
                why: "a test".into(),
                time: None,
            }],
            publish: Some(d.path().join("minimal.csv")),
        };
        let out_dir = d.path().join("out");
        std::fs::create_dir_all(&out_dir).unwrap();
        let ctx = StageContext::new(out_dir, "minimal-models".into(), d.path().to_path_buf());
        let out = MinimalModels::run(&p, &ctx).unwrap();
        let rows = out.summary["rows"].as_array().unwrap();
        assert_eq!(rows.len(), 3);
        let row = |n: &str| rows.iter().find(|r| r["simplification"] == n).unwrap();
        let b = row("no-rolling")["bound"].as_f64().unwrap();
        assert!((b - (0.002 + 2.0 * 0.001 / 3f64.sqrt())).abs() < 1e-12, "{b}");
        assert_eq!(row("no-rolling")["harmless"], true);
        assert_eq!(row("no-rolling")["time_saved"].as_f64(), Some(0.5));
        assert_eq!(row("no-liquid")["harmless"], false);
        assert_eq!(
            (row("f32")["harmless"].as_bool(), row("f32")["failed"].as_u64()),
            (Some(false), Some(1))
        );
        // The published table is what `minimal = true` reads.
        let v = simplify::read_verdicts(&d.path().join("minimal.csv")).unwrap();
        let names: Vec<&str> = simplify::harmless_for(&v, "shear-cell")
            .iter()
            .map(|s| s.name)
            .collect();
        assert_eq!(names, ["no-rolling"]);
        assert!(simplify::harmless_for(&v, "float").is_empty());
    }

    /// `time` and `axis` are a sweep's keys: beside `runs` each is refused, naming the study, the
    /// key and the fix; the same study without it passes the check.
    #[test]
    fn sweep_keys_beside_runs_are_refused() {
        let study = |extra: &str| -> Params {
            toml::from_str(&format!(
                "[[studies]]\nfamily = \"shear-cell\"\nstudy = \"fig 11\"\nresult = \"eps_vol_dem\"\n\
                 tolerance = 0.0018\nwhy = \"a test\"\n{extra}\n\
                 [studies.runs]\nnone = \"a\"\nno-liquid = \"b\"\n"
            ))
            .unwrap()
        };
        check(&study("")).unwrap();
        for (line, key) in [("time = \"shear_wall\"", "time"), ("axis = \"simplify\"", "axis")] {
            let e = check(&study(line)).unwrap_err().to_string();
            assert!(
                e.contains("study 'fig 11'")
                    && e.contains(&format!("{key} = \""))
                    && e.contains(&format!("remove {key}")),
                "{e}"
            );
        }
    }
}
