#!/usr/bin/env bash
# Instructions (and simulated branch mispredictions) that one build of `mirrorbox trace`
# executes for one small render, counted by valgrind's cachegrind: a measure of a change to
# the tracer that a shared, noisy machine does not disturb (docs/tracer-performance.md).
# Timing stays the judge (scripts/ab-trace.sh); the count says whether a change removed
# work, and how much, long before a paired timing can resolve a few per cent.
#
# Usage: scripts/count-instructions.sh BIN SCENE [TRACE_ARGS...]
#   e.g. scripts/count-instructions.sh target/release/mirrorbox mirror_room
#   BIN: a path from where you call it; SCENE: a name in scenes/. Defaults: 160×90, 16 spp,
#   Whitted to 10 000 reflections, one thread; TRACE_ARGS come after them (so
#   `--integrator path --max-segments 10` overrides). Needs valgrind (apt install valgrind),
#   which offers no AVX-512: the AVX2 build is what gets counted. The whole process is
#   counted: loading and the BVH build too (a few per cent at this size).
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 BIN SCENE [TRACE_ARGS...]" >&2
  exit 2
fi
bin=$1 scene=$2
shift 2
[ -x "$bin" ] || { echo "not an executable: $bin" >&2; exit 2; }
bin=$(realpath "$bin")
cd "$(dirname "$0")/.."
[ -f "scenes/$scene.json" ] || { echo "no scene scenes/$scene.json" >&2; exit 2; }
command -v valgrind > /dev/null || { echo "valgrind is not installed (apt install valgrind)" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
RAYON_NUM_THREADS=1 valgrind --tool=cachegrind --cache-sim=no --branch-sim=yes \
  --cachegrind-out-file="$work/counts" \
  "$bin" trace "scenes/$scene.json" -o "$work/out.exr" \
  --width 160 --height 90 --spp 16 "$@" 2> "$work/log" > /dev/null ||
  { cat "$work/log" >&2; exit 1; }
grep -qE 'I +refs' "$work/log" || { cat "$work/log" >&2; echo "no instruction count in valgrind's output" >&2; exit 1; }
grep -E 'I +refs|Mispredicts' "$work/log" | sed -e 's/^==[0-9]*== *//' -e "s|^|$scene: |"
