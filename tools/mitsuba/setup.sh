#!/usr/bin/env bash
# Makes tools/mitsuba/.venv with the pinned Mitsuba 3 (requirements.txt) and, for the fast
# llvm_ad_rgb variant, installs Debian's libllvm19 (Mitsuba 3.9's JIT crashes with LLVM 15).
# Idempotent; prints what it does. Exits non-zero only if the venv cannot be made.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="$here/.venv"
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c 'import mitsuba' 2>/dev/null; then
  echo "mitsuba setup: creating $venv with $(python3 --version) and pinned requirements..."
  python3 -m venv "$venv"
  "$venv/bin/pip" install -q --disable-pip-version-check -r "$here/requirements.txt"
fi
llvm=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
if [ ! -e "$llvm" ] && command -v apt-get >/dev/null && [ "$(id -u)" -eq 0 ]; then
  echo "mitsuba setup: installing libllvm19 with apt-get (for the llvm_ad_rgb variant)..."
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends libllvm19 >/dev/null ||
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends libllvm19 >/dev/null; } ||
    echo "mitsuba setup: could not install libllvm19; only scalar_rgb will work." >&2
fi
echo "mitsuba setup: ready ($("$venv/bin/python" -c 'import mitsuba; print("mitsuba", mitsuba.__version__)'))."
