//! The time series: one row per trigger (and at the last step), `series.csv` at the end.

use crate::report::table::{Col, write_table};
use crate::scenes::timeloop::{Flow, LoopCtx, Model, Observer, Trigger};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};

pub struct Series {
    trigger: Trigger,
    state: State,
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
        }
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
