#!/usr/bin/env bash
# Builds of `mirrorbox` against each other on one scene, for a change to the tracer
# (docs/tracer-performance.md): one-thread renders of every build per round, the order rotated
# round by round, so that drift of a shared machine falls on all alike. Prints each build's
# median and minimum image-loop time and, for every build after the first, the median of the
# per-round ratios to the first (B / A, C / A, ...) with a bootstrap 90 % interval: a change
# is real when the interval excludes 1. Two builds of the same logic can differ by their
# code's layout alone (issue 56's eleventh session: ±2 %), so more than two builds of a
# change's forms, with a copy of the baseline as a control, show how far that goes.
#
# Usage: scripts/ab-trace.sh ROUNDS SCENE BIN_A BIN_B [BIN_C ...] [-- TRACE_ARGS...]
#   e.g. scripts/ab-trace.sh 16 mirror_room /tmp/before target/release/mirrorbox -- --spp 16
#   Build them outside scripts/test-build-env.sh: its clippy wrapper compiles with MIR
#   optimisations off (5-8 % slower; docs/tracer-performance.md).
#   Name --spp in TRACE_ARGS: `trace` defaults to 1 sample per pixel since issue 37 (16 before),
#   so two builds from either side of that change would otherwise trace different images.
#   On an AVX-512 CPU, `-- … --simd avx2` (or `baseline`) times the narrower builds' code too
#   (`trace --simd`; not a claim about an AVX2 CPU).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 4 ]; then
  echo "usage: $0 ROUNDS SCENE BIN_A BIN_B [BIN_C ...] [-- TRACE_ARGS...]" >&2
  exit 2
fi
rounds=$1 scene=$2
shift 2
bins=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
  bins+=("$1")
  shift
done
[ "${1:-}" = "--" ] && shift
case $rounds in '' | *[!0-9]* | 0*) echo "ROUNDS must be a positive whole number, not '$rounds'" >&2; exit 2 ;; esac
[ -f "scenes/$scene.json" ] || { echo "no scene scenes/$scene.json" >&2; exit 2; }
[ ${#bins[@]} -ge 2 ] || { echo "name at least two builds before --" >&2; exit 2; }
[ ${#bins[@]} -le 26 ] || { echo "at most 26 builds (A to Z), not ${#bins[@]}" >&2; exit 2; }
for bin in "${bins[@]}"; do
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
    > "$work/run.json" 2>"$work/err" || { cat "$work/err" >&2; exit 1; } # a failed render says why
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['render_seconds'])" "$work/run.json"
}
# Round r runs the builds from index r mod N on (two builds: A then B in even rounds, B then
# A in odd ones); each line holds one round's times in the builds' order.
n=${#bins[@]}
for round in $(seq "$rounds"); do
  times=()
  for k in $(seq 0 $((n - 1))); do
    i=$(((round + k) % n))
    times[i]=$(seconds "${bins[i]}" "$@")
  done
  echo "${times[*]}"
done > "$work/rounds"
python3 - "$work/rounds" "${bins[@]}" <<'PY'
import random, statistics, sys
rounds = [tuple(map(float, line.split())) for line in open(sys.argv[1])]
bins = sys.argv[2:]
letter = lambda i: chr(ord("A") + i)
for i, b in enumerate(bins):
    t = [r[i] for r in rounds]
    print(f"{letter(i)} {b}: median {statistics.median(t):.4f} s, min {min(t):.4f} s")
for i in range(1, len(bins)):
    ratios = [r[i] / r[0] for r in rounds]
    random.seed(1)
    boots = sorted(statistics.median(random.choices(ratios, k=len(ratios))) for _ in range(2000))
    lo, hi = boots[len(boots) * 5 // 100], boots[len(boots) * 95 // 100]
    print(f"{letter(i)} / A: median {statistics.median(ratios):.3f} [{lo:.3f}–{hi:.3f}] over {len(ratios)} rounds")
PY
