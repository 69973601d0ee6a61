#!/usr/bin/env bash
# Experiment advise (issue 55): `mirrorbox advise` on the paper's box, the mirror room, the
# imported CAD engine (110 k triangles) and a scene the search was never tuned on
# (tilted_pair), at three budgets each, 320×180, α = 1 (the frontier's size and α), and the
# mirror room's middle budget a second time (does a repeat pick the same or a tie?);
# then every coarse candidate of mirror_box and mirror_room timed in one round (--exhaustive),
# the front each search's pick is judged against.
# Each advice goes to reports/advise/<scene>_<budget>ms[_repeat|_exhaustive]/ (its search rounds' images
# are not kept: the pick's are).
# Usage: scripts/measure-advise.sh
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/lib/advice.sh
. scripts/lib/reports-aside.sh
bin=${MIRRORBOX:-target/release/mirrorbox}
out=reports/advise
# The committed advice stays until this run has made all of its own (a failed run puts it back).
set_reports_aside "$out"
advise() { # SCENE BUDGET_MS [SUFFIX] [FLAGS...]
  local scene=$1 budget=$2 suffix=${3:-}
  shift 3 || shift $#
  local dir="$out/${scene##*/}_${budget}ms$suffix"
  echo "== advise: $scene within $budget ms$suffix"
  "$bin" advise "scenes/$scene.json" --budget-ms "$budget" --width 320 --height 180 \
    --alpha 1 -o "$dir" "$@"
  keep_advice_records "$dir"
}
for budget in 2 4 8; do advise mirror_box "$budget" ""; done
for budget in 3 6 12; do advise mirror_room "$budget" ""; done
advise mirror_room 6 _repeat
# What the search is judged against: every coarse candidate of both scenes in one round (the
# budget only names the folder; the region applies each advice's budget to these records).
advise mirror_box 8 _exhaustive --exhaustive
advise mirror_room 12 _exhaustive --exhaustive
for budget in 2 4 8; do advise tilted_pair "$budget" ""; done
# The engine: every frame 40 ms and more here; 6 timed rounds per candidate.
for budget in 60 120 400; do advise imported/engine_box "$budget" "" --frames 6; done
keep_new_reports
