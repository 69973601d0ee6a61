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
# MIRRORBOX_GPU_TESTS=0 leaves them out (the `tests` and `retest` steps need them; the
# measurements do not, and the binaries are most of what travels).
if [ "${MIRRORBOX_GPU_TESTS:-1}" != 0 ]; then
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
fi
gzip -9 .gpu/*
# The commit the binary was built from, as the sweeps record it (harness `source_commit`, read
# there from MIRRORBOX_SOURCE_COMMIT): the GPU machine has no history to ask.
commit=$(git describe --always --abbrev=10)
if [ -n "$(git status --porcelain -- crates shaders scenes scripts tools Cargo.toml Cargo.lock)" ]; then
  commit="$commit-dirty"
fi
echo "$commit" >.gpu/commit.txt
# The real-assets experiment's engine (Debian's assimp-testmodels here; the GPU machine has
# no package registry).
engine_glb=/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb
if [ -f "$engine_glb" ]; then
  mkdir -p .gpu/assets && cp "$engine_glb" .gpu/assets/
fi
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
