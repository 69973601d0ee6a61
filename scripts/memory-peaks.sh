#!/usr/bin/env bash
# Issue 37: the peak resident memory of every bundled scene × every registered method at its
# defaults, each rendered in its own `mirrorbox render` process (the release binary), next to
# the plan's memory estimate — the combinations tests/memory.rs renders (in one process
# there), written to reports/memory/peaks.md. `render --json` reports both: `peak_rss_bytes` (the process's
# VmHWM) and `memory_estimate` (GPU + host bytes, `mirrorbox_raster::memory`).
# Usage: scripts/memory-peaks.sh [WIDTH HEIGHT]   (default 32 18, as the test)
set -euo pipefail
cd "$(dirname "$0")/.."
width=${1:-32}
height=${2:-18}
bin=${MIRRORBOX:-target/release/mirrorbox}
[ -x "$bin" ] || cargo build --release -p mirrorbox
export NODEVICE_SELECT=1
# Memory, not time: keep Mesa's shader cache, which `render` turns off for its timings (issue
# 54). With it off, every one of its `render` processes compiled its shaders: 227 s in the main
# job of 2026-11-27 (fresh clone of 27cba85), 32 s with the cache (the step alone, warm build).
export MESA_SHADER_CACHE_DISABLE=false
out=reports/memory/peaks.md
tmp=$(mktemp -d)
# No half-written table when a render fails.
trap 'rm -rf "$tmp" "$out.tmp"' EXIT
methods=$("$bin" render --help | sed -n '/Possible values:/,/^$/p' | sed -n 's/^ *- \([a-z-]*\):.*/\1/p')
mkdir -p reports/memory
mb() { awk -v b="$1" 'BEGIN { printf "%.0f", b / 1e6 }'; }
# Processes at once (the machine's cores, at most 2: lavapipe renders on every core).
at_once=$(($(nproc) < 2 ? 1 : 2))
# One row of the table into $tmp/row.N (a failure's message into $tmp/fail.N).
peak_row() {
  local k=$1 scene=$2 method=$3 name json code peak gpu host
  name=$(basename "$scene" .json)
  set +e
  json=$("$bin" render "$scene" --method "$method" --width "$width" --height "$height" \
    --frames 1 --warmup 0 --json -o "$tmp/out.$k.png" 2>"$tmp/err.$k")
  code=$?
  set -e
  case $code in
    0)
      peak=$(sed -n 's/.*"peak_rss_bytes":\([0-9]*\).*/\1/p' <<<"$json")
      gpu=$(sed -n 's/.*"memory_estimate":{[^}]*"gpu_bytes":\([0-9]*\).*/\1/p' <<<"$json")
      host=$(sed -n 's/.*"memory_estimate":{[^}]*"host_bytes":\([0-9]*\).*/\1/p' <<<"$json")
      echo "| $name | $method | $(mb "$peak") | $(mb $((gpu + host))) |" >"$tmp/row.$k"
      ;;
    2)
      echo "| $name | $method | refused: $(sed -n 's/^error: //p' "$tmp/err.$k" | head -1) | |" >"$tmp/row.$k"
      ;;
    *)
      echo "$name $method: exit $code: $(cat "$tmp/err.$k")" >"$tmp/fail.$k"
      ;;
  esac
}
{
  echo "# Peak memory per scene and method"
  echo
  echo "Made by \`scripts/memory-peaks.sh\` (the release binary, lavapipe): every bundled scene ×"
  echo "every method at its defaults, ${width}×${height}, one \`mirrorbox render --frames 1 --warmup 0\`"
  echo "process each. Peak: the process's resident high-water mark (VmHWM). Estimate: the plan's"
  echo "GPU + host estimate (docs/memory.md), the number \`--memory-budget\` (default 2 GiB) is"
  echo "checked against. Refused: the CLI's reason (exit 2)."
  echo
  echo "Measured $(date -u +%Y-%m-%d) on $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $(nproc) cores: $("$bin" info | sed -n 's/^driver: *//p')."
  echo
  echo "| scene | method | peak RSS (MB) | estimate (MB) |"
  echo "|---|---|---:|---:|"
  # Two processes at a time: each row is a separate process's own high-water mark, which the
  # other does not change; the rows are written in order from their files below.
  i=0
  for scene in scenes/*.json; do
    for method in $methods; do
      i=$((i + 1))
      peak_row "$i" "$scene" "$method" &
      while [ "$(jobs -rp | wc -l)" -ge "$at_once" ]; do wait -n || true; done
    done
  done
  wait
  for k in $(seq 1 "$i"); do
    if [ ! -f "$tmp/row.$k" ]; then
      cat "$tmp/fail.$k" >&2 2>/dev/null || echo "row $k: no result" >&2
      exit 1
    fi
    cat "$tmp/row.$k"
  done
} >"$out.tmp"
mv "$out.tmp" "$out"
echo "wrote $out"
