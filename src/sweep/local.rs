//! Cases side by side on one machine: `parallel` worker threads, each running one case at a
//! time in its own rayon pool of `threads` threads (parallel × threads ≤ cores), pulling the
//! next case from a shared queue so long and short cases balance. A case's results do not
//! depend on how many ran beside it: its pool is its own and every kernel is deterministic for
//! any thread count.

use super::cases::Case;
use super::results;
use super::schema::ResultSpec;
use crate::pipeline::{self, RunOpts};
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// How a case ended.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum Outcome {
    /// It ran to its end (or was already finished): one value per declared result (`null` when
    /// missing, with the reason in `notes`).
    Done {
        values: Vec<serde_json::Value>,
        notes: Vec<String>,
        wall_s: f64,
        /// Every stage was reused from an earlier run.
        cached: bool,
        /// A stage continued from an interrupted run's checkpoint.
        resumed: bool,
    },
    /// It stopped with an error (or a panic); it gives no result.
    Failed { error: String, wall_s: f64 },
}

impl Outcome {
    pub fn wall_s(&self) -> f64 {
        match self {
            Outcome::Done { wall_s, .. } | Outcome::Failed { wall_s, .. } => *wall_s,
        }
    }
    pub fn is_done(&self) -> bool {
        matches!(self, Outcome::Done { .. })
    }
}

/// How every case runs.
pub struct CaseOpts<'a> {
    pub sweep_file: &'a Path,
    pub results: &'a [ResultSpec],
    pub threads: usize,
    pub force: bool,
}

/// Run one case through the runner (cache, resume, atomic outputs) in a pool of its own, and
/// read its results. Never panics and never returns an error: a failure is an [`Outcome`].
pub fn run_case(case: &Case, o: &CaseOpts) -> Outcome {
    let t0 = Instant::now();
    let ran = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| -> anyhow::Result<_> {
        std::fs::create_dir_all(&case.dir)?;
        lbdem_core::atomic::write_atomic(
            &case.dir.join("case.json"),
            &serde_json::to_vec_pretty(&case.record())?,
        )?;
        let pool = rayon::ThreadPoolBuilder::new().num_threads(o.threads).build()?;
        pool.install(|| {
            pipeline::run_pipeline(
                &case.pipeline,
                o.sweep_file,
                &case.dir,
                RunOpts {
                    force: o.force,
                    quiet: true,
                    lanes: 1,
                },
            )
        })
    }));
    let wall_s = t0.elapsed().as_secs_f64();
    let records = match ran {
        Ok(Ok(r)) => r,
        Ok(Err(e)) => {
            return Outcome::Failed {
                error: format!("{e:#}"),
                wall_s,
            };
        }
        Err(panic) => {
            let what = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "a panic".into());
            return Outcome::Failed {
                error: format!("the case panicked: {what}"),
                wall_s,
            };
        }
    };
    let stages: Vec<(String, String)> = case
        .pipeline
        .stages
        .iter()
        .map(|s| (s.name.clone(), s.kind.clone()))
        .collect();
    let mut values = Vec::new();
    let mut notes = Vec::new();
    for spec in o.results {
        match results::extract(spec, &case.dir, &stages) {
            Ok(v) => values.push(v),
            Err(e) => {
                values.push(serde_json::Value::Null);
                notes.push(format!("{}: {e:#}", spec.name));
            }
        }
    }
    Outcome::Done {
        values,
        notes,
        wall_s,
        cached: records.iter().all(|r| r.cached),
        resumed: records.iter().any(|r| r.resumed),
    }
}

/// The cases still to hand out, shared by every worker (and by MPI's dispatcher).
pub struct Queue {
    next: AtomicUsize,
    order: Vec<usize>,
}

impl Queue {
    /// The cases in their order, or replica by replica with `interleave` (`[sweep] interleave`).
    pub fn new(cases: &[Case], interleave: bool) -> Self {
        let mut order: Vec<usize> = (0..cases.len()).collect();
        if interleave {
            order.sort_by_key(|&i| (cases[i].replica.map_or(0, |r| r.0), i));
        }
        Self {
            next: AtomicUsize::new(0),
            order,
        }
    }
    pub fn take(&self) -> Option<usize> {
        let i = self.next.fetch_add(1, Ordering::Relaxed);
        self.order.get(i).copied()
    }
}

/// Run cases from `queue` on `parallel` worker threads; `done(index, outcome)` is called as
/// each ends (from the worker's thread) and `started(index)` as each begins.
pub fn run_workers(
    cases: &[Case],
    queue: &Queue,
    parallel: usize,
    o: &CaseOpts,
    started: &(dyn Fn(usize) + Sync),
    done: &(dyn Fn(usize, Outcome) + Sync),
) {
    std::thread::scope(|s| {
        for _ in 0..parallel.max(1) {
            s.spawn(|| {
                while let Some(i) = queue.take() {
                    started(i);
                    let out = run_case(&cases[i], o);
                    done(i, out);
                }
            });
        }
    });
}

/// Every case on this machine; outcomes in case order.
pub fn run_all(
    cases: &[Case],
    interleave: bool,
    parallel: usize,
    o: &CaseOpts,
    progress: &super::progress::SweepProgress,
) -> Vec<Outcome> {
    let slots: Mutex<Vec<Option<Outcome>>> = Mutex::new(vec![None; cases.len()]);
    let queue = Queue::new(cases, interleave);
    run_workers(
        cases,
        &queue,
        parallel,
        o,
        &|i| progress.started(&cases[i]),
        &|i, out| {
            progress.finished(&cases[i], &out);
            if let Ok(mut s) = slots.lock() {
                s[i] = Some(out);
            }
        },
    );
    slots
        .into_inner()
        .unwrap_or_default()
        .into_iter()
        .map(|o| {
            o.unwrap_or(Outcome::Failed {
                error: "the case was never run".into(),
                wall_s: 0.0,
            })
        })
        .collect()
}
