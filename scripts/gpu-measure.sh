#!/usr/bin/env bash
# Issue 21: every GPU measurement in one command, run on a lent GPU machine (NVIDIA H100/H200)
# through the workplace's device tool. That machine reaches no package registry and has no Rust
# toolchain, so everything it runs is built here first (scripts/gpu-prepare.sh):
#   .gpu/mirrorbox.gz          stripped release binary
#   .gpu/<test>.gz             the raster crate's test binaries (goldens, truth agreement)
#   .gl/*.deb                  the Vulkan/EGL loaders (libvulkan1, libglvnd, …)
# Usage there (repository root, `.gl` and `.gpu` carried):
#   scripts/gpu-measure.sh STEP...      steps: info frontier engine real-assets table1-pair
#                                       table1-pair-reversed
#                                       table1 table1-repeat table1-1080p depth depth-1080p
#                                       room trace tests retest symmetry lighting advise
# Results go to reports/gpu/ and, packed one archive per step, to $OUT/gpu-STEP.tar.gz (what
# comes back: at most 8 files of 16 MiB each, so a step's images travel in its own archive).
# Each step is skipped once less than its own budget is left of MIRRORBOX_GPU_DEADLINE seconds
# (default 540), so the command ends inside the tool's 10-minute limit; sweeps resume where a
# cut one stopped.
set -uo pipefail
cd "$(dirname "$0")/.."
. scripts/lib/advice.sh
out=${OUT:-/tmp/gpu-out}
mkdir -p "$out" reports/gpu
log=$out/log.txt
deadline=${MIRRORBOX_GPU_DEADLINE:-540}
started=$SECONDS
say() { echo "[$((SECONDS - started)) s] $*" | tee -a "$log"; }

# The loaders, unpacked into / where none is installed (the machine is bare and thrown away
# after the lease).
if ! ldconfig -p | grep -q 'libvulkan.so.1 '; then
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
if [ -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]; then
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
fi
mkdir -p /tmp/gpu-bin
for f in .gpu/*.gz; do gunzip -c "$f" >"/tmp/gpu-bin/$(basename "$f" .gz)"; done
chmod +x /tmp/gpu-bin/*
bin=/tmp/gpu-bin/mirrorbox
# The commit the binary was built from (scripts/gpu-prepare.sh), for the records.
if [ -f .gpu/commit.txt ]; then
  MIRRORBOX_SOURCE_COMMIT=$(cat .gpu/commit.txt)
  export MIRRORBOX_SOURCE_COMMIT
fi

# The 2CylinderEngine glTF of `real-assets` (Debian's assimp-testmodels here), carried in
# .gpu/assets/ by scripts/gpu-prepare.sh and put where scenes/imported/engine_box.json names it.
engine_glb=/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb
if [ ! -f "$engine_glb" ] && [ -f .gpu/assets/2CylinderEngine.glb ]; then
  mkdir -p "$(dirname "$engine_glb")" && cp .gpu/assets/2CylinderEngine.glb "$engine_glb"
fi

# pack NAME: what the step wrote (reports/gpu/ files newer than its start marker) into
# $OUT/gpu-NAME.tar.gz. Truth caches, locks and 1920×1080 images (several MiB each: too large
# to bring back or to keep in git) stay behind; those reports keep their numbers and plots.
pack() {
  local name=$1
  (find reports/gpu -type f -newer "$out/.started-$name" -not -path '*/cache/*' \
    -not -name '.mirrorbox.lock' -not -path 'reports/gpu/*_1080p/images/*' -print0 |
    tar -czf "$out/gpu-$name.tar.gz.part" --null -T -) &&
    mv "$out/gpu-$name.tar.gz.part" "$out/gpu-$name.tar.gz"
  rm -f "$out/.started-$name"
}

# step NAME BUDGET_SECONDS COMMAND...: runs COMMAND (a program with a timeout of what is left,
# or a function below) if at least BUDGET seconds are left.
step() {
  local name=$1 budget=$2
  shift 2
  local left=$((deadline - (SECONDS - started)))
  if [ "$left" -lt "$budget" ]; then
    say "== $name: skipped ($left s left, needs $budget)"
    return
  fi
  say "== $name: start"
  touch "$out/.started-$name"
  sleep 1 # the marker's time is in whole seconds on some file systems
  if declare -F "$1" >/dev/null; then
    "$@" >>"$log" 2>&1 # a function of this script: its commands carry their own timeouts
  else
    timeout "$left" "$@" >>"$log" 2>&1
  fi
  say "== $name: exit $?"
  pack "$name"
}

# The adapter and the GPU, into files named after the GPU (info_h200.txt, …; the first
# machine's, an H100's, are the unsuffixed info.txt and nvidia-smi.txt, which a later lease
# must not overwrite).
info() {
  local gpu
  gpu=$(gpu_slug)
  nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv
  grep -m1 'model name' /proc/cpuinfo
  nproc
  "$bin" info | tee "reports/gpu/info_$gpu.txt"
  "$bin" info --json >"reports/gpu/info_$gpu.json"
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader >"reports/gpu/nvidia-smi_$gpu.txt"
}

# The mirror room at 1920×1080: unrolled and portal, depth 1…1024, 3 rounds in an order shuffled
# per round, 5 timed frames each (2 warm-up). One `render --json` line per run, or a refusal.
room() {
  local file=reports/gpu/room_1080p.jsonl tmp
  tmp=$(mktemp reports/gpu/.room.XXXXXX)
  for round in 1 2 3; do
    for run in $(for m in unrolled portal; do for d in ${ROOM_DEPTHS:-1 2 4 8 16 32 64 128 256 512 1024}; do
      echo "$m:$d"; done; done | shuf --random-source=<(yes "$round")); do
      local m=${run%%:*} d=${run##*:} line
      if line=$(timeout 120 "$bin" render scenes/mirror_room.json --method "$m" --depth "$d" \
        --width "${ROOM_WIDTH:-1920}" --height "${ROOM_HEIGHT:-1080}" --frames 5 --warmup 2 --json -o /tmp/room.png 2>/tmp/room.err); then
        echo "$line" | sed "s/^{/{\"round\":$round,/" >>"$tmp"
      else
        local code=$? why
        why=$(tr '\n"\\' '   ' </tmp/room.err | cut -c1-400)
        echo "{\"round\":$round,\"method\":\"$m\",\"depth\":$d,\"exit\":$code,\"refused\":\"$why\"}" >>"$tmp"
      fi
    done
  done
  mv "$tmp" "$file"
}

# The tracer on 1, 2, 4, 8 and 16 threads: the mirror room at 960×540, 16 spp, 3 rounds in an
# order shuffled per round. One `trace --json` line per run.
trace_threads() {
  local file=reports/gpu/trace_threads.jsonl tmp
  tmp=$(mktemp reports/gpu/.trace.XXXXXX)
  for round in 1 2 3; do
    for t in $(printf '%s\n' 1 2 4 8 16 | shuf --random-source=<(yes "$round")); do
      RAYON_NUM_THREADS=$t "$bin" trace scenes/mirror_room.json --width 960 --height 540 --spp 16 --json \
        -o /tmp/trace.exr | sed "s/^{/{\"round\":$round,/" >>"$tmp"
    done
  done
  mv "$tmp" "$file"
  # The CPU of these threads, which the gpu-trace-threads region names beside them.
  grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//' >reports/gpu/cpu.txt
}

# The raster crate's tests (goldens, agreement with the truth) on the GPU. The binaries look for
# the repository where they were built (/work/main); point that path here.
tests() {
  if [ ! -e /work/main ]; then
    mkdir -p /work && ln -s "$PWD" /work/main
  fi
  local t rc=0
  for t in /tmp/gpu-bin/*; do
    [ "$t" = "$bin" ] && continue
    echo "---- $(basename "$t")"
    (cd crates/raster && "$t" --test-threads 4) 2>&1 | tee "reports/gpu/tests_$(basename "$t").txt" | tail -n 40 || rc=1
  done
  return $rc
}

# The tests that failed on the GPU in the first run, one at a time, with the images they write
# on failure kept; and wgpu's GL backend on the NVIDIA driver (EGL) by hand.
retest() {
  if [ ! -e /work/main ]; then
    mkdir -p /work && ln -s "$PWD" /work/main
  fi
  local t
  for t in light_images_match_the_truth_and_direct_ignores_them \
    symmetry_methods_match_the_truth_on_every_symmetry_scene \
    every_registered_method_renders_on_the_gl_backend; do
    (cd crates/raster && RUST_BACKTRACE=0 /tmp/gpu-bin/test_methods --exact "$t" --test-threads 1 --nocapture) 2>&1 |
      tail -n 30
  done
  WGPU_BACKEND=gl "$bin" info
  WGPU_BACKEND=gl "$bin" render scenes/mirror_box.json --method unrolled -o /tmp/gl.png --json | cut -c1-300
  mkdir -p reports/gpu/golden-failures
  cp -r target/tmp/golden-failures/. reports/gpu/golden-failures/ 2>/dev/null
  ls -la reports/gpu/golden-failures
}

# The paper's experiment and the depth scaling again at 1920×1080, where a GPU has work to do:
# sweeps of their own, not the experiments' (9 timed frames, where Table 1 takes 15, to fit a
# lent machine's minutes; their reports say so by their records' frame counts).
table1_1080p() {
  timeout 240 "$bin" sweep scenes/mirror_box.json --methods auxiliary,portal,unrolled --n 0,1,2,3,4 \
    --depth 64 --alpha 1,0.7 --width 1920 --height 1080 --frames 9 --out reports/gpu/table1_1080p
}
depth_1080p() {
  timeout 240 "$bin" sweep scenes/mirror_box.json --methods portal,unrolled \
    --depth 1,2,4,8,16,32,64,128,256,512,1024 --alpha 1 --width 1920 --height 1080 --frames 9 \
    --out reports/gpu/depth_scaling_1080p
}

# The GPU's model for folder names (`h200`), or `gpu` where nvidia-smi names none.
gpu_slug() {
  local g
  g=$(nvidia-smi --query-gpu=name --format=csv,noheader 2>/dev/null | head -n1 | grep -oE 'H[0-9]+' | tr 'H' 'h')
  echo "${g:-gpu}"
}

# Table 1 twice on this device, back to back (issue 57: a repeat is only a repeat on the same
# device and in the same lease), into folders named after the GPU (the H100's table1/ stays).
table1_pair() {
  local gpu
  gpu=$(gpu_slug)
  timeout 200 "$bin" experiment table1 --fresh --out "reports/gpu/table1_$gpu" &&
    timeout 200 "$bin" experiment table1-repeat --fresh --out "reports/gpu/table1_repeat_$gpu"
}
# The same pair again, the repeat first (issue 54: on lavapipe whichever runs second is slower
# for the exact methods): into table1_repeat_<gpu>_run2, then table1_<gpu>_run2.
table1_pair_reversed() {
  local gpu
  gpu=$(gpu_slug)
  timeout 200 "$bin" experiment table1-repeat --fresh --out "reports/gpu/table1_repeat_${gpu}_run2" &&
    timeout 200 "$bin" experiment table1 --fresh --out "reports/gpu/table1_${gpu}_run2"
}

# `mirrorbox advise` on this GPU (issue 55's question, answered on lavapipe in reports/advise/,
# where a user ships): the box and the room at 960×540 (a quarter of 1080p: the pick's images
# stay small enough for git), α = 1, at budgets inside the spread of the methods' times on an
# H200 (0.06–6 ms at 320×180, reports/gpu/frontier_*). Of the search rounds the records only
# (keep_advice_records). ADVISE_RUNS: SCENE:BUDGET_MS pairs, most wanted first;
# the default asks for what the lease of 2026-11-28 left (it ran the room at 1 ms on a cold GPU,
# the box at 1 ms, the room at 0.5 and 2 ms; reports/gpu/advise_h200/).
# The first advice of the lease of 2026-11-28 (the machine's first GPU work after `info`) timed
# every candidate 1.4× slower, with wide intervals whose low ends were the later runs' medians
# (docs/gpu.md): so the GPU first renders untimed for WARM_SECONDS (default 60).
advise_gpu() {
  local gpu run scene budget dir left
  gpu=$(gpu_slug)
  local until=$((SECONDS + ${WARM_SECONDS:-60}))
  while [ "$SECONDS" -lt "$until" ]; do
    timeout 60 "$bin" render scenes/mirror_room.json --method portal --depth 8 --width 960 --height 540 \
      --warmup 200 --frames 1 -o /tmp/warm.png >/dev/null || break
  done
  for run in ${ADVISE_RUNS:-mirror_room:1 mirror_box:0.5 mirror_box:2 mirror_room:4}; do
    scene=${run%%:*} budget=${run##*:}
    dir=reports/gpu/advise_$gpu/${scene}_${budget}ms_960x540
    left=$((deadline - (SECONDS - started)))
    [ "$left" -gt 20 ] || break
    mkdir -p "$(dirname "$dir")"
    timeout "$left" "$bin" advise "scenes/$scene.json" --budget-ms "$budget" --width 960 --height 540 \
      --alpha 1 -o "$dir" || echo "advise $scene $budget ms: exit $?"
    keep_advice_records "$dir"
  done
}

say "steps: $*"
for s in "$@"; do
  case $s in
  info) step info 10 info ;;
  frontier) step frontier 120 "$bin" experiment frontier --out reports/gpu/frontier_box ;;
  engine) step engine-reflections 150 "$bin" experiment engine-reflections --out reports/gpu/engine_reflections ;;
  real-assets) step real-assets 90 "$bin" experiment real-assets --out reports/gpu/real_assets ;;
  table1-pair) step table1-pair 100 table1_pair ;;
  table1-pair-reversed) step table1-pair-reversed 100 table1_pair_reversed ;;
  table1) step table1 120 "$bin" experiment table1 --fresh --out "reports/gpu/table1_$(gpu_slug)" ;;
  depth) step depth-scaling 120 "$bin" experiment depth-scaling --out reports/gpu/depth_scaling ;;
  room) step room 120 room ;;
  trace) step trace-threads 60 trace_threads ;;
  tests) step tests 60 tests ;;
  retest) step retest 30 retest ;;
  table1-repeat) step table1-repeat 60 "$bin" experiment table1-repeat --out reports/gpu/table1_repeat ;;
  table1-1080p) step table1-1080p 60 table1_1080p ;;
  depth-1080p) step depth-1080p 60 depth_1080p ;;
  symmetry) step symmetry-scaling 120 "$bin" experiment symmetry-scaling --out reports/gpu/symmetry_scaling ;;
  lighting) step lighting 120 "$bin" experiment lighting --out reports/gpu/lighting ;;
  advise) step advise $((${WARM_SECONDS:-60} + 80)) advise_gpu ;; # the warm-up and one advice
  *) say "unknown step $s" ;;
  esac
done
say "done"
