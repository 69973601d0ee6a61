#!/usr/bin/env python3
"""Writes a scene of N small mirror facets (issue 51, "many mirrors at linear cost").

Seed 002 names many mirrors as the mirror camera's limit: a disco ball or a mirror facade
has thousands of facets. This script makes such scenes, deterministically (seeded), so that
scripts/bench-many-mirrors.sh can time `check`, `trace` and `render` against N:

- `--shape wall` (default): a mirror facade, a grid of facets on the plane z = -2
  (x in [-2, 2], y in [0, 3], 4:3 like the bundled mirror box's mirrors), each facet
  tilted by a small random angle (at most `--tilt-deg`, default 3) like a hammered mirror,
  with a dark grout quad behind the grid, a floor, a red box, a blue sphere, a wall behind
  the camera and one point light, so that every facet reflects something.
- `--shape sphere`: a disco ball of radius 0.5 at (0, 1.6, 0), its N facets on rings of
  latitude (as many per ring as its circumference holds), each facing outwards, in a
  6 x 3 x 6 room of diffuse walls (each wall its own colour) with a box, a sphere and one
  point light.
- `--coincident`: the degenerate case: the N facets all at the same place (one facet, the
  same N times): for the wall a 0.8 x 0.6 mirror at the wall's centre facing +z, for the
  sphere a facet of the ball's front facing the camera.
- `--normal-map [PATH]`: every facet gets the same `bump.normal_map` (PATH, default the
  bundled scenes/textures/hammered.png; strength `--normal-map-strength`, default 0.05,
  tiling 1 x 1). The scene format resolves the path against the scene file's folder
  (docs/scene-format.md), so the script writes PATH relative to the folder of `-o`, whatever
  that folder is.

The scene format's limits that bear on it (crates/scene/src/limits.rs, docs/scene-format.md):
there is no limit on the number of mirrors as such; each mirror is two triangles and a scene
holds at most 4 194 304 (2^22) triangles, objects and mirrors together (this script's
objects are under 1 300, so the triangle limit alone would allow ~2 M facets); every
position within +-10^6 units; image sides 1..16384 and at most 8192^2 pixels; and the scene
file at most 16 MiB (16 777 216 bytes). The file size is the limit that bites: a facet takes
about 145 bytes here (about 240 with a normal map, depending on the length of its relative
path), so at most about 116 000 facets fit (about 70 000 with a normal map). `--count` is validated to 1..200000; a scene that would
exceed 16 MiB is refused (exit 2) before anything is written. Normal maps: a PNG of at most
4096 texels a side (the bundled one is 256 x 256).

Usage:
  scripts/make_mirror_mosaic.py --count N [--shape wall|sphere] [--coincident]
      [--normal-map [PATH]] [--normal-map-strength S] [--tilt-deg D] [--seed S]
      [--width W] [--height H] -o OUT.json

Standard library only. Exit 2 on a bad argument.
"""
import argparse
import json
import math
import os
import random
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
HAMMERED = os.path.join(ROOT, "scenes", "textures", "hammered.png")

MAX_COUNT = 200_000
MAX_SCENE_FILE_BYTES = 16 << 20  # crates/scene/src/limits.rs
MAX_IMAGE_SIDE = 16384
MAX_PIXELS = 1 << 26
REFLECTANCE = [0.9, 0.9, 0.9]
FILL = 0.9  # a facet's side over its pitch: the rest is grout


def fail(msg):
    print(f"make_mirror_mosaic.py: error: {msg}", file=sys.stderr)
    sys.exit(2)


def num(x, digits=5):
    """A short decimal: enough for facets of 0.01 units on a 4-unit wall, and no "-0"."""
    s = f"{x:.{digits}f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def vec(v, digits=5):
    return "[" + ",".join(num(c, digits) for c in v) + "]"


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


# --- layouts: lists of (center, normal, up, width, height) -----------------------------------

def wall_facets(n, tilt_deg, rng):
    """A cols x rows grid over x in [-2, 2], y in [0, 3], filled row by row from the top; a
    last, partial row is centred. Each facet's normal is +z tilted by an angle uniform in
    [0, tilt_deg] towards a uniformly random direction."""
    w, h, z = 4.0, 3.0, -2.0
    cols = max(1, round(math.sqrt(n * w / h)))
    rows = math.ceil(n / cols)
    pitch = min(w / cols, h / rows)
    x0 = -cols * pitch / 2
    y0 = 1.5 + rows * pitch / 2  # the top edge; the grid is centred on the wall
    facets = []
    for k in range(n):
        r, c = divmod(k, cols)
        in_row = min(cols, n - r * cols)
        shift = (cols - in_row) * pitch / 2
        cx = x0 + shift + (c + 0.5) * pitch
        cy = y0 - (r + 0.5) * pitch
        t = math.radians(rng.uniform(0.0, tilt_deg))
        p = rng.uniform(0.0, 2 * math.pi)
        normal = [math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)]
        facets.append(([cx, cy, z], normal, [0.0, 1.0, 0.0], pitch * FILL, pitch * FILL))
    return facets


def apportion(n, weights):
    """n split over the weights, at least one each (n >= len(weights)), largest remainders."""
    k = len(weights)
    total = sum(weights)
    quotas = [(n - k) * wt / total for wt in weights]
    counts = [1 + int(q) for q in quotas]
    rest = n - sum(counts)
    order = sorted(range(k), key=lambda i: (-(quotas[i] - int(quotas[i])), i))
    for i in order[:rest]:
        counts[i] += 1
    return counts


def ball_facets(n, centre, radius, rng):
    """Rings of latitude, as many as make the facets about square (sqrt(pi N)/2), each ring's
    share of N proportional to its circumference; each ring turned by a random offset."""
    rings = max(1, min(n, round(math.sqrt(math.pi * n) / 2)))
    lats = [-math.pi / 2 + (i + 0.5) * math.pi / rings for i in range(rings)]
    counts = apportion(n, [math.cos(a) for a in lats])
    band = math.pi * radius / rings
    facets = []
    for lat, count in zip(lats, counts):
        offset = rng.uniform(0.0, 2 * math.pi)
        width = 2 * math.pi * radius * math.cos(lat) / count
        for j in range(count):
            lon = offset + 2 * math.pi * j / count
            normal = [math.cos(lat) * math.cos(lon), math.sin(lat), math.cos(lat) * math.sin(lon)]
            up = [-math.sin(lat) * math.cos(lon), math.cos(lat), -math.sin(lat) * math.sin(lon)]
            centre_j = [centre[i] + radius * normal[i] for i in range(3)]
            facets.append((centre_j, normal, up, min(width, band) * FILL, band * FILL))
    return facets


# --- the settings around the facets ----------------------------------------------------------

def quad(name, size, translate, rotate, albedo):
    return {"type": "quad", "name": name, "size": size,
            "transform": {"translate": translate, "rotate_deg": rotate}, "albedo": albedo}


def wall_setting(width, height):
    camera = {"position": [0.6, 1.6, 2.6], "look_at": [-0.1, 1.3, -2.0], "up": [0, 1, 0],
              "fov_y_deg": 50, "width": width, "height": height, "exposure": 1.0}
    objects = [
        quad("grout", [4.2, 3.2], [0, 1.5, -2.05], [0, 0, 0], [0.05, 0.05, 0.05]),
        quad("floor", [6, 6], [0, 0, 0.5], [-90, 0, 0], [0.6, 0.55, 0.5]),
        quad("wall behind the camera", [6, 3.5], [0, 1.75, 3.5], [0, 180, 0], [0.3, 0.5, 0.35]),
        {"type": "box", "name": "red box", "size": [0.8, 0.8, 0.8],
         "transform": {"translate": [-0.7, 0.4, -0.6], "rotate_deg": [0, 30, 0]},
         "albedo": [0.8, 0.15, 0.1]},
        {"type": "sphere", "name": "blue sphere", "radius": 0.5, "subdivisions": 3,
         "transform": {"translate": [0.8, 0.5, 0.2]}, "albedo": [0.15, 0.3, 0.8]},
    ]
    lights = [{"position": [0.3, 2.8, 1.0], "intensity": [15, 15, 15]}]
    return camera, objects, lights


BALL_CENTRE = [0.0, 1.6, 0.0]
BALL_RADIUS = 0.5


def sphere_setting(width, height):
    camera = {"position": [0.4, 1.3, 2.4], "look_at": BALL_CENTRE, "up": [0, 1, 0],
              "fov_y_deg": 40, "width": width, "height": height, "exposure": 1.0}
    objects = [
        quad("floor", [6, 6], [0, 0, 0], [-90, 0, 0], [0.55, 0.5, 0.45]),
        quad("ceiling", [6, 6], [0, 3, 0], [90, 0, 0], [0.7, 0.7, 0.7]),
        quad("back wall", [6, 3], [0, 1.5, -3], [0, 0, 0], [0.75, 0.6, 0.3]),
        quad("front wall", [6, 3], [0, 1.5, 3], [0, 180, 0], [0.3, 0.6, 0.4]),
        quad("left wall", [6, 3], [-3, 1.5, 0], [0, 90, 0], [0.7, 0.25, 0.2]),
        quad("right wall", [6, 3], [3, 1.5, 0], [0, -90, 0], [0.25, 0.35, 0.75]),
        {"type": "box", "name": "box", "size": [0.8, 0.8, 0.8],
         "transform": {"translate": [-1.2, 0.4, -1.0], "rotate_deg": [0, 30, 0]},
         "albedo": [0.8, 0.8, 0.2]},
        {"type": "sphere", "name": "sphere", "radius": 0.4, "subdivisions": 3,
         "transform": {"translate": [1.2, 0.4, -0.6]}, "albedo": [0.2, 0.7, 0.8]},
    ]
    lights = [{"position": [1.0, 2.7, 1.2], "intensity": [20, 20, 20]}]
    return camera, objects, lights


def main():
    ap = argparse.ArgumentParser(
        description="Write a scene of N mirror facets (a facade or a disco ball; issue 51).")
    ap.add_argument("--shape", choices=("wall", "sphere"), default="wall")
    ap.add_argument("--count", type=int, required=True, help=f"facets, 1..{MAX_COUNT}")
    ap.add_argument("--normal-map", nargs="?", const=HAMMERED, default=None, metavar="PATH",
                    help="every facet's bump.normal_map (a PNG; without PATH the bundled "
                         "scenes/textures/hammered.png); PATH as given to this script, "
                         "written relative to the output's folder")
    ap.add_argument("--normal-map-strength", type=float, default=0.05,
                    help="the normal map's strength, in [0, 100] (default 0.05)")
    ap.add_argument("--coincident", action="store_true",
                    help="every facet at the same place (the degenerate case)")
    ap.add_argument("--tilt-deg", type=float, default=3.0,
                    help="wall: largest tilt of a facet, degrees in [0, 45] (default 3)")
    ap.add_argument("--seed", type=int, default=51)
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--height", type=int, default=90)
    ap.add_argument("-o", "--output", required=True, metavar="OUT.json")
    a = ap.parse_args()

    if not 1 <= a.count <= MAX_COUNT:
        fail(f"--count must be in [1, {MAX_COUNT}], got {a.count}")
    for flag, side in (("--width", a.width), ("--height", a.height)):
        if not 1 <= side <= MAX_IMAGE_SIDE:
            fail(f"{flag} must be in [1, {MAX_IMAGE_SIDE}] pixels, got {side}")
    if a.width * a.height > MAX_PIXELS:
        fail(f"--width x --height must be at most {MAX_PIXELS} pixels, got {a.width * a.height}")
    if not 0.0 <= a.tilt_deg <= 45.0:
        fail(f"--tilt-deg must be in [0, 45], got {a.tilt_deg}")
    if not 0.0 <= a.normal_map_strength <= 100.0:
        fail(f"--normal-map-strength must be in [0, 100], got {a.normal_map_strength}")

    out = os.path.abspath(a.output)
    out_dir = os.path.dirname(out)
    if not os.path.isdir(out_dir):
        fail(f"the output's folder {out_dir} does not exist")
    bump = rel = ""
    if a.normal_map is not None:
        if not os.path.isfile(a.normal_map):
            fail(f"--normal-map {a.normal_map}: no such file")
        # Real paths on both sides: the loader joins the path to the scene's folder and the
        # kernel resolves "..", which follows a symlinked folder to its target's parent.
        rel = os.path.relpath(os.path.realpath(a.normal_map), os.path.realpath(out_dir))
        bump = (',"bump":{"normal_map":{"path":' + json.dumps(rel) +
                ',"strength":' + num(a.normal_map_strength) + '}}')

    rng = random.Random(a.seed)
    if a.shape == "wall":
        camera, objects, lights = wall_setting(a.width, a.height)
        if a.coincident:
            facets = [([0.0, 1.5, -2.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], 0.8, 0.6)] * a.count
        else:
            facets = wall_facets(a.count, a.tilt_deg, rng)
    else:
        camera, objects, lights = sphere_setting(a.width, a.height)
        if a.coincident:
            n = normalize([camera["position"][i] - BALL_CENTRE[i] for i in range(3)])
            centre = [BALL_CENTRE[i] + BALL_RADIUS * n[i] for i in range(3)]
            side = BALL_RADIUS * 0.4
            facets = [(centre, n, [0.0, 1.0, 0.0], side, side)] * a.count
        else:
            facets = ball_facets(a.count, BALL_CENTRE, BALL_RADIUS, rng)
    assert len(facets) == a.count

    refl = vec(REFLECTANCE)
    lines = []
    for center, normal, up, w, h in facets:
        lines.append('{"center":' + vec(center) + ',"normal":' + vec(normalize(normal)) +
                     ',"up":' + vec(up) + ',"width":' + num(w, 6) + ',"height":' + num(h, 6) +
                     ',"reflectance":' + refl + bump + '}')
    what = ("coincident " if a.coincident else "") + a.shape
    text = ('{"camera":' + json.dumps(camera, separators=(",", ":")) + ',\n"mirrors":[\n' + ",\n".join(lines) + "\n],\n" +
            '"objects":' + json.dumps(objects, separators=(",", ":")) + ",\n" +
            '"lights":' + json.dumps(lights, separators=(",", ":")) + ",\n" +
            '"ambient":[0.05,0.05,0.05],"background":[0.02,0.02,0.03],"terminal":[0,0,0]}\n')
    json.loads(text)  # what is written is JSON
    size = len(text.encode())
    if size > MAX_SCENE_FILE_BYTES:
        per = size / a.count
        fail(f"{a.count} facets ({what}{', normal map' if bump else ''}) make a "
             f"{size} byte scene file, over the scene format's {MAX_SCENE_FILE_BYTES} "
             f"bytes (16 MiB; crates/scene/src/limits.rs): at most about "
             f"{int((MAX_SCENE_FILE_BYTES - (size - per * a.count)) / per)} facets fit")
    with open(out, "w") as f:
        f.write(text)
    print(f"wrote {a.output}: {a.count} {what} facets"
          f"{' with normal map ' + rel if bump else ''}, {size} bytes",
          file=sys.stderr)


if __name__ == "__main__":
    main()
