#!/usr/bin/env bash
# Frame rates of `mirrorbox view` per method at the scene's own size, as a user sees them:
# the real viewer in a window (Xvfb when no DISPLAY is set), the live truth switched off so
# the method has the CPU to itself (on a CPU adapter the tracer would share its cores), every
# method of the registry at its defaults, interleaved over rounds so that drift of a shared
# machine spreads over all methods alike.
#
# Per method and round: 5 warm-up frames, 30 frames with a still camera (the frame built once,
# drawn again), 30 frames walking (each frame re-planned and rebuilt for the moved camera).
# Writes reports/viewer/frame_rates.md and .json: medians over all rounds' frames with the
# 5th–95th percentile range, and the device.
#
# Usage: scripts/viewer-frame-rates.sh [SCENE] [ROUNDS]   (defaults: scenes/mirror_box.json 3)
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/mirror_box.json}
rounds=${2:-3}
bin=target/release/mirrorbox
[ -x "$bin" ] || cargo build --release -p mirrorbox
out=reports/viewer
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
methods=$("$bin" render --help | sed -n '/Possible values:/,/default:/p' | grep -oE '^ +- [a-z-]+:' | sed -E 's/ +- //; s/://')
{
  echo "truth off"
  echo "frames 5"
  echo "frames 30"
  for _ in $(seq 30); do echo "walk 0.01 0 0"; echo "frames 1"; done
  echo "exit"
} > "$work/script.txt"
run() {
  if [ -n "${DISPLAY:-}" ]; then "$@"; else xvfb-run -a -s "-screen 0 1920x1080x24" "$@"; fi
}
for round in $(seq "$rounds"); do
  for m in $(echo "$methods" | shuf); do
    echo "round $round: $m" >&2
    run "$bin" view "$scene" --method "$m" --no-vsync --script "$work/script.txt" \
      --log "$work/$m.$round.jsonl"
  done
done
"$bin" info > "$work/info.txt"
python3 - "$work" "$scene" "$rounds" "$out" <<'PY'
import json, sys, glob, os, statistics, datetime, platform
work, scene, rounds, out = sys.argv[1:]
def pct(v, p):
    v = sorted(v); return v[min(len(v) - 1, max(0, round(p / 100 * (len(v) - 1))))]
rows = {}
for path in sorted(glob.glob(f"{work}/*.jsonl")):
    method = os.path.basename(path).split(".")[0]
    recs = [json.loads(l) for l in open(path)]
    # Frames 1-5 warm up; 6-35 still; the rest walking (each rebuilt).
    still = [r for r in recs if 6 <= r["frame"] <= 35]
    moving = [r for r in recs if r["frame"] > 35 and (r.get("build_ms") or 0) > 0]
    d = rows.setdefault(method, {"key": recs[-1]["method"], "still_gpu": [], "still_wall": [], "move_wall": [], "move_build": [], "still_draw": [], "still_paint": [], "passes": recs[-1]["passes"]})
    d["still_gpu"] += [r["gpu_ms"] for r in still]
    d["still_draw"] += [r["phases_ms"]["draw"] for r in still]
    d["still_paint"] += [r["phases_ms"]["paint_present"] for r in still]
    d["still_wall"] += [r["wall_ms"] for r in still]
    d["move_wall"] += [r["wall_ms"] for r in moving]
    d["move_build"] += [r["build_ms"] for r in moving]
info = open(f"{work}/info.txt").read().splitlines()
adapter = next((l.split(":", 1)[1].strip() for l in info if l.startswith("adapter:")), "?")
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), platform.processor())
summary = {"scene": scene, "rounds": int(rounds), "adapter": adapter, "cpu": cpu, "cores": os.cpu_count(),
           "date": datetime.date.today().isoformat(), "methods": {}}
lines = [f"# `mirrorbox view` frame rates", "",
         f"Measured {summary['date']} with `scripts/viewer-frame-rates.sh {scene} {rounds}` on {cpu}, {os.cpu_count()} cores: adapter {adapter}.",
         "Each method at its defaults in the real viewer (window under Xvfb), live truth off; per round 30 frames with a still camera and 30 walking (each re-planned and rebuilt), methods in a shuffled order per round. Medians over all rounds' frames, [5th–95th percentile].", "",
         "| method | passes | still: GPU ms/frame | still: draw + read back ms | still: paint + present window ms | still: ms between frames | still: fps | walking: ms between frames | walking: fps | walking: plan + build ms |",
         "|---|---|---|---|---|---|---|---|---|---|"]
for method, d in sorted(rows.items()):
    def cell(v): return f"{statistics.median(v):.1f} [{pct(v,5):.1f}–{pct(v,95):.1f}]" if v else "–"
    fps = lambda v: f"{1000 / statistics.median(v):.1f}" if v else "–"
    summary["methods"][d["key"]] = {k: statistics.median(v) if v else None for k, v in d.items() if isinstance(v, list)}
    summary["methods"][d["key"]]["passes"] = d["passes"]
    lines.append(f"| {d['key']} | {d['passes']} | {cell(d['still_gpu'])} | {cell(d['still_draw'])} | {cell(d['still_paint'])} | {cell(d['still_wall'])} | {fps(d['still_wall'])} | {cell(d['move_wall'])} | {fps(d['move_wall'])} | {cell(d['move_build'])} |")
win = summary.setdefault("window", None)
lines += ["", "The time between frames adds to the GPU frame the readback of the image, its tone mapping and upload to the pane, egui, and painting and presenting the whole window (software on lavapipe, growing with the window's pixels: the default window of the panel and four 640×360 panes is 1600×728); walking adds planning and building the method's frame for every camera position."]
open(f"{out}/frame_rates.md", "w").write("\n".join(lines) + "\n")
json.dump(summary, open(f"{out}/frame_rates.json", "w"), indent=2)
print("\n".join(lines))
PY
