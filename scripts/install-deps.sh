#!/usr/bin/env bash
# Installs what the build and tests need beyond the Rust toolchain: Debian's chromium for the
# headless-browser check of the HTML report. Peer benchmarks have their own scripts (see README).
set -euo pipefail
command -v cargo >/dev/null || { echo "cargo not found: install Rust (rustup) first" >&2; exit 1; }
rustup component list --installed 2>/dev/null | grep -q rustfmt || rustup component add rustfmt clippy 2>/dev/null || true
# The headless-browser check of the HTML report (tests/su2020_ci_pipeline.rs) needs Debian's
# chromium.
if ! command -v chromium >/dev/null; then
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq && $sudo apt-get install -y -qq chromium >/dev/null \
    || { echo "cannot install chromium (Debian package 'chromium'); the report test needs it" >&2; exit 1; }
fi
