#!/usr/bin/env python3
"""The report of scripts/bench-many-mirrors.sh (issue 51, "many mirrors at linear cost")
from its raw.jsonl: OUT/report.md and OUT/report.svg.

report.md: findings first (per variant and command: the exponent b of time ~ a * N^b,
fitted by least squares on log-log over the N values at their medians, and b between the
two largest N, which fixed costs such as process start weigh on least; the medians; the peak
resident memory at the largest N; failures with their exit code and first error line), then
a table of medians with min-max per variant, command and N, the machine, the date, the
commit and the exact commands. report.svg: time and peak memory against N, log-log, one
panel per variant, one colour and marker per command; lines join only the N values of one
command within one variant.

/usr/bin/time's %e has a resolution of 0.01 s: a median below it is left out of the fits
(said so in the findings).

Usage: many_mirrors_report.py RAW.jsonl OUT_DIR
Standard library only.
"""
import json
import math
import os
import statistics
import sys

RESOLUTION_S = 0.01
# Per command: colour and marker, in the plot and legend. The methods' and the truth's are
# their styles in every report (crates/report/src/plot.rs, `method_style`: naive, unrolled,
# truth); `check` is no method, black.
STYLE = {
    "check": ("#000000", "square"),
    "trace": ("#333333", "cross"),
    "naive": ("#E69F00", "triangle-down"),
    "unrolled": ("#0072B2", "plus"),
}
DEFAULT_STYLE = ("#666666", "circle")


def fit(points):
    """Least squares of log t = log a + b log N: (a, b), or None with fewer than 2 distinct N."""
    pts = [(math.log(n), math.log(t)) for n, t in points if t and t > 0]
    if len({x for x, _ in pts}) < 2:
        return None
    mx = statistics.fmean(x for x, _ in pts)
    my = statistics.fmean(y for _, y in pts)
    sxx = sum((x - mx) ** 2 for x, _ in pts)
    b = sum((x - mx) * (y - my) for x, y in pts) / sxx
    return math.exp(my - b * mx), b


def fmt_s(t):
    if t is None:
        return "–"
    if t < 1:
        return f"{t:.2f}"
    if t < 100:
        return f"{t:.3g}"
    return f"{t:.0f}"


def fmt_mb(kb):
    if kb is None:
        return "–"
    mb = kb / 1024
    return f"{mb / 1024:.2f} GB" if mb >= 1024 else f"{mb:.0f} MB"


def fmt_bytes(b):
    if not b:
        return "–"
    return f"{b / 1e6:.2f} MB" if b >= 1e6 else f"{b / 1e3:.1f} kB"


def fmt_n(n):
    return f"{n:,}".replace(",", " ")


def load(path):
    meta, scenes, runs = {}, {}, []
    with open(path) as f:
        for i, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            try:
                r = json.loads(line)
            except json.JSONDecodeError as e:
                sys.exit(f"{path}:{i}: not JSON ({e})")
            kind = r.get("kind")
            if kind == "meta":
                meta = r
            elif kind == "scene":
                scenes[(r["variant"], r["n"])] = r
            elif kind == "run":
                runs.append(r)
    return meta, scenes, runs


def cells(runs):
    """(variant, command, n) -> {"ok": [(s, kb)], "failed": [run], "skipped": [run]}."""
    out = {}
    for r in runs:
        c = out.setdefault((r["variant"], r["command"], r["n"]), {"ok": [], "failed": [], "skipped": []})
        if r.get("skipped"):
            c["skipped"].append(r)
        elif r.get("exit") == 0 and r.get("seconds") is not None:
            c["ok"].append((r["seconds"], r.get("max_rss_kb")))
        else:
            c["failed"].append(r)
    return out


def ordered(seen, preferred):
    return [x for x in preferred if x in seen] + sorted(x for x in seen if x not in preferred)


def summarise(cell):
    """Medians and ranges of a cell's successful runs; None where there are none or where a
    run failed (a median over the runs that happened to succeed would flatter it)."""
    if not cell or not cell["ok"] or cell["failed"] or cell["skipped"]:
        return None
    secs = [s for s, _ in cell["ok"]]
    rss = [k for _, k in cell["ok"] if k is not None]
    return {
        "median": statistics.median(secs), "min": min(secs), "max": max(secs),
        "rss": statistics.median(rss) if rss else None,
        "rss_min": min(rss) if rss else None, "rss_max": max(rss) if rss else None,
        "runs": len(secs),
    }


def failure_text(cell):
    if cell["failed"]:
        r = cell["failed"][0]
        return f"exit {r.get('exit')}: {r.get('error') or '(no message)'}"
    if cell["skipped"]:
        return f"skipped: {cell['skipped'][0]['skipped']}"
    return None


# --- the plot -------------------------------------------------------------------------------

def log_ticks(lo, hi):
    """Tick values for a log axis over [lo, hi]: the decades, with 2 and 5 between them when
    fewer than three decades fall in the range."""
    ticks = []
    for mult in ((1,), (1, 2, 5)):
        ticks = []
        for e in range(math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 1):
            for m in mult:
                v = m * 10.0 ** e
                if lo * (1 - 1e-9) <= v <= hi * (1 + 1e-9):
                    ticks.append(v)
        if len(ticks) >= 3:
            break
    return ticks


def tick_label(v, unit=""):
    if v >= 1000:
        s = f"{v / 1000:g}k"
    else:
        s = f"{v:g}"
    return s + unit


def marker(shape, x, y, colour, r=4.0, hollow=False):
    fill = "none" if hollow else colour
    a = f'fill="{fill}" stroke="{colour}" stroke-width="1.5"'
    if shape == "square":
        return f'<rect x="{x - r:.1f}" y="{y - r:.1f}" width="{2 * r:.1f}" height="{2 * r:.1f}" {a}/>'
    if shape == "triangle":
        return (f'<polygon points="{x:.1f},{y - r * 1.2:.1f} {x - r * 1.1:.1f},{y + r * 0.8:.1f} '
                f'{x + r * 1.1:.1f},{y + r * 0.8:.1f}" {a}/>')
    if shape == "triangle-down":
        return (f'<polygon points="{x:.1f},{y + r * 1.2:.1f} {x - r * 1.1:.1f},{y - r * 0.8:.1f} '
                f'{x + r * 1.1:.1f},{y - r * 0.8:.1f}" {a}/>')
    if shape == "diamond":
        return (f'<polygon points="{x:.1f},{y - r * 1.3:.1f} {x + r:.1f},{y:.1f} '
                f'{x:.1f},{y + r * 1.3:.1f} {x - r:.1f},{y:.1f}" {a}/>')
    if shape in ("plus", "cross"):
        k = r * 1.3
        d = (f"M{x - k:.1f},{y:.1f} L{x + k:.1f},{y:.1f} M{x:.1f},{y - k:.1f} L{x:.1f},{y + k:.1f}"
             if shape == "plus" else
             f"M{x - r:.1f},{y - r:.1f} L{x + r:.1f},{y + r:.1f} M{x - r:.1f},{y + r:.1f} "
             f"L{x + r:.1f},{y - r:.1f}")
        return f'<path d="{d}" stroke="{colour}" stroke-width="2.2" fill="none"/>'
    return f'<circle cx="{x:.1f}" cy="{y:.1f}" r="{r:.1f}" {a}/>'


def cross_mark(x, y, colour, r=4.0):
    """A failed, timed-out or skipped run: a crossed circle (the truth's marker is a cross)."""
    k = r * 0.7
    return (f'<circle cx="{x:.1f}" cy="{y:.1f}" r="{r + 1:.1f}" fill="white" stroke="{colour}" '
            f'stroke-width="1.2"/><path d="M{x - k:.1f},{y - k:.1f} L{x + k:.1f},{y + k:.1f} '
            f'M{x - k:.1f},{y + k:.1f} L{x + k:.1f},{y - k:.1f}" stroke="{colour}" '
            f'stroke-width="1.4" fill="none"/>')


def esc(s):
    return s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def svg(variants, commands, ns, table, cellmap):
    ns = [n for n in ns if n > 0] or [1]  # a log axis
    pw, ph = 250, 190  # a panel's plot area
    ml, mr, mt, mb = 62, 16, 46, 44  # margins around each panel
    cw, chh = ml + pw + mr, mt + ph + mb
    legend_h = 40
    width = cw * len(variants)
    height = legend_h + 2 * chh + 10
    rows = [("seconds", "time", "wall time (s)"), ("rss", "peak resident memory", "peak RSS (MB)")]
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="11">',
           f'<rect width="{width}" height="{height}" fill="white"/>']
    # Legend.
    x = 10
    for c in commands:
        colour, shape = STYLE.get(c, DEFAULT_STYLE)
        out.append(marker(shape, x + 6, 20, colour))
        out.append(f'<text x="{x + 16}" y="24">{esc(c)}</text>')
        x += 30 + 7 * len(c)
    out.append(cross_mark(x + 6, 20, "#444"))
    out.append(f'<text x="{x + 16}" y="24">failed, timed out or skipped (at the top)</text>')
    x += 260
    out.append(marker("circle", x + 6, 20, "#444", r=3.5, hollow=True))
    out.append(f'<text x="{x + 16}" y="24">below the 0.01 s resolution (at the bottom)</text>')
    x += 270
    out.append(f'<path d="M{x},20 L{x + 24},20" stroke="#aaa" stroke-dasharray="4,3"/>')
    out.append(f'<text x="{x + 30}" y="24">slope 1: linear cost</text>')
    nlo, nhi = min(ns), max(ns)
    if nlo == nhi:
        nlo, nhi = nlo / 2, nhi * 2
    nlo, nhi = nlo / 1.3, nhi * 1.3
    for ri, (key, title, label) in enumerate(rows):
        vals = []
        for (v, c, n), s in table.items():
            if s:
                val = s["median"] if key == "seconds" else (s["rss"] / 1024 if s["rss"] else None)
                if val and val > 0:
                    vals.append(val)
                if key == "seconds" and s["min"] > 0:
                    vals += [s["min"], s["max"]]
        if not vals:
            vals = [RESOLUTION_S, 1.0]
        lo, hi = min(vals) / 1.5, max(vals) * 1.5
        if hi / lo < 10:
            mid = math.sqrt(lo * hi)
            lo, hi = mid / math.sqrt(10), mid * math.sqrt(10)
        oy = legend_h + ri * chh
        for vi, v in enumerate(variants):
            ox = vi * cw + ml
            top = oy + mt
            X = lambda n: ox + pw * (math.log(n) - math.log(nlo)) / (math.log(nhi) - math.log(nlo))
            Y = lambda t: top + ph - ph * (math.log(t) - math.log(lo)) / (math.log(hi) - math.log(lo))
            out.append(f'<text x="{ox + pw / 2}" y="{oy + mt - 10}" text-anchor="middle" '
                       f'font-weight="bold">{esc(v)}: {title}</text>')
            out.append(f'<rect x="{ox}" y="{top}" width="{pw}" height="{ph}" fill="none" stroke="#888"/>')
            for t in log_ticks(lo, hi):
                y = Y(t)
                out.append(f'<line x1="{ox}" y1="{y:.1f}" x2="{ox + pw}" y2="{y:.1f}" stroke="#e4e4e4"/>')
                out.append(f'<text x="{ox - 5}" y="{y + 4:.1f}" text-anchor="end">{tick_label(t)}</text>')
            for n in log_ticks(nlo, nhi):
                xx = X(n)
                out.append(f'<line x1="{xx:.1f}" y1="{top}" x2="{xx:.1f}" y2="{top + ph}" stroke="#e4e4e4"/>')
                out.append(f'<text x="{xx:.1f}" y="{top + ph + 15}" text-anchor="middle">{tick_label(n)}</text>')
            out.append(f'<text x="{ox + pw / 2}" y="{top + ph + 34}" text-anchor="middle">'
                       f'N, mirror facets (log)</text>')
            out.append(f'<text transform="translate({ox - 46},{top + ph / 2}) rotate(-90)" '
                       f'text-anchor="middle">{label}, log</text>')
            if key == "seconds":  # a line of slope 1 (linear cost) to read the others against
                n0, t0 = min(ns), lo * 1.6
                n1 = min(max(ns), n0 * hi / t0 / 1.05)
                if n1 > n0:
                    out.append(f'<path d="M{X(n0):.1f},{Y(t0):.1f} L{X(n1):.1f},{Y(t0 * n1 / n0):.1f}" '
                               f'stroke="#aaa" stroke-width="1" stroke-dasharray="4,3" fill="none"/>')
                    out.append(f'<text x="{X(n1) - 4:.1f}" y="{Y(t0 * n1 / n0) - 5:.1f}" text-anchor="end" '
                               f'fill="#888">∝ N</text>')
            for c in commands:
                colour, shape = STYLE.get(c, DEFAULT_STYLE)
                pts, bad = [], []
                for n in ns:
                    s = table.get((v, c, n))
                    val = None
                    if s:
                        val = s["median"] if key == "seconds" else (s["rss"] / 1024 if s["rss"] else None)
                    if val and val > 0:
                        pts.append((n, val, s))
                    elif (v, c, n) in cellmap and not s:
                        bad.append(n)
                if len(pts) > 1:
                    d = " ".join(f"{'M' if i == 0 else 'L'}{X(n):.1f},{Y(t):.1f}" for i, (n, t, _) in enumerate(pts))
                    out.append(f'<path d="{d}" stroke="{colour}" stroke-width="1.4" fill="none"/>')
                for n, t, s in pts:
                    if key == "seconds" and s["min"] > 0 and s["max"] > s["min"]:
                        out.append(f'<line x1="{X(n):.1f}" y1="{Y(s["min"]):.1f}" x2="{X(n):.1f}" '
                                   f'y2="{Y(s["max"]):.1f}" stroke="{colour}" stroke-width="1"/>')
                    out.append(marker(shape, X(n), Y(t), colour))
                for n in bad:  # side by side, so that two commands failing at one N both show
                    out.append(cross_mark(X(n) + 9 * (commands.index(c) - (len(commands) - 1) / 2),
                                          top + 6, colour))
                if key == "seconds":
                    for n in ns:
                        s = table.get((v, c, n))
                        if s and s["median"] < RESOLUTION_S:
                            out.append(marker(shape, X(n), top + ph - 6, colour, r=3.5, hollow=True))
    out.append("</svg>")
    return "\n".join(out) + "\n"


# --- the report -----------------------------------------------------------------------------

def main():
    if len(sys.argv) != 3:
        sys.exit("usage: many_mirrors_report.py RAW.jsonl OUT_DIR")
    raw, outdir = sys.argv[1:]
    meta, scenes, runs = load(raw)
    cellmap = cells(runs)
    variants = ordered({v for v, _, _ in cellmap}, meta.get("variants") or [])
    commands = ordered({c for _, c, _ in cellmap}, meta.get("command_names") or list(STYLE))
    ns = sorted({n for _, _, n in cellmap})
    table = {k: summarise(c) for k, c in cellmap.items()}

    L = ["# Many mirrors at linear cost (issue 51)", ""]
    L.append("Wall time and peak resident memory of `check`, `trace` and two raster methods "
             "against the number N of mirror facets, for each variant of "
             "`scripts/make_mirror_mosaic.py`. Written by `scripts/many_mirrors_report.py` "
             "from `raw.jsonl` (`scripts/bench-many-mirrors.sh`).")
    L.append("")
    L += ["## Findings", ""]
    L.append("b: the exponent of time ≈ a·N^b, least squares on log-log over the N values "
             "(medians); b(last): between the two largest N, where fixed costs (process start, "
             "adapter, the objects of the setting) weigh least. Linear cost is b ≈ 1 at large N.")
    L.append("")
    worst = []
    for v in variants:
        L.append(f"**{v}**")
        L.append("")
        for c in commands:
            pts, below, fails = [], [], []
            for n in ns:
                cell = cellmap.get((v, c, n))
                if cell is None:
                    continue
                s = table[(v, c, n)]
                if s is None:
                    fails.append((n, failure_text(cell)))
                elif s["median"] < RESOLUTION_S:
                    below.append(n)
                else:
                    pts.append((n, s["median"]))
            parts = []
            f_all = fit(pts)
            f_last = fit(pts[-2:]) if len(pts) >= 2 else None
            if f_all:
                parts.append(f"b = {f_all[1]:.2f}")
                parts.append(f"b(last) = {f_last[1]:.2f}")
                worst.append((f_last[1], v, c, pts[-2][0], pts[-1][0]))
            else:
                parts.append("b: too few timed N to fit")
            meds = ", ".join(f"{fmt_s(t)} s at {fmt_n(n)}" for n, t in pts)
            if meds:
                parts.append("medians " + meds)
            if below:
                parts.append("below the 0.01 s resolution at N = " + ", ".join(fmt_n(n) for n in below)
                             + " (left out of the fit)")
            ok_ns = [n for n in ns if table.get((v, c, n))]
            if ok_ns:
                s = table[(v, c, ok_ns[-1])]
                parts.append(f"peak RSS {fmt_mb(s['rss'])} at N = {fmt_n(ok_ns[-1])}")
            groups = {}  # one message, the N values it came at
            for n, why in fails:
                groups.setdefault(why, []).append(n)
            for why, at in groups.items():
                verb = "not run" if why.startswith("skipped") else "failed"
                parts.append(f"**{verb} at N = {', '.join(fmt_n(n) for n in at)}** ({why})")
            L.append(f"- `{c}`: " + "; ".join(parts))
        L.append("")
    if worst:
        worst.sort(reverse=True)
        b, v, c, n0, n1 = worst[0]
        L.append(f"Steepest growth between the two largest N: {v} `{c}`, b(last) = {b:.2f} "
                 f"({fmt_n(n0)} → {fmt_n(n1)}).")
        over = [w for w in worst if w[0] > 1.3]
        if over:
            L.append("Above b(last) = 1.3 (worse than linear): " +
                     ", ".join(f"{v} `{c}` ({b:.2f})" for b, v, c, _, _ in over) + ".")
        L.append("")

    L += ["## Medians", ""]
    L.append("Seconds: median [min–max] over the repetitions; peak RSS: median [min–max]. A cell "
             "with a failed run shows the failure instead (exit code and the first error line).")
    L.append("")
    L.append("| variant | command | N | scene file | runs | seconds median [min–max] | peak RSS median [min–max] |")
    L.append("|---|---|---|---|---|---|---|")
    for v in variants:
        for c in commands:
            for n in ns:
                cell = cellmap.get((v, c, n))
                if cell is None:
                    continue
                sc = scenes.get((v, n), {})
                size = fmt_bytes(sc.get("bytes"))
                s = table[(v, c, n)]
                if s:
                    L.append(f"| {v} | {c} | {fmt_n(n)} | {size} | {s['runs']} | "
                             f"{fmt_s(s['median'])} [{fmt_s(s['min'])}–{fmt_s(s['max'])}] | "
                             f"{fmt_mb(s['rss'])} [{fmt_mb(s['rss_min'])}–{fmt_mb(s['rss_max'])}] |")
                else:
                    why = failure_text(cell).replace("|", "\\|")
                    total = len(cell["ok"]) + len(cell["failed"]) + len(cell["skipped"])
                    L.append(f"| {v} | {c} | {fmt_n(n)} | {size} | {len(cell['ok'])} of {total} ok | "
                             f"{why} | |")
    L.append("")
    gen_fail = [r for r in scenes.values() if r.get("exit")]
    if gen_fail:
        L.append("Scenes the generator refused: " + "; ".join(
            f"{r['variant']} N = {fmt_n(r['n'])} (exit {r['exit']}: {r.get('error', '')})" for r in gen_fail) + ".")
        L.append("")

    L += ["## How it was measured", ""]
    cores = meta.get("cores")
    in_info = meta.get("cpus_in_cpuinfo")
    L.append(f"- Machine: {meta.get('cpu', 'unknown CPU')}, {cores} cores available"
             + (f" ({in_info} in /proc/cpuinfo)" if in_info not in (None, cores) else ""))
    L.append(f"- Date: {meta.get('date', '?')}")
    L.append(f"- Commit: `{meta.get('commit', '?')}` (binary `{meta.get('binary', '?')}`, "
             f"modified {meta.get('binary_mtime', '?')})")
    L.append(f"- N: {', '.join(fmt_n(n) for n in ns)}; {meta.get('reps', '?')} repetition(s), "
             f"round-robin (repetition r runs every N, variant and command before r+1); each "
             f"command under `timeout {meta.get('timeout_s', '?')}` (a command that timed out is "
             f"not run again for its variant at that N or above) and `/usr/bin/time -f '%e %M'` "
             f"(wall seconds at 0.01 s resolution, peak resident KB)")
    L.append("- Scenes (written into a temporary folder before the timing, not timed):")
    for g in meta.get("generator", []):
        L.append(f"  - `{g}`")
    L.append("- Commands (SCENE the generated scene; outputs into the temporary folder):")
    for c in meta.get("commands", []):
        L.append(f"  - `{c}`")
    L.append("")
    L.append("![time and peak memory against N](report.svg)")
    L.append("")

    os.makedirs(outdir, exist_ok=True)
    with open(os.path.join(outdir, "report.md"), "w") as f:
        f.write("\n".join(L))
    with open(os.path.join(outdir, "report.svg"), "w") as f:
        f.write(svg(variants, commands, ns, table, cellmap))
    print(f"wrote {os.path.join(outdir, 'report.md')} and report.svg", file=sys.stderr)


if __name__ == "__main__":
    main()
