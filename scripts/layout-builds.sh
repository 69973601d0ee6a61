#!/usr/bin/env bash
# The working tree's release `mirrorbox`, built once and linked once per layout seed 1..SEEDS
# with its functions in a different order each time (lld's --shuffle-sections, through
# scripts/lib/shuffle-cc): PREFIX-1 … PREFIX-SEEDS. The same code in different places, for
# scripts/ab-layouts.sh, which times a change over several layouts (docs/tracer-performance.md,
# "How it is measured": where a function's code sits moves the tracer by a few per cent with
# nothing else changed).
#
# Usage: scripts/layout-builds.sh SEEDS PREFIX      (e.g. 4 /tmp/before, then 4 /tmp/after)
#   Builds in target/layouts (a linker of its own there: the first build there compiles
#   everything, about as long as a cold release build; later ones only what changed, and each
#   seed one relink of the command-line crate). Outside scripts/test-build-env.sh's clippy
#   wrapper, as every measured build. Needs rustc's default linker on x86-64 Linux, lld
#   (rustc 1.90 and later); SEEDS at most 16.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -ne 2 ]; then
  echo "usage: $0 SEEDS PREFIX" >&2
  exit 2
fi
seeds=$1 prefix=$2
case $seeds in '' | *[!0-9]* | 0*) echo "SEEDS must be a whole number from 1 to 16, not '$seeds'" >&2; exit 2 ;; esac
[ "$seeds" -le 16 ] || { echo "SEEDS must be a whole number from 1 to 16, not '$seeds'" >&2; exit 2; }
[ -d "$(dirname "$prefix")" ] || { echo "PREFIX's folder $(dirname "$prefix") does not exist" >&2; exit 2; }
unset RUSTC_WORKSPACE_WRAPPER CLIPPY_ARGS RUSTFLAGS CARGO_ENCODED_RUSTFLAGS
export CARGO_TARGET_DIR=$PWD/target/layouts
export CARGO_TARGET_X86_64_UNKNOWN_LINUX_GNU_LINKER=$PWD/scripts/lib/shuffle-cc
for seed in $(seq "$seeds"); do
  # The seed is read by the linker, which cargo does not know of: the command-line crate is
  # marked changed so that the binary is linked again.
  touch crates/cli/src/main.rs
  if ! MIRRORBOX_LAYOUT_SEED=$seed cargo build --release --locked -q -p mirrorbox; then
    echo "layout-builds: the build with layout seed $seed failed (the linker must be lld: rustc's default on x86-64 Linux since 1.90)" >&2
    exit 1
  fi
  cp "$CARGO_TARGET_DIR/release/mirrorbox" "$prefix-$seed"
  echo "$prefix-$seed"
done
