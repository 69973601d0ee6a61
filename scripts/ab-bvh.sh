#!/usr/bin/env bash
# Two single-ray hierarchies of one `mirrorbox` build against each other (issue 56,
# docs/tracer-performance.md): paired one-thread `path` renders (640×360, 16 spp, 10
# segments), `--bvh A` and `--bvh B` alternating which goes first round by round. Prints each
# round's image-loop seconds, then the median of the per-round ratios B / A with its range.
#
# Usage: scripts/ab-bvh.sh ROUNDS SCENE [A B]     (defaults: cwbvh wide)
#   e.g. scripts/ab-bvh.sh 8 mirror_room
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 2 ]; then
  sed -n '/^# Usage:/,/^#   e.g./p' "$0" >&2
  exit 2
fi
rounds=$1 scene=$2 a=${3:-cwbvh} b=${4:-wide}
case $rounds in '' | *[!0-9]* | 0*) echo "ROUNDS must be a positive whole number, not '$rounds'" >&2; exit 2 ;; esac
[ -f "scenes/$scene.json" ] || { echo "no scene scenes/$scene.json" >&2; exit 2; }
bin=target/release/mirrorbox
[ -x "$bin" ] || { echo "error: $bin is not built (cargo build --release --locked -p mirrorbox)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
seconds() { # BVH
  RAYON_NUM_THREADS=1 "$bin" trace "scenes/$scene.json" -o "$work/out.exr" --integrator path \
    --spp 16 --max-segments 10 --bvh "$1" --json > "$work/run.json" 2>"$work/err" ||
    { cat "$work/err" >&2; exit 1; } # a failed render says why
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['render_seconds'])" "$work/run.json"
}
: > "$work/rounds"
for round in $(seq "$rounds"); do
  if [ $((round % 2)) = 0 ]; then ta=$(seconds "$a"); tb=$(seconds "$b")
  else tb=$(seconds "$b"); ta=$(seconds "$a"); fi
  echo "round $round: $a $ta s, $b $tb s"
  echo "$ta $tb" >> "$work/rounds"
done
python3 - "$work/rounds" "$a" "$b" <<'PY'
import statistics, sys
rows = [tuple(map(float, l.split())) for l in open(sys.argv[1])]
r = sorted(b / a for a, b in rows)
print(f"{sys.argv[3]} / {sys.argv[2]}: median x{statistics.median(r):.3f} [{r[0]:.3f}-{r[-1]:.3f}] over {len(r)} rounds; "
      f"medians {statistics.median(a for a, _ in rows):.3f} s and {statistics.median(b for _, b in rows):.3f} s")
PY
