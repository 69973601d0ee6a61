#!/usr/bin/env bash
# The test command (README): installs missing system packages, then checks formatting,
# lints and runs every test of the workspace (unit tests beside the code, end-to-end tests
# in tests/, the local Slurm test when root) and checks the cluster files of deploy/. Exits
# non-zero on any failure. Each step prints how long it took, and the total is printed last
# and written to target/test-timing.json: the figure for the machine it ran on, measured,
# not quoted (docs/budgets.md says where the time goes).
#
# Compiled once: clippy's lints run inside the test build itself (clippy-driver as the
# compiler of the workspace's own crates, which is what `cargo clippy` does, but with code
# generation), so no crate is compiled twice. `cargo clippy --workspace --all-targets -- -D
# warnings` reports the same lints.
#
# MIRRORBOX_TEST_SKIP (scripts/lib/skip.sh; CI sets none): the components the user agrees to
# go without (corpus, xvfb, xdotool, slurm, mitsuba, chromium, raytracing, web). The install steps
# fail on a component they cannot install unless it is listed; a test that skips appends
# `<component>\t<test name>\t<reason>` to $MIRRORBOX_SKIP_LOG (target/test-skips.tsv, emptied
# here). The end lists every skip with its reason, records them in target/test-timing.json
# ("skipped"), and fails when a test skipped a component the list does not name: that is a
# bug in the test.
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=scripts/lib/skip.sh
. scripts/lib/skip.sh
skip_check_list test
mkdir -p target
export MIRRORBOX_SKIP_LOG="$PWD/target/test-skips.tsv"
: >"$MIRRORBOX_SKIP_LOG"
echo "== MIRRORBOX_TEST_SKIP: $(skip_listed) (the components agreed to be skipped; a skip is logged to target/test-skips.tsv)"
# Whether cargo had to download the crates: a fresh machine's cost is with an empty cache
# (issue 51); recorded beside the times.
if [ -n "$(ls -A "${CARGO_HOME:-$HOME/.cargo}/registry/cache" 2>/dev/null)" ]; then
  cargo_cache=warm
else
  cargo_cache=empty
fi
steps_json=""
timed() {
  echo "== $*"
  local started=$SECONDS
  "$@"
  local took=$((SECONDS - started))
  echo "== done in $took s: $*"
  local name="$*"
  steps_json+="${steps_json:+,}{\"name\":\"${name//\"/\'}\",\"seconds\":$took}"
}
# What the build needs (compilers, headers, Vulkan's loader) comes first, alone.
timed scripts/install-system-deps.sh
# What only the tests need is installed while the build compiles, one step after another in
# the background (the apt steps never wait on each other's lock; the downloads wait on the
# network, not the cores): 20-30 s of a fresh clone's wall time (docs/budgets.md). Their
# output goes to target/test-setup.log, printed after the build; a failing step fails this
# script there, before any test runs.
# - Mitsuba 3 for the agreement tests (tests/mitsuba.rs): a pinned venv, libllvm19 via apt;
# - the web clients of the exchange (clients/web: three.js in headless Chromium) for
#   tests/exchange.rs: pinned npm packages, installed by `npm ci` (exits 1 unless
#   MIRRORBOX_TEST_SKIP names web);
# - Slurm and munge for the sharded-sweep test on a local one-node Slurm (tests/slurm.rs,
#   root; not root: exits 1 unless MIRRORBOX_TEST_SKIP names slurm);
# - the cluster files: Slurm scripts parse, the Kubernetes manifest validates.
setup_log=target/test-setup.log
setup_steps=target/test-setup-steps.json
: >"$setup_steps"
(
  for step in tools/mitsuba/setup.sh scripts/install-web-clients.sh \
    "scripts/slurm-local.sh install" scripts/check-deploy.sh; do
    echo "== $step"
    started=$SECONDS
    # shellcheck disable=SC2086 # a step is a script and its words
    $step
    echo "== done in $((SECONDS - started)) s: $step"
    printf '%s{"name":"%s","seconds":%s,"during_build":true}' "$([ -s "$setup_steps" ] && echo ,)" "$step" \
      "$((SECONDS - started))" >>"$setup_steps"
  done
) >"$setup_log" 2>&1 &
setup_pid=$!
# Waits for the background steps, prints what they wrote, and fails on the first that failed.
finish_setup() {
  local rc=0
  wait "$setup_pid" || rc=$?
  setup_pid=""
  echo "== the tests' own set-up, run during the build ($setup_log):"
  cat "$setup_log"
  steps_json+="${steps_json:+,}$(cat "$setup_steps")"
  if [ "$rc" -ne 0 ]; then
    echo "== ERROR: a set-up step above failed (exit $rc)" >&2
    exit "$rc"
  fi
  # Only a Mitsuba set-up that finished (skipped with MIRRORBOX_TEST_SKIP=mitsuba, it is not
  # marked ready and the tests skip, rather than fail on half a venv).
  if [ -f tools/mitsuba/.venv/.ready ]; then
    export MIRRORBOX_MITSUBA_PYTHON="$PWD/tools/mitsuba/.venv/bin/python"
  fi
}

# JSON string contents: backslashes, quotes and control characters escaped.
json_escape() {
  local s=$1
  s=${s//\\/\\\\}
  s=${s//\"/\\\"}
  s=${s//$'\t'/\\t}
  s=${s//$'\r'/\\r}
  printf '%s' "$s" | tr -d '\000-\010\013-\037'
}
# The skips the tests logged (collect_skips): skips_json for target/test-timing.json, the
# summary's lines, and in skip_bugs the skips MIRRORBOX_TEST_SKIP did not agree to (or lines
# that are not `<component>\t<test name>\t<reason>`). print_skips prints the summary.
skips_json=""
skip_lines=()
skip_bugs=0
skips_printed=""
collect_skips() {
  skips_json=""
  skip_lines=()
  skip_bugs=0
  local line component test reason agreed
  [ -f "$MIRRORBOX_SKIP_LOG" ] || return 0
  while IFS= read -r line || [ -n "$line" ]; do
    [ -n "$line" ] || continue
    if [[ $line == *$'\t'*$'\t'* ]]; then
      component=${line%%$'\t'*}
      test=${line#*$'\t'}
      reason=${test#*$'\t'}
      test=${test%%$'\t'*}
    else
      component=$line test="" reason=""
    fi
    agreed=true
    if [ -z "$test" ] || [ -z "$reason" ] || ! skip_allowed "$component"; then
      agreed=false
      skip_bugs=$((skip_bugs + 1))
      skip_lines+=("NOT AGREED: ${line//$'\t'/ | }")
    else
      skip_lines+=("$component: $test: $reason")
    fi
    skips_json+="${skips_json:+,}{\"component\":\"$(json_escape "$component")\",\"test\":\"$(json_escape "$test")\",\"reason\":\"$(json_escape "$reason")\",\"agreed\":$agreed}"
  done <"$MIRRORBOX_SKIP_LOG"
}
print_skips() {
  skips_printed=yes
  echo "== skipped tests (target/test-skips.tsv; MIRRORBOX_TEST_SKIP: $(skip_listed)):"
  if [ ${#skip_lines[@]} -eq 0 ]; then
    echo "==   no test skipped"
  else
    printf '==   %s\n' "${skip_lines[@]}"
  fi
  if [ "$skip_bugs" -gt 0 ]; then
    {
      echo "== ERROR: $skip_bugs skip(s) above marked NOT AGREED: a test skipped a component that MIRRORBOX_TEST_SKIP ($(skip_listed)) does not name, or wrote a line that is not <component> TAB <test name> TAB <reason>."
      [ -n "$(skip_names)" ] || echo "== ERROR: MIRRORBOX_TEST_SKIP is empty, so no test may skip at all."
      echo "== ERROR: that is a bug in the test that wrote it: a test may skip only a component the user named in MIRRORBOX_TEST_SKIP, and must fail otherwise."
    } >&2
  fi
}
# A failing step ends the script early: the skips logged so far are still listed.
on_exit() {
  local rc=$?
  # The background set-up is never cut off mid-install: a failing build (or format check)
  # waits for it, says so, and shows how it ended.
  if [ -n "${setup_pid:-}" ]; then
    echo "== waiting for the tests' set-up to finish ($setup_log) before exiting" >&2
    local setup_rc=0
    wait "$setup_pid" 2>/dev/null || setup_rc=$?
    tail -n 20 "$setup_log" >&2 || true
    echo "== the set-up exited $setup_rc" >&2
  fi
  if [ -z "$skips_printed" ]; then
    collect_skips || true
    print_skips || true
  fi
  exit "$rc"
}
trap on_exit EXIT

timed cargo fmt --all -- --check
. scripts/test-build-env.sh
# Every target (benches included) built and linted; then every test run. The workspace has
# no doc tests, so rustdoc is not asked to look for them. --timings: where the build's time
# goes, per crate (target/cargo-timings/cargo-timing.html).
timed cargo test --workspace --locked --all-targets --no-run --timings
finish_setup
# The tests check images, not times: they keep Mesa's on-disk shader cache, which the commands
# that time frames turn off (issue 54, docs/budgets.md). With it off the suite compiled every
# shader in every process: 335 s of tests instead of 148 s here.
export MESA_SHADER_CACHE_DISABLE=false
# cargo-nextest, where installed (it is on the project's machines), schedules every test of
# every binary in one pool: the long tests (the scene fuzz) overlap the other binaries'
# instead of running after them (docs/budgets.md, measured). Otherwise cargo's own runner.
if cargo nextest --version >/dev/null 2>&1; then
  timed cargo nextest run --workspace --locked --no-fail-fast --lib --bins --tests
else
  timed cargo test --workspace --locked --no-fail-fast --lib --bins --tests
fi
collect_skips
cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//; s/"/'"'"'/g')
# The vector width names the machine kind where the model name does not (two "AMD EPYC"
# machines here built the same tree in 394 s and 627 s: docs/budgets.md).
if grep -qw avx512f /proc/cpuinfo; then cpu="$cpu (AVX-512)"; elif grep -qw avx2 /proc/cpuinfo; then cpu="$cpu (AVX2)"; fi
mkdir -p target
printf '{"date":"%s","cpu":"%s, %s cores","cargo_cache":"%s","seconds":%s,"steps":[%s],"test_skip":"%s","skipped":[%s]}\n' \
  "$(date -u +%Y-%m-%dT%H:%M:%SZ)" "$cpu" "$(nproc)" "$cargo_cache" "$SECONDS" "$steps_json" \
  "$(json_escape "${MIRRORBOX_TEST_SKIP:-}")" "$skips_json" >target/test-timing.json
echo "== tests done in $SECONDS s on $cpu, $(nproc) cores"
print_skips
if [ "$skip_bugs" -gt 0 ]; then
  echo "== tests FAILED: $skip_bugs skip(s) without MIRRORBOX_TEST_SKIP's agreement (listed above)" >&2
  exit 1
fi
