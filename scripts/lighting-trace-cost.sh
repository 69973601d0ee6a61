#!/usr/bin/env bash
# The tracer's cost against the mirrored-light depth k (issue 15): `mirrorbox trace` of the lit
# mirror box and mirror room at k = 0, 1, 2, 4, 8 (640×360, 1 spp, shadows on), each run 3
# times with the runs interleaved (k order shuffled per round), into
# reports/lighting/trace_cost.jsonl (one `trace --json` line per run). `mirrorbox readme`
# quotes the medians (region lighting-trace-cost).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${MIRRORBOX:-target/release/mirrorbox}
out=reports/lighting/trace_cost.jsonl
mkdir -p reports/lighting
tmp=$(mktemp reports/lighting/.trace_cost.XXXXXX)
work=$(mktemp -d)
trap 'rm -rf "$work" "$tmp"' EXIT
commit=$(git rev-parse HEAD | cut -c1-7)
git diff --quiet HEAD -- crates shaders Cargo.toml Cargo.lock || commit="$commit+changes"
cpu=$(grep -m1 '^model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')
today=$(date -u +%F)
for round in 1 2 3; do
  for run in $(printf '%s\n' box:0 box:1 box:2 box:4 box:8 room:0 room:1 room:2 room:4 room:8 | shuf --random-source=<(yes "$round")); do
    scene=scenes/mirror_${run%%:*}_lit.json
    k=${run##*:}
    "$bin" trace "$scene" --mirrored-lights "$k" --spp 1 --json -o "$work/t.exr" |
      python3 -c 'import json, sys
run = json.load(sys.stdin)
round, k, date, commit, cpu = sys.argv[1:]
print(json.dumps({"measured": {"date": date, "commit": commit, "cpu": cpu},
                  "round": int(round), "mirrored_lights": int(k), **run}))' \
        "$round" "$k" "$today" "$commit" "$cpu" >>"$tmp"
  done
done
mv "$tmp" "$out"
echo "wrote $out"
