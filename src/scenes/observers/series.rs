//! The time series: one row per trigger (and at the last step), `series.csv` at the end.

use crate::report::table::{Col, write_table};
use crate::scenes::timeloop::{Flow, LoopCtx, Model, Observer, Trigger};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

pub struct Series {
    trigger: Trigger,
    state: State,
    /// `[lattice] mach_warn`: the liquid's largest Mach number (`max_mach`) the scene's checks
    /// assumed it would stay under; a run that went above it is named after it ends.
    mach_warn: Option<f64>,
}

#[derive(Default, Serialize, Deserialize)]
struct State {
    steps: Vec<u64>,
    rows: Vec<Vec<f64>>,
}

/// The file the series is written to.
pub const FILE: &str = "series.csv";

impl Series {
    pub fn new(trigger: Trigger) -> Self {
        Self {
            trigger,
            state: State::default(),
            mach_warn: None,
        }
    }

    /// Name the run after it ends if its `max_mach` column went above `limit`.
    pub fn warn_above_mach(mut self, limit: Option<f64>) -> Self {
        self.mach_warn = limit;
        self
    }
}

impl Observer for Series {
    fn name(&self) -> &'static str {
        "series"
    }
    fn trigger(&self) -> &Trigger {
        &self.trigger
    }
    fn at_last_step(&self) -> bool {
        true
    }
    fn needs_fields(&self) -> bool {
        true
    }
    fn observe(&mut self, m: &mut dyn Model, _cx: &LoopCtx) -> Result<Flow> {
        let step = m.steps_done();
        if self.state.steps.last() != Some(&step) {
            let mut row = vec![m.time()];
            row.extend(m.sample());
            self.state.steps.push(step);
            self.state.rows.push(row);
        }
        Ok(Flow::Continue)
    }
    fn at_failure(&self) -> bool {
        true
    }
    fn finish(&mut self, m: &mut dyn Model, cx: &LoopCtx) -> Result<()> {
        let mut names = vec!["time".to_string()];
        names.extend(m.series_columns());
        let cols: Vec<(String, Vec<f64>)> = names
            .into_iter()
            .enumerate()
            .map(|(k, n)| (n, self.state.rows.iter().map(|r| r[k]).collect()))
            .collect();
        let path = cx.dir.join(FILE);
        let mut table: Vec<(&str, Col)> = vec![("step", Col::U64(&self.state.steps))];
        table.extend(cols.iter().map(|(n, v)| (n.as_str(), Col::F64(v))));
        write_table(&path, &table).with_context(|| format!("cannot write {}", path.display()))
    }
    fn save(&self) -> serde_json::Value {
        // JSON has no NaN: a missing value is written as null and read back as NaN.
        serde_json::to_value(&self.state).unwrap_or_default()
    }
    fn restore(&mut self, v: serde_json::Value) -> Result<()> {
        #[derive(Deserialize)]
        struct Stored {
            steps: Vec<u64>,
            rows: Vec<Vec<Option<f64>>>,
        }
        let st: Stored = serde_json::from_value(v)?;
        self.state = State {
            steps: st.steps,
            rows: st
                .rows
                .into_iter()
                .map(|r| r.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect())
                .collect(),
        };
        Ok(())
    }
    fn report(&self, m: &dyn Model) -> (Vec<std::path::PathBuf>, Option<(&'static str, serde_json::Value)>) {
        (vec![FILE.into()], Some(("last", self.last(m))))
    }
    fn warnings(&self, m: &dyn Model) -> Vec<String> {
        let (Some(limit), Some(k)) = (
            self.mach_warn,
            m.series_columns().iter().position(|c| c == "max_mach"),
        ) else {
            return Vec::new();
        };
        // column k of the model's sample is column k + 1 of a row (time first)
        let mach: Vec<f64> = self.state.rows.iter().map(|r| r[k + 1]).collect();
        let times: Vec<f64> = self.state.rows.iter().map(|r| r[0]).collect();
        mach_warning(limit, &self.state.steps, &times, &mach)
            .into_iter()
            .collect()
    }
}

/// The warning for a run whose liquid went above the Mach number `limit` at some output: when it
/// first did and how far it went. The checks before a run bound the Mach number the scene
/// expects (`u_max`); a run can still leave it, e.g. a light membrane ringing with the liquid
/// after seconds of quiet (docs/stability.md, "Damped membrane bonds"), and its series from then
/// on is not accurate.
fn mach_warning(limit: f64, steps: &[u64], times: &[f64], mach: &[f64]) -> Option<String> {
    let first = mach.iter().position(|&m| m > limit)?;
    let (peak_at, peak) =
        mach.iter()
            .enumerate()
            .filter(|(_, m)| !m.is_nan())
            .fold(
                (first, mach[first]),
                |best, (i, &m)| if m > best.1 { (i, m) } else { best },
            );
    Some(format!(
        "the liquid's largest Mach number went above [lattice] mach_warn = {limit} at step {} (t = {:.4e} s) \
         and reached {peak:.3} at step {} (t = {:.4e} s): the results from step {} on are not accurate. \
         The series' max_mach column shows how it grew: from a quiet start over many outputs, \
         grains lighter than the liquid ringing with it are the likely cause (a Su membrane at \
         1-1.5 times Table 1's mass did; three times heavier, [membrane] mass_scale = 3, it did not; more \
         [bonds] damping did not help: docs/stability.md, \"Damped membrane bonds\"); from the \
         first outputs, the scene's u_max is too low for the flow",
        steps[first], times[first], steps[peak_at], times[peak_at], steps[first]
    ))
}

impl Series {
    /// The last row as (column, value), for the summary.
    fn last(&self, m: &dyn Model) -> serde_json::Value {
        let mut out = serde_json::Map::new();
        if let (Some(step), Some(row)) = (self.state.steps.last(), self.state.rows.last()) {
            out.insert("step".into(), (*step).into());
            let mut names = vec!["time".to_string()];
            names.extend(m.series_columns());
            for (n, v) in names.into_iter().zip(row) {
                out.insert(n, serde_json::json!(v));
            }
        }
        serde_json::Value::Object(out)
    }
}

#[cfg(test)]
mod tests {
    use super::mach_warning;

    #[test]
    fn a_run_above_its_mach_warning_is_named_with_when_and_how_far() {
        let steps = [0, 155, 310, 465, 620];
        let times = [0.0, 0.1, 0.2, 0.3, 0.4];
        // quiet, then growing past 0.1 and back down: the first crossing and the peak
        let mach = [0.0009, 0.0022, 0.14, 0.6, 0.3];
        let w = mach_warning(0.1, &steps, &times, &mach).unwrap();
        assert!(w.contains("at step 310 (t = 2.0000e-1 s)"), "{w}");
        assert!(w.contains("reached 0.600 at step 465"), "{w}");
        assert!(w.contains("[membrane] mass_scale"), "{w}");
        // never above: nothing; exactly at the limit is not above it
        assert_eq!(
            mach_warning(0.1, &steps, &times, &[0.0009, 0.1, 0.05, 0.0, 0.01]),
            None
        );
        // a NaN output (a series with a missing value) neither triggers nor becomes the peak
        let w = mach_warning(0.1, &steps, &times, &[f64::NAN, 0.2, f64::NAN, 0.15, 0.0]).unwrap();
        assert!(w.contains("reached 0.200 at step 155"), "{w}");
    }
}
