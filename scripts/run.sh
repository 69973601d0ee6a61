#!/usr/bin/env bash
# The main job (README): installs missing system packages, builds mirrorbox in release mode,
# validates every bundled scene, reports the wgpu adapter, and regenerates the reproduction
# of the seed paper's Table 1 in reports/table1/ and the exact methods' cost against depth in
# reports/depth_scaling/ (measuring every point again; cached
# ground truths are reused when present).
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
echo "== mirrorbox table1 --fresh"
"$bin" table1 --fresh
echo "== mirrorbox depth-scaling --fresh"
"$bin" depth-scaling --fresh
