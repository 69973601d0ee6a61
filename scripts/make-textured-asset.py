#!/usr/bin/env python3
"""Writes scenes/assets/textured_cube.gltf: mirrorbox's own glTF 2.0 test asset (docs/gltf.md).

One self-contained .gltf (buffers and PNG images embedded as base64 data URIs), made to
exercise every glTF path of the contract at once, with textures whose orientation shows:
- a cube, base colour texture "quadrants" (red, green, blue, yellow quarters under a dark
  grid, a white notch in the top-left quarter), one node rotated, scaled and translated;
- the same cube mirrored (a node with scale −1 on x: its winding must be flipped back);
- a tile whose base colour reads "quadrants" through KHR_texture_transform (scale 3,
  rotation 0.3 rad, an offset) and a mirrored-repeat sampler;
- a small emissive panel: emissive factor × an emissive texture of stripes;
- a mirror: a planar rectangle of metallic 1, roughness 0 (mirrorbox makes it a mirror);
- a KHR_lights_punctual point light;
- a perspective camera (for a scene's `camera.gltf`).
Only the Python standard library; run it again to regenerate the same bytes.
"""
import base64
import json
import math
import struct
import zlib
from pathlib import Path


def png(width, height, pixel):
    """An 8-bit RGB PNG, pixel(x, y) -> (r, g, b), row 0 at the top."""
    raw = b"".join(
        b"\x00" + bytes(c for x in range(width) for c in pixel(x, y)) for y in range(height)
    )

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


def quadrants(x, y):
    n = 64
    if x % 8 == 0 or y % 8 == 0:
        return (40, 40, 40)
    if x < 20 and y < 12 and 4 < x and 4 < y:
        return (255, 255, 255)  # the notch: marks the top-left corner (u = 0, v = 0)
    left, top = x < n // 2, y < n // 2
    return {(True, True): (220, 40, 30), (False, True): (40, 190, 60),
            (True, False): (40, 70, 220), (False, False): (235, 210, 40)}[(left, top)]


def stripes(x, y):
    return (255, 240, 200) if (x // 2) % 2 == 0 else (60, 20, 0)


def data_uri(mime, data):
    return f"data:{mime};base64," + base64.b64encode(data).decode()


def main():
    cube_p, cube_uv, cube_i = [], [], []
    faces = [  # (normal axis, sign): each face's four corners counter-clockwise from outside
        ((1, 0, 0), [(1, -1, 1), (1, -1, -1), (1, 1, -1), (1, 1, 1)]),
        ((-1, 0, 0), [(-1, -1, -1), (-1, -1, 1), (-1, 1, 1), (-1, 1, -1)]),
        ((0, 1, 0), [(-1, 1, 1), (1, 1, 1), (1, 1, -1), (-1, 1, -1)]),
        ((0, -1, 0), [(-1, -1, -1), (1, -1, -1), (1, -1, 1), (-1, -1, 1)]),
        ((0, 0, 1), [(-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]),
        ((0, 0, -1), [(1, -1, -1), (-1, -1, -1), (-1, 1, -1), (1, 1, -1)]),
    ]
    for _, corners in faces:
        base = len(cube_p)
        for c in corners:
            cube_p.append(tuple(0.5 * v for v in c))
        cube_uv += [(0, 1), (1, 1), (1, 0), (0, 0)]  # v = 0 at the top edge
        cube_i += [base, base + 1, base + 2, base, base + 2, base + 3]
    quad_p = [(-0.5, 0, 0.5), (0.5, 0, 0.5), (0.5, 0, -0.5), (-0.5, 0, -0.5)]  # facing +y
    quad_uv = [(0, 1), (1, 1), (1, 0), (0, 0)]
    quad_i = [0, 1, 2, 0, 2, 3]
    panel_p = [(-0.5, -0.5, 0), (0.5, -0.5, 0), (0.5, 0.5, 0), (-0.5, 0.5, 0)]  # facing +z

    blob = bytearray()
    views, accessors = [], []

    def add(values, fmt, kind, component, target, minmax=False):
        while len(blob) % 4:
            blob.append(0)
        start = len(blob)
        for v in values:
            blob.extend(struct.pack("<" + fmt, *(v if isinstance(v, tuple) else (v,))))
        views.append({"buffer": 0, "byteOffset": start, "byteLength": len(blob) - start, "target": target})
        acc = {"bufferView": len(views) - 1, "componentType": component, "count": len(values), "type": kind}
        if minmax:
            acc["min"] = [min(v[k] for v in values) for k in range(3)]
            acc["max"] = [max(v[k] for v in values) for k in range(3)]
        accessors.append(acc)
        return len(accessors) - 1

    ARRAY, ELEMENTS, FLOAT, USHORT = 34962, 34963, 5126, 5123
    cp = add(cube_p, "3f", "VEC3", FLOAT, ARRAY, True)
    cu = add(cube_uv, "2f", "VEC2", FLOAT, ARRAY)
    ci = add(cube_i, "H", "SCALAR", USHORT, ELEMENTS)
    qp = add(quad_p, "3f", "VEC3", FLOAT, ARRAY, True)
    qu = add(quad_uv, "2f", "VEC2", FLOAT, ARRAY)
    qi = add(quad_i, "H", "SCALAR", USHORT, ELEMENTS)
    pp = add(panel_p, "3f", "VEC3", FLOAT, ARRAY, True)

    def prim(p, i, material, uv=None):
        attributes = {"POSITION": p}
        if uv is not None:
            attributes["TEXCOORD_0"] = uv
        return {"attributes": attributes, "indices": i, "material": material}

    s, c = math.sin(math.radians(20)), math.cos(math.radians(20))
    gltf = {
        "asset": {"version": "2.0", "generator": "mirrorbox scripts/make-textured-asset.py"},
        "extensionsUsed": ["KHR_texture_transform", "KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1.0, 0.9, 0.8], "intensity": 2.0}]}},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"name": "root", "children": [1, 2, 3, 4, 5, 6, 7], "translation": [0, 0, 0]},
            {"name": "cube", "mesh": 0, "translation": [-0.45, 0.35, -0.2],
             "rotation": [0, s, 0, c], "scale": [0.7, 0.7, 0.7]},
            {"name": "mirrored cube", "mesh": 0, "translation": [0.55, 0.25, 0.35],
             "scale": [-0.5, 0.5, 0.5]},
            {"name": "tile", "mesh": 1, "translation": [0.3, 0.002, -0.6], "scale": [1.2, 1, 0.8]},
            {"name": "panel", "mesh": 2, "translation": [0.0, 0.8, -1.2], "scale": [0.8, 0.3, 1]},
            {"name": "mirror", "mesh": 3, "translation": [1.3, 0.6, -0.4],
             "rotation": [0, -0.7071068, 0, 0.7071068], "scale": [0.9, 1.1, 1]},
            {"name": "light", "translation": [0.0, 1.6, 0.4],
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "camera", "camera": 0, "translation": [0.2, 1.3, 1.9],
             "rotation": [math.sin(math.radians(-12)), 0, 0, math.cos(math.radians(-12))]},
        ],
        "cameras": [{"type": "perspective", "perspective": {
            "yfov": 0.8, "znear": 0.05, "aspectRatio": 1.7777778}}],
        "meshes": [
            {"name": "cube", "primitives": [prim(cp, ci, 0, cu)]},
            {"name": "tile", "primitives": [prim(qp, qi, 1, qu)]},
            {"name": "panel", "primitives": [prim(pp, qi, 2, qu)]},
            {"name": "mirror", "primitives": [prim(pp, qi, 3)]},
        ],
        "materials": [
            {"name": "quadrants", "pbrMetallicRoughness": {
                "baseColorTexture": {"index": 0}, "metallicFactor": 0.0}},
            {"name": "tiled quadrants", "pbrMetallicRoughness": {
                "baseColorFactor": [0.9, 0.9, 0.9, 1.0],
                "baseColorTexture": {"index": 1, "extensions": {"KHR_texture_transform": {
                    "offset": [0.25, 0.1], "rotation": 0.3, "scale": [3.0, 3.0]}}},
                "metallicFactor": 0.0}},
            {"name": "glowing stripes", "pbrMetallicRoughness": {
                "baseColorFactor": [0.2, 0.2, 0.2, 1.0], "metallicFactor": 0.0},
             "emissiveFactor": [1.5, 1.2, 0.8], "emissiveTexture": {"index": 2}},
            {"name": "mirror", "pbrMetallicRoughness": {
                "baseColorFactor": [0.85, 0.85, 0.9, 1.0], "metallicFactor": 1.0,
                "roughnessFactor": 0.0}},
        ],
        "samplers": [{}, {"wrapS": 33648, "wrapT": 33648}, {"wrapS": 33071, "wrapT": 33071}],
        "textures": [{"source": 0, "sampler": 0}, {"source": 0, "sampler": 1},
                     {"source": 1, "sampler": 2}],
        "images": [{"name": "quadrants", "uri": data_uri("image/png", png(64, 64, quadrants))},
                   {"name": "stripes", "uri": data_uri("image/png", png(16, 16, stripes))}],
        "buffers": [{"byteLength": len(blob), "uri": data_uri("application/octet-stream", bytes(blob))}],
        "bufferViews": views,
        "accessors": accessors,
    }
    out = Path(__file__).resolve().parent.parent / "scenes" / "assets" / "textured_cube.gltf"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(gltf, indent=1) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
