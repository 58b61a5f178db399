//! A sweep over MPI ranks (run under `mpirun -n N lbdem-mpi sweep ...`): every
//! rank expands the same cases from the sweep file; rank 0 hands them out one at a time to
//! whichever rank asks (dynamic assignment, so long and short cases balance), runs cases
//! itself on a second thread meanwhile, and gathers every outcome; then it alone writes the
//! tables and the page, exactly as a single-machine run does. Each rank runs one case at a time
//! with `threads` threads (default: the node's cores shared among the ranks on the node).
//!
//! Messages: a worker sends its last outcome (JSON, empty at first) and receives the index of
//! its next case, or −1 when there is none. Rank 0 polls for requests (20 times a second) rather
//! than block, so its dispatcher costs no core. The case directories must be on a filesystem
//! every rank sees (as a cluster's home or scratch is), or rank 0's page links to nothing.

use anyhow::{Context, Result};
use lbdem::sweep::cases::Case;
use lbdem::sweep::local::{self, CaseOpts, Outcome, Queue};
use lbdem::sweep::progress::SweepProgress;
use lbdem::sweep::schema::Sweep;
use lbdem::sweep::{Summary, finish};
use mpi::traits::*;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::Mutex;
use std::time::{Duration, Instant};

#[derive(Serialize, Deserialize)]
struct Request {
    done: Option<(usize, Outcome)>,
}

/// Run the sweep's cases over the ranks; rank 0 writes the results.
pub fn run(
    sweep: &Sweep,
    out: &Path,
    cases: &[Case],
    threads: usize,
    force: bool,
    t0: Instant,
) -> Result<Summary> {
    let (universe, _) = mpi::initialize_with_threading(mpi::Threading::Funneled)
        .context("MPI could not be initialised (was it already, or is the launcher broken?)")?;
    let world = universe.world();
    let (rank, size) = (world.rank(), world.size());
    let node = world.split_shared(rank);
    let per_node = node.size().max(1) as usize;
    let threads = match threads {
        0 => (lbdem::sweep::cores() / per_node).max(1),
        t => t,
    };
    lbdem::contract::set_quiet(true);
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let opts = CaseOpts {
        sweep_file: &sweep.file,
        results: &sweep.results,
        threads,
        force,
    };
    if rank != 0 {
        let root = world.process_at_rank(0);
        let mut done = None;
        loop {
            root.send(&serde_json::to_vec(&Request { done: done.take() })?[..]);
            let (next, _) = root.receive::<i64>();
            let Ok(i) = usize::try_from(next) else { break };
            let outcome = local::run_case(&cases[i], &opts);
            done = Some((i, outcome));
        }
        return Ok(Summary {
            cases: cases.len(),
            finished: 0,
            failed: 0,
            reused: 0,
        });
    }
    eprintln!(
        "sweep '{}': {} cases over {size} MPI ranks, one case at a time each with {threads} thread(s); outputs in {}",
        sweep.name,
        cases.len(),
        out.display()
    );
    let progress = SweepProgress::new(cases.len(), size as usize, false);
    let queue = Queue::new(cases, sweep.interleave);
    let slots: Mutex<Vec<Option<Outcome>>> = Mutex::new(vec![None; cases.len()]);
    let record = |i: usize, o: Outcome| {
        progress.finished(&cases[i], &o);
        if let Ok(mut s) = slots.lock() {
            s[i] = Some(o);
        }
    };
    let mut bad_message = None;
    std::thread::scope(|s| {
        // Rank 0's own share of the work, on a thread that makes no MPI call (Funneled).
        s.spawn(|| {
            local::run_workers(
                cases,
                &queue,
                1,
                &opts,
                &|i| progress.started(&cases[i]),
                &|i, o| record(i, o),
            )
        });
        let mut active = size - 1;
        while active > 0 {
            let Some(status) = world.any_process().immediate_probe() else {
                std::thread::sleep(Duration::from_millis(50));
                continue;
            };
            let from = world.process_at_rank(status.source_rank());
            let (bytes, _) = from.receive_vec::<u8>();
            match serde_json::from_slice::<Request>(&bytes) {
                Ok(Request { done: Some((i, o)) }) if i < cases.len() => record(i, o),
                Ok(_) => {}
                Err(e) => {
                    bad_message = Some(format!(
                        "rank {} sent a message that is not a request: {e}",
                        status.source_rank()
                    ))
                }
            }
            let next = queue.take();
            if let Some(i) = next {
                progress.started(&cases[i]);
            }
            from.send(&next.map_or(-1, |i| i as i64));
            if next.is_none() {
                active -= 1;
            }
        }
    });
    progress.finish();
    if let Some(e) = bad_message {
        eprintln!("warning: {e}");
    }
    let outcomes: Vec<Outcome> = slots
        .into_inner()
        .unwrap_or_default()
        .into_iter()
        .map(|o| {
            o.unwrap_or(Outcome::Failed {
                error: "no rank reported this case".into(),
                wall_s: 0.0,
            })
        })
        .collect();
    // `node`, `world` and then `universe` (MPI_Finalize) drop in that order on return.
    finish(
        sweep,
        out,
        cases,
        &outcomes,
        t0.elapsed().as_secs_f64(),
        size as usize * threads,
    )
}
