#!/usr/bin/env bash
# The AVX2 masked stores (`vmaskmovps`/`vmaskmovpd`/`vpmaskmovd`/`vpmaskmovq` to memory) in
# mirrorbox's own code of one build: AMD's Zen 1–3 run them as microcode, and LLVM 22 makes
# them from a lane loop's select written back in place (docs/tracer-performance.md, issue 56's
# eighth session; `mirrorbox_scene::lanes::store_unmasked`). Lists each with its source line
# and exits 1 if there is any; the dependencies' (a viewer crate has four) are not counted.
#
# Usage: scripts/check-masked-stores.sh [BIN]   (default: target/release/mirrorbox, built
#   here when BIN is not given). Needs objdump and addr2line (binutils), and a build with
#   line tables (the release profile has them).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -gt 1 ]; then
  echo "usage: $0 [BIN]" >&2
  exit 2
fi
bin=${1:-}
if [ -z "$bin" ]; then
  # A measured build is a plain one (scripts/test-build-env.sh's wrapper changes the code).
  (unset RUSTC_WORKSPACE_WRAPPER CLIPPY_ARGS; cargo build --release --locked -p mirrorbox >&2)
  bin=target/release/mirrorbox
fi
[ -f "$bin" ] || { echo "no binary $bin" >&2; exit 2; }
for tool in objdump addr2line; do
  command -v "$tool" > /dev/null || { echo "$tool is not installed (apt install binutils)" >&2; exit 2; }
done
addresses=$(objdump -d --no-show-raw-insn "$bin" |
  grep -E 'v(p)?maskmov(ps|pd|d|q) +%ymm[0-9]+,%ymm[0-9]+,|v(p)?maskmov(ps|pd|d|q) +%xmm[0-9]+,%xmm[0-9]+,' |
  awk '{ sub(":", "", $1); print "0x" $1 }' || true)
if [ -z "$addresses" ]; then
  echo "$bin: no masked stores"
  exit 0
fi
# The innermost source line of each (inlined code names the function it was written in).
ours=$(addr2line -e "$bin" $addresses | grep -E '/crates/[^/]+/src/' || true)
total=$(echo "$addresses" | wc -w)
if [ -z "$ours" ]; then
  echo "$bin: $total masked stores, none in mirrorbox's crates"
  exit 0
fi
echo "$bin: masked stores in mirrorbox's crates (count, source line):"
echo "$ours" | sed 's|.*/crates/|crates/|' | sort | uniq -c | sort -rn
exit 1
