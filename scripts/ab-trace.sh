#!/usr/bin/env bash
# Two builds of `mirrorbox` against each other on one scene, for a change to the tracer
# (docs/tracer-performance.md): paired one-thread renders, the order alternating round by
# round, so that drift of a shared machine falls on both alike. Prints each build's median
# and minimum image-loop time and the median of the per-round ratios B / A with a bootstrap
# 90 % interval: the change is real when the interval excludes 1.
#
# Usage: scripts/ab-trace.sh ROUNDS SCENE BIN_A BIN_B [-- TRACE_ARGS...]
#   e.g. scripts/ab-trace.sh 16 mirror_room /tmp/before target/release/mirrorbox -- --spp 16
#   Build both outside scripts/test-build-env.sh: its clippy wrapper compiles with MIR
#   optimisations off (5-8 % slower; docs/tracer-performance.md).
#   Name --spp in TRACE_ARGS: `trace` defaults to 1 sample per pixel since issue 37 (16 before),
#   so two builds from either side of that change would otherwise trace different images.
#   On an AVX-512 CPU, `-- … --simd avx2` (or `baseline`) times the narrower builds' code too
#   (`trace --simd`; not a claim about an AVX2 CPU).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 4 ]; then
  echo "usage: $0 ROUNDS SCENE BIN_A BIN_B [-- TRACE_ARGS...]" >&2
  exit 2
fi
rounds=$1 scene=$2 a=$3 b=$4
shift 4
[ "${1:-}" = "--" ] && shift
case $rounds in '' | *[!0-9]* | 0*) echo "ROUNDS must be a positive whole number, not '$rounds'" >&2; exit 2 ;; esac
[ -f "scenes/$scene.json" ] || { echo "no scene scenes/$scene.json" >&2; exit 2; }
for bin in "$a" "$b"; do
  [ -x "$bin" ] || { echo "not an executable: $bin" >&2; exit 2; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# One render's image-loop seconds (the JSON is read after the render: a reader started
# beside it would take a core).
seconds() {
  local bin=$1
  shift
  RAYON_NUM_THREADS=1 "$bin" trace "scenes/$scene.json" -o "$work/out.exr" --json "$@" \
    > "$work/run.json" 2>/dev/null
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['render_seconds'])" "$work/run.json"
}
for round in $(seq "$rounds"); do
  if [ $((round % 2)) = 0 ]; then
    ta=$(seconds "$a" "$@"); tb=$(seconds "$b" "$@")
  else
    tb=$(seconds "$b" "$@"); ta=$(seconds "$a" "$@")
  fi
  echo "$ta $tb"
done > "$work/pairs"
python3 - "$work/pairs" "$a" "$b" <<'PY'
import random, statistics, sys
pairs = [tuple(map(float, line.split())) for line in open(sys.argv[1])]
a, b = [p[0] for p in pairs], [p[1] for p in pairs]
ratios = [y / x for x, y in pairs]
random.seed(1)
boots = sorted(statistics.median(random.choices(ratios, k=len(ratios))) for _ in range(2000))
lo, hi = boots[len(boots) * 5 // 100], boots[len(boots) * 95 // 100]
print(f"A {sys.argv[2]}: median {statistics.median(a):.4f} s, min {min(a):.4f} s")
print(f"B {sys.argv[3]}: median {statistics.median(b):.4f} s, min {min(b):.4f} s")
print(f"B / A: median {statistics.median(ratios):.3f} [{lo:.3f}–{hi:.3f}] over {len(ratios)} rounds")
PY
