#!/usr/bin/env bash
# CI: build lbdem with MPI (--features mpi) and run sweeps/su2020-ci.toml twice, on this machine
# and under `mpirun -n 2`; the two results tables must be the same bytes (docs/scaling.md).
# Needs Open MPI (scripts/install-deps.sh). Usage: scripts/mpi-sweep-check.sh [WORKDIR]
set -euo pipefail
cd "$(dirname "$0")/.."
work="${1:-$(mktemp -d)}"
t0=$(date +%s)
# Built as `cargo test` builds it (dev-dependencies' features unified), so after the README's
# `cargo test` only the lbdem crate and the MPI crates compile; a plain `cargo build` would
# rebuild polars with other features.
cargo test --features mpi --no-run --test sweep_cli
t1=$(date +%s)
bin=target/debug/lbdem
"$bin" sweep sweeps/su2020-ci.toml --out "$work/local"
t2=$(date +%s)
# As root, Open MPI needs --allow-run-as-root; --oversubscribe lets two ranks share fewer cores.
root_flag=()
[ "$(id -u)" = 0 ] && root_flag=(--allow-run-as-root)
mpirun -n 2 "${root_flag[@]}" --oversubscribe "$bin" sweep sweeps/su2020-ci.toml --out "$work/mpi" --threads 1
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
