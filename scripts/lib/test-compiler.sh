#!/usr/bin/env bash
# The compiler of the workspace's own crates in the test build (RUSTC_WORKSPACE_WRAPPER, set
# by scripts/test-build-env.sh); cargo calls it as `test-compiler.sh RUSTC ARGS...`.
#
# - clippy's lints: through clippy-driver ($MIRRORBOX_CLIPPY_DRIVER) where there is one, as
#   `cargo clippy` does, with code generation; plain rustc otherwise.
# - Every library's own unit-test harness (`--test` on a `src/lib.rs`) and every bench, in
#   the test build's profile (`-C debug-assertions=on`, which cargo passes to units above
#   opt-level 0 with debug assertions: not `cargo bench`'s), at opt-level 0. Cargo has no
#   profile setting for one kind of target: `[profile.test]` applies to the libraries the
#   integration tests link as well, which would unoptimise the tracer they render with
#   (docs/budgets.md). These units only run their own small cases (or, for the benches, are
#   linted and never run), and their optimised builds were a sixth of the test build's
#   compiler time: the tracer's harness 52 -> 7 s of compiler time, the scene's 29 -> 6 s,
#   the rasterizer's 17 -> 5 s, the image metrics' 12 -> 2 s, the two benches 18 -> 2 s; the
#   harnesses' cases 1.8 -> 6.9 s in all (docs/budgets.md, measured). The same -C flag given
#   twice: rustc takes the last. Cargo's fingerprints do not include the flag: a change to
#   these rules rebuilds nothing by itself.
set -euo pipefail
harness=no lib=no bench=no checked=no
for arg in "$@"; do
  case $arg in
  --test) harness=yes ;;
  debug-assertions=on) checked=yes ;;
  src/lib.rs | */src/lib.rs) lib=yes ;;
  benches/*.rs | */benches/*.rs) bench=yes ;;
  esac
done
extra=()
if [ "$checked" = yes ] && { [ "$bench" = yes ] || { [ "$harness" = yes ] && [ "$lib" = yes ]; }; }; then
  extra=(-C opt-level=0)
fi
if [ -n "${MIRRORBOX_CLIPPY_DRIVER:-}" ]; then
  exec "$MIRRORBOX_CLIPPY_DRIVER" "$@" ${extra[@]+"${extra[@]}"}
fi
exec "$@" ${extra[@]+"${extra[@]}"}
