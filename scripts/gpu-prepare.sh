#!/usr/bin/env bash
# Issue 21: builds here what scripts/gpu-measure.sh runs on a lent GPU machine, which has no Rust
# toolchain and reaches no package registry: the stripped release binary and the raster crate's
# test binaries, gzipped, in .gpu/, and the Vulkan/EGL loader packages in .gl/. Both folders are
# ignored (.git/info/exclude) and carried to the machine by the device tool.
set -euo pipefail
cd "$(dirname "$0")/.."
grep -qx '/.gl/' .git/info/exclude 2>/dev/null || printf '/.gl/\n' >>.git/info/exclude
grep -qx '/.gpu/' .git/info/exclude 2>/dev/null || printf '/.gpu/\n' >>.git/info/exclude
rm -rf .gpu && mkdir -p .gpu .gl
"${CARGO:-cargo}" build --release --locked -p mirrorbox
strip -o .gpu/mirrorbox target/release/mirrorbox
# The raster crate's test binaries (dev profile, optimized): their paths from cargo's messages.
"${CARGO:-cargo}" test --locked -p mirrorbox-raster --no-run --message-format=json 2>/dev/null |
  python3 -c '
import json, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m["profile"]["test"]:
        print(m["target"]["name"], m["executable"])
' | while read -r name exe; do
  [ "$name" = structure ] && continue # reads sources only; nothing GPU-dependent
  strip -o ".gpu/test_$name" "$exe"
done
gzip -9 .gpu/*
if ! ls .gl/libvulkan1_*.deb >/dev/null 2>&1; then
  # Not through scripts/lib/apt.sh: a private lists folder and `apt-get download` into .gl/
  # take none of the system's apt or dpkg locks (checked with apt 2.6.1 while all four were
  # held: both succeed), so there is nothing of another apt-get's to wait for.
  o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
  mkdir -p /tmp/amd64/partial
  # shellcheck disable=SC2086
  apt-get $o update >/dev/null
  # shellcheck disable=SC2086
  (cd .gl && apt-get $o download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
fi
du -sh .gpu .gl
