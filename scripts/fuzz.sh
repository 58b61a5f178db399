#!/usr/bin/env bash
# The fuzz campaign: every reader of user input (tests/fuzz.rs) for N executions each
# (default 1,000,000), in release, one target at a time, printing per target the executions,
# wall time, accepted/refused counts and the peak memory of one execution.
#   scripts/fuzz.sh [N] [TARGET...]      e.g. scripts/fuzz.sh 1000000 tiff scene_toml
# LBDEM_FUZZ_SEED=K changes the mutation sequence (default 17, the one CI runs);
# LBDEM_FUZZ_DUMP=FILE keeps the input being executed in FILE (after a hang, the culprit).
# LBDEM_FUZZ_TIMEOUT_S=S fails a harness whose execution runs longer than S seconds (default 60).
set -euo pipefail
cd "$(dirname "$0")/.."
case "${1:-}" in
  -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
  -*|*[!0-9]*) [ -n "${1:-}" ] && { echo "fuzz.sh: the first argument is the number of executions, not '$1' (see --help)" >&2; exit 2; } ;;
esac
n="${1:-1000000}"
shift || true
export LBDEM_FUZZ_EXECS="$n"
cargo test --release --test fuzz -- --nocapture --test-threads 1 "$@" 2>&1 | grep --line-buffered -oE "fuzz [a-z_]+: .*|test result.*|panicked.*|FAILED.*"
