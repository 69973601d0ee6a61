#!/usr/bin/env bash
# The test command (README): installs missing system packages, then checks formatting,
# lints and runs every test of the workspace (unit tests beside the code, end-to-end tests
# in tests/, the local Slurm test when root) and checks the cluster files of deploy/. Exits
# non-zero on any failure. Each step prints how long it took, and the total is printed last
# and written to target/test-timing.json: the figure for the machine it ran on, measured,
# not quoted (docs/budgets.md says where the time goes).
#
# Compiled once: clippy's lints run inside the test build itself (clippy-driver as the
# compiler of the workspace's own crates, which is what `cargo clippy` does, but with code
# generation), so no crate is compiled twice. `cargo clippy --workspace --all-targets -- -D
# warnings` reports the same lints.
set -euo pipefail
cd "$(dirname "$0")/.."
steps_json=""
timed() {
  echo "== $*"
  local started=$SECONDS
  "$@"
  local took=$((SECONDS - started))
  echo "== done in $took s: $*"
  local name="$*"
  steps_json+="${steps_json:+,}{\"name\":\"${name//\"/\'}\",\"seconds\":$took}"
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
. scripts/test-build-env.sh
# Every target (benches included) built and linted; then every test run. The workspace has
# no doc tests, so rustdoc is not asked to look for them. --timings: where the build's time
# goes, per crate (target/cargo-timings/cargo-timing.html).
timed cargo test --workspace --locked --all-targets --no-run --timings
# cargo-nextest, where installed (it is on the project's machines), schedules every test of
# every binary in one pool: the long tests (the scene fuzz) overlap the other binaries'
# instead of running after them (docs/budgets.md, measured). Otherwise cargo's own runner.
if cargo nextest --version >/dev/null 2>&1; then
  timed cargo nextest run --workspace --locked --no-fail-fast --lib --bins --tests
else
  timed cargo test --workspace --locked --no-fail-fast --lib --bins --tests
fi
cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//; s/"/'"'"'/g')
mkdir -p target
printf '{"date":"%s","cpu":"%s, %s cores","seconds":%s,"steps":[%s]}\n' \
  "$(date -u +%Y-%m-%dT%H:%M:%SZ)" "$cpu" "$(nproc)" "$SECONDS" "$steps_json" >target/test-timing.json
echo "== tests done in $SECONDS s on $cpu, $(nproc) cores"
