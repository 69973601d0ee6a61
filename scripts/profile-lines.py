#!/usr/bin/env python3
"""Where a `perf record` of mirrorbox spent its samples, by mirrorbox's own source lines.

`perf report --sort srcline` charges an inlined instruction to its innermost frame: the
tracer's walks are one function with everything inlined, so most samples land on the
standard library's `range.rs`, `arith.rs` or `index.rs` and say little. Here each sampled
address is resolved with all its inlined frames (`addr2line -i`), and charged to

- the innermost frame in mirrorbox's crates (`crates/…`): "lines" and "files";
- the outermost frame in FILE (default: the integrators' `whitted.rs` and `path.rs`), and
  the one inside it: "call sites" — which call of the walk (the query, the bounce, the
  shading, …) the sample is under.

Usage: scripts/profile-lines.py PERF_DATA BIN [--top N] [--site-file NAME ...]
  PERF_DATA from `perf record` (no call graph needed) of BIN. See scripts/profile-lines.sh.
"""

import argparse
import collections
import functools
import os
import re
import subprocess
import sys


def load_segments(binary):
    """The ELF LOAD segments: (file offset, virtual address, file size)."""
    out = subprocess.run(["readelf", "-lW", binary], capture_output=True, text=True, check=True).stdout
    segments = []
    for line in out.splitlines():
        fields = line.split()
        if fields and fields[0] == "LOAD":
            offset, vaddr, filesz = (int(fields[i], 16) for i in (1, 2, 4))
            segments.append((offset, vaddr, filesz))
    return segments


def samples(perf_data, binary):
    """Each sample's address in `binary`'s own numbering (the one addr2line reads), counted."""
    script = subprocess.run(
        ["perf", "script", "-i", perf_data, "-F", "ip,dso", "--show-mmap-events"],
        capture_output=True, text=True, check=True,
    ).stdout
    maps = []
    counts = collections.Counter()
    total = 0
    mmap = re.compile(r"\[(0x[0-9a-f]+)\((0x[0-9a-f]+)\) @ (0x[0-9a-f]+|0) .*\]: \S+ (\S+)$")
    for line in script.splitlines():
        if "PERF_RECORD_MMAP" in line:
            m = mmap.search(line)
            if m and m.group(4) == binary:
                maps.append((int(m.group(1), 16), int(m.group(2), 16), int(m.group(3), 16)))
            continue
        fields = line.split()
        if len(fields) < 2:
            continue
        total += 1
        if fields[1] != f"({binary})":
            continue
        ip = int(fields[0], 16)
        for start, length, pgoff in maps:
            if start <= ip < start + length:
                counts[(ip - start + pgoff)] += 1
                break
    segments = load_segments(binary)
    resolved = collections.Counter()
    for file_offset, n in counts.items():
        for offset, vaddr, filesz in segments:
            if offset <= file_offset < offset + filesz:
                resolved[vaddr + file_offset - offset] += n
                break
    return resolved, total


def frames(binary, addresses):
    """Per address, its frames innermost first (`path:line`)."""
    out = subprocess.run(
        ["addr2line", "-e", binary, "-i", "-a"] + [hex(a) for a in addresses],
        capture_output=True, text=True, check=True,
    ).stdout
    result, current = {}, None
    for line in out.splitlines():
        if line.startswith("0x"):
            current = int(line, 16)
            result[current] = []
        elif current is not None:
            result[current].append(line.split(" ")[0])
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("perf_data")
    parser.add_argument("binary")
    parser.add_argument("--top", type=int, default=30)
    parser.add_argument("--site-file", action="append", default=None)
    args = parser.parse_args()
    site_files = tuple(args.site_file or ["whitted.rs", "path.rs"])
    for path, what in ((args.perf_data, "perf data"), (args.binary, "binary")):
        if not os.path.isfile(path):
            print(f"profile-lines: no {what} file '{path}'", file=sys.stderr)
            sys.exit(2)
    if args.top < 1:
        print(f"profile-lines: --top must be at least 1, not {args.top}", file=sys.stderr)
        sys.exit(2)
    binary = os.path.realpath(args.binary)  # perf names the binary by its absolute path
    counts, total = samples(args.perf_data, binary)
    if not counts:
        print(f"profile-lines: no samples of {binary} in {args.perf_data}", file=sys.stderr)
        sys.exit(2)
    ours_total = sum(counts.values())
    # Our crates' files: paths under this checkout's crates/ (addr2line gives full paths; the
    # standard library's are under /rustc/…, dependencies' under the cargo registry).
    crates = os.path.join(os.path.dirname(os.path.dirname(os.path.realpath(__file__))), "crates") + "/"

    def short(frame):
        path, _, line = frame.rpartition(":")
        return (path[len(crates):] if path.startswith(crates) else path.rsplit("/", 1)[-1]) + ":" + line

    def is_ours(frame):
        return frame.startswith(crates)

    def in_site(frame):
        return is_ours(frame) and frame.rpartition(":")[0].rsplit("/", 1)[-1] in site_files

    by_line, by_file, by_site = collections.Counter(), collections.Counter(), collections.Counter()
    addresses = sorted(counts)
    resolved = {}
    for i in range(0, len(addresses), 2000):
        resolved.update(frames(binary, addresses[i : i + 2000]))
    for address, n in counts.items():
        stack = resolved.get(address) or ["??:0"]
        own = short(next((f for f in stack if is_ours(f)), stack[0]))
        by_line[own] += n
        by_file[own.rpartition(":")[0]] += n
        sites = [short(f) for f in stack if in_site(f)]
        site = sites[-2] if len(sites) > 1 else (sites[0] if sites else "(outside " + "/".join(site_files) + ")")
        by_site[site] += n
    print(f"# {total} samples; {ours_total} in {binary} ({100 * ours_total / total:.1f} %); shares below are of all samples")

    @functools.cache
    def source_lines(path):
        try:
            with open(crates + path, encoding="utf-8") as source:
                return source.read().splitlines()
        except OSError:
            return []

    def text(key):
        """The source line itself, where `key` is `crates/`-relative `path:line`."""
        path, _, line = key.rpartition(":")
        lines = source_lines(path)
        return " ".join(lines[int(line) - 1].split())[:70] if line.isdigit() and 0 < int(line) <= len(lines) else ""

    site_title = "call sites (the frame inside the outermost one in " + "/".join(site_files) + ")"
    for title, table, top, with_text in (("files", by_file, 15, False),
                                         ("lines (innermost in crates/)", by_line, args.top, True),
                                         (site_title, by_site, args.top, True)):
        print(f"\n## {title}")
        for key, n in table.most_common(top):
            shown = f"{key:45s} {text(key)}" if with_text else key
            print(f"{100 * n / total:6.2f} %  {shown}".rstrip())


if __name__ == "__main__":
    main()
