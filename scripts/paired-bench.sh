#!/usr/bin/env bash
# Paired benchmark of two lbdem binaries: runs `lbdem bench WHICH ARGS...` with OLD and NEW
# alternately, ROUNDS times (old, new, old, new, ...), so that both see the same machine load,
# and keeps every output in DIR/{old,new}-<round>.txt for the comparison table.
#   scripts/paired-bench.sh OLD_BINARY NEW_BINARY ROUNDS DIR WHICH [ARGS...]
# Example (the architecture issue's "no figure moves" check):
#   cp target/release/lbdem target/lbdem-old   # before the change, then rebuild
#   scripts/paired-bench.sh target/lbdem-old target/release/lbdem 3 target/paired lbm --reps 3
set -euo pipefail
old=$1 new=$2 rounds=$3 dir=$4
shift 4
mkdir -p "$dir"
for r in $(seq 1 "$rounds"); do
  for which in old new; do
    bin=$old
    [ "$which" = new ] && bin=$new
    echo "== round $r: $which ($bin bench $*) at $(date -u +%H:%M:%S), load $(cut -d' ' -f1 /proc/loadavg)" | tee "$dir/$which-$r.txt"
    "$bin" bench "$@" 2>&1 | tee -a "$dir/$which-$r.txt"
  done
done
