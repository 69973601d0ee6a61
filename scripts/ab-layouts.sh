#!/usr/bin/env bash
# A change to the tracer timed over several code layouts (docs/tracer-performance.md, "How it
# is measured"): builds A_PREFIX-1 … and B_PREFIX-1 … from scripts/layout-builds.sh, the same
# seed giving both sides the same order of functions. Round by round, every seed's A and B run
# back to back (one thread, `mirrorbox trace`, the order alternating), so that the machine's
# drift falls on both; the ratio B / A of each pair is a change's effect in one layout. Prints
# each side's median per seed (how far layout alone moves the render) and each seed's median
# ratio, then the median of all ratios with a bootstrap 90 % interval (resampling the
# rounds, each round's ratios kept together): the change is real, whatever the layout, when
# that interval excludes 1.
#
# Usage: scripts/ab-layouts.sh ROUNDS SCENE A_PREFIX B_PREFIX [-- TRACE_ARGS...]
#   e.g. scripts/ab-layouts.sh 6 mirror_room /tmp/before /tmp/after -- --spp 16 --integrator path --max-segments 10
#   Name --spp in TRACE_ARGS (`trace` defaults to 1 sample per pixel).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 4 ]; then
  echo "usage: $0 ROUNDS SCENE A_PREFIX B_PREFIX [-- TRACE_ARGS...]" >&2
  exit 2
fi
rounds=$1 scene=$2 a=$3 b=$4
shift 4
[ "${1:-}" = "--" ] && shift
case $rounds in '' | *[!0-9]* | 0*) echo "ROUNDS must be a positive whole number, not '$rounds'" >&2; exit 2 ;; esac
[ -f "scenes/$scene.json" ] || { echo "no scene scenes/$scene.json" >&2; exit 2; }
seeds=0
while [ -x "$a-$((seeds + 1))" ] && [ -x "$b-$((seeds + 1))" ]; do
  seeds=$((seeds + 1))
done
[ "$seeds" -ge 1 ] || { echo "no builds $a-1 and $b-1 (scripts/layout-builds.sh makes them)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
seconds() {
  local bin=$1
  shift
  if ! RAYON_NUM_THREADS=1 "$bin" trace "scenes/$scene.json" -o "$work/out.exr" --json "$@" \
    > "$work/run.json" 2> "$work/stderr"; then
    echo "$bin trace failed:" >&2
    cat "$work/stderr" >&2
    exit 1
  fi
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['render_seconds'])" "$work/run.json"
}
# One line per round and seed: round, seed, A's seconds, B's seconds.
for round in $(seq "$rounds"); do
  for seed in $(seq "$seeds"); do
    if [ $(((round + seed) % 2)) = 0 ]; then
      ta=$(seconds "$a-$seed" "$@")
      tb=$(seconds "$b-$seed" "$@")
    else
      tb=$(seconds "$b-$seed" "$@")
      ta=$(seconds "$a-$seed" "$@")
    fi
    echo "$round $seed $ta $tb"
  done
done > "$work/pairs"
python3 - "$work/pairs" "$a" "$b" <<'PY'
import collections, random, statistics, sys
pairs = [line.split() for line in open(sys.argv[1])]
a, b = sys.argv[2], sys.argv[3]
by_seed = collections.defaultdict(list)
by_round = collections.defaultdict(list)
for r, s, ta, tb in pairs:
    by_seed[int(s)].append((float(ta), float(tb)))
    by_round[int(r)].append(float(tb) / float(ta))
for s in sorted(by_seed):
    t = by_seed[s]
    ratios = [tb / ta for ta, tb in t]
    print(f"layout {s}: A {statistics.median(x[0] for x in t):.4f} s, B {statistics.median(x[1] for x in t):.4f} s, B / A {statistics.median(ratios):.3f}")
a_medians = [statistics.median(x[0] for x in by_seed[s]) for s in by_seed]
print(f"A's layouts span x{max(a_medians) / min(a_medians):.3f} (slowest / fastest median)")
ratios = [x for r in by_round.values() for x in r]
rounds = list(by_round.values())
random.seed(1)
boots = sorted(
    statistics.median([x for r in random.choices(rounds, k=len(rounds)) for x in r])
    for _ in range(2000)
)
lo, hi = boots[len(boots) * 5 // 100], boots[len(boots) * 95 // 100]
print(f"B / A ({b} / {a}): median {statistics.median(ratios):.3f} [{lo:.3f}–{hi:.3f}] over {len(rounds)} rounds × {len(by_seed)} layouts")
PY
