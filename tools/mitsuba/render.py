#!/usr/bin/env python3
"""Render a mirrorbox scene exported with `mirrorbox export-mitsuba` in Mitsuba 3.

Integrators:
  whitted       our shading contract (docs/shading.md) written as a Mitsuba SamplingIntegrator:
                perfect mirror chains (throughput x reflectance), at the first diffuse hit the
                emission, the point lights without shadows and the ambient term (read from
                mirrorbox.json beside the XML, as are background and terminal radiance). The
                leanest formulation found (issue 41, the benchmark's baseline): camera rays
                intersected with Mitsuba's `coherent` hint, no sampler draws (a mirror's
                reflection is deterministic), each point light's term computed from one
                diffuse-reflectance lookup per hit instead of a BSDF evaluation per light, the
                area-emitter lookup only where the scene has area emitters.
  whitted-bsdf  the same contract in Mitsuba's general form (sampler draws for `bsdf.sample`,
                `sample_direction` and `bsdf.eval` per light): the same image, kept to show it.
  path          Mitsuba's own `path` integrator (adds diffuse interreflection; no ambient term),
                through the export's second sensor, whose sampler is `independent` (the first's
                unjittered grid puts every dimension at a stratum's centre: biased).

Writes a float32 RGB EXR and prints one JSON line with the timings. The first render of a
JIT variant (llvm_*) includes kernel compilation; --runs K renders K more times and reports
the fastest as `render_seconds`.

Usage: .venv/bin/python render.py SCENE.xml -o OUT.exr [--integrator whitted|whitted-bsdf|path]
         [--variant llvm_ad_rgb|scalar_rgb] [--spp N] [--max-depth D] [--rr-depth R] [--runs K]
"""
import argparse
import json
import os
import sys
import time

LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(LLVM19):
    os.environ["DRJIT_LIBLLVM_PATH"] = LLVM19  # Mitsuba 3.9's JIT needs LLVM >= 16

try:
    import drjit as dr  # noqa: E402
    import mitsuba as mi  # noqa: E402
except ImportError as e:  # no LLVM at all, or not the venv's Python
    sys.exit(f"render.py: cannot import Mitsuba 3 ({e}): run tools/mitsuba/setup.sh and use its "
             ".venv/bin/python")


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("scene")
    p.add_argument("-o", "--output", required=True)
    p.add_argument("--integrator", choices=["whitted", "whitted-bsdf", "path"], default="whitted")
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument("--spp", type=int, default=None, help="default: the export's")
    p.add_argument("--max-depth", type=int, default=10000,
                   help="mirror reflections (whitted) or path segments (path)")
    p.add_argument("--min-throughput", type=float, default=1e-4)
    p.add_argument("--rr-depth", type=int, default=1 << 30,
                   help="path: depth from which Russian roulette may end paths (default: never)")
    p.add_argument("--runs", type=int, default=1, help="timed renders after the first")
    p.add_argument("--seed", type=int, default=0, help="seed of Mitsuba's sampler")
    return p.parse_args()


def define_whitted():
    """Defined after mi.set_variant: the class binds to the variant's types. Returns it."""

    class Whitted(mi.SamplingIntegrator):
        def __init__(self, props):
            super().__init__(props)
            self.max_depth = props.get("max_depth", 10000)
            self.min_throughput = props.get("min_throughput", 1e-4)
            self.ambient = mi.Color3f(props.get("ambient_r", 0.0), props.get("ambient_g", 0.0), props.get("ambient_b", 0.0))
            self.background = mi.Color3f(props.get("background_r", 0.0), props.get("background_g", 0.0), props.get("background_b", 0.0))
            self.terminal = mi.Color3f(props.get("terminal_r", 0.0), props.get("terminal_g", 0.0), props.get("terminal_b", 0.0))

        @dr.syntax
        def sample(self, scene, sampler, ray, medium=None, active=True):
            ctx = mi.BSDFContext()
            ray = mi.Ray3f(ray)
            active = mi.Bool(active)
            L = mi.Spectrum(0.0)
            beta = mi.Spectrum(1.0)
            depth = mi.UInt32(0)
            lights = [e for e in scene.emitters() if mi.has_flag(e.flags(), mi.EmitterFlags.DeltaPosition)]
            while active:
                si = scene.ray_intersect(ray, active)
                escaped = active & ~si.is_valid()
                L += dr.select(escaped, beta * self.background, 0.0)
                active &= si.is_valid()
                bsdf = si.bsdf(ray)
                bs, weight = bsdf.sample(ctx, si, sampler.next_1d(active), sampler.next_2d(active), active)
                mirror = active & mi.has_flag(bs.sampled_type, mi.BSDFFlags.DeltaReflection)
                diffuse = active & ~mirror
                # Diffuse: E (front only, via the area emitter) + sum of lights + albedo * ambient.
                Ld = si.emitter(scene).eval(si, diffuse)
                for light in lights:
                    ds, intensity = light.sample_direction(si, mi.Point2f(0.5), diffuse)
                    f = bsdf.eval(ctx, si, si.to_local(ds.d), diffuse)  # albedo/pi * max(0, n.l)
                    Ld += f * intensity
                Ld += bsdf.eval_diffuse_reflectance(si, diffuse) * self.ambient
                L += dr.select(diffuse, beta * Ld, 0.0)
                # Mirror: terminal radiance when it cannot be followed, else reflect. An
                # uneven mirror (normalmap) that sends the ray behind it has weight 0: the
                # path ends with nothing (docs/shading.md, "Uneven mirrors").
                absorbed = mirror & (dr.max(weight) == 0.0)
                mirror &= ~absorbed
                nxt = beta * weight
                cut = mirror & ((depth >= self.max_depth) | (dr.max(nxt) < self.min_throughput))
                L += dr.select(cut, beta * self.terminal, 0.0)
                follow = mirror & ~cut
                beta = dr.select(follow, nxt, beta)
                ray = dr.select(follow, si.spawn_ray(si.to_world(bs.wo)), ray)
                depth = dr.select(follow, depth + 1, depth)
                active = follow
            return L, mi.Bool(True), []

    mi.register_integrator("mirrorbox_whitted", lambda props: Whitted(props))
    return Whitted


def define_whitted_lean():
    """The contract as `Whitted` above, in fewer operations (the same image, checked by
    tests/mitsuba.rs): see the module's doc."""

    # The same settings as the general form (its __init__); only `sample` differs.
    class WhittedLean(define_whitted()):
        @dr.syntax
        def sample(self, scene, sampler, ray, medium=None, active=True):
            ctx = mi.BSDFContext()
            ray = mi.Ray3f(ray)
            active = mi.Bool(active)
            L = mi.Spectrum(0.0)
            beta = mi.Spectrum(1.0)
            depth = mi.UInt32(0)
            emitters = scene.emitters()
            lights = [e for e in emitters if mi.has_flag(e.flags(), mi.EmitterFlags.DeltaPosition)]
            surface_emitters = any(mi.has_flag(e.flags(), mi.EmitterFlags.Surface) for e in emitters)
            # A mirror's reflection needs no random numbers: its delta lobe is sampled the
            # same for any sample values, and a diffuse hit's sampled direction is not used.
            no_sample = mi.Point2f(0.5)
            # The camera rays of neighbouring samples are coherent.
            si = scene.ray_intersect(ray, mi.RayFlags.All, True, active)
            while active:
                escaped = active & ~si.is_valid()
                L += dr.select(escaped, beta * self.background, 0.0)
                active &= si.is_valid()
                bsdf = si.bsdf(ray)
                bs, weight = bsdf.sample(ctx, si, 0.5, no_sample, active)
                mirror = active & mi.has_flag(bs.sampled_type, mi.BSDFFlags.DeltaReflection)
                diffuse = active & ~mirror
                # Diffuse: E (front only, via the area emitter) + albedo * (sum over the
                # lights of max(0, n.l) I / (pi r^2) + ambient), on the side the ray arrives.
                albedo = bsdf.eval_diffuse_reflectance(si, diffuse)
                side = dr.sign(mi.Frame3f.cos_theta(si.wi))
                irradiance = mi.Spectrum(self.ambient)
                for light in lights:
                    ds, intensity = light.sample_direction(si, no_sample, diffuse)
                    cos = dr.maximum(mi.Frame3f.cos_theta(si.to_local(ds.d)) * side, 0.0)
                    irradiance += intensity * (cos * dr.inv_pi)
                Ld = albedo * irradiance
                if surface_emitters:
                    Ld += si.emitter(scene).eval(si, diffuse)
                L += dr.select(diffuse, beta * Ld, 0.0)
                absorbed = mirror & (dr.max(weight) == 0.0)
                mirror &= ~absorbed
                nxt = beta * weight
                cut = mirror & ((depth >= self.max_depth) | (dr.max(nxt) < self.min_throughput))
                L += dr.select(cut, beta * self.terminal, 0.0)
                follow = mirror & ~cut
                beta = dr.select(follow, nxt, beta)
                ray = dr.select(follow, si.spawn_ray(si.to_world(bs.wo)), ray)
                depth = dr.select(follow, depth + 1, depth)
                active = follow
                si = scene.ray_intersect(ray, active)
            return L, mi.Bool(True), []

    mi.register_integrator("mirrorbox_whitted_lean", lambda props: WhittedLean(props))


def llvm_found():
    """Whether Dr.Jit has an LLVM >= 16: the one DRJIT_LIBLLVM_PATH names, else one in the
    usual folders (Dr.Jit finds those itself; the system's 15 crashes its JIT)."""
    named = os.environ.get("DRJIT_LIBLLVM_PATH")
    if named:
        return os.path.exists(named)
    import glob
    folders = ("/usr/lib", "/usr/lib64", "/usr/local/lib", "/usr/lib/x86_64-linux-gnu",
               "/usr/lib/aarch64-linux-gnu")
    return any(f"-{v}" in p or f".so.{v}" in p
               for d in folders for p in glob.glob(os.path.join(d, "libLLVM*.so*"))
               for v in range(16, 40))


def refuse(message):
    """Bad input: a clear message and exit 2, as mirrorbox's commands do."""
    print(f"render.py: {message}", file=sys.stderr)
    sys.exit(2)


def main():
    args = parse_args()
    # Our contract is RGB; a spectral variant would read every <rgb> as a spectrum.
    if not args.variant.endswith("_rgb"):
        refuse(f"--variant {args.variant}: an RGB variant (llvm_ad_rgb, scalar_rgb, ...)")
    # Without LLVM >= 16 Dr.Jit falls back to the system's (15 here), which crashes the JIT
    # with a dump of LLVM's: said instead, where neither DRJIT_LIBLLVM_PATH names a library nor
    # one of LLVM 16 or later lies in the usual folders (Dr.Jit finds those on its own).
    if args.variant.startswith("llvm") and not llvm_found():
        where = os.environ.get("DRJIT_LIBLLVM_PATH") or LLVM19
        print(f"render.py: {args.variant} needs LLVM >= 16, and {where} is missing: run tools/mitsuba/setup.sh "
              "(Debian's libllvm19), set DRJIT_LIBLLVM_PATH to it, or give --variant scalar_rgb", file=sys.stderr)
        sys.exit(1)
    mi.set_variant(args.variant)
    scene_dir = os.path.dirname(os.path.abspath(args.scene))
    sidecar = os.path.join(scene_dir, "mirrorbox.json")
    try:
        with open(sidecar) as f:
            extra = json.load(f)
    except (OSError, ValueError) as e:
        refuse(f"{sidecar}: cannot read the export's sidecar ({e}); export with `mirrorbox export-mitsuba`")
    # The sidecar is the XML's own (one export per folder; exports before the field: unknown).
    xml = os.path.basename(args.scene)
    if extra.get("xml", xml) != xml:
        refuse(f"{sidecar} belongs to {extra['xml']}, not {xml}: give each export a folder of its own")
    spp = args.spp or extra["spp"]
    # The stratified sampler rounds to a square: the record must say what was rendered.
    if spp < 1 or int(spp ** 0.5) ** 2 != spp:
        refuse(f"--spp {spp}: a perfect square (1, 4, 9, 16, ...), as the stratified sampler takes")
    if args.integrator in ("whitted", "whitted-bsdf"):
        if args.integrator == "whitted":
            define_whitted_lean()
            kind = "mirrorbox_whitted_lean"
        else:
            define_whitted()
            kind = "mirrorbox_whitted"
        integrator = {"type": kind, "max_depth": args.max_depth, "min_throughput": args.min_throughput}
        for name in ("ambient", "background", "terminal"):
            for c, v in zip("rgb", extra[name]):
                integrator[f"{name}_{c}"] = float(v)
    else:
        integrator = {"type": "path", "max_depth": args.max_depth, "rr_depth": args.rr_depth}
    t0 = time.perf_counter()
    scene = mi.load_file(args.scene, spp=spp)
    load_seconds = time.perf_counter() - t0
    # `whitted` renders through the first sensor (our sub-pixel grid, unjittered); `path`
    # through the second, whose independent sampler is unbiased: the unjittered stratified
    # one puts every random dimension at its strata's centres, a fixed quadrature that left
    # mirror_room's image mean 0.12 % low (docs/mitsuba.md).
    sensor = 1 if args.integrator == "path" else 0
    if sensor >= len(scene.sensors()):
        refuse(f"{args.scene} has one sensor (an export from before 2026-12-01): export it again "
               "for `path`'s unbiased sampler")
    integrator = mi.load_dict(integrator)

    def render():
        t = time.perf_counter()
        image = mi.render(scene, integrator=integrator, spp=spp, seed=args.seed, sensor=sensor)
        dr.eval(image)
        dr.sync_thread()
        return image, time.perf_counter() - t

    image, first = render()
    times = [render()[1] for _ in range(args.runs)] if args.runs > 0 else []
    bitmap = mi.Bitmap(image)
    # The camera's exposure, as `trace` records it: `mirrorbox compare` reads it from here.
    bitmap.metadata()["mirrorbox.exposure"] = str(extra.get("exposure", 1.0))
    bitmap.write(args.output)
    width, height = scene.sensors()[sensor].film().crop_size()
    print(json.dumps({
        "output": args.output, "variant": args.variant, "integrator": args.integrator,
        "spp": spp, "sampler": ["stratified, unjittered", "independent"][sensor],
        "max_depth": args.max_depth,
        "rr_depth": args.rr_depth if args.integrator == "path" else None,
        "width": int(width), "height": int(height),
        "load_seconds": load_seconds, "first_render_seconds": first,
        "render_seconds": min(times) if times else first, "runs": len(times),
        "threads": os.cpu_count(),
    }))


if __name__ == "__main__":
    sys.exit(main())
