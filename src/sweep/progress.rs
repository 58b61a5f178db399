//! One progress display for a whole sweep: cases done, running and failed, and the time left
//! estimated from the cases that ran in this invocation (cases reused from an earlier run
//! finish at once and would make the estimate meaningless). On a terminal it is a bar with
//! failures printed above it; elsewhere (CI logs, batch jobs) one line per case.

use super::cases::Case;
use super::local::Outcome;
use indicatif::{ProgressBar, ProgressStyle};
use std::sync::Mutex;
use std::time::Duration;

#[derive(Default)]
struct Counts {
    done: usize,
    running: usize,
    failed: usize,
    /// Wall time of the cases that really ran here (not reused).
    ran_s: f64,
    ran: usize,
}

pub struct SweepProgress {
    bar: ProgressBar,
    total: usize,
    /// Cases that run at once (to turn mean case time into time left).
    slots: usize,
    counts: Mutex<Counts>,
    quiet: bool,
}

impl SweepProgress {
    /// `quiet`: draw nothing (the MPI ranks that are not rank 0).
    pub fn new(total: usize, slots: usize, quiet: bool) -> Self {
        let bar = if quiet {
            ProgressBar::hidden()
        } else {
            ProgressBar::new(total as u64)
        };
        bar.set_style(
            ProgressStyle::with_template("sweep [{bar:30}] {pos}/{len} cases {msg} ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        bar.enable_steady_tick(Duration::from_millis(500));
        Self {
            bar,
            total,
            slots: slots.max(1),
            counts: Mutex::new(Counts::default()),
            quiet,
        }
    }

    fn say(&self, line: String) {
        if self.quiet {
            return;
        }
        if self.bar.is_hidden() {
            eprintln!("{line}");
        } else {
            self.bar.println(line);
        }
    }

    fn refresh(&self, c: &Counts) {
        let left = self.total - c.done;
        let eta = if c.ran == 0 || left == 0 {
            String::new()
        } else {
            let s = c.ran_s / c.ran as f64 * left.div_ceil(self.slots) as f64;
            format!(
                ", about {} left",
                humantime::format_duration(Duration::from_secs(s.round() as u64))
            )
        };
        self.bar
            .set_message(format!("done, {} running, {} failed{eta}", c.running, c.failed));
        self.bar.set_position(c.done as u64);
    }

    pub fn started(&self, _case: &Case) {
        if let Ok(mut c) = self.counts.lock() {
            c.running += 1;
            self.refresh(&c);
        }
    }

    pub fn finished(&self, case: &Case, out: &Outcome) {
        let Ok(mut c) = self.counts.lock() else { return };
        c.running = c.running.saturating_sub(1);
        c.done += 1;
        let n = c.done;
        match out {
            Outcome::Done {
                cached,
                wall_s,
                notes,
                resumed,
                ..
            } => {
                if !cached {
                    c.ran += 1;
                    c.ran_s += wall_s;
                }
                let how = match (cached, resumed) {
                    (true, _) => "finished before, reused".to_string(),
                    (false, true) => format!("resumed and done in {wall_s:.1} s"),
                    (false, false) => format!("done in {wall_s:.1} s"),
                };
                self.say(format!(
                    "case {n}/{} {} ({}): {how}",
                    self.total,
                    case.id,
                    case.label()
                ));
                for note in notes {
                    self.say(format!("    missing result {note}"));
                }
            }
            Outcome::Failed { error, .. } => {
                c.failed += 1;
                self.say(format!(
                    "case {n}/{} {} ({}) FAILED: {}",
                    self.total,
                    case.id,
                    case.label(),
                    error.replace('\n', " ")
                ));
            }
        }
        self.refresh(&c);
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
