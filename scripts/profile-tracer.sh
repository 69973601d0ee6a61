#!/usr/bin/env bash
# Where the tracer's time goes (docs/tracer-performance.md): `perf record` of one `mirrorbox
# trace` at one thread (640×360, 16 spp; the bench's depths), reported by function and by
# source file, into reports/tracer/profile_<scene>_<integrator>.txt with the CPU and date.
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
commit=$(git rev-parse --short HEAD)
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
  echo "# Functions above 0.7 % of self time. cpu_features::x86::* is code compiled through cpu_features::widest: the packet walks with the kernel inlined (and, for path, the per-lane path code), and the image row; obvhs::cwbvh is the single-ray hierarchy."
  perf report -i "$work/perf.data" --no-children --sort comm,dso,symbol 2>/dev/null | grep -v '^#' | grep -v '^$' |
    awk '{ v = $1; sub("%", "", v); if (v + 0 >= 0.7) print }'
  echo
  echo "# The same samples by source file (perf report --sort srcline, summed per file; files above 0.5 %): packet.rs + watertight.rs = the packet kernel and the single-ray triangle test, whitted.rs / path.rs = the walks, mirror_bounce.rs = the f64 bounces, shading.rs / geometry.rs = surfaces, camera.rs / render.rs = the row; index.rs, arith.rs, mod.rs, simd.rs = indexing, vector arithmetic and obvhs' SIMD node test inlined from std, glam and obvhs."
  perf report -i "$work/perf.data" --no-children --sort srcline 2>/dev/null | grep -v '^#' | grep '%' |
    awk '{ v = $1; sub("%", "", v); split($2, f, ":"); s[f[1]] += v } END { for (k in s) if (s[k] >= 0.5) printf "  %6.2f%%  %s\n", s[k], k }' | sort -rn
} > "$out"
echo "wrote $out" >&2
