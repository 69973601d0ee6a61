#!/usr/bin/env bash
# Where the tracer's time goes (docs/tracer-performance.md): `perf record` of one `mirrorbox
# trace` at one thread (640×360, 16 spp; the bench's depths), reported by function and, with
# every inlined frame resolved (scripts/profile-lines.py), by mirrorbox's own source files and
# lines and by the integrator's call sites, into reports/tracer/profile_<scene>_<integrator>.txt
# with the CPU and date.
#
# Usage: scripts/profile-tracer.sh SCENE INTEGRATOR     (e.g. mirror_room path)
#   Needs perf (apt install linux-perf); builds the release binary (a no-op when current).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -ne 2 ]; then
  echo "usage: $0 SCENE whitted|path" >&2
  exit 2
fi
scene=$1 integrator=$2
[ -f "scenes/$scene.json" ] || { echo "no scene scenes/$scene.json" >&2; exit 2; }
case $integrator in whitted) cut=(--max-depth 10000) ;; path) cut=(--max-segments 10) ;; *) echo "INTEGRATOR must be whitted or path, not '$integrator'" >&2; exit 2 ;; esac
command -v perf > /dev/null || { echo "perf is not installed (apt install linux-perf)" >&2; exit 1; }
bin=target/release/mirrorbox
# A measured build is a plain one: scripts/test-build-env.sh's clippy wrapper compiles the
# workspace with MIR optimisations off (clippy-driver sets mir-opt-level 0), measured 5-8 %
# slower on the tracer (issue 56, docs/tracer-performance.md).
unset RUSTC_WORKSPACE_WRAPPER CLIPPY_ARGS
# Always built (a no-op when current), so that the profile's commit is the build profiled.
cargo build --release --locked -p mirrorbox >&2
commit=$(git rev-parse HEAD | cut -c1-7)
git diff --quiet HEAD -- crates shaders Cargo.toml Cargo.lock || commit="$commit+changes"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
args=(trace "scenes/$scene.json" --width 640 --height 360 --spp 16 --integrator "$integrator" "${cut[@]}")
RAYON_NUM_THREADS=1 perf record -F 15000 -o "$work/perf.data" "$bin" "${args[@]}" -o "$work/out.exr" > /dev/null 2>&1
cpu=$(grep -m1 '^model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')
simd=SSE; grep -qw avx2 /proc/cpuinfo && simd=AVX2; grep -qw avx512f /proc/cpuinfo && simd=AVX-512
out=reports/tracer/profile_${scene}_${integrator}.txt
{
  echo "# perf record (1 thread, 15 kHz); mirrorbox ${args[*]}; $(date -u +%F), $cpu ($simd), $(nproc) cores, commit $commit"
  echo "# Functions above 0.7 % of self time. cpu_features::x86::* is code compiled through cpu_features::widest: the walks with the packet kernel and the 8-wide single-ray traversal inlined, and the image row; obvhs:: is the hierarchies' build."
  perf report -i "$work/perf.data" --no-children --sort comm,dso,symbol 2>/dev/null | grep -v '^#' | grep -v '^$' |
    awk '{ v = $1; sub("%", "", v); if (v + 0 >= 0.7) print }'
  echo
  echo "# The same samples by mirrorbox's own source (scripts/profile-lines.py: each sampled instruction's inlined frames by addr2line -i, charged to the innermost frame in crates/; call sites: the frame inside the integrator's outermost one, which call of the walk a sample is under — the query, the bounces, the step, the shading)."
  python3 scripts/profile-lines.py "$work/perf.data" "$(realpath "$bin")" --top 25
} > "$out"
echo "wrote $out" >&2
