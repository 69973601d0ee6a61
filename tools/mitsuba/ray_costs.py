#!/usr/bin/env python3
"""What one ray query costs Mitsuba 3 (its Embree), per kind of ray, for comparison with
mirrorbox's traversals on the same kinds of rays (issue 56; docs/tracer-performance.md).

The scattered and missing sets are built as `cargo bench -p mirrorbox-trace --bench
ray_sets -- single_` builds them, on Mitsuba's side of an export (`mirrorbox
export-mitsuba`); the camera set is the render's, not the benchmark's:
  camera     16 rays per pixel (the 4x4 grid) at 320x180, traced with the `coherent` hint
             (as Mitsuba's `path` traces its camera rays) and without it (as it traces
             every later ray);
  scattered  from the diffuse point each pixel-centre camera ray hits first (320x180), a
             uniform direction over the hemisphere on the camera's side: closest hit
             (`ray_intersect_preliminary`, no surface interaction), and any hit within 1;
  miss       rays from 10 units around (0, 1000, 0), pointing away from it and upwards,
             far above the scene: a query's fixed cost.
The same number of scattered rays on both sides (printed as `scattered_rays`) checks that
the camera and the diffuse surfaces agree. Each set is repeated to about a million rays;
the best of 6 timed evaluations (after a first that compiles the kernel), on `--threads`
threads (default 1), as nanoseconds per ray per thread. Prints one JSON line.

Usage: .venv/bin/python ray_costs.py SCENE.xml [--threads N]
"""
import argparse
import json
import os
import time

LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(LLVM19):
    os.environ["DRJIT_LIBLLVM_PATH"] = LLVM19  # Mitsuba 3.9's JIT needs LLVM >= 16

import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402

WIDTH, HEIGHT, GRID, TARGET = 320, 180, 4, 1_000_000


def repeated(values, n, target):
    """`values` (n entries each) repeated to about `target` entries."""
    index = dr.arange(mi.UInt32, n * max(1, target // n)) % n
    return [dr.gather(type(v), v, index) for v in values]


def best_ns(origins, dirs, query, threads, runs=6):
    """Nanoseconds per ray per thread of `query(ray)`, the best of `runs` after a first."""
    n = dr.width(dirs)
    best = float("inf")
    for run in range(runs + 1):
        ray = mi.Ray3f(mi.Point3f(origins), mi.Vector3f(dirs))
        dr.eval(ray.o, ray.d)
        dr.sync_thread()
        start = time.perf_counter()
        dr.eval(query(ray))
        dr.sync_thread()
        if run > 0:
            best = min(best, time.perf_counter() - start)
    return round(best / n * 1e9 * threads, 1)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("scene")
    p.add_argument("--threads", type=int, default=1)
    args = p.parse_args()
    if not os.path.isfile(args.scene):
        p.error(f"{args.scene}: no such file (a scene written by `mirrorbox export-mitsuba`)")
    if args.threads < 1:
        p.error(f"--threads {args.threads}: must be at least 1")
    mi.set_variant("llvm_ad_rgb")
    dr.set_thread_count(args.threads)
    scene = mi.load_file(args.scene)
    sensor = scene.sensors()[0]

    # Camera rays: 16 per pixel on the 4x4 grid.
    index = dr.arange(mi.UInt32, WIDTH * HEIGHT * GRID * GRID)
    pixel, sub = index // (GRID * GRID), index % (GRID * GRID)
    x = mi.Float(pixel % WIDTH) + (mi.Float(sub % GRID) + 0.5) / GRID
    y = mi.Float(pixel // WIDTH) + (mi.Float(sub // GRID) + 0.5) / GRID
    camera, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(x / WIDTH, y / HEIGHT), mi.Point2f(0.5))

    # Scattered rays from the diffuse points of the pixel-centre camera rays.
    index = dr.arange(mi.UInt32, WIDTH * HEIGHT)
    centre = mi.Point2f((mi.Float(index % WIDTH) + 0.5) / WIDTH,
                        (mi.Float(index // WIDTH) + 0.5) / HEIGHT)
    first, _ = sensor.sample_ray(0.0, 0.5, centre, mi.Point2f(0.5))
    si = scene.ray_intersect(first)
    diffuse = si.is_valid() & ~mi.has_flag(si.bsdf(first).flags(), mi.BSDFFlags.Delta)
    rng = mi.PCG32(size=WIDTH * HEIGHT)
    d = mi.warp.square_to_uniform_sphere(mi.Point2f(rng.next_float32(), rng.next_float32()))
    n = dr.select(dr.dot(si.n, first.d) > 0, -si.n, si.n)
    d = dr.select(dr.dot(d, n) < 0, -d, d)
    scattered = si.spawn_ray(d)
    keep = dr.compress(diffuse)
    count = dr.width(keep)
    if count == 0:
        p.error(f"{args.scene}: no camera ray meets a diffuse surface (no scattered rays)")
    s_o, s_d = repeated([dr.gather(mi.Point3f, scattered.o, keep),
                         dr.gather(mi.Vector3f, scattered.d, keep)], count, TARGET)

    # Rays far outside the scene, pointing away.
    rng = mi.PCG32(size=TARGET)
    m_d = mi.warp.square_to_uniform_sphere(mi.Point2f(rng.next_float32(), rng.next_float32()))
    m_d = mi.Vector3f(m_d.x, dr.abs(m_d.y), m_d.z)
    m_o = mi.Point3f(0, 1000, 0) + m_d * 10

    def closest(coherent):
        return lambda ray: scene.ray_intersect_preliminary(ray, coherent=coherent).t

    def any_within(t_max):
        return lambda ray: scene.ray_test(
            mi.Ray3f(ray.o, ray.d, t_max, 0.0, mi.Color0f()), coherent=False)

    t = args.threads
    print(json.dumps({
        "scene": args.scene,
        "threads": t,
        "mitsuba": mi.__version__,
        "scattered_rays": count,
        "ns_per_ray": {
            "camera_coherent": best_ns(camera.o, camera.d, closest(True), t),
            "camera": best_ns(camera.o, camera.d, closest(False), t),
            "scattered": best_ns(s_o, s_d, closest(False), t),
            "scattered_any_hit_within_1": best_ns(s_o, s_d, any_within(1.0), t),
            "miss": best_ns(m_o, m_d, closest(False), t),
        },
    }))


if __name__ == "__main__":
    main()
