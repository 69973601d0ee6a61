#!/usr/bin/env bash
# Two forms of a change to the tracer timed inside one process (docs/tracer-performance.md,
# "How it is measured"): one build with the change behind `mirrorbox_trace::ab_switch::on()`,
# whose `trace --warm-up 10 --ab-switch` renders alternate the switch off (A) and on (B), one
# thread. Renders in one process are a fraction of a second apart, so the machine's drift
# (from process to process and over seconds) falls on both forms of a pair alike. Each
# process's first pair is dropped (its first render warms threads and memory), the processes
# start alternately with A and with B, and the pairs are (A, B) or (B, A) in render order.
# Prints each form's median render time and the median of the per-pair ratios B / A with a
# bootstrap 90 % interval, as scripts/ab-trace.sh does: the change is real when the interval
# excludes 1. A binary holding both forms lays out its code differently from either alone, so
# the step's two builds are compared too: scripts/count-instructions.sh, and
# scripts/ab-trace.sh where the effect is large enough for it to resolve.
#
# Usage: scripts/ab-inprocess.sh PROCESSES SCENE BIN [-- TRACE_ARGS...]
#   e.g. scripts/ab-inprocess.sh 16 mirror_room target/release/mirrorbox -- --spp 16 --width 320 --height 180
#   Each process renders 10 times (4 pairs counted). Build outside scripts/test-build-env.sh
#   (its clippy wrapper compiles with MIR optimisations off). Name --spp in TRACE_ARGS.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 3 ]; then
  echo "usage: $0 PROCESSES SCENE BIN [-- TRACE_ARGS...]" >&2
  exit 2
fi
processes=$1 scene=$2 bin=$3
shift 3
[ "${1:-}" = "--" ] && shift
case $processes in '' | *[!0-9]* | 0*) echo "PROCESSES must be a positive whole number, not '$processes'" >&2; exit 2 ;; esac
[ -f "scenes/$scene.json" ] || { echo "no scene scenes/$scene.json" >&2; exit 2; }
[ -x "$bin" ] || { echo "not an executable: $bin" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for p in $(seq "$processes"); do
  first=a
  [ $((p % 2)) = 0 ] && first=b
  if ! RAYON_NUM_THREADS=1 "$bin" trace "scenes/$scene.json" -o "$work/out.exr" --json \
    --warm-up 10 --ab-switch "$first" "$@" > "$work/run-$p.json" 2> "$work/stderr"; then
    echo "$bin trace failed:" >&2
    cat "$work/stderr" >&2
    exit 1
  fi
done
python3 - "$work" "$processes" <<'PY'
import json, random, statistics, sys
work, processes = sys.argv[1], int(sys.argv[2])
ratios, times = [], {"a": [], "b": []}
for p in range(1, processes + 1):
    run = json.load(open(f"{work}/run-{p}.json"))
    renders = list(zip(run["warm_up_forms"], run["warm_up_seconds"]))[2:]
    for pair in zip(renders[0::2], renders[1::2]):
        t = dict(pair)
        ratios.append(t["b"] / t["a"])
        for form in "ab":
            times[form].append(t[form])
random.seed(1)
boots = sorted(statistics.median(random.choices(ratios, k=len(ratios))) for _ in range(2000))
lo, hi = boots[len(boots) * 5 // 100], boots[len(boots) * 95 // 100]
for form in "ab":
    print(f"{form.upper()} (switch {'on' if form == 'b' else 'off'}): median {statistics.median(times[form]):.4f} s, min {min(times[form]):.4f} s")
print(f"B / A: median {statistics.median(ratios):.3f} [{lo:.3f}–{hi:.3f}] over {len(ratios)} pairs in {processes} processes")
PY
