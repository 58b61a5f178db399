//! A progress bar over the run's steps (drawn only on a terminal).

use crate::scenes::timeloop::{Flow, LoopCtx, Model, Observer, Trigger};
use anyhow::Result;
use indicatif::{ProgressBar, ProgressStyle};

pub struct Progress {
    bar: ProgressBar,
    trigger: Trigger,
    label: String,
}

impl Progress {
    pub fn new(total: u64, done: u64, label: &str) -> Self {
        let bar = crate::contract::progress_bar(total);
        bar.set_style(
            ProgressStyle::with_template("{msg} {bar:40} {pos}/{len} steps, {eta} left")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar.set_message(label.to_string());
        bar.set_position(done);
        Self {
            bar,
            trigger: Trigger::Every((total / 500).max(1)),
            label: label.to_string(),
        }
    }
}

impl Observer for Progress {
    fn name(&self) -> &'static str {
        "progress"
    }
    fn trigger(&self) -> &Trigger {
        &self.trigger
    }
    fn observe(&mut self, m: &mut dyn Model, _cx: &LoopCtx) -> Result<Flow> {
        self.bar.set_position(m.steps_done());
        if let Some(note) = m.progress_note() {
            self.bar.set_message(format!("{} {note}", self.label));
        }
        Ok(Flow::Continue)
    }
    fn finish(&mut self, _m: &mut dyn Model, _cx: &LoopCtx) -> Result<()> {
        self.bar.finish_and_clear();
        Ok(())
    }
}
