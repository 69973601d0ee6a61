#!/usr/bin/env bash
# Remakes every committed report from its records alone, without rendering: each sweep
# folder's files (`mirrorbox report DIR`: a folder with `sweep.json`, or a sequence sweep's
# `motion.json`), then the overview (`report --index reports`) and the generated regions of
# the README and the book (`mirrorbox readme`). After a change to the report code, `git status`
# then shows exactly what the change did to the committed reports (nothing, for a refactor).
#
# Usage: scripts/rewrite-reports.sh [--bin target/release/mirrorbox]
set -euo pipefail
cd "$(dirname "$0")/.."
bin=target/release/mirrorbox
if [ $# -ge 2 ] && [ "$1" = --bin ]; then bin=$2; shift 2; fi
[ $# -eq 0 ] || { sed -n '/^# Usage:/p' "$0" >&2; exit 2; }
[ -x "$bin" ] || { echo "error: $bin is not built (cargo build --release --locked -p mirrorbox)" >&2; exit 2; }
dirs=()
# An advice's rounds (reports/advise/*/search/round-K) keep their records only: the advice
# is rewritten as a whole (its advice.json), not its rounds.
while IFS= read -r f; do dirs+=("$(dirname "$f")"); done < <(
  find reports \( -path '*/search/round-*' -prune \) -o \( -name sweep.json -o -name motion.json -o -name advice.json \) -print | sort)
echo "rewriting ${#dirs[@]} report folders"
"$bin" report "${dirs[@]}" >/dev/null
"$bin" report --index reports
"$bin" readme >/dev/null
git status --short -- reports README.md docs
