//! `lbdem-mpi sweep SWEEP.toml`: `lbdem sweep` spread over MPI ranks, started by a launcher
//! (`mpirun -n N lbdem-mpi sweep ...`, or `srun` where Slurm has PMIx). Every rank expands the
//! same cases; the outputs, tables and page are those of a single-machine `lbdem sweep` of the
//! same file (docs/scaling.md; `scripts/mpi-sweep-check.sh` compares them in CI).

mod ranks;

use anyhow::{Result, bail};
use clap::{Parser, Subcommand};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "lbdem-mpi",
    version,
    about = "lbdem sweeps over MPI ranks (run under mpirun)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a sweep's cases over the ranks; rank 0 writes the tables and the page.
    Sweep {
        /// The sweep file, e.g. sweeps/su2020-ci.toml (docs/sweeps.md).
        sweep: PathBuf,
        /// Output directory (default: the sweep file's `out`, else out/<name>).
        #[arg(long, short)]
        out: Option<PathBuf>,
        /// Threads per case on each rank (default: the node's cores shared among its ranks).
        #[arg(long)]
        threads: Option<usize>,
        /// Rerun every case even when it finished before with the same inputs.
        #[arg(long)]
        force: bool,
    },
}

fn main() -> Result<()> {
    // SAFETY: the first statement of `main`, before any thread of this process exists.
    unsafe { lbdem::cli::refusals_without_backtraces() };
    let Command::Sweep {
        sweep,
        out,
        threads,
        force,
    } = Cli::parse().command;
    if !lbdem::sweep::launched_by_mpi() {
        bail!(
            "lbdem-mpi was not started by an MPI launcher: run it as `mpirun -n N lbdem-mpi sweep {}` \
             (or run `lbdem sweep {}` on one machine)",
            sweep.display(),
            sweep.display()
        );
    }
    let t0 = std::time::Instant::now();
    let plan = lbdem::sweep::plan(&sweep, out)?;
    let threads = threads.unwrap_or(plan.sweep.threads);
    ranks::run(&plan.sweep, &plan.out, &plan.cases, threads, force, t0).map(|_| ())
}
