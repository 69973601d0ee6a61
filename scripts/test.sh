#!/usr/bin/env bash
# The test command (README): installs missing system packages, then checks formatting,
# lints and runs every test of the workspace (unit tests beside the code, end-to-end tests
# in tests/, the local Slurm test when root) and checks the cluster files of deploy/. Exits
# non-zero on any failure. Each step prints how long it took, and the
# total is printed last: the figure for the machine it ran on, measured, not quoted.
set -euo pipefail
cd "$(dirname "$0")/.."
export NODEVICE_SELECT=1          # quiet Mesa's device-select layer on headless machines
timed() {
  echo "== $*"
  local started=$SECONDS
  "$@"
  echo "== done in $((SECONDS - started)) s: $*"
}
timed scripts/install-system-deps.sh
# Mitsuba 3 for the agreement tests (tests/mitsuba.rs): a pinned venv, and libllvm19 via apt.
timed tools/mitsuba/setup.sh
export MIRRORBOX_MITSUBA_PYTHON="$PWD/tools/mitsuba/.venv/bin/python"
# Slurm and munge for the sharded-sweep test on a local one-node Slurm (tests/slurm.rs, root).
if [ "$(id -u)" -eq 0 ]; then
  timed scripts/slurm-local.sh install
fi
# The cluster files: Slurm scripts parse, the Kubernetes manifest validates.
timed scripts/check-deploy.sh

timed cargo fmt --all -- --check
timed cargo clippy --workspace --all-targets --locked -- -D warnings
timed cargo test --workspace --locked
echo "== tests done in $SECONDS s on $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $(nproc) cores"
