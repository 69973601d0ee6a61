#!/usr/bin/env bash
# The truth on the GPU against the CPU truth (issue 39): `mirrorbox trace` (CPU: obvhs,
# rayon) and `mirrorbox trace --device gpu` (wgpu ray queries, `ray-query --primary rays`) of
# mirror_box and mirror_room at 640×360×16 spp, --max-depth 4096 for both (the GPU's cap),
# ROUNDS rounds (default 5) with the four runs shuffled per round. Writes
# reports/gpu_truth/runs.jsonl (one `trace --json` line per run, with round and device) and
# reports/gpu_truth/report.md: per scene and device the median and range of the render time
# (CPU: render_seconds; GPU: the frame's trace_ms, acceleration structures apart), and the
# largest |Δ| between the two images and their FLIP mean, with each scene's FLIP map
# (reports/gpu_truth/mirror_SCENE_flip.png: where they differ).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${MIRRORBOX:-target/release/mirrorbox}
rounds=${1:-5}
dir=reports/gpu_truth
mkdir -p "$dir"
work=$(mktemp -d)
tmp=$(mktemp "$dir/.runs.XXXXXX")
trap 'rm -rf "$work" "$tmp"' EXIT
for round in $(seq 1 "$rounds"); do
  for run in $(printf '%s\n' box:cpu box:gpu room:cpu room:gpu | shuf --random-source=<(yes "$round")); do
    scene=${run%%:*}
    device=${run##*:}
    "$bin" trace "scenes/mirror_$scene.json" --device "$device" --width 640 --height 360 \
      --spp 16 --max-depth 4096 --json -o "$work/${scene}_$device.exr" |
      sed "s/^{/{\"round\":$round,\"device_kind\":\"$device\",\"scene_name\":\"$scene\",/" >>"$tmp"
  done
done
mv "$tmp" "$dir/runs.jsonl"
for scene in box room; do
  "$bin" compare "$work/${scene}_cpu.exr" "$work/${scene}_gpu.exr" --json \
    --heatmap "$dir/mirror_${scene}_flip.png" >"$work/$scene.compare.json"
done
adapter=$("$bin" info 2>/dev/null | sed -n 's/^adapter: *//p' | head -1)
python3 - "$dir" "$work" "$adapter" <<'PY'
import json, sys, statistics, datetime, subprocess
out, work, adapter = sys.argv[1], sys.argv[2], sys.argv[3]
runs = [json.loads(l) for l in open(f"{out}/runs.jsonl")]
cpu = subprocess.run(["sh", "-c", "grep -m1 'model name' /proc/cpuinfo | cut -d: -f2"],
                     capture_output=True, text=True).stdout.strip()
lines = [
    "# The truth on the GPU against the CPU truth",
    "",
    f"Measured {datetime.date.today()} by `scripts/gpu-truth-bench.sh` ({len(runs)} runs, "
    f"interleaved): 640×360, 16 spp (the 4×4 grid), `--max-depth 4096`. CPU: {cpu}; GPU "
    f"adapter: {adapter}. CPU time is the render (BVH build apart); GPU time the frame's "
    "trace (acceleration structures apart).",
    "",
    "| scene | device | median | range | acceleration structures / BVH |",
    "|---|---|---|---|---|",
]
for scene in ["box", "room"]:
    for device in ["cpu", "gpu"]:
        rs = [r for r in runs if r["scene_name"] == scene and r["device_kind"] == device]
        if device == "cpu":
            t = [1e3 * r["render_seconds"] for r in rs]
            build = statistics.median(1e3 * r["bvh_build_seconds"] for r in rs)
        else:
            t = [r["trace_ms"] for r in rs]
            build = statistics.median(r["acceleration_build_ms"] for r in rs)
        lines.append(f"| mirror_{scene} | {device} | {statistics.median(t):.0f} ms | "
                     f"{min(t):.0f}–{max(t):.0f} ms | {build:.1f} ms |")
lines += ["", "| scene | max abs. difference, GPU vs CPU | FLIP mean |", "|---|---|---|"]
for scene in ["box", "room"]:
    c = json.load(open(f"{work}/{scene}.compare.json"))
    lines.append(f"| mirror_{scene} | {c['max_abs']:.2e} | {c['flip_mean']:.2e} |")
lines += ["", "Where they differ: the FLIP maps `mirror_box_flip.png`, `mirror_room_flip.png` beside this file."]
open(f"{out}/report.md", "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PY
echo "wrote $dir/runs.jsonl, $dir/report.md"
