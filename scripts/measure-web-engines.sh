#!/usr/bin/env bash
# Experiment web-engines (issue 53): the planar reflections two web engines ship, scored
# against the truth through the exchange (docs/exchange.md), beside our own equivalents
# measured on the same device.
#
# Per scene (mirror_box, mirror_room, textured_box at 320×180, α = 0.9):
#   1. `mirrorbox export-views` into target/web-engines/<scene>/export (truths not committed);
#   2. the web clients (clients/web, headless Chromium: WebGL 2 on ANGLE on SwiftShader) draw
#      every variant — three.js: floor, reflector, cubecamera; Babylon.js: floor,
#      mirrortexture, probe — into target/web-engines/<scene>/run;
#   3. our equivalents (naive for the Reflector; feedback at history 0 for the MirrorTexture,
#      one texture per mirror per frame; cubemap at 256² for the probes, with the frames the
#      engines' cubes drew before their saved image as its history: warm-up 2 + FRAMES) and
#      the exact methods swept on SwiftShader's Vulkan —
#      the same software rasterizer the browser runs on, loaded by wgpu from Chromium's own
#      ICD file — so that milliseconds compare like with like;
#   4. `mirrorbox score … --with <our sweeps>` writes reports/web_engines[_room|_textured].
# Usage: scripts/measure-web-engines.sh [FRAMES]   (timed frames per point, default 9)
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${MIRRORBOX:-target/release/mirrorbox}
frames=${1:-9}
work=target/web-engines
icd=/usr/lib/chromium/vk_swiftshader_icd.json
if [ ! -f "$icd" ]; then
  echo "measure-web-engines: $icd not found (Chromium's SwiftShader Vulkan driver, from Debian's chromium-headless-shell)" >&2
  exit 1
fi
scripts/install-web-clients.sh
mkdir -p "$work"
for entry in mirror_box: mirror_room:_room textured_box:_textured; do
  scene=${entry%%:*}
  suffix=${entry##*:}
  dir=$work/$scene
  rm -rf "$dir/run" "$dir/ours"
  mkdir -p "$dir"
  echo "== $scene: export"
  "$bin" export-views "scenes/$scene.json" -o "$dir/export" --width 320 --height 180 --alpha 0.9
  echo "== $scene: web clients"
  node clients/web/run.mjs "$dir/export" "$dir/run" --clients three,babylon \
    --variants floor,reflector,cubecamera,mirrortexture,probe \
    --frames "$frames" --warmup 2
  echo "== $scene: our methods on SwiftShader"
  depths=1,4,16,64
  [ "$scene" = mirror_room ] && depths=1,2,4,8
  VK_DRIVER_FILES=$icd "$bin" sweep "scenes/$scene.json" --alpha 0.9 --width 320 --height 180 \
    --frames "$frames" --warmup 2 --out "$dir/ours" \
    --methods naive,feedback,portal,unrolled --depth "$depths" --history 0
  # The engines' cubes refresh every frame, and their saved image is drawn after the warm-up
  # and timed frames: our cubemap with that much history (the clients' `history` knob).
  rm -rf "$dir/ours_cube"
  VK_DRIVER_FILES=$icd "$bin" sweep "scenes/$scene.json" --alpha 0.9 --width 320 --height 180 \
    --frames "$frames" --warmup 2 --out "$dir/ours_cube" \
    --methods cubemap --history $((frames + 2)) --cube-size 256
  echo "== $scene: score"
  "$bin" score "$dir/export" "$dir/run" --with "$dir/ours" --with "$dir/ours_cube" \
    -o "reports/web_engines$suffix"
done
