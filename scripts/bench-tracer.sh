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
# image), `path` Mitsuba's own with the same max_depth and rr_depth as ours.
#
# A result is a claim only on the CPU it was measured on: each CPU kind keeps its own files,
# reports/tracer/bench-<cpu>-<vector width>.md and .json (e.g. bench-amd-epyc-avx512.md),
# and reports/tracer/bench.md (with bench.json) lists every CPU's file with its ratios and
# the goals (per round: whitted >= 3x, path >= 2x Mitsuba's compiled kernel).
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
  commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
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
        "${ours_cut[@]}" --warm-up 1 --json > "$work/ours.json" 2>/dev/null
      # Parsed after the render, not through a pipe: a Python started beside the render
      # took one of the two cores during it (0.15 s instead of 0.10 s for mirror_box).
      python3 -c "import json,sys; r=json.load(sys.stdin); print(json.dumps({'who':'mirrorbox','scene':'$s','integrator':'$integrator','round':$round,'seconds':r['render_seconds'],'first_seconds':r['warm_up_seconds'][0],'rays':r['rays'],'threads':r['threads']}))" < "$work/ours.json" >> "$work/runs.jsonl"
      # A fresh HOME: Dr.Jit's kernel cache (~/.drjit) starts empty, so Mitsuba's first
      # render compiles its kernels, as a user's first run does.
      fresh_home="$work/home.$round.$s.$integrator"
      mkdir -p "$fresh_home"
      HOME="$fresh_home" "$py" tools/mitsuba/render.py "$work/$s/scene.xml" -o "$work/mitsuba.exr" --integrator "$integrator" \
        --max-depth "$depth" --rr-depth "$rr_depth" --runs 1 > "$work/mitsuba.json" 2>/dev/null
      python3 -c "import json,sys; r=json.loads(sys.stdin.read().strip().splitlines()[-1]); print(json.dumps({'who':'mitsuba','scene':'$s','integrator':'$integrator','round':$round,'seconds':r['render_seconds'],'first_seconds':r['first_render_seconds'],'variant':r['variant']}))" < "$work/mitsuba.json" >> "$work/runs.jsonl"
    done
  done
done
# MIRRORBOX_BENCH_RUNS: where to keep every round's raw times (one JSON object per render).
[ -z "${MIRRORBOX_BENCH_RUNS:-}" ] || cp "$work/runs.jsonl" "$MIRRORBOX_BENCH_RUNS"
mitsuba_version=$("$py" -c 'import mitsuba; print(mitsuba.__version__)')
python3 - "$work/runs.jsonl" "$out" "$rounds" "$spp" "$mitsuba_version" "$commit" "$rr_depth" <<'PY'
import json, sys, statistics, datetime, os, re, glob
runs_path, out, rounds, spp, mver, commit, rr_depth = sys.argv[1:]
runs = [json.loads(l) for l in open(runs_path)]
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
flags = next((l.split(":", 1)[1].split() for l in open("/proc/cpuinfo") if l.startswith("flags")), [])
simd = "AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "SSE"
GOALS = __import__("runpy").run_path("scripts/tracer-bench-index.py")["GOALS"]
def stats(v):
    v = sorted(v); return statistics.median(v), v[0], v[-1]
rows, summary = [], {"date": datetime.date.today().isoformat(), "cpu": cpu, "cores": os.cpu_count(), "simd": simd,
                     "rounds": int(rounds), "spp": int(spp), "mitsuba": mver, "commit": commit,
                     "mitsuba_whitted": f"lean Whitted; path with roulette from {rr_depth}", "path_rr_depth": int(rr_depth),
                     "mirrorbox_timed": "second render", 
                     "results": []}
for scene in ["mirror_box", "mirror_room"]:
    for integ in ["whitted", "path"]:
        ours = [r["seconds"] for r in runs if r["who"] == "mirrorbox" and r["scene"] == scene and r["integrator"] == integ]
        mits = [r["seconds"] for r in runs if r["who"] == "mitsuba" and r["scene"] == scene and r["integrator"] == integ]
        first = [r["first_seconds"] for r in runs if r["who"] == "mitsuba" and r["scene"] == scene and r["integrator"] == integ]
        ours_first = [r["first_seconds"] for r in runs if r["who"] == "mirrorbox" and r["scene"] == scene and r["integrator"] == integ]
        rays = next(r["rays"] for r in runs if r["who"] == "mirrorbox" and r["scene"] == scene and r["integrator"] == integ)
        o, m, f, of = stats(ours), stats(mits), stats(first), stats(ours_first)
        ratio = m[0] / o[0]
        # Paired: within each round, Mitsuba's compiled-kernel time over ours (the two ran
        # back to back, so a slow spell of the shared machine falls on both).
        by_round = lambda who: {r["round"]: r["seconds"] for r in runs if r["who"] == who and r["scene"] == scene and r["integrator"] == integ}
        ours_r, mits_r = by_round("mirrorbox"), by_round("mitsuba")
        paired = stats([mits_r[k] / ours_r[k] for k in ours_r if k in mits_r])
        # The same against mirrorbox's first render (how every record before 2026-11-28's
        # fourth session of issue 56 timed mirrorbox).
        ours_first_r = {r["round"]: r["first_seconds"] for r in runs if r["who"] == "mirrorbox" and r["scene"] == scene and r["integrator"] == integ}
        paired_first = stats([mits_r[k] / ours_first_r[k] for k in ours_first_r if k in mits_r])
        summary["results"].append({"scene": scene, "integrator": integ, "ours_s": o, "ours_first_s": of, "mitsuba_s": m, "mitsuba_first_s": f,
                                   "rays": rays, "speedup_vs_mitsuba": ratio, "speedup_vs_mitsuba_paired": paired,
                                   "speedup_vs_mitsuba_paired_first_render": paired_first,
                                   "speedup_vs_mitsuba_first": f[0] / of[0]})
        goal = GOALS[integ]
        met = "met" if paired[0] >= goal else f"not met ({paired[0] / goal:.0%} of it)"
        rows.append(f"| `{scene}` | {integ} | {o[0]:.3f} [{o[1]:.3f}–{o[2]:.3f}] | {of[0]:.3f} [{of[1]:.3f}–{of[2]:.3f}] | {rays/o[0]/1e6:.1f} | {m[0]:.3f} [{m[1]:.3f}–{m[2]:.3f}] | {f[0]:.3f} [{f[1]:.3f}–{f[2]:.3f}] | {ratio:.2f}× | {paired[0]:.2f}× [{paired[1]:.2f}–{paired[2]:.2f}] | {paired_first[0]:.2f}× [{paired_first[1]:.2f}–{paired_first[2]:.2f}] | {f[0]/of[0]:.2f}× | ≥ {goal:.0f}×: {met} |")
note = os.environ.get("MIRRORBOX_BENCH_NOTE", "").strip()
note = f" ({note})" if note else ""
slug = re.sub(r"[^a-z0-9]+", "-", cpu.lower()).strip("-") + "-" + simd.lower().replace("-", "")
summary["file"] = f"bench-{slug}.md"
lines = [f"# The tracer against Mitsuba 3 on {cpu} ({simd})", "",
         f"Measured {summary['date']} (commit {commit}) with `scripts/bench-tracer.sh {rounds} {spp}` on {cpu} ({simd}), {os.cpu_count()} cores{note}: 640×360, {spp} spp; Mitsuba {mver} `llvm_ad_rgb`; the two renderers alternated, one process each per round; medians over {rounds} rounds [min–max]. A claim about this CPU only: other CPUs have their own files ([bench.md](bench.md)).",
         "",
         "| scene | integrator | mirrorbox s (second render) | mirrorbox s (first render) | mirrorbox Mrays/s | Mitsuba s (compiled kernel: second render) | Mitsuba s (first render, JIT included) | Mitsuba ÷ mirrorbox | per round: Mitsuba ÷ mirrorbox | per round: Mitsuba ÷ mirrorbox's first render | first ÷ first | goal (per round) |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|"] + rows + ["",
         f"A ratio above 1 means mirrorbox is faster. 'Mitsuba ÷ mirrorbox' divides the medians; 'per round' is the median [min–max] of each round's ratio of the two renders run back to back, which a slow spell of the shared machine affects less. Whitted: mirror chains to 10 000 reflections, cut at a throughput of 1e-4; Mitsuba runs `tools/mitsuba/render.py`'s lean formulation of the contract (coherent camera rays, no sampler draws, one reflectance lookup per hit; the same image as its general form, `tests/mitsuba.rs`). Path: 10 segments, Russian roulette from {rr_depth} in both renderers; Mitsuba's own `path`. mirrorbox's time is its image loop (BVH build apart); Mitsuba's is `mi.render` to an evaluated image (scene loading apart). Both are timed on their process's second render, the goal's measure: Mitsuba's first render compiles its kernels (each of its processes starts with an empty Dr.Jit kernel cache), mirrorbox's (`trace --warm-up 1`) starts its threads and warms its memory; each renderer's first render is in the table too ('first ÷ first': Mitsuba's first over mirrorbox's), and 'Mitsuba ÷ mirrorbox's first render' is the measure of the records made before 2026-11-28's fourth session of issue 56."]
open(f"{out}/bench-{slug}.md", "w").write("\n".join(lines) + "\n")
json.dump(summary, open(f"{out}/bench-{slug}.json", "w"), indent=2)
print("\n".join(lines))
PY
python3 scripts/tracer-bench-index.py "$out"
