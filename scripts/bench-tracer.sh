#!/usr/bin/env bash
# The ground truth against Mitsuba 3, side by side in one run (issue 19): `mirrorbox trace`
# and Mitsuba 3 (`tools/mitsuba`, variant llvm_ad_rgb) on the same exported scenes, same
# size, spp and depth, alternating the two renderers round by round so that drift of a
# shared machine falls on both alike.
#
# Per scene × integrator and round: one `mirrorbox trace --json --warm-up 1` process and one
# Mitsuba process, each rendering twice and timed on its second render: Mitsuba's first
# includes compiling its JIT kernels (each Mitsuba process gets an empty Dr.Jit kernel cache),
# mirrorbox's starts its threads and warms its memory; both first renders are kept too.
# mirrorbox's time is its image loop (BVH build apart). Medians over rounds with the range,
# and the ratios.
#
# Mitsuba's side is the fastest formulation of the same picture (issue 41): `whitted` is
# tools/mitsuba/render.py's lean form of the contract (tested to give the general form's
# image), `path` Mitsuba's own with the same max_depth and rr_depth as ours (its sampler
# independent since 2026-12-01, the export's second sensor: the unjittered grid before was a
# biased quadrature, and ×1.12 cheaper; docs/tracer-performance.md, twenty-sixth session).
#
# A result is a claim only on the CPU it was measured on: each CPU kind, vector width and core
# count keeps its own files, reports/tracer/bench-<cpu>-<vector width>-<N>cores.md and .json
# (e.g. bench-amd-epyc-avx512-2cores.md), and reports/tracer/bench.md (with bench.json) lists
# every CPU's file with its ratios and the goals (per round: whitted >= 3x, path >= 2x
# Mitsuba's compiled kernel).
#
# Usage: scripts/bench-tracer.sh [ROUNDS] [SPP]      (defaults: 5 rounds, 16 spp, 640×360)
#
# On a machine with no toolchain or registry (a lent device machine, scripts/bench-tracer-device.sh)
# the renderers come prepared: MIRRORBOX_BENCH_BIN names a built binary (nothing is built),
# MIRRORBOX_MITSUBA_PYTHON a Python that imports Mitsuba (tools/mitsuba/setup.sh is not run),
# MIRRORBOX_SOURCE_COMMIT the commit the binary was built from (no git history there) and
# MIRRORBOX_BENCH_NOTE a sentence the record adds about where it ran.
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-5}
spp=${2:-16}
bin=${MIRRORBOX_BENCH_BIN:-target/release/mirrorbox}
# A measured build is a plain one: scripts/test-build-env.sh's clippy wrapper compiles the
# workspace with MIR optimisations off (clippy-driver sets mir-opt-level 0), measured 5-8 %
# slower on the tracer (issue 56, docs/tracer-performance.md).
unset RUSTC_WORKSPACE_WRAPPER CLIPPY_ARGS
# Built here (a no-op when current) unless MIRRORBOX_BENCH_BIN names a binary, so that the
# record's commit is the build measured; a tree with changes to the code is marked "+changes".
if [ -z "${MIRRORBOX_BENCH_BIN:-}" ]; then
  cargo build --release --locked -p mirrorbox >&2
fi
if [ -n "${MIRRORBOX_MITSUBA_PYTHON:-}" ]; then
  py=$MIRRORBOX_MITSUBA_PYTHON
else
  tools/mitsuba/setup.sh >&2
  py=tools/mitsuba/.venv/bin/python
fi
out=reports/tracer
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scenes="mirror_box mirror_room"
# path: Russian roulette from this depth in both renderers (Mitsuba's default is 5 too).
rr_depth=5
if [ -n "${MIRRORBOX_SOURCE_COMMIT:-}" ]; then
  commit=$MIRRORBOX_SOURCE_COMMIT
elif [ -n "${MIRRORBOX_BENCH_BIN:-}" ]; then
  commit="unknown (a prebuilt binary)" # not HEAD's: nothing says the binary was built from it
else
  # The first seven hex digits, as every record has (git's own abbreviation grows).
  commit=$(git rev-parse HEAD 2>/dev/null | cut -c1-7 || true)
  [ -n "$commit" ] || commit=unknown
  git diff --quiet HEAD -- crates shaders Cargo.toml Cargo.lock tools 2>/dev/null || commit="$commit+changes"
fi
# Whitted follows mirror chains to 10 000 reflections (cut by the throughput); path traces
# to 10 segments with Russian roulette from 5, the same in both renderers.
for s in $scenes; do
  mkdir -p "$work/$s"
  "$bin" export-mitsuba "scenes/$s.json" -o "$work/$s/scene.xml" --spp "$spp" >/dev/null
done
: > "$work/runs.jsonl"
for round in $(seq "$rounds"); do
  for s in $scenes; do
    for integrator in whitted path; do
      # Ours counts whitted's reflections (--max-depth) and path's segments (--max-segments,
      # Mitsuba's max_depth); Mitsuba's script takes its own names for both.
      depth=10000; ours_cut=(--max-depth "$depth")
      if [ "$integrator" = path ]; then
        depth=10; ours_cut=(--max-segments "$depth" --rr-from "$rr_depth")
      fi
      echo "round $round: $s $integrator" >&2
      # One untimed render first (--warm-up 1): the timed render is the process's second, as
      # Mitsuba's compiled-kernel time is its second render; the first render's time is kept too.
      "$bin" trace "scenes/$s.json" -o "$work/ours.exr" --spp "$spp" --integrator "$integrator" \
        "${ours_cut[@]}" --warm-up 1 --json > "$work/ours.json" 2>"$work/err" ||
        { cat "$work/err" >&2; exit 1; } # a failed render says why (it had ended the run unsaid)
      # Parsed after the render, not through a pipe: a Python started beside the render
      # took one of the two cores during it (0.15 s instead of 0.10 s for mirror_box).
      python3 -c "import json,sys; r=json.load(sys.stdin); print(json.dumps({'who':'mirrorbox','scene':'$s','integrator':'$integrator','round':$round,'seconds':r['render_seconds'],'first_seconds':r['warm_up_seconds'][0],'rays':r['rays'],'threads':r['threads']}))" < "$work/ours.json" >> "$work/runs.jsonl"
      # A fresh HOME: Dr.Jit's kernel cache (~/.drjit) starts empty, so Mitsuba's first
      # render compiles its kernels, as a user's first run does.
      fresh_home="$work/home.$round.$s.$integrator"
      mkdir -p "$fresh_home"
      HOME="$fresh_home" "$py" tools/mitsuba/render.py "$work/$s/scene.xml" -o "$work/mitsuba.exr" --integrator "$integrator" \
        --max-depth "$depth" --rr-depth "$rr_depth" --runs 1 > "$work/mitsuba.json" 2>"$work/err" ||
        { cat "$work/err" >&2; exit 1; }
      python3 -c "import json,sys; r=json.loads(sys.stdin.read().strip().splitlines()[-1]); print(json.dumps({'who':'mitsuba','scene':'$s','integrator':'$integrator','round':$round,'seconds':r['render_seconds'],'first_seconds':r['first_render_seconds'],'variant':r['variant']}))" < "$work/mitsuba.json" >> "$work/runs.jsonl"
    done
  done
done
mitsuba_version=$("$py" -c 'import mitsuba; print(mitsuba.__version__)')
# The record (and a copy of the rounds beside it, to make it again from): tracer-bench-record.py.
python3 scripts/tracer-bench-record.py "$work/runs.jsonl" "$out" "$rounds" "$spp" "$mitsuba_version" "$commit" "$rr_depth"
python3 scripts/tracer-bench-index.py "$out"
