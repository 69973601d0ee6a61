#!/usr/bin/env bash
# Frame rates of `mirrorbox view` per method at the scene's own size, as a user sees them,
# against the goals of issue 42: the real viewer in its default window (Xvfb when no DISPLAY
# is set), the live truth switched off so the method has the CPU to itself (on a CPU adapter
# the tracer would share its cores), every method of the registry at its defaults,
# interleaved over rounds (a shuffled order per round) so that drift of a shared machine
# spreads over all methods alike.
#
# Per method and round: 5 warm-up frames, then 30 frames with a still camera and 30 walking
# (the camera moved before each frame), alternating in blocks of 5. With
# BASELINE_BIN=path/to/an/older/mirrorbox (and BASELINE_COMMIT=its commit), each round
# also runs that binary on every method, interleaved with this one, for a before/after table
# measured in the same minutes on the same machine. KEEP_LOGS=DIR keeps the frame logs.
#
# Writes reports/viewer/frame_rates.md and .json (scripts/viewer_frame_rates_report.py):
# medians over all rounds' frames with the 5th–95th percentile range, the phases of a frame,
# the goals met or not and what is missing where not, and the device.
#
# Usage: scripts/viewer-frame-rates.sh [SCENE] [ROUNDS]   (defaults: scenes/mirror_box.json 3)
#        METHODS="symmetry naive" … measures only those (the report then lists only them).
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-scenes/mirror_box.json}
rounds=${2:-3}
bin=target/release/mirrorbox
cargo build --release -p mirrorbox
baseline=${BASELINE_BIN:-}
out=reports/viewer
mkdir -p "$out"
work=$(mktemp -d)
echo "logs in $work (removed when the report is written)" >&2
methods=${METHODS:-$("$bin" render --help | sed -n '/Possible values:/,/default:/p' | grep -oE '^ +- [a-z-]+:' | sed -E 's/ +- //; s/://')}
# Standing and walking alternate in blocks of 5 frames, so that a noisy minute of a shared
# machine falls on both alike.
{
  echo "truth off"
  echo "frames 5"
  for _ in $(seq 6); do
    echo "frames 5"
    for _ in $(seq 5); do echo "walk 0.01 0 0"; echo "frames 1"; done
  done
  echo "exit"
} > "$work/script.txt"
run() {
  if [ -n "${DISPLAY:-}" ]; then "$@"; else xvfb-run -a -s "-screen 0 1920x1080x24" "$@"; fi
}
binaries="now"
[ -n "$baseline" ] && binaries="now before"
for round in $(seq "$rounds"); do
  for job in $(for m in $methods; do for b in $binaries; do echo "$m:$b"; done; done | shuf); do
    m=${job%%:*}
    which=${job##*:}
    exe=$bin
    [ "$which" = before ] && exe=$baseline
    echo "round $round: $m ($which)" >&2
    run "$exe" view "$scene" --method "$m" --no-vsync --script "$work/script.txt" \
      --log "$work/$which.$m.$round.jsonl"
  done
done
"$bin" info > "$work/info.txt"
commit=$(git rev-parse HEAD | cut -c1-7)
git diff --quiet HEAD -- crates shaders || commit="$commit+changes"
baseline_commit=${BASELINE_COMMIT:-}
if [ -n "${KEEP_LOGS:-}" ]; then
  mkdir -p "$KEEP_LOGS" && cp "$work"/* "$KEEP_LOGS"/
  echo "logs kept in $KEEP_LOGS (python3 scripts/viewer_frame_rates_report.py $KEEP_LOGS $scene $rounds $out $commit $baseline_commit writes the report again)" >&2
fi
python3 scripts/viewer_frame_rates_report.py "$work" "$scene" "$rounds" "$out" "$commit" "$baseline_commit"
rm -rf "$work"
