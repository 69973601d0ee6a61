#!/usr/bin/env bash
# Makes tools/mitsuba/.venv with the pinned Mitsuba 3 (requirements.txt) and, for the fast
# llvm_ad_rgb variant the agreement tests use, installs Debian's libllvm19 (Mitsuba 3.9's JIT
# crashes with LLVM 15) as root, through scripts/lib/apt.sh (waits for the package system's
# locks, at most MIRRORBOX_APT_LOCK_TIMEOUT seconds, default 600, naming who holds them).
# Idempotent; prints what it does. Exits 1 naming what failed when the venv cannot be made or
# libllvm19 is not installed (neither root nor password-less sudo, apt-get's error, a lock
# held too long), unless MIRRORBOX_TEST_SKIP names `mitsuba`: then a warning, exit 0 (the
# Mitsuba tests skip). The venv is marked ready (.venv/.ready, the requirements' hash) only
# when everything is in place, and made again when requirements.txt changes; scripts/test.sh
# hands the tests its Python only when it is marked.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
scripts="$here/../../scripts"
APT_LOG_PREFIX="mitsuba setup"
# shellcheck source=scripts/lib/skip.sh
. "$scripts/lib/skip.sh"
skip_check_list "mitsuba setup"
# shellcheck source=scripts/lib/apt.sh
. "$scripts/lib/apt.sh"

venv="$here/.venv"
ready="$venv/.ready"
# Ends the script: an error (exit 1), or a warning (exit 0) when the user skips Mitsuba; the
# venv is not marked ready either way (the tests must not run on half a setup).
fail() {
  rm -f "$ready"
  if skip_allowed mitsuba; then
    echo "mitsuba setup: warning: $1. MIRRORBOX_TEST_SKIP names mitsuba, so the Mitsuba 3 tests will skip." >&2
    exit 0
  fi
  echo "mitsuba setup: error: $1. To go without the Mitsuba 3 tests instead: MIRRORBOX_TEST_SKIP=mitsuba." >&2
  exit 1
}

pins=$(sha256sum "$here/requirements.txt" | cut -d' ' -f1)
# Made again when the pins change (an existing venv had kept the old versions).
if [ -x "$venv/bin/python" ] && [ "$(cat "$ready" 2>/dev/null)" != "$pins" ]; then
  rm -f "$ready"
  echo "mitsuba setup: $here/requirements.txt is not what $venv was made from: installing it again..."
  "$venv/bin/pip" install -q --disable-pip-version-check -r "$here/requirements.txt" ||
    fail "\`pip install -r $here/requirements.txt\` failed (its message is above; it needs PyPI)"
fi
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c 'import mitsuba' 2>/dev/null; then
  command -v python3 >/dev/null || fail "python3 is not installed (Debian: apt-get install python3 python3-venv)"
  echo "mitsuba setup: creating $venv with $(python3 --version) and pinned requirements..."
  python3 -m venv "$venv" ||
    fail "\`python3 -m venv $venv\` failed (Debian: apt-get install python3-venv)"
  "$venv/bin/pip" install -q --disable-pip-version-check -r "$here/requirements.txt" ||
    fail "\`pip install -r $here/requirements.txt\` failed (its message is above; it needs PyPI)"
fi

llvm=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
if [ ! -e "$llvm" ]; then
  if ! command -v apt-get >/dev/null; then
    fail "$llvm (Debian's libllvm19) is missing and there is no apt-get here: install LLVM 19's shared library"
  elif [ "$(id -u)" -ne 0 ]; then
    # As scripts/install-system-deps.sh: through sudo where it needs no password.
    if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
      APT_SUDO=(sudo)
    else
      fail "$llvm (Debian's libllvm19) is missing, and installing it needs root or password-less sudo: run tools/mitsuba/setup.sh as root"
    fi
  fi
  echo "mitsuba setup: installing libllvm19 with apt-get (for the llvm_ad_rgb variant)..."
  rc=0
  apt_get install -y -qq --no-install-recommends libllvm19 >/dev/null || rc=$?
  if [ "$rc" -ne 0 ] && [ "$rc" -ne "$APT_LOCK_TIMED_OUT" ]; then
    # Perhaps only stale package lists: update them and try again.
    echo "mitsuba setup: apt-get install failed; apt-get update, then once more..."
    rc=0
    apt_get -qq update >/dev/null || rc=$?
    if [ "$rc" -ne "$APT_LOCK_TIMED_OUT" ]; then
      [ "$rc" -eq 0 ] || echo "mitsuba setup: warning: $APT_ERROR; trying the lists already here." >&2
      rc=0
      apt_get install -y -qq --no-install-recommends libllvm19 >/dev/null || rc=$?
    fi
  fi
  [ -e "$llvm" ] ||
    fail "libllvm19 is not installed ($llvm is missing): ${APT_ERROR:-apt-get reported success, but the library is not there}"
  echo "mitsuba setup: libllvm19 installed."
fi
version=$("$venv/bin/python" -c 'import mitsuba; print("mitsuba", mitsuba.__version__)') ||
  fail "$venv/bin/python cannot import mitsuba (its message is above); delete $venv to make it again"
# The version the pins name, not only one that imports.
pinned=$(sed -n 's/^mitsuba==//p' "$here/requirements.txt")
[ "$version" = "mitsuba $pinned" ] ||
  fail "$venv has $version, requirements.txt pins $pinned; delete $venv to make it again"
printf '%s\n' "$pins" > "$ready"
echo "mitsuba setup: ready ($version, $llvm)."
