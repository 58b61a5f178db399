//! Snapshots: the model writes its state as tables that can be read back (particles, contacts,
//! fluid nodes) and as VTK for ParaView; this observer keeps the list, and at the end writes
//! `snapshots.csv` (step, time, kind, file) and one `.pvd` collection per VTK kind.

use crate::report::table::{Col, write_table};
use crate::scenes::timeloop::{Flow, LoopCtx, Model, Observer, Trigger};
use anyhow::{Context, Result};
use lbdem_core::vtk::write_pvd;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

pub struct Snapshots {
    trigger: Trigger,
    state: State,
}

#[derive(Default, Serialize, Deserialize)]
struct State {
    /// (step, time, kind, file relative to the run's directory).
    written: Vec<(u64, f64, String, PathBuf)>,
}

/// The index of every snapshot file.
pub const INDEX: &str = "snapshots.csv";

impl Snapshots {
    pub fn new(trigger: Trigger) -> Self {
        Self {
            trigger,
            state: State::default(),
        }
    }
}

impl Observer for Snapshots {
    fn name(&self) -> &'static str {
        "snapshots"
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
    fn observe(&mut self, m: &mut dyn Model, cx: &LoopCtx) -> Result<Flow> {
        let step = m.steps_done();
        if self.state.written.last().is_some_and(|w| w.0 == step) {
            return Ok(Flow::Continue);
        }
        std::fs::create_dir_all(cx.dir.join("snapshots"))
            .with_context(|| format!("cannot create {}", cx.dir.join("snapshots").display()))?;
        let t = m.time();
        for (kind, file) in m.snapshot(cx.dir)? {
            self.state.written.push((step, t, kind.to_string(), file));
        }
        Ok(Flow::Continue)
    }
    fn finish(&mut self, _m: &mut dyn Model, cx: &LoopCtx) -> Result<()> {
        let w = &self.state.written;
        let mut kinds: Vec<&str> = w.iter().map(|x| x.2.as_str()).collect();
        kinds.sort_unstable();
        kinds.dedup();
        for kind in kinds.iter().filter(|k| k.ends_with("_vtk")) {
            let list: Vec<(f64, String)> = w
                .iter()
                .filter(|x| x.2 == *kind)
                .map(|x| (x.1, x.3.to_string_lossy().into_owned()))
                .collect();
            let path = cx.dir.join(format!("{}.pvd", kind.trim_end_matches("_vtk")));
            write_pvd(&path, &list).with_context(|| format!("cannot write {}", path.display()))?;
        }
        let steps: Vec<u64> = w.iter().map(|x| x.0).collect();
        let times: Vec<f64> = w.iter().map(|x| x.1).collect();
        let kinds: Vec<String> = w.iter().map(|x| x.2.clone()).collect();
        let files: Vec<String> = w.iter().map(|x| x.3.to_string_lossy().into_owned()).collect();
        write_table(
            &cx.dir.join(INDEX),
            &[
                ("step", Col::U64(&steps)),
                ("time", Col::F64(&times)),
                ("kind", Col::Str(&kinds)),
                ("file", Col::Str(&files)),
            ],
        )
    }
    fn save(&self) -> serde_json::Value {
        serde_json::to_value(&self.state).unwrap_or_default()
    }
    fn restore(&mut self, v: serde_json::Value) -> Result<()> {
        self.state = serde_json::from_value(v)?;
        Ok(())
    }
    fn report(&self, _m: &dyn Model) -> (Vec<PathBuf>, Option<(&'static str, serde_json::Value)>) {
        (self.files(), None)
    }
}

impl Snapshots {
    /// Every file written, relative to the run's directory, with the `.pvd` collections.
    fn files(&self) -> Vec<PathBuf> {
        let mut out: Vec<PathBuf> = self.state.written.iter().map(|w| w.3.clone()).collect();
        let mut kinds: Vec<&str> = self.state.written.iter().map(|x| x.2.as_str()).collect();
        kinds.sort_unstable();
        kinds.dedup();
        for kind in kinds.iter().filter(|k| k.ends_with("_vtk")) {
            out.push(format!("{}.pvd", kind.trim_end_matches("_vtk")).into());
        }
        out.push(INDEX.into());
        out
    }
}
