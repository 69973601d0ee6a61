#!/usr/bin/env bash
# Where the test time goes: every test of every test binary of the workspace run alone, one
# after the other (`--exact`, one thread), its wall time recorded; writes
# reports/tests/test_times.md (slowest first, with each binary's total). Uses the binaries
# scripts/test.sh builds (same compiler wrapper, so nothing is rebuilt after it); run it after
# scripts/test.sh. Alone, tests cannot share the cores, so the sum is more than test.sh's
# parallel run takes; the ranking is what it is for.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/test-build-env.sh   # as scripts/test.sh builds, so nothing is rebuilt
export MIRRORBOX_MITSUBA_PYTHON="${MIRRORBOX_MITSUBA_PYTHON:-$PWD/tools/mitsuba/.venv/bin/python}"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The test executables, as cargo names them (JSON messages of the build).
cargo test --workspace --locked --lib --bins --tests --no-run --message-format=json 2>/dev/null |
  python3 -c '
import json, sys
for line in sys.stdin:
    try:
        m = json.loads(line)
    except ValueError:
        continue
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m["profile"]["test"]:
        crate = m["package_id"].split("#")[-1].split("@")[0].split("/")[-1]
        print(crate + " " + m["target"]["name"] + "\t" + m["executable"] + "\t" + m["manifest_path"])
' >"$tmp/binaries"
: >"$tmp/times"
while IFS=$'\t' read -r name exe manifest; do
  dir=$(dirname "$manifest")
  (cd "$dir" && "$exe" --list --format terse 2>/dev/null) | sed -n 's/: test$//p' >"$tmp/list"
  while read -r t; do
    start=$(date +%s.%N)
    status=ok
    (cd "$dir" && "$exe" --exact "$t" --test-threads 1 >/dev/null 2>&1) || status=FAILED
    end=$(date +%s.%N)
    printf '%s\t%s\t%.2f\t%s\n' "$name" "$t" "$(echo "$end - $start" | bc)" "$status" >>"$tmp/times"
  done <"$tmp/list"
done <"$tmp/binaries"
mkdir -p reports/tests
python3 - "$tmp/times" >reports/tests/test_times.md <<'PY'
import sys, collections, datetime, subprocess
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
cores = subprocess.run(["nproc"], capture_output=True, text=True).stdout.strip()
total = sum(float(r[2]) for r in rows)
print("# Where the test time goes")
print()
print(f"Made by `scripts/test-times.sh` on {datetime.date.today()}, {cpu}, {cores} cores: every test run")
print(f"alone, one after the other ({len(rows)} tests, {total:.0f} s in all; `scripts/test.sh` runs")
print("them in parallel: cargo-nextest, one pool over every binary). Per binary, then the 25 slowest tests.")
print()
print("| test binary | tests | seconds alone |")
print("|---|---:|---:|")
per = collections.defaultdict(lambda: [0, 0.0])
for b, t, s, st in rows:
    per[b][0] += 1
    per[b][1] += float(s)
for b, (n, s) in sorted(per.items(), key=lambda kv: -kv[1][1]):
    print(f"| {b} | {n} | {s:.1f} |")
print()
print("| test binary | test | seconds | result |")
print("|---|---|---:|---|")
for b, t, s, st in sorted(rows, key=lambda r: -float(r[2]))[:25]:
    print(f"| {b} | `{t}` | {float(s):.1f} | {st} |")
PY
echo "wrote reports/tests/test_times.md"
