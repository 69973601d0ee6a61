#!/usr/bin/env bash
# The main job (README): installs missing system packages, builds mirrorbox in release mode
# (without the viewer), validates every bundled scene, reports the wgpu adapter, then runs
# every experiment of the registry that the main job runs (crates/experiments, `mirrorbox
# experiment --main-job`: the paper's Table 1 twice — two consecutive runs side by side — the
# exact methods' depth scaling, the symmetry planes, lighting, uneven mirrors, stereo, motion,
# the cross-method frontier, the truth's cost against mirrored lights and every scene's memory
# peak), each measuring every point again (cached ground truths are reused when present). It
# records each step's time and peak memory in reports/main_job.json, writes the overview
# reports/index.html and reports/README.md (`report --index`) and fills the generated regions
# of the README and the book from the reports.
set -euo pipefail
cd "$(dirname "$0")/.."
export NODEVICE_SELECT=1
bin=target/release/mirrorbox
# The steps: install, build, check, info, one per experiment of the main job, the overview and
# the README. The experiments are counted from their source before the build (each registry
# row of crates/experiments says `main_job: true|false`), so the counter is right from the
# first step; the built binary's own list is checked against that count below.
main_job_in_source=$(cat crates/experiments/src/*.rs crates/experiments/src/*/*.rs | grep -cE '^[[:space:]]*main_job: true,' || true)
steps_total=$((6 + main_job_in_source))
step=0
# Whether cargo had to download the crates: a fresh machine's cost is with an empty cache
# (issue 51); recorded beside the times.
if [ -n "$(ls -A "${CARGO_HOME:-$HOME/.cargo}/registry/cache" 2>/dev/null)" ]; then
  cargo_cache=warm
else
  cargo_cache=empty
fi
steps_json=""
started_at=$(date -u +%Y-%m-%dT%H:%M:%SZ)
peak_file=$(mktemp)
trap 'rm -f "$peak_file"' EXIT
# Each step says when it starts, how long it took and (with GNU time) its peak memory, and is
# recorded for reports/main_job.json.
run_step() {
  step=$((step + 1))
  echo "== [$step/$steps_total] $*"
  local started=$SECONDS peak=null
  if [ -x /usr/bin/time ]; then
    /usr/bin/time -f "%M" -o "$peak_file" "$@"
    peak=$(tail -n 1 "$peak_file")
    echo "== [$step/$steps_total] peak memory $peak KB (largest process)"
  else
    "$@"
  fi
  local took=$((SECONDS - started))
  echo "== [$step/$steps_total] done in $took s"
  local name="$*"
  name=${name//\"/\'}
  steps_json+="${steps_json:+,}{\"name\":\"$name\",\"seconds\":$took,\"peak_kb\":$peak}"
}
run_step scripts/install-system-deps.sh
# A measured build is a plain one: scripts/test-build-env.sh's clippy wrapper compiles the
# workspace with MIR optimisations off (clippy-driver sets mir-opt-level 0), measured 5-8 %
# slower on the tracer (issue 56, docs/tracer-performance.md).
unset RUSTC_WORKSPACE_WRAPPER CLIPPY_ARGS
# --timings: target/cargo-timings/cargo-timing.html says which crates the build's time goes to.
# Without the viewer (`--no-default-features`): the main job draws no window, and the window's
# crates (egui, winit, their fonts and protocols) were about a third of this build's compiler
# time (docs/budgets.md). `mirrorbox view` in this binary says how to build it with the viewer;
# `cargo build --release -p mirrorbox` then compiles only those crates and the CLI.
run_step cargo build --release --locked -p mirrorbox --no-default-features --timings
main_job_experiments=$("$bin" experiment --main-job)
main_job_built=$(echo "$main_job_experiments" | grep -c . || true)
if [ "$main_job_built" -ne "$main_job_in_source" ]; then
  steps_total=$((6 + main_job_built))
  echo "== run.sh: the binary lists $main_job_built experiments of the main job, but 'main_job: true' appears $main_job_in_source times in crates/experiments/src: counting $steps_total steps from here (scripts/run.sh's count needs fixing)." >&2
fi
run_step "$bin" check scenes/*.json
run_step "$bin" info
# Every experiment of the registry the main job runs, in its order (crates/experiments:
# `mirrorbox experiment --list` says what each measures).
# One truth cache for all of them: Table 1's repeat and the depth scaling trace the truths
# Table 1 traced (the cache is keyed by the scene's content and the truth's settings).
for experiment in $main_job_experiments; do
  run_step "$bin" experiment "$experiment" --fresh --truth-cache target/truth-cache
done
cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//; s/"/'"'"'/g')
cores=$(nproc)
tmp=$(mktemp reports/.main_job.XXXXXX)
printf '{"date":"%s","cpu":"%s, %s cores","cargo_cache":"%s","seconds":%s,"steps":[%s]}\n' \
  "$started_at" "$cpu" "$cores" "$cargo_cache" "$SECONDS" "$steps_json" >"$tmp"
mv "$tmp" reports/main_job.json
run_step "$bin" report --index reports
run_step "$bin" readme
echo "== main job done in $SECONDS s"
