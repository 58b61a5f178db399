#!/usr/bin/env bash
# Installs what the build and tests need beyond the Rust toolchain: Debian's chromium for the
# headless-browser check of the HTML report, and Open MPI and libclang for `lbdem-mpi`
# (crates/mpi: sweeps over MPI ranks; the default build does not need them). Idempotent and quick when
# everything is installed. Peer benchmarks have their own scripts (see README).
set -euo pipefail
command -v cargo >/dev/null || { echo "cargo not found: install Rust (rustup) first" >&2; exit 1; }
rustup component list --installed 2>/dev/null | grep -q rustfmt || rustup component add rustfmt clippy 2>/dev/null || true
# chromium: the report test (tests/it/su2020_ci_pipeline.rs). Open MPI (mpicc, mpirun, headers) and
# libclang (bindgen in mpi-sys): crates/mpi.
need=()
for p in chromium libopenmpi-dev openmpi-bin libclang-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || need+=("$p")
done
if [ ${#need[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ]; then sudo=(); else sudo=(sudo); fi
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq "${need[@]}" \
    || { echo "cannot install ${need[*]} from Debian; the report test needs chromium, lbdem-mpi Open MPI" >&2; exit 1; }
fi
