#!/usr/bin/env bash
# The main job (README): installs missing system packages, builds mirrorbox in release mode,
# validates every bundled scene, reports the wgpu adapter, and regenerates the reproduction
# of the seed paper's Table 1 in reports/table1/ and the exact methods' cost against depth in
# reports/depth_scaling/ (measuring every point again; cached
# ground truths are reused when present).
set -euo pipefail
cd "$(dirname "$0")/.."
export NODEVICE_SELECT=1
# Each step says when it starts, how long it took and (with GNU time) its peak memory.
step=0
run_step() {
  step=$((step + 1))
  echo "== [$step/6] $*"
  local started=$SECONDS
  if [ -x /usr/bin/time ]; then
    /usr/bin/time -f "== [$step/6] peak memory %M KB (largest process)" "$@"
  else
    "$@"
  fi
  echo "== [$step/6] done in $((SECONDS - started)) s"
}
run_step scripts/install-system-deps.sh
run_step cargo build --release --locked -p mirrorbox
bin=target/release/mirrorbox
run_step "$bin" check scenes/*.json
run_step "$bin" info
run_step "$bin" table1 --fresh
run_step "$bin" depth-scaling --fresh
echo "== main job done in $SECONDS s"
