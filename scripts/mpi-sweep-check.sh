#!/usr/bin/env bash
# CI: build the MPI binary (crates/mpi, `lbdem-mpi`) and run sweeps/su2020-ci.toml twice, with
# `lbdem sweep` on this machine and with `mpirun -n 2 lbdem-mpi sweep`; the two results tables
# must be the same bytes (docs/scaling.md). Needs Open MPI (scripts/install-deps.sh).
# Usage: scripts/mpi-sweep-check.sh [WORKDIR]
set -euo pipefail
cd "$(dirname "$0")/.."
work="${1:-$(mktemp -d)}"
t0=$(date +%s)
# Built as the README's `cargo test --workspace` builds, so after it nothing compiles (a plain
# `cargo build`, or a build without the MPI crate, resolves other features for shared
# dependencies, e.g. syn's for bindgen, and rebuilds polars and `lbdem`).
cargo test --workspace --no-run
t1=$(date +%s)
"target/debug/lbdem" sweep sweeps/su2020-ci.toml --out "$work/local"
t2=$(date +%s)
# As root, Open MPI needs --allow-run-as-root; --oversubscribe lets two ranks share fewer cores.
root_flag=()
[ "$(id -u)" = 0 ] && root_flag=(--allow-run-as-root)
mpirun -n 2 "${root_flag[@]}" --oversubscribe target/debug/lbdem-mpi sweep sweeps/su2020-ci.toml --out "$work/mpi" --threads 1
t3=$(date +%s)
for f in results.csv; do
  if ! cmp "$work/local/$f" "$work/mpi/$f"; then
    echo "MPI sweep: $f differs from the single-machine run ($work/local, $work/mpi)" >&2
    exit 1
  fi
done
rows=$(($(wc -l < "$work/local/results.csv") - 1))
echo "MPI sweep check: results.csv identical ($rows cases) on one machine and over 2 ranks;" \
     "build $((t1 - t0)) s, local sweep $((t2 - t1)) s, mpirun sweep $((t3 - t2)) s"
