#!/usr/bin/env bash
# Issue 20's measurement: the Table 1 preset unsharded, then as 4 shards (2 at a time)
# through a local one-node Slurm with the merge as a dependent job; wall time of each, and
# whether the merged sweep holds the unsharded one's points with the same errors (timings
# aside). ROUNDS (default 3) alternate the two, each from empty folders (truths traced
# again), so that drift of a shared machine hits both; the JSON keeps every round's time.
# Writes reports/cluster/sharded_table1.json. Needs root (scripts/slurm-local.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${MIRRORBOX:-target/release/mirrorbox}
bin=$(realpath "$bin")
work=$(mktemp -d)
trap 'scripts/slurm-local.sh stop "$work/slurm" >/dev/null 2>&1 || true' EXIT
eval "$(scripts/slurm-local.sh start "$work/slurm")"
rounds=${ROUNDS:-3}
times=""
for r in $(seq 1 "$rounds"); do
  rm -rf "$work/unsharded" "$work/runs"
  t0=$(date +%s.%N)
  "$bin" experiment table1 --out "$work/unsharded" >/dev/null 2>&1
  t1=$(date +%s.%N)
  MIRRORBOX=$bin SWEEP_COMMAND=experiment deploy/slurm/submit.sh 4 2 "$work/runs" table1 >/dev/null
  while [ -n "$(squeue -h -o %i)" ]; do sleep 1; done
  t2=$(date +%s.%N)
  times="$times $t0,$t1,$t2"
  awk -v r="$r" -v a="$t0" -v b="$t1" -v c="$t2" 'BEGIN { printf "round %d: unsharded %.1f s, sharded %.1f s\n", r, b - a, c - b }' >&2
done
mkdir -p reports/cluster
python3 - "$work" "$times" "$(nproc)" "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')" <<'PY'
import json, sys, datetime, statistics
work, times, cores, cpu = sys.argv[1:5]
rounds = [tuple(map(float, t.split(","))) for t in times.split()]
unsharded = [round(b - a, 1) for a, b, _ in rounds]
sharded = [round(c - b, 1) for _, b, c in rounds]
read = lambda p: {r["key"]: r for r in map(json.loads, open(p))}
full, merged = read(f"{work}/unsharded/results.jsonl"), read(f"{work}/runs/merged/results.jsonl")
metrics = lambda r: r["metrics"]
same_errors = all(
    abs(metrics(full[k])[m] - metrics(merged[k])[m]) <= 1e-12 * max(1.0, abs(metrics(full[k])[m]))
    for k in full for m in ("flip_mean", "rmse", "relmse", "ssim"))
out = {
    "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
    "device": f"{cpu}, {cores} cores; lavapipe (Vulkan)",
    "unsharded_seconds": unsharded,
    "sharded_seconds": sharded,
    "unsharded_median": statistics.median(unsharded),
    "sharded_median": statistics.median(sharded),
    "shards": 4, "concurrent": 2,
    "points": len(full),
    "same_points": sorted(full) == sorted(merged),
    "same_errors": same_errors,
}
json.dump(out, open("reports/cluster/sharded_table1.json", "w"), indent=2)
print(json.dumps(out, indent=2))
PY
