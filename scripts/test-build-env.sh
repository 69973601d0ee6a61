# Sourced by scripts/test.sh and scripts/test-times.sh: the environment of the one test
# build, so that both use (and neither rebuilds) the same artifacts.
# - clippy's lints run inside the build: clippy-driver is the compiler of the workspace's own
#   crates (what `cargo clippy` does, with code generation), `-D warnings` passed the way
#   cargo-clippy passes it;
# - no incremental compilation: a fresh clone's build has nothing to reuse;
# - Mesa's device-select layer quiet on headless machines.
export NODEVICE_SELECT=1
export CARGO_INCREMENTAL=${CARGO_INCREMENTAL:-0}
clippy_driver=$(rustup which clippy-driver 2>/dev/null || command -v clippy-driver || true)
if [ -n "$clippy_driver" ]; then
  export RUSTC_WORKSPACE_WRAPPER="$clippy_driver"
  export CLIPPY_ARGS="-D__CLIPPY_HACKERY__warnings__CLIPPY_HACKERY__"
else
  echo "$(basename "$0"): no clippy-driver (rustup component add clippy); building without lints" >&2
fi
