#!/usr/bin/env python3
"""One CPU's tracer bench record (issue 41, 56): reports/tracer/bench-<cpu>-<width>-<N>cores.md and
.json from the rounds scripts/bench-tracer.sh measured (one JSON object per render: who,
scene, integrator, round, seconds, first_seconds, ...), which it keeps beside them as
bench-<cpu>-<width>-<N>cores-rounds.jsonl, so that a record can be made again from its rounds.

Per scene and integrator: medians over rounds [min–max], the ratio of the medians, and per
round the ratio of the two renders run back to back, with the 95 % interval of that median
(order statistics: the ranks whose binomial tails hold at most 2.5 % each, 96.5 % for 15
rounds). A goal is met when the interval lies above it, not met when below it, and
undecided when the interval holds it.

The CPU and its vector width are this machine's (/proc/cpuinfo): run it where the rounds were
measured, or on a machine of the same CPU kind and vector width. The core count is the
rounds' own: the threads mirrorbox rendered with (the bench gives it every core; a run with
RAYON_NUM_THREADS set records that count), the same in every round or the record is refused.
MIRRORBOX_BENCH_DATE overrides the record's date (default today), MIRRORBOX_BENCH_NOTE adds
a sentence about where it ran.

Usage: scripts/tracer-bench-record.py ROUNDS.jsonl OUT_DIR ROUNDS SPP MITSUBA_VERSION COMMIT RR_DEPTH"""
import json, sys, statistics, datetime, os, re, shutil
from math import comb
if len(sys.argv) != 8:
    sys.exit(__doc__.split("Usage: ")[1])
runs_path, out, rounds, spp, mver, commit, rr_depth = sys.argv[1:]
runs = [json.loads(l) for l in open(runs_path)]
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
flags = next((l.split(":", 1)[1].split() for l in open("/proc/cpuinfo") if l.startswith("flags")), [])
simd = "AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "SSE"
# The cores are the threads mirrorbox rendered with (the bench gives both renderers every
# core), so a record made again from its rounds on another machine keeps its own count. Rounds
# of several counts are not one record; rounds without the count (none are committed) are
# this machine's.
threads = {r.get("threads") for r in runs if r.get("who") == "mirrorbox"}
if len(threads) > 1:
    sys.exit(f"{runs_path}: mirrorbox's rounds have several thread counts {sorted(threads, key=str)}: "
             "a record is one core count's (run scripts/bench-tracer.sh again)")
(count,) = threads or {None}
cores = count if count is not None else os.cpu_count()
if threads == {None}:
    print(f"{runs_path}: no thread count in mirrorbox's rounds: recorded as this machine's {cores} cores",
          file=sys.stderr)
# The goals and the rule that judges a row against its goal: the index's, one place for both.
index = __import__("runpy").run_path("scripts/tracer-bench-index.py")
GOALS, row_state = index["GOALS"], index["row_state"]
def stats(v):
    v = sorted(v); return statistics.median(v), v[0], v[-1]
def median_interval(v):
    """The 95 % interval of the median of v by exact order statistics, or None below 6 values
    (the Rust reports' `stats::median_interval` bootstraps the same order statistics)."""
    v, n = sorted(v), len(v)
    tail, j = 0.0, 0
    while True:
        tail += comb(n, j) / 2 ** n  # P(fewer than j + 1 values below the median)
        if 2 * tail > 0.05:
            break
        j += 1
    return (v[j - 1], v[n - j]) if j > 0 else None
rows, summary = [], {"date": os.environ.get("MIRRORBOX_BENCH_DATE") or datetime.date.today().isoformat(), "cpu": cpu, "cores": cores, "simd": simd,
                     "rounds": int(rounds), "spp": int(spp), "mitsuba": mver, "commit": commit,
                     "mitsuba_whitted": f"lean Whitted; path with roulette from {rr_depth}, independent sampler", "path_rr_depth": int(rr_depth),
                     "mirrorbox_timed": "second render", 
                     "results": []}
for scene in ["mirror_box", "mirror_room"]:
    for integ in ["whitted", "path"]:
        # Each renderer's times by round, for this scene and integrator.
        def by_round(who, field):
            return {r["round"]: r[field] for r in runs
                    if r["who"] == who and r["scene"] == scene and r["integrator"] == integ}
        ours_r, ours_first_r = by_round("mirrorbox", "seconds"), by_round("mirrorbox", "first_seconds")
        mits_r, mits_first_r = by_round("mitsuba", "seconds"), by_round("mitsuba", "first_seconds")
        rays = next(iter(by_round("mirrorbox", "rays").values()))
        o, m, f, of = (stats(list(t.values())) for t in (ours_r, mits_r, mits_first_r, ours_first_r))
        ratio = m[0] / o[0]
        # Paired: within each round, Mitsuba's compiled-kernel time over ours (the two ran
        # back to back, so a slow spell of the shared machine falls on both); and the same
        # against mirrorbox's first render (how every record before 2026-11-28's fourth
        # session of issue 56 timed mirrorbox).
        paired_with = lambda ours: [mits_r[k] / ours[k] for k in ours if k in mits_r]
        per_round = paired_with(ours_r)
        paired, interval = stats(per_round), median_interval(per_round)
        paired_first = stats(paired_with(ours_first_r))
        summary["results"].append({"scene": scene, "integrator": integ, "ours_s": o, "ours_first_s": of, "mitsuba_s": m, "mitsuba_first_s": f,
                                   "rays": rays, "speedup_vs_mitsuba": ratio, "speedup_vs_mitsuba_paired": paired,
                                   "speedup_vs_mitsuba_paired_interval": interval,
                                   "speedup_vs_mitsuba_paired_first_render": paired_first,
                                   "speedup_vs_mitsuba_first": f[0] / of[0]})
        goal = GOALS[integ]
        share = f"{paired[0] / goal:.0%} of it"
        state = row_state(goal, paired[0], interval)
        met = {"above": "met", "below": f"not met ({share})", "holds": f"undecided ({share})"}[state]
        met += (": the median's 95 % interval " f"{interval[0]:.2f}–{interval[1]:.2f}×" if interval
                else " (too few rounds for an interval)")
        rows.append(f"| `{scene}` | {integ} | {o[0]:.3f} [{o[1]:.3f}–{o[2]:.3f}] | {of[0]:.3f} [{of[1]:.3f}–{of[2]:.3f}] | {rays/o[0]/1e6:.1f} | {m[0]:.3f} [{m[1]:.3f}–{m[2]:.3f}] | {f[0]:.3f} [{f[1]:.3f}–{f[2]:.3f}] | {ratio:.2f}× | {paired[0]:.2f}× [{paired[1]:.2f}–{paired[2]:.2f}] | {paired_first[0]:.2f}× [{paired_first[1]:.2f}–{paired_first[2]:.2f}] | {f[0]/of[0]:.2f}× | ≥ {goal:.0f}×: {met} |")
note = os.environ.get("MIRRORBOX_BENCH_NOTE", "").strip()
note = f" ({note})" if note else ""
# One record per CPU kind, vector width and core count: the ratios move with the cores (a
# frame's fixed costs weigh more when 16 threads share it), so a 16-core run of a CPU kind
# does not replace its 2-core record.
slug = (re.sub(r"[^a-z0-9]+", "-", cpu.lower()).strip("-") + "-" + simd.lower().replace("-", "")
        + f"-{cores}cores")
summary["file"] = f"bench-{slug}.md"
lines = [f"# The tracer against Mitsuba 3 on {cpu} ({simd}, {cores} cores)", "",
         f"Measured {summary['date']} (commit {commit}) with `scripts/bench-tracer.sh {rounds} {spp}` on {cpu} ({simd}), {cores} cores{note}: 640×360, {spp} spp; Mitsuba {mver} `llvm_ad_rgb`; the two renderers alternated, one process each per round; medians over {rounds} rounds [min–max]. A claim about this CPU only: other CPUs have their own files ([bench.md](bench.md)).",
         "",
         "| scene | integrator | mirrorbox s (second render) | mirrorbox s (first render) | mirrorbox Mrays/s | Mitsuba s (compiled kernel: second render) | Mitsuba s (first render, JIT included) | Mitsuba ÷ mirrorbox | per round: Mitsuba ÷ mirrorbox | per round: Mitsuba ÷ mirrorbox's first render | first ÷ first | goal (per round) |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|"] + rows + ["",
         f"A ratio above 1 means mirrorbox is faster. 'Mitsuba ÷ mirrorbox' divides the medians; 'per round' is the median [min–max] of each round's ratio of the two renders run back to back, which a slow spell of the shared machine affects less; a goal is met when the 95 % interval of that median lies above it, undecided when the interval holds it. Whitted: mirror chains to 10 000 reflections, cut at a throughput of 1e-4; Mitsuba runs `tools/mitsuba/render.py`'s lean formulation of the contract (coherent camera rays, no sampler draws, one reflectance lookup per hit; the same image as its general form, `tests/mitsuba.rs`). Path: 10 segments, Russian roulette from {rr_depth} in both renderers; Mitsuba's own `path` with its `independent` sampler (records before 2026-12-01: an unjittered `stratified` grid, a biased quadrature about ×1.12 cheaper). mirrorbox's time is its image loop (BVH build apart); Mitsuba's is `mi.render` to an evaluated image (scene loading apart). Both are timed on their process's second render, the goal's measure: Mitsuba's first render compiles its kernels (each of its processes starts with an empty Dr.Jit kernel cache), mirrorbox's (`trace --warm-up 1`) starts its threads and warms its memory; each renderer's first render is in the table too ('first ÷ first': Mitsuba's first over mirrorbox's), and 'Mitsuba ÷ mirrorbox's first render' is the measure of the records made before 2026-11-28's fourth session of issue 56."]
open(f"{out}/bench-{slug}.md", "w").write("\n".join(lines) + "\n")
rounds_file = f"{out}/bench-{slug}-rounds.jsonl"
if os.path.abspath(runs_path) != os.path.abspath(rounds_file):
    shutil.copyfile(runs_path, rounds_file)
json.dump(summary, open(f"{out}/bench-{slug}.json", "w"), indent=2)
print("\n".join(lines))
