#!/usr/bin/env python3
"""Loads that no store forwarding can serve, weighted by where a `perf record` spent its time.

A load that reads bytes written by a recent store is normally served from the store queue
("store-to-load forwarding"); when the load is not contained in one store — it spans two
stores, or is wider than the store — the processor waits for the stores to retire first
(on AMD Zen 3 and Intel cores alike, a stall of tens of cycles). Compilers make these when
they copy a small struct as one 16-byte and one 8-byte move and then read a 12-byte
field across the two (issue 56's thirteenth session: `path`'s vertex, 7 % of its time on
one instruction).

Here every sampled instruction of BIN that loads from `[base+off]` or `[base+index*scale+off]`
is checked against the stores to the same registers in the instructions before it (up to --window, in address
order, within the function): a store that overlaps the load without containing it is
reported, with the samples on the load and on the instruction after it (where `perf`'s
sample often lands), as a share of all samples. Static, so a candidate needs a look at its
disassembly: the store may be on another path through a branch.

Usage: scripts/store-forwarding.py PERF_DATA BIN [--top N] [--window N] [--min-share PCT]
  PERF_DATA from `perf record` of BIN (as scripts/profile-tracer.sh records one).
"""

import argparse
import collections
import importlib.util
import os
import re
import subprocess
import sys

SIZES = {"BYTE": 1, "WORD": 2, "DWORD": 4, "QWORD": 8, "XMMWORD": 16, "YMMWORD": 32, "ZMMWORD": 64}
MEM = re.compile(r"(BYTE|WORD|DWORD|QWORD|XMMWORD|YMMWORD|ZMMWORD) PTR \[(\w+(?:[+]\w+\*\d)?)([+-]0x[0-9a-f]+)?\]")
# Instructions whose first operand, when memory, is written without being read.
STORES = re.compile(r"^(v?mov\w*|v?extract\w*|v?pextr\w*|v?cvt\w*2\w*|v?movnt\w*)$")


def profile_lines():
    here = os.path.dirname(os.path.abspath(__file__))
    spec = importlib.util.spec_from_file_location("profile_lines", os.path.join(here, "profile-lines.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def disassemble(binary, start, stop):
    """(address, mnemonic, operands) of the instructions in [start, stop)."""
    out = subprocess.run(
        ["objdump", "-d", "-M", "intel", "--no-show-raw-insn", f"--start-address={start:#x}",
         f"--stop-address={stop:#x}", binary],
        capture_output=True, text=True, check=True,
    ).stdout
    rows = []
    for line in out.splitlines():
        m = re.match(r"^\s*([0-9a-f]+):\s+(\S+)\s*(.*)$", line)
        if m:
            rows.append((int(m.group(1), 16), m.group(2), m.group(3)))
    return rows


def access(mnemonic, operands):
    """('load' | 'store', base, offset, size) of an instruction's stack or memory operand."""
    m = MEM.search(operands)
    if not m or mnemonic.startswith("lea"):
        return None
    size = SIZES[m.group(1)]
    base = m.group(2)
    offset = int(m.group(3), 16) if m.group(3) else 0
    first = operands.split(",")[0]
    if MEM.search(first) and STORES.match(mnemonic):
        return ("store", base, offset, size)
    if MEM.search(first) and not STORES.match(mnemonic):
        return None  # read-modify-write or a compare: left out
    return ("load", base, offset, size)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("perf_data")
    parser.add_argument("binary")
    parser.add_argument("--top", type=int, default=20)
    parser.add_argument("--window", type=int, default=48, help="instructions looked back")
    parser.add_argument("--min-share", type=float, default=0.05, help="percent of samples")
    args = parser.parse_args()
    binary = os.path.realpath(args.binary)
    pl = profile_lines()
    counts, total = pl.samples(args.perf_data, binary)
    if total == 0:
        sys.exit("no samples")
    hot = [a for a, n in counts.items() if 100.0 * n / total >= args.min_share / 4]
    found = []
    seen = set()
    for address in sorted(hot, key=lambda a: -counts[a]):
        rows = disassemble(binary, max(0, address - 16 * args.window), address + 32)
        at = next((i for i, r in enumerate(rows) if r[0] == address), None)
        if at is None:
            continue
        # The sample lands on the stalled load or the instruction after it.
        for load_at in (at, at - 1):
            if load_at < 0:
                continue
            a, mnemonic, operands = rows[load_at]
            acc = access(mnemonic, operands)
            if not acc or acc[0] != "load" or a in seen:
                continue
            _, base, offset, size = acc
            for b, m2, o2 in reversed(rows[max(0, load_at - args.window):load_at]):
                st = access(m2, o2)
                if not st or st[0] != "store" or st[1] != base:
                    continue
                s_off, s_size = st[2], st[3]
                overlaps = s_off < offset + size and offset < s_off + s_size
                contains = s_off <= offset and offset + size <= s_off + s_size
                if overlaps and not contains:
                    weight = counts[a] + (counts[rows[load_at + 1][0]] if load_at + 1 < len(rows) else 0)
                    found.append((weight, a, f"{mnemonic} {operands}", b, f"{m2} {o2}"))
                    seen.add(a)
                    break
                if contains:
                    break
    found.sort(reverse=True)
    shown = [f for f in found if 100.0 * f[0] / total >= args.min_share][: args.top]
    print(f"# {total} samples; loads from [reg+off] partly covered by an earlier store (no forwarding)")
    frames = pl.frames(binary, [f[1] for f in shown]) if shown else {}
    for weight, a, load, b, store in shown:
        where = frames.get(a)
        where = str(where[0]) if where else "?"
        print(f"{100.0 * weight / total:6.2f} %  {a:#x}  {load}\n          after {b:#x}  {store}\n          {where}")


if __name__ == "__main__":
    main()
