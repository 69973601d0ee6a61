# Sourced by scripts/test.sh and scripts/test-times.sh: the environment of the one test
# build, so that both use (and neither rebuilds) the same artifacts.
# - clippy's lints run inside the build: clippy-driver is the compiler of the workspace's own
#   crates (what `cargo clippy` does, with code generation), `-D warnings` passed the way
#   cargo-clippy passes it, through scripts/lib/test-compiler.sh, which also builds the
#   libraries' unit-test harnesses and the benches unoptimised (its header says why);
# - no incremental compilation: a fresh clone's build has nothing to reuse;
# - Mesa's device-select layer quiet on headless machines.
export NODEVICE_SELECT=1
export CARGO_INCREMENTAL=${CARGO_INCREMENTAL:-0}
clippy_driver=$(rustup which clippy-driver 2>/dev/null || command -v clippy-driver || true)
export RUSTC_WORKSPACE_WRAPPER="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/lib/test-compiler.sh"
if [ -n "$clippy_driver" ]; then
  export MIRRORBOX_CLIPPY_DRIVER="$clippy_driver"
  export CLIPPY_ARGS="-D__CLIPPY_HACKERY__warnings__CLIPPY_HACKERY__"
else
  unset MIRRORBOX_CLIPPY_DRIVER
  echo "$(basename "$0"): no clippy-driver (rustup component add clippy); building without lints" >&2
fi
