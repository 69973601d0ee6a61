# shellcheck shell=bash
# keep_advice_records DIR: of an advice's search rounds (DIR/search/round-K), the records only
# (results.jsonl, sweep.json: what `mirrorbox report DIR` remakes the advice from); their
# images, caches and reports go, and so does DIR/cache (~5 MB per advice otherwise; advice.md
# shows the pick's images). Sourced by scripts/measure-advise.sh and scripts/gpu-measure.sh.
keep_advice_records() {
  if [ -d "$1/search" ]; then
    find "$1/search" -mindepth 2 -maxdepth 2 ! -name results.jsonl ! -name sweep.json \
      -exec rm -rf {} +
  fi
  rm -rf "$1/cache"
}
