#!/usr/bin/env bash
# The main job (README): installs missing system packages, builds mirrorbox in release mode,
# validates every bundled scene and reports the wgpu adapter that renders and timings use.
# Later stages (trace, render, sweep, table1) extend this script as they land.
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
