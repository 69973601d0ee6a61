#!/usr/bin/env bash
# The main job (README): installs missing system packages, builds mirrorbox in release mode,
# validates every bundled scene, reports the wgpu adapter that renders and timings use, and
# traces the ground truth of every bundled scene into out/ (EXR + PNG + bounce map).
# Later stages (render, sweep, table1) extend this script as they land.
set -euo pipefail
cd "$(dirname "$0")/.."
export NODEVICE_SELECT=1
scripts/install-system-deps.sh
cargo build --release --locked -p mirrorbox
bin=target/release/mirrorbox
echo "== mirrorbox check scenes/*.json"
"$bin" check scenes/*.json
echo "== mirrorbox info"
"$bin" info
mkdir -p out
for scene in scenes/*.json; do
  name=$(basename "$scene" .json)
  echo "== mirrorbox trace $scene"
  "$bin" trace "$scene" -o "out/${name}_truth.exr" --bounces "out/${name}_bounces.exr"
done
