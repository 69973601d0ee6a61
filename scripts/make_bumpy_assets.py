#!/usr/bin/env python3
"""Writes the bumpy scenes' assets (committed; rerun only to change them):

- scenes/meshes/checker_light.obj, checker_dark.obj: a 8 x 6 floor checkerboard of
  0.5-unit squares over x in [-2, 2], z in [-2, 1] at y = 0.001 (just above the floor quad
  it is not drawn with: bumpy_single has no floor quad), as two meshes so that each gets
  one albedo.
- scenes/textures/hammered.png: a 256 x 256 tangent-space normal map (8-bit RGB, green =
  +up, periodic so it tiles) of a hammered surface: shallow dents on a jittered grid.
  Normal = normalize(-dh/du, -dh/dv, 1) of the height field h, encoded rgb = (n + 1)/2.

Standard library only (zlib for the PNG).
"""
import math
import os
import random
import struct
import zlib

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def checker():
    for name, parity in (("checker_light", 0), ("checker_dark", 1)):
        verts, faces = [], []
        for i in range(8):
            for j in range(6):
                if (i + j) % 2 != parity:
                    continue
                x0, z0 = -2.0 + 0.5 * i, -2.0 + 0.5 * j
                k = len(verts)
                verts += [(x0, 0.001, z0), (x0, 0.001, z0 + 0.5), (x0 + 0.5, 0.001, z0 + 0.5), (x0 + 0.5, 0.001, z0)]
                faces += [(k + 1, k + 2, k + 3), (k + 1, k + 3, k + 4)]
        with open(os.path.join(ROOT, "scenes", "meshes", name + ".obj"), "w") as f:
            f.write(f"# {name}: half of a floor checkerboard, scripts/make_bumpy_assets.py\n")
            for v in verts:
                f.write("v %g %g %g\n" % v)
            for t in faces:
                f.write("f %d %d %d\n" % t)


def png(path, w, h, rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    data += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(data)


def hammered(n=256, cells=8, seed=7):
    rng = random.Random(seed)
    centres = []
    for i in range(cells):
        for j in range(cells):
            cx = (i + 0.5 + rng.uniform(-0.3, 0.3)) / cells
            cy = (j + 0.5 + rng.uniform(-0.3, 0.3)) / cells
            r = rng.uniform(0.45, 0.7) / cells
            centres.append((cx, cy, r))

    def height(x, y):
        h = 0.0
        for cx, cy, r in centres:
            for ox in (-1, 0, 1):
                for oy in (-1, 0, 1):
                    d2 = (x - cx - ox) ** 2 + (y - cy - oy) ** 2
                    if d2 < r * r:
                        h -= (r * r - d2) / (r * r) * r  # a smooth paraboloid dent
        return h

    e = 0.5 / n
    rows = []
    for j in range(n):
        row = []
        y = (j + 0.5) / n  # row coordinate, down
        for i in range(n):
            x = (i + 0.5) / n
            du = (height(x + e, y) - height(x - e, y)) / (2 * e)
            dv = -(height(x, y + e) - height(x, y - e)) / (2 * e)  # v is up, rows go down
            nx, ny, nz = -du, -dv, 1.0
            l = math.sqrt(nx * nx + ny * ny + nz * nz)
            row += [round((c / l + 1) * 127.5) for c in (nx, ny, nz)]
        rows.append(row)
    png(os.path.join(ROOT, "scenes", "textures", "hammered.png"), n, n, rows)


if __name__ == "__main__":
    checker()
    hammered()
