//! Shifts of a result between finished simulate stages, one run per simplification: the paper-
//! scale studies whose runs are too long for a sweep (Su Fig. 11: the 84 %PK cell to 9.7 d̄ of
//! plate travel with and without rate sensitivity and liquid, hours each) but were run anyway as
//! a pipeline's stages. One realisation each, so the bound of a shift is the shift itself.

use super::studies::Shift;
use crate::report::table::{f64_column, read_table};
use anyhow::{Context, Result, bail};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Where a run ended and what it measured there.
struct End {
    value: f64,
    /// Plate travel at the end, d̄, where the series records it.
    travel: Option<f64>,
    /// The run's wall time; NaN when it was resumed (only the last session is on record).
    wall: f64,
}

fn end_of(dir: &Path, result: &str) -> Result<End> {
    let series = dir.join("series.csv");
    if !series.is_file() {
        bail!(
            "{} is missing: run the simulate stage whose out directory is {} first, or leave the run out",
            series.display(),
            dir.display()
        );
    }
    let df = read_table(&series)?;
    let last = |col: &str| -> Result<Option<f64>> { Ok(f64_column(&df, col, &series)?.last().copied()) };
    let value = last(result)?.with_context(|| format!("{}: no rows", series.display()))?;
    let travel = match df.column("plate_displacement_d") {
        Ok(_) => last("plate_displacement_d")?,
        Err(_) => None,
    };
    let manifest = dir.join("stage.json");
    let m: serde_json::Value = serde_json::from_slice(
        &std::fs::read(&manifest).with_context(|| format!("cannot read {}", manifest.display()))?,
    )
    .with_context(|| format!("{} is not JSON", manifest.display()))?;
    let wall = match (m["wall_s"].as_f64(), m["resumed"].as_bool()) {
        (Some(w), Some(false)) => w,
        _ => f64::NAN,
    };
    Ok(End { value, travel, wall })
}

/// Per run (a simplification name → a finished simulate stage's directory), the shift of the
/// last value of series column `result` against the `reference` run's. Runs that stopped at
/// different plate travels (more than 1 % apart) are refused: their results are not comparable.
/// A run whose result is not finite counts as failed.
pub fn run_shifts(
    study: &str,
    runs: &BTreeMap<String, PathBuf>,
    reference: &str,
    result: &str,
    resolve: impl Fn(&Path) -> PathBuf,
) -> Result<Vec<Shift<String>>> {
    let Some(ref_dir) = runs.get(reference) else {
        bail!(
            "study '{study}': runs has no entry for the reference {reference:?}; name the full model's run \
             (e.g. none = \"reports/.../pk84-2150um\")"
        );
    };
    let base =
        end_of(&resolve(ref_dir), result).with_context(|| format!("study '{study}', run {reference:?}"))?;
    if !base.value.is_finite() {
        bail!(
            "study '{study}': the reference run {reference:?} ended with {result} = {}",
            base.value
        );
    }
    let mut out = Vec::new();
    for (name, dir) in runs {
        let end = end_of(&resolve(dir), result).with_context(|| format!("study '{study}', run {name:?}"))?;
        if let (Some(a), Some(b)) = (base.travel, end.travel)
            && (a - b).abs() > 0.01 * a.abs().max(b.abs())
        {
            bail!(
                "study '{study}': run {name:?} stopped at a plate travel of {b:.3} d but the reference at {a:.3} d; \
                 compare runs that stop at the same travel"
            );
        }
        let ok = end.value.is_finite();
        out.push(Shift {
            at: name.clone(),
            shifts: if ok {
                vec![end.value - base.value]
            } else {
                Vec::new()
            },
            failed: usize::from(!ok),
            of: 1,
            wall_seconds: end.wall,
            wall_ratios: if (end.wall / base.wall).is_finite() {
                vec![end.wall / base.wall]
            } else {
                Vec::new()
            },
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(dir: &Path, eps: &[f64], travel: f64, wall: f64, resumed: bool) {
        std::fs::create_dir_all(dir).unwrap();
        let mut t = String::from("step,plate_displacement_d,eps_vol_dem\n");
        for (k, e) in eps.iter().enumerate() {
            t += &format!("{k},{},{e}\n", travel * (k + 1) as f64 / eps.len() as f64);
        }
        std::fs::write(dir.join("series.csv"), t).unwrap();
        let m = serde_json::json!({"wall_s": wall, "resumed": resumed});
        std::fs::write(dir.join("stage.json"), m.to_string()).unwrap();
    }

    #[test]
    fn shifts_at_the_end_and_refusals() {
        let d = tempfile::tempdir().unwrap();
        run(&d.path().join("full"), &[0.0, -0.01, -0.03], 9.7, 100.0, false);
        run(&d.path().join("fixed"), &[0.0, -0.012, -0.032], 9.7, 80.0, false);
        run(&d.path().join("dry"), &[0.02, 0.0, -0.015], 9.7, 50.0, true);
        let runs: BTreeMap<String, PathBuf> = [
            ("none", "full"),
            ("no-rate-sensitivity", "fixed"),
            ("no-liquid", "dry"),
        ]
        .iter()
        .map(|(a, b)| (a.to_string(), PathBuf::from(b)))
        .collect();
        let base = d.path().to_path_buf();
        let s = run_shifts("t", &runs, "none", "eps_vol_dem", |p| base.join(p)).unwrap();
        let at = |n: &str| s.iter().find(|x| x.at == n).unwrap();
        assert!((at("no-rate-sensitivity").shifts[0] + 0.002).abs() < 1e-15);
        assert!((at("no-rate-sensitivity").bound() - 0.002).abs() < 1e-15);
        assert!((at("no-rate-sensitivity").time_saved() - 0.2).abs() < 1e-15);
        assert!((at("no-liquid").shifts[0] - 0.015).abs() < 1e-15);
        // Resumed: its wall time is not on record, so no time saved.
        assert!(at("no-liquid").time_saved().is_nan());
        assert_eq!(at("none").shifts, [0.0]);

        // A run that stopped elsewhere is refused, naming it.
        run(&d.path().join("short"), &[0.0, -0.01], 5.0, 10.0, false);
        let mut bad = runs.clone();
        bad.insert("f32".into(), "short".into());
        let e = run_shifts("t", &bad, "none", "eps_vol_dem", |p| base.join(p)).unwrap_err();
        assert!(
            format!("{e:#}").contains("\"f32\" stopped at a plate travel of 5.000"),
            "{e:#}"
        );
        // No reference run.
        let e = run_shifts("t", &runs, "full", "eps_vol_dem", |p| base.join(p)).unwrap_err();
        assert!(e.to_string().contains("no entry for the reference"), "{e}");
    }
}
