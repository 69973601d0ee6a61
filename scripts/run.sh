#!/usr/bin/env bash
# The main job (README): installs missing system packages, builds mirrorbox in release mode,
# validates every bundled scene, reports the wgpu adapter, regenerates the reproduction of the
# seed paper's Table 1 in reports/table1/ — twice, the second run into reports/table1_repeat/,
# so that the README shows two consecutive runs side by side — and the exact methods' cost
# against depth in reports/depth_scaling/ and the symmetry methods' cost against the number of
# planes in reports/symmetry_scaling/, the lighting variants (shadows, mirrored lights) in
# reports/lighting/ and reports/lighting_room/ with the tracer's cost against the mirrored-light
# depth in reports/lighting/trace_cost.jsonl, the uneven-mirror tricks in reports/uneven_mirrors*/
# stereo mirrors (per-eye against shared) in reports/stereo/ and error over time (feedback, cube maps; still and
# walking) in reports/motion/, and the cross-method frontier sweeps of every method on
# mirror_box and mirror_room in reports/frontier_box/ and reports/frontier_room/ (measuring
# every point again; cached ground truths are reused when present), then the overview
# reports/index.html and reports/README.md (`report --index`). It records each step's time and peak memory in
# reports/main_job.json and fills the README's generated regions from the reports. Last, the
# peak memory of every bundled scene × method in reports/memory/peaks.md.
set -euo pipefail
cd "$(dirname "$0")/.."
export NODEVICE_SELECT=1
bin=target/release/mirrorbox
steps_total=18
step=0
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
# --timings: target/cargo-timings/cargo-timing.html says which crates the build's time goes to.
run_step cargo build --release --locked -p mirrorbox --timings
run_step "$bin" check scenes/*.json
run_step "$bin" info
run_step "$bin" table1 --fresh
run_step "$bin" table1 --fresh --out reports/table1_repeat
run_step "$bin" depth-scaling --fresh
run_step "$bin" symmetry-scaling --fresh
run_step "$bin" lighting --fresh
run_step "$bin" bumpy --fresh
run_step "$bin" stereo --fresh
run_step "$bin" motion
# The frontier (issue 38): every method at a few settings on both bundled mirror scenes, at
# 320×180 and α = 1. The room leaves out path-textures (over 5 000 passes past depth 4) and
# auxiliary n ≥ 2 (3 761 passes, 2.9 s/frame), and caps the depth at 16 (unrolled's 8 M
# triangle bound).
run_step "$bin" sweep scenes/mirror_box.json --out reports/frontier_box --fresh \
  --methods naive,auxiliary,path-textures,portal,unrolled,feedback,cubemap \
  --n 0,1,2,3 --depth 1,4,16,64 --history 16 --cube-size 128,512 --alpha 1 \
  --width 320 --height 180 --frames 5 --warmup 1
run_step "$bin" sweep scenes/mirror_room.json --out reports/frontier_room --fresh \
  --methods naive,auxiliary,portal,unrolled,feedback,cubemap \
  --n 0,1 --depth 1,2,4,8,16 --history 16 --cube-size 128,512 --alpha 1 \
  --width 320 --height 180 --frames 5 --warmup 1
run_step env MIRRORBOX="$bin" scripts/lighting-trace-cost.sh
run_step scripts/memory-peaks.sh
cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//; s/"/'"'"'/g')
cores=$(nproc)
tmp=$(mktemp reports/.main_job.XXXXXX)
printf '{"date":"%s","cpu":"%s, %s cores","seconds":%s,"steps":[%s]}\n' \
  "$started_at" "$cpu" "$cores" "$SECONDS" "$steps_json" >"$tmp"
mv "$tmp" reports/main_job.json
run_step "$bin" report --index reports
run_step "$bin" readme
echo "== main job done in $SECONDS s"
