//! Shifts of a result between finished simulate stages, one run per simplification: the paper-
//! scale studies whose runs are too long for a sweep (Su Fig. 11: the 84 %PK cell to 9.7 d̄ of
//! plate travel with and without rate sensitivity and liquid, hours each) but were run anyway as
//! a pipeline's stages. One realisation each, so the bound of a shift is the shift itself.

use super::studies::Shift;
use crate::report::table::f64_column;
use anyhow::{Context, Result, bail};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The series column holding the plate's travel in mean grain diameters (the shear cell's).
const TRAVEL: &str = "plate_displacement_d";

/// A finished run: its series (the result and, where recorded, the plate travel) and wall time.
struct Run {
    dir: PathBuf,
    series: PathBuf,
    value: Vec<f64>,
    /// Plate travel per row, d̄, where the series records it.
    travel: Option<Vec<f64>>,
    /// The run's wall time; NaN when it was resumed (only the last session is on record).
    wall: f64,
}

impl Run {
    /// The plate travel at the last row (None without the column or rows; NaN kept).
    fn end_travel(&self) -> Option<f64> {
        self.travel.as_ref().and_then(|t| t.last().copied())
    }

    /// One output interval: the largest travel between consecutive rows.
    fn interval(&self) -> f64 {
        self.travel
            .as_ref()
            .map(|t| t.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max))
            .unwrap_or(0.0)
    }

    /// The result at plate travel `at` (at most the run's end travel), linear between the two
    /// rows around it; the last row's value without a travel column.
    fn value_at(&self, at: Option<f64>) -> f64 {
        let (Some(t), Some(at)) = (&self.travel, at) else {
            return self.value.last().copied().unwrap_or(f64::NAN);
        };
        let Some(j) = t.iter().rposition(|&x| x <= at) else {
            return f64::NAN;
        };
        if j + 1 == t.len() {
            return self.value[j];
        }
        // t[j] <= at < t[j + 1]: the weight is in [0, 1).
        let w = (at - t[j]) / (t[j + 1] - t[j]);
        self.value[j] + w * (self.value[j + 1] - self.value[j])
    }
}

fn load(dir: &Path, result: &str) -> Result<Run> {
    let manifest = dir.join("stage.json");
    let m: serde_json::Value = serde_json::from_slice(&std::fs::read(&manifest).with_context(|| {
        format!(
            "cannot read {}: run the simulate stage whose out directory is {} first, or leave the run out",
            manifest.display(),
            dir.display()
        )
    })?)
    .with_context(|| format!("{} is not JSON", manifest.display()))?;
    if m["kind"].as_str() != Some("simulate") {
        bail!(
            "{} records a stage of kind {}, not \"simulate\": runs = {{ NAME = \"DIR\" }} takes the out directory \
             of a finished simulate stage (its series.csv is the run's time series)",
            manifest.display(),
            m["kind"]
        );
    }
    let series = dir.join("series.csv");
    if !series.is_file() {
        bail!(
            "{} is missing: run the simulate stage whose out directory is {} first, or leave the run out",
            series.display(),
            dir.display()
        );
    }
    let df = crate::stages::run_data::read_series(&series)?;
    let value = f64_column(&df, result, &series)?;
    if value.is_empty() {
        bail!("{}: no rows; the run wrote no time series", series.display());
    }
    let travel = match df.column(TRAVEL) {
        Ok(_) => Some(f64_column(&df, TRAVEL, &series)?),
        Err(_) => None,
    };
    let wall = match (m["wall_s"].as_f64(), m["resumed"].as_bool()) {
        (Some(w), Some(false)) => w,
        _ => f64::NAN,
    };
    Ok(Run {
        dir: dir.to_path_buf(),
        series,
        value,
        travel,
        wall,
    })
}

/// Per run (a simplification name → a finished simulate stage's directory), the shift of series
/// column `result` against the `reference` run's, at the end of the runs. A run whose result is
/// not finite there counts as failed.
///
/// Where the runs record the plate travel (the shear cell's `plate_displacement_d`), every run
/// must: the runs are compared at the same travel, the smallest end travel among them, each
/// run's result interpolated linearly between the two rows around it. And every run's end travel
/// must lie within one output interval (the largest travel between consecutive rows of that
/// run's series) above it. Both are needed. The agreement makes the comparison one of the runs'
/// ends: a run stopped early (a blow-up, a wall-clock stop) is refused instead of silently
/// moving the comparison point to where it stopped. The interpolation removes what is left: runs
/// stopped by the same `until_wall_moved` still end a fraction of an interval apart, and their
/// last rows differ by the result's change over that fraction (at Fig. 11's rate about 1e-4 of
/// ε_vol per interval, a twentieth of the 0.0018 tolerance), while the error of interpolating
/// linearly inside one interval is second order in it. Runs without the column are compared at
/// their last rows.
pub fn run_shifts(
    study: &str,
    runs: &BTreeMap<String, PathBuf>,
    reference: &str,
    result: &str,
    resolve: impl Fn(&Path) -> PathBuf,
) -> Result<Vec<Shift<String>>> {
    if !runs.contains_key(reference) {
        bail!(
            "study '{study}': runs has no entry for the reference {reference:?}; name the full model's run \
             (e.g. none = \"reports/.../pk84-2150um\")"
        );
    }
    let loaded: Vec<(&String, Run)> = runs
        .iter()
        .map(|(name, dir)| {
            let run =
                load(&resolve(dir), result).with_context(|| format!("study '{study}', run {name:?}"))?;
            Ok((name, run))
        })
        .collect::<Result<_>>()?;
    let at = common_travel(study, &loaded)?;
    let base = &loaded
        .iter()
        .find(|(n, _)| n.as_str() == reference)
        .context("internal: the reference run was not loaded")?
        .1;
    let base_value = base.value_at(at);
    if !base_value.is_finite() {
        bail!(
            "study '{study}': the reference run {reference:?} ({}) ended with {result} = {base_value}",
            base.series.display()
        );
    }
    Ok(loaded
        .iter()
        .map(|(name, run)| {
            let v = run.value_at(at);
            let ok = v.is_finite();
            Shift {
                at: (*name).clone(),
                shifts: if ok { vec![v - base_value] } else { Vec::new() },
                failed: usize::from(!ok),
                of: 1,
                wall_seconds: run.wall,
                wall_ratios: if (run.wall / base.wall).is_finite() {
                    vec![run.wall / base.wall]
                } else {
                    Vec::new()
                },
            }
        })
        .collect())
}

/// The plate travel the runs are compared at (see [`run_shifts`]), or None when no run records
/// it; refuses runs that do not all record it, a travel that is not finite, and end travels
/// more than one output interval apart.
fn common_travel(study: &str, runs: &[(&String, Run)]) -> Result<Option<f64>> {
    let Some((with, w)) = runs
        .iter()
        .find_map(|(n, r)| r.end_travel().filter(|t| t.is_finite()).map(|t| (n, t)))
    else {
        return Ok(None);
    };
    for (name, run) in runs {
        let Some(t) = &run.travel else {
            bail!(
                "study '{study}': run {name:?} ({}) has no {TRAVEL} column but run {with:?} ended at a plate travel \
                 of {w:.3} d; compare runs of the same scene, which all record the plate travel, or leave {name:?} out",
                run.dir.display()
            );
        };
        if let Some(k) = t.iter().position(|x| !x.is_finite()) {
            bail!(
                "study '{study}': run {name:?}: {} row {} has {TRAVEL} = {} but run {with:?} ended at a plate travel \
                 of {w:.3} d; rerun {name:?} (its series is damaged or the run blew up) or leave it out",
                run.series.display(),
                k + 1,
                t[k]
            );
        }
    }
    let ends: Vec<f64> = runs.iter().filter_map(|(_, r)| r.end_travel()).collect();
    let at = ends.iter().copied().fold(f64::INFINITY, f64::min);
    let (shortest, _) = runs
        .iter()
        .find(|(_, r)| r.end_travel() == Some(at))
        .context("internal: no run ends at the smallest end travel")?;
    for (name, run) in runs {
        let (end, h) = (run.end_travel().unwrap_or(at), run.interval());
        if end - at > h {
            bail!(
                "study '{study}': run {name:?} ({}) stopped at a plate travel of {end:.3} d but run {shortest:?} at \
                 {at:.3} d, more than one output interval ({h:.3} d) apart; compare runs that stop at the same \
                 travel (the same [run] until_wall_moved), or rerun {shortest:?} to the end",
                run.dir.display()
            );
        }
    }
    Ok(Some(at))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A finished simulate stage in `dir`: `rows` rows of the plate travel 0 .. `travel` and
    /// eps_vol_dem = `slope` × travel (so a value between rows is known exactly).
    fn run(dir: &Path, rows: usize, travel: f64, slope: f64, wall: f64, resumed: bool) {
        std::fs::create_dir_all(dir).unwrap();
        let mut t = String::from("step,plate_displacement_d,eps_vol_dem\n");
        for k in 0..rows {
            let u = travel * k as f64 / (rows - 1) as f64;
            t += &format!("{k},{u},{}\n", slope * u);
        }
        std::fs::write(dir.join("series.csv"), t).unwrap();
        manifest(dir, "simulate", wall, resumed);
    }

    fn manifest(dir: &Path, kind: &str, wall: f64, resumed: bool) {
        let m = serde_json::json!({"kind": kind, "wall_s": wall, "resumed": resumed});
        std::fs::write(dir.join("stage.json"), m.to_string()).unwrap();
    }

    fn names(pairs: &[(&str, &str)]) -> BTreeMap<String, PathBuf> {
        pairs
            .iter()
            .map(|(a, b)| (a.to_string(), PathBuf::from(b)))
            .collect()
    }

    /// Three runs ending at 9.70, 9.71 and 9.72 d (output interval 0.0485 d): every run is read
    /// at 9.70 d, between its own rows, so each shift is exactly (slope - slope_ref) × 9.70; the
    /// last rows would have given (for the dry run) -0.0015 × 9.72 - (-0.003 × 9.70) instead.
    #[test]
    fn shifts_at_the_smallest_end_travel() {
        let d = tempfile::tempdir().unwrap();
        run(&d.path().join("full"), 201, 9.70, -0.003, 100.0, false);
        run(&d.path().join("fixed"), 201, 9.71, -0.0032, 80.0, false);
        run(&d.path().join("dry"), 201, 9.72, -0.0015, 50.0, true);
        let runs = names(&[
            ("none", "full"),
            ("no-rate-sensitivity", "fixed"),
            ("no-liquid", "dry"),
        ]);
        let base = d.path().to_path_buf();
        let s = run_shifts("t", &runs, "none", "eps_vol_dem", |p| base.join(p)).unwrap();
        let at = |n: &str| s.iter().find(|x| x.at == n).unwrap();
        let fixed = at("no-rate-sensitivity").shifts[0];
        assert!((fixed - (-0.0002 * 9.70)).abs() < 1e-15, "{fixed}");
        assert!((at("no-rate-sensitivity").bound() - 0.0002 * 9.70).abs() < 1e-15);
        assert!((at("no-rate-sensitivity").time_saved() - 0.2).abs() < 1e-15);
        let dry = at("no-liquid").shifts[0];
        assert!((dry - 0.0015 * 9.70).abs() < 1e-15, "{dry}");
        // Resumed: its wall time is not on record, so no time saved.
        assert!(at("no-liquid").time_saved().is_nan());
        assert_eq!(at("none").shifts, [0.0]);
        // No reference run.
        let e = run_shifts("t", &runs, "full", "eps_vol_dem", |p| base.join(p)).unwrap_err();
        assert!(e.to_string().contains("no entry for the reference"), "{e}");
    }

    /// Each refusal names the run, its directory or file, and the fix; the same runs with the
    /// offending one left out are accepted (so each refusal is about that run alone).
    #[test]
    fn runs_that_cannot_be_compared_are_refused() {
        let d = tempfile::tempdir().unwrap();
        let base = d.path().to_path_buf();
        let shifts = |extra: (&str, &str)| {
            let runs = names(&[("none", "full"), extra]);
            run_shifts("t", &runs, "none", "eps_vol_dem", |p| base.join(p)).map_err(|e| format!("{e:#}"))
        };
        run(&d.path().join("full"), 201, 9.70, -0.003, 100.0, false);
        run(&d.path().join("good"), 201, 9.72, -0.003, 100.0, false);
        assert!(shifts(("f32", "good")).is_ok());

        // Stopped 0.06 d before the reference, more than its interval of 0.0485 d.
        run(&d.path().join("early"), 201, 9.64, -0.003, 10.0, false);
        let e = shifts(("f32", "early")).unwrap_err();
        assert!(
            e.contains("run \"none\"")
                && e.contains("stopped at a plate travel of 9.700 d but run \"f32\" at 9.640 d")
                && e.contains("more than one output interval (0.04")
                && e.contains("rerun \"f32\" to the end"),
            "{e}"
        );
        // No travel column beside a run that has one.
        let nt = d.path().join("no-travel");
        std::fs::create_dir_all(&nt).unwrap();
        std::fs::write(nt.join("series.csv"), "step,eps_vol_dem\n0,0\n1,-0.03\n").unwrap();
        manifest(&nt, "simulate", 10.0, false);
        let e = shifts(("f32", "no-travel")).unwrap_err();
        assert!(
            e.contains("run \"f32\"")
                && e.contains(&nt.display().to_string())
                && e.contains(
                    "has no plate_displacement_d column but run \"none\" ended at a plate travel of 9.700 d"
                )
                && e.contains("leave \"f32\" out"),
            "{e}"
        );
        // A travel that is not finite at the end (a blown-up run).
        let nan = d.path().join("nan");
        run(&nan, 3, 9.7, -0.003, 10.0, false);
        let text = std::fs::read_to_string(nan.join("series.csv")).unwrap();
        std::fs::write(nan.join("series.csv"), text.replace("2,9.7,", "2,NaN,")).unwrap();
        let e = shifts(("f32", "nan")).unwrap_err();
        assert!(
            e.contains("run \"f32\"")
                && e.contains("row 3 has plate_displacement_d = NaN")
                && e.contains("rerun \"f32\""),
            "{e}"
        );
        // A directory of another stage kind.
        let an = d.path().join("analysed");
        run(&an, 201, 9.70, -0.003, 10.0, false);
        manifest(&an, "analyse", 10.0, false);
        let e = shifts(("f32", "analysed")).unwrap_err();
        assert!(
            e.contains(&an.join("stage.json").display().to_string())
                && e.contains("kind \"analyse\", not \"simulate\"")
                && e.contains("out directory of a finished simulate stage"),
            "{e}"
        );
        // The reference checked like any other run.
        manifest(&d.path().join("full"), "report", 100.0, false);
        let e = shifts(("f32", "good")).unwrap_err();
        assert!(e.contains("run \"none\"") && e.contains("kind \"report\""), "{e}");
    }
}
