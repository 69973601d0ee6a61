#!/usr/bin/env bash
# Experiment table1-runs (issue 54): do Table 1's speed verdicts hold from run to run on this
# machine, and what decided them when they did not?
#
#   order:        `table1`, `table1-repeat`, `table1-repeat`, `table1` back to back, as the
#                 main job runs them (every shader compiled afresh, the timing commands'
#                 default) into reports/table1_runs/{a_table1,b_repeat,c_repeat,d_table1};
#   shader cache: Table 1 with Mesa's disk shader cache on, in a folder of its own: first
#                 empty (every shader compiled, then stored: a fresh machine), then again
#                 (every shader loaded from it: any later run on the same machine), then
#                 with the cache off (the default) — twice over, into
#                 reports/table1_runs/cache_{1_cold,2_warm,3_off,4_cold,5_warm,6_off}.
#
# The hand-made fresh_* runs in the same folder are kept as they are.
# The images are not kept (Table 1's own report has them); the records, reports and charts
# are. One cached truth for every run (target/truth-cache, as the main job's).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${MIRRORBOX:-target/release/mirrorbox}
out=reports/table1_runs
. scripts/lib/reports-aside.sh
run() { # NAME EXPERIMENT [ENV=VALUE...]
  local name=$1 experiment=$2
  shift 2
  echo "== table1-runs: $name ($experiment${*:+, $*})"
  env "$@" "$bin" experiment "$experiment" --fresh --out "$out/$name" \
    --truth-cache target/truth-cache >/dev/null
  rm -rf "$out/$name/images" "$out/$name/cache"
}
# The committed runs stay until this run has made all of its own (a failed run puts them back).
set_reports_aside "$out"
cache=$(mktemp -d)
on_exit 'rm -rf "$cache"'
run a_table1 table1
run b_repeat table1-repeat
run c_repeat table1-repeat
run d_table1 table1
for round in 0 1; do
  rm -rf "${cache:?}"/*
  on=(MESA_SHADER_CACHE_DISABLE=false "MESA_SHADER_CACHE_DIR=$cache")
  run "cache_$((round * 3 + 1))_cold" table1 "${on[@]}"
  run "cache_$((round * 3 + 2))_warm" table1 "${on[@]}"
  run "cache_$((round * 3 + 3))_off" table1 MESA_SHADER_CACHE_DISABLE=true
done
# The runs made by hand in a fresh clone (fresh_*, crates/experiments/src/table1/section.rs)
# are not this script's to remake: they carry over.
carry_over_reports 'fresh_*'
keep_new_reports
