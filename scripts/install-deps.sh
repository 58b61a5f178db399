#!/usr/bin/env bash
# Installs what the build and tests need beyond the Rust toolchain: Open MPI and libclang for the
# `mpi` feature (sweeps over MPI ranks; the default build does not need them). Idempotent and
# quick when everything is installed.
set -euo pipefail
command -v cargo >/dev/null || { echo "cargo not found: install Rust (rustup) first" >&2; exit 1; }
rustup component list --installed 2>/dev/null | grep -q rustfmt || rustup component add rustfmt clippy 2>/dev/null || true
# Open MPI (mpicc, mpirun, headers) and libclang (bindgen in mpi-sys), from Debian.
need=()
for p in libopenmpi-dev openmpi-bin libclang-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || need+=("$p")
done
if [ ${#need[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ]; then sudo=(); else sudo=(sudo); fi
  "${sudo[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq "${need[@]}"
fi
