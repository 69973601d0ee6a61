#!/usr/bin/env bash
# Issue 37: the peak resident memory of every bundled scene × every registered method at its
# defaults, each rendered in its own `mirrorbox render` process (the release binary), next to
# the plan's memory estimate — the same sweep as tests/memory.rs, written to
# reports/memory/peaks.md. `render --json` reports both: `peak_rss_bytes` (the process's
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
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
methods=$("$bin" render --help | sed -n '/Possible values:/,/^$/p' | sed -n 's/^ *- \([a-z-]*\):.*/\1/p')
out=reports/memory/peaks.md
mkdir -p reports/memory
mb() { awk -v b="$1" 'BEGIN { printf "%.0f", b / 1e6 }'; }
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
  for scene in scenes/*.json; do
    name=$(basename "$scene" .json)
    for method in $methods; do
      set +e
      json=$("$bin" render "$scene" --method "$method" --width "$width" --height "$height" \
        --frames 1 --warmup 0 --json -o "$tmp/out.png" 2>"$tmp/err")
      code=$?
      set -e
      case $code in
        0)
          peak=$(sed -n 's/.*"peak_rss_bytes":\([0-9]*\).*/\1/p' <<<"$json")
          gpu=$(sed -n 's/.*"memory_estimate":{[^}]*"gpu_bytes":\([0-9]*\).*/\1/p' <<<"$json")
          host=$(sed -n 's/.*"memory_estimate":{[^}]*"host_bytes":\([0-9]*\).*/\1/p' <<<"$json")
          echo "| $name | $method | $(mb "$peak") | $(mb $((gpu + host))) |"
          ;;
        2)
          echo "| $name | $method | refused: $(sed -n 's/^error: //p' "$tmp/err" | head -1) | |"
          ;;
        *)
          echo "$name $method: exit $code: $(cat "$tmp/err")" >&2
          exit 1
          ;;
      esac
    done
  done
} >"$out.tmp"
mv "$out.tmp" "$out"
echo "wrote $out"
