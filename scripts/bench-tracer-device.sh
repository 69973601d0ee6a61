#!/usr/bin/env bash
# Issue 56: scripts/bench-tracer.sh on a lent device machine's CPU (16 cores; an Intel Xeon when
# last seen, reports/gpu/cpu.txt), a CPU kind this project has no other way to measure. That
# machine has no Rust toolchain, no Mitsuba, no LLVM library for Dr.Jit and reaches no registry,
# so everything travels, prepared here, in .bench/ (ignored; carried by the device tool, which
# sends at most 64 MiB with the working tree: run scripts/gpu-tree.sh light first):
#   scripts/bench-tracer-device.sh prepare   here: the stripped binary (built without the
#       viewer), Mitsuba's wheel for the device's Python 3.12 cut to the one variant and the
#       plugins the bench loads (found by tracing its file opens), Dr.Jit's wheel, and this
#       machine's libLLVM with the libraries it needs that a bare image may lack
#   scripts/bench-tracer-device.sh run ROUNDS SPP   there: unpacks them under /tmp, checks that
#       both renderers draw a small image, then runs scripts/bench-tracer.sh; the record lands
#       in reports/tracer/ (carry reports/tracer) and, with its rounds, under $OUT
set -euo pipefail
cd "$(dirname "$0")/.."
d=.bench
case ${1:-} in
prepare)
  grep -qx '/.bench/' .git/info/exclude 2>/dev/null || printf '/.bench/\n' >>.git/info/exclude
  rm -rf "$d" && mkdir -p "$d"
  (unset RUSTC_WORKSPACE_WRAPPER CLIPPY_ARGS CARGO_INCREMENTAL; cargo build --release --locked -q -p mirrorbox --no-default-features)
  strip -o "$d/mirrorbox" target/release/mirrorbox && xz -T0 -6 "$d/mirrorbox"
  commit=$(git rev-parse HEAD | cut -c1-7)
  git diff --quiet HEAD -- crates shaders Cargo.toml Cargo.lock tools || commit="$commit+changes"
  echo "$commit" >"$d/commit.txt"
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  pins=$(grep -E '^(mitsuba|drjit)==' tools/mitsuba/requirements.txt)
  # shellcheck disable=SC2086
  python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
    --platform manylinux_2_28_x86_64 --platform manylinux_2_27_x86_64 --platform manylinux_2_17_x86_64 \
    -d "$work" $pins
  cp "$work"/drjit-*.whl "$d/"
  mkdir -p "$work/site" && (cd "$work/site" && unzip -q "$work"/mitsuba-*.whl)
  m=$work/site/mitsuba
  rm -rf "$m"/cuda_* "$m"/llvm_ad_mono* "$m"/llvm_ad_spectral* "$m"/scalar_* "$m"/data "$m"/include \
    "$m"/cmake "$m"/pkgconfig "$m"/mitsuba_stubs "$m"/*.pyi "$m"/libIlmImfUtil-mitsuba.so
  keep=" box conductor constant diffuse hdrfilm merge obj path perspective point srgb stratified twosided uniform "
  for f in "$m"/plugins/*.so; do
    n=$(basename "$f" .so)
    case $keep in *" $n "*) ;; *) rm -f "$f" ;; esac
  done
  tar -C "$work/site" -cJf "$d/mitsuba.tar.xz" .
  l=/usr/lib/x86_64-linux-gnu
  llvm=$(ls "$l"/libLLVM.so.* | sort -V | tail -n 1)
  libs=$(ldd "$llvm" | awk '/=>/ {print $3}' | grep -E 'libz3|libedit|libxml2|libbsd|libmd|libicu' || true)
  # The files themselves (-h: ldd names symbolic links such as libedit.so.2), by their
  # soname, flat.
  # shellcheck disable=SC2086
  tar -chJf "$d/llvm.tar.xz" --transform 's,.*/,,' "$llvm" $libs
  basename "$llvm" >"$d/llvm.txt"
  du -sh "$d"
  ;;
run)
  rounds=${2:?rounds} spp=${3:?spp}
  t=/tmp/bench-tools
  rm -rf "$t" && mkdir -p "$t/site" "$t/llvm"
  xz -dc "$d/mirrorbox.xz" >"$t/mirrorbox" && chmod +x "$t/mirrorbox"
  tar -C "$t/site" -xJf "$d/mitsuba.tar.xz"
  tar -C "$t/llvm" -xJf "$d/llvm.tar.xz"
  python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --target "$t/site" "$d"/drjit-*.whl
  export PYTHONPATH=$t/site DRJIT_LIBLLVM_PATH=$t/llvm/$(cat "$d/llvm.txt") LD_LIBRARY_PATH=$t/llvm
  export MIRRORBOX_BENCH_BIN=$t/mirrorbox MIRRORBOX_MITSUBA_PYTHON=$(command -v python3)
  export MIRRORBOX_SOURCE_COMMIT=$(cat "$d/commit.txt")
  export MIRRORBOX_BENCH_NOTE=${MIRRORBOX_BENCH_NOTE:-"a lent device machine's CPU"}
  nproc; grep -m1 'model name' /proc/cpuinfo; grep -m1 -o 'avx512f' /proc/cpuinfo || true
  # Both renderers draw a small image first, with their errors shown (the bench hides them).
  "$t/mirrorbox" export-mitsuba scenes/mirror_box.json -o "$t/scene.xml" --spp 1 >/dev/null
  "$t/mirrorbox" trace scenes/mirror_box.json -o "$t/ours.exr" --spp 1 --width 64 --height 36 --json | tail -c 300
  python3 tools/mitsuba/render.py "$t/scene.xml" -o "$t/mitsuba.exr" --integrator whitted --max-depth 10 --runs 1
  out=${OUT:-/tmp/bench-out}
  mkdir -p "$out"
  scripts/bench-tracer.sh "$rounds" "$spp"
  # This CPU's record (the newest rounds file names it) and the index.
  rounds_file=$(ls -t reports/tracer/bench-*-rounds.jsonl | head -n 1)
  stem=${rounds_file%-rounds.jsonl}
  cp reports/tracer/bench.md reports/tracer/bench.json "$stem.md" "$stem.json" "$rounds_file" "$out/"
  ;;
*)
  echo "usage: scripts/bench-tracer-device.sh prepare | run ROUNDS SPP" >&2
  exit 2
  ;;
esac
