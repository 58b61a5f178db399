#!/usr/bin/env bash
# Installs what the build and tests need beyond the Rust toolchain. The tests need
# nothing else; peer benchmarks have their own scripts (see README).
set -euo pipefail
command -v cargo >/dev/null || { echo "cargo not found: install Rust (rustup) first" >&2; exit 1; }
rustup component list --installed 2>/dev/null | grep -q rustfmt || rustup component add rustfmt clippy 2>/dev/null || true
