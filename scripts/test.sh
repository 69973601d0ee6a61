#!/usr/bin/env bash
# The test command (README): installs missing system packages, then checks formatting,
# lints and runs every test of the workspace (unit tests beside the code, end-to-end tests
# in tests/). Exits non-zero on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
export NODEVICE_SELECT=1          # quiet Mesa's device-select layer on headless machines
scripts/install-system-deps.sh
# Mitsuba 3 for the agreement tests (tests/mitsuba.rs): a pinned venv, and libllvm19 via apt.
tools/mitsuba/setup.sh
export MIRRORBOX_MITSUBA_PYTHON="$PWD/tools/mitsuba/.venv/bin/python"

echo "== cargo fmt --check"
cargo fmt --all -- --check
echo "== cargo clippy (warnings are errors)"
cargo clippy --workspace --all-targets --locked -- -D warnings
echo "== cargo test"
cargo test --workspace --locked
