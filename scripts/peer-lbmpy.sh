#!/usr/bin/env bash
# scripts/peer-lbmpy.sh -- run the peer LBM code (lbmpy 2.0 / pystencils 2.0) on the same D2Q9 BGK
# periodic case as `lbdem bench lbm`, so that lbdem's MLUPS can be divided by lbmpy's measured in the
# same run (the machine is shared; only ratios taken together mean anything).
#
# Usage: scripts/peer-lbmpy.sh SIZE DTYPE THREADS [VARIANT]
#   SIZE = 256x192 | 1024x1024 | 4096x4096, DTYPE = float64 | float32, THREADS = 1 | 2,
#   VARIANT = aa (default: lbmpy's fastest, AA in-place + AVX-512) | avx512 | auto.
#   `scripts/peer-lbmpy.sh install` only creates the venv.
# Prints one JSON line (lbmpy_bench.py's output, field "median" = MLUPS).
# The venv lives in target/peer-lbmpy-venv (git-ignored, next to the build); lbmpy and pystencils
# come from PyPI by name and pinned version. The driver is scripts/peers/lbmpy_bench.py, override
# with LBMPY_BENCH=path.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${LBMPY_VENV:-$ROOT/target/peer-lbmpy-venv}"
BENCH="${LBMPY_BENCH:-$ROOT/scripts/peers/lbmpy_bench.py}"
PY="$VENV/bin/python"

install() {
    if [ ! -x "$PY" ]; then python3 -m venv "$VENV"; fi
    if ! "$PY" -c "import lbmpy, pystencils, cpuinfo" 2>/dev/null; then
        "$PY" -m pip install -q --upgrade pip >&2
        "$PY" -m pip install -q "lbmpy==2.0" "pystencils==2.0" py-cpuinfo >&2
    fi
}

if [ "${1:-}" = install ]; then install; exit 0; fi
if [ $# -lt 3 ]; then
    echo "usage: $0 SIZE DTYPE THREADS [VARIANT]   or   $0 install" >&2
    exit 2
fi
[ -n "$BENCH" ] && [ -f "$BENCH" ] || { echo "peer-lbmpy: driver $BENCH not found; set LBMPY_BENCH=path" >&2; exit 2; }
install
SIZE="$1" DTYPE="$2" THREADS="$3" VARIANT="${4:-aa}"
# threads pinned to cores unless the caller says otherwise (OMP_PROC_BIND=false lets the OS move a
# thread off a core another process is using)
export OMP_PROC_BIND="${OMP_PROC_BIND:-close}" OMP_PLACES="${OMP_PLACES:-cores}"
OMP_NUM_THREADS="$THREADS" "$PY" "$BENCH" --stencil D2Q9 --size "$SIZE" --dtype "$DTYPE" \
    --variant "$VARIANT" --blocks "${LBMPY_BLOCKS:-5}" --block-time "${LBMPY_BLOCK_TIME:-1.0}" \
    --warmup-time 0.5 --cache "$ROOT/target/peer-lbmpy-cache" 2>/dev/null | tail -n 1
