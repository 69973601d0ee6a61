#!/usr/bin/env python3
"""The index of the tracer benches (issue 41): reports/tracer/bench.md and bench.json from
every CPU kind's reports/tracer/bench-<cpu>-<width>-<N>cores.json (written by scripts/bench-tracer.sh
on that CPU): a summary row per CPU with the per-round ratios and the goals, then each CPU's
table. A result is a claim only on the CPU it was measured on.

Usage: scripts/tracer-bench-index.py [FOLDER]     (default reports/tracer)"""
import glob
import json
import os
import sys

# Per round, Mitsuba ÷ mirrorbox (issue 41); scripts/bench-tracer.sh reads them from here.
GOALS = {"whitted": 3.0, "path": 2.0}
SCENES = ["mirror_box", "mirror_room"]


def row_state(goal, median, ci):
    """A row against its goal: "above", "below", or "holds" (its median's 95 % interval holds
    the goal); by the median alone where the record has no interval (records before
    2026-11-28) and "below" where it has no median."""
    if median is None:
        return "below"
    if ci:
        return "above" if ci[0] >= goal else "below" if ci[1] < goal else "holds"
    return "above" if median >= goal else "below"


def verdict(ratios, intervals):
    """"met" when every row is above its goal, "not met" when some row is below it, else
    "undecided" (an interval holds a goal)."""
    states = [row_state(GOALS[i], ratios.get((s, i)), intervals.get((s, i)))
              for s in SCENES for i in ["whitted", "path"]]
    if "below" in states:
        return "not met"
    return "undecided" if "holds" in states else "met"


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "reports/tracer"
    benches = []
    records = []
    for path in glob.glob(os.path.join(out, "bench-*.json")):
        try:
            records.append((path, json.load(open(path))))
        except (OSError, ValueError) as e:
            sys.exit(f"{path}: not a bench record ({e})")
    # By CPU, vector width, then cores as a number (2 before 16), not by file name.
    records.sort(key=lambda r: (str(r[1].get("cpu")), str(r[1].get("simd")),
                                r[1].get("cores") if isinstance(r[1].get("cores"), int) else 0, r[0]))
    for path, b in records:
        name = os.path.basename(path)[:-5] + ".md"
        ratios = {(r.get("scene"), r.get("integrator")): r.get("speedup_vs_mitsuba_paired", [None])[0]
                  for r in b.get("results", [])}
        # A record without a scene or integrator shows "–" there and cannot meet the goals.
        cells = [f"{ratios[(s, i)]:.2f}×" if ratios.get((s, i)) is not None else "–"
                 for s in SCENES for i in ["whitted", "path"]]
        intervals = {(r.get("scene"), r.get("integrator")): r.get("speedup_vs_mitsuba_paired_interval")
                     for r in b.get("results", [])}
        met = verdict(ratios, intervals)
        try:
            body = open(os.path.join(out, name)).read().split("\n")
            body = "\n".join(l for l in body if not l.startswith("# ")).strip()
        except OSError:
            body = f"(`{name}` is missing: only the record's ratios above.)"
        benches.append((b, name, cells, met, body))
    lines = ["# The tracer against Mitsuba 3, per CPU", "",
             "One record per CPU kind, vector width and core count: `scripts/bench-tracer.sh` writes the one of the machine it runs on, "
             "and a result is a claim only on that CPU. Per round: the median of each round's Mitsuba ÷ "
             "mirrorbox (above 1: mirrorbox faster). Goals (issue 41): `whitted` ≥ 3×, `path` ≥ 2× "
             "Mitsuba's compiled kernel, on both scenes. Mitsuba's compiled kernel is its process's "
             "second render; 'mirrorbox timed' says which of its process's renders mirrorbox was "
             "timed on (records before 2026-11-28's fourth session of issue 56: its first, a cold one). "
             "A goal is met when the 95 % interval of a row's per-round median lies above it (the "
             "records that have one), and undecided when the interval holds it.", "",
             "| CPU | vector width | cores | date | commit | rounds | Mitsuba baseline | mirrorbox timed | `mirror_box` whitted | `mirror_box` path | `mirror_room` whitted | `mirror_room` path | goals |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for b, name, cells, met, _ in benches:
        lines.append(f"| [{b.get('cpu', '?')}]({name}) | {b.get('simd', '?')} | {b.get('cores', '?')} | {b.get('date', '?')} | {b.get('commit', '–')} | {b.get('rounds', '?')} | "
                     f"{b.get('mitsuba_whitted', '–')} | {b.get('mirrorbox_timed', 'first render')} | " + " | ".join(cells) + f" | {met} |")
    for b, name, _, _, body in benches:
        lines += ["", f"## {b.get('cpu', '?')} ({b.get('simd', '?')}, {b.get('cores', '?')} cores)", "", body]
    open(os.path.join(out, "bench.md"), "w").write("\n".join(lines) + "\n")
    json.dump([b for b, *_ in benches], open(os.path.join(out, "bench.json"), "w"), indent=2)


if __name__ == "__main__":
    main()
