#!/usr/bin/env python3
"""Agreement of mirrorbox's tracer with Mitsuba 3 on scenes, both integrators.

For each scene: export it (`mirrorbox export-mitsuba`), render it with our tracer and with
Mitsuba (render.py), and compare on linear radiance:
  whitted (deterministic, same sub-pixel grid): mean |difference| and the share of pixels
          that differ by more than 1e-3 (silhouette samples that land on another triangle);
  path    (Monte Carlo): the mean of the difference over B pixel blocks, as a share of the
          image mean, and its t statistic, mean(d) / (std(d)/sqrt(B)) — |t| < 4 means the two
          agree within their measured noise.
Prints a Markdown table. Usage (from the repository root, after tools/mitsuba/setup.sh):
  tools/mitsuba/.venv/bin/python tools/mitsuba/agreement.py scenes/*.json [--width 160 --height 90]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def run(cmd):
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        # The command's own message, not only its status.
        sys.exit(f"agreement.py: {' '.join(cmd)} exited {out.returncode}:\n{out.stderr.strip()}")
    return out.stdout


def load(path):
    import mitsuba as mi
    return np.array(mi.Bitmap(path))[..., :3].astype(np.float64)


def block_means(x, k):
    h, w, _ = x.shape
    return x[: h // k * k, : w // k * k].reshape(h // k, k, w // k, k, 3).mean(axis=(1, 3, 4)).ravel()


def main():
    p = argparse.ArgumentParser()
    p.add_argument("scenes", nargs="+")
    p.add_argument("--width", type=int, default=160)
    p.add_argument("--height", type=int, default=90)
    p.add_argument("--whitted-spp", type=int, default=4)
    p.add_argument("--path-spp", type=int, default=256)
    p.add_argument("--path-depth", type=int, default=66)
    p.add_argument("--block", type=int, default=6)
    p.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "mirrorbox"))
    args = p.parse_args()
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    py = sys.executable
    print("| scene | whitted: mean abs diff | whitted: pixels > 1e-3 | path: image mean (ours / Mitsuba) | path: rel. mean diff | path: t |")
    print("|---|---|---|---|---|---|")
    for scene in args.scenes:
        with tempfile.TemporaryDirectory() as d:
            size = ["--width", str(args.width), "--height", str(args.height)]
            rows = {}
            for integ, spp, depth in (("whitted", args.whitted_spp, 10000), ("path", args.path_spp, args.path_depth)):
                xml = os.path.join(d, integ, "scene.xml")
                os.makedirs(os.path.dirname(xml), exist_ok=True)  # outputs' folders must exist
                run([args.bin, "export-mitsuba", scene, "-o", xml, "--spp", str(spp)] + size)
                ours = os.path.join(d, integ, "ours.exr")
                # path: segments as Mitsuba's max_depth, no roulette, jittered (Mitsuba's
                # samples independently, render.py); whitted: reflections, the grid of both.
                cut = (["--max-segments", str(depth), "--rr-from", "1000000", "--jitter"]
                       if integ == "path" else ["--max-depth", str(depth)])
                run([args.bin, "trace", scene, "-o", ours, "--spp", str(spp), "--integrator", integ]
                    + cut + size)
                theirs = os.path.join(d, integ, "mitsuba.exr")
                run([py, os.path.join(HERE, "render.py"), xml, "-o", theirs, "--integrator", integ,
                     "--max-depth", str(depth), "--runs", "0"])
                rows[integ] = (load(ours), load(theirs))
                with open(os.path.join(d, integ, "mirrorbox.json")) as f:
                    # The camera's path or stereo rig left out change nothing of one view.
                    left_out = [x for x in json.load(f)["not_exported"] if x.startswith("lighting.")]
            a, b = rows["whitted"]
            diff = np.abs(a - b).max(axis=-1)
            # What the export leaves out (a lit scene's shadows and mirrored lights) is in our
            # Whitted image and not in Mitsuba's: no agreement to state. `path` has both.
            whitted = (f"{np.abs(a - b).mean():.2e} | {100 * (diff > 1e-3).mean():.2f} %" if not left_out
                       else "– | – (not exported: " + "; ".join(x.split(" (")[0] for x in left_out) + ")")
            a, b = rows["path"]
            dm = block_means(a, args.block) - block_means(b, args.block)
            t = dm.mean() / (dm.std(ddof=1) / np.sqrt(len(dm)))
            print(f"| {os.path.basename(scene)} | {whitted} | {a.mean():.5f} / {b.mean():.5f} | "
                  f"{100 * dm.mean() / a.mean():+.2f} % | {t:+.2f} |")


if __name__ == "__main__":
    main()
