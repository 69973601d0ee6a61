#!/usr/bin/env python3
"""A minimal client of mirrorbox's exchange (docs/exchange.md), to copy and adapt.

Draws every view of an export with a renderer and writes RUN/<client>/<variant>/ — one
image per view and timing.json — for `mirrorbox score EXPORT RUN -o OUT`. Replace draw()
with your renderer; as shipped it runs mirrorbox's own `naive` method, so its score equals
what `mirrorbox sweep` measures for `naive` (tests/exchange.rs checks it).

usage: client.py EXPORT RUN [--mirrorbox PATH] [--frames N]
"""
import argparse, json, os, pathlib, shutil, subprocess, sys, tempfile

CLIENT, VARIANT, EQUIVALENT = "minimal", "naive", "naive"


def draw(export, view, out, mirrorbox, frames):
    """Your renderer: view (from views.json) into out — linear radiance (EXR), or 8-bit sRGB
    (PNG), top row first — drawn `frames` times after a warm-up; returns each warm frame's ms."""
    scene = json.loads((export / "scene.json").read_text())
    cam = view["camera"]
    scene["camera"].update(position=cam["position"], look_at=cam["look_at"], up=cam["up"],
                           fov_y_deg=cam["fov_y_deg"], width=view["width"], height=view["height"])
    for obj in scene.get("objects", []):  # the glTF by its absolute path: the scene is elsewhere
        if "path" in obj:
            obj["path"] = str((export / obj["path"]).resolve())
    with tempfile.TemporaryDirectory() as tmp:
        view_scene = pathlib.Path(tmp) / "view.json"
        view_scene.write_text(json.dumps(scene))
        done = subprocess.run([mirrorbox, "render", str(view_scene), "--method", "naive",
                               "--ssaa", str(view["ssaa"]), "--frames", str(frames), "--json",
                               "-o", str(out.with_suffix(".png"))],
                              capture_output=True, text=True)
    if done.returncode != 0:  # the renderer's own words, not only its status
        sys.exit(f"client.py: view {view['name']}: mirrorbox render exited {done.returncode}:\n"
                 f"{done.stderr.strip()}")
    out.with_suffix(".png").unlink()  # `render` writes the linear EXR beside its PNG
    # Each warm frame's time as render took it (GPU timestamps where the adapter has them,
    # else the wall clock around the frame: its timing_source), not the process's start-up.
    report = json.loads(done.stdout.strip().splitlines()[-1])
    return report["frames_ms"], report["timing_source"], report["adapter"]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("export", type=pathlib.Path)
    p.add_argument("run", type=pathlib.Path)
    p.add_argument("--mirrorbox", default=os.environ.get("MIRRORBOX", "mirrorbox"))
    p.add_argument("--frames", type=int, default=6, help="timed frames per view, 1..100 (6+ give an interval)")
    a = p.parse_args()
    if not 1 <= a.frames <= 100:
        p.error(f"--frames {a.frames}: 1 to 100")  # exit 2, as mirrorbox's own commands
    views = json.loads((a.export / "views.json").read_text())["views"]
    folder = a.run / CLIENT / VARIANT
    # Drawn into a folder beside it and put in place at the end: a failed view leaves nothing
    # half-written for `score` to refuse.
    a.run.mkdir(parents=True, exist_ok=True)
    staged = pathlib.Path(tempfile.mkdtemp(prefix=f".{CLIENT}-", dir=a.run))
    try:
        drawn = {view["name"]: draw(a.export, view, staged / f"{view['name']}.exr", a.mirrorbox, a.frames)
                 for view in views}
        times = {name: ms for name, (ms, _, _) in drawn.items()}
        clocks = sorted({clock for _, clock, _ in drawn.values()})
        devices = sorted({adapter for _, _, adapter in drawn.values()})
        version = subprocess.run([a.mirrorbox, "--version"], capture_output=True, text=True).stdout.split()
        (staged / "timing.json").write_text(json.dumps({
            "format": "mirrorbox-timing", "version": 1, "engine": "mirrorbox render (minimal client)",
            "engine_version": version[-1] if version else "unknown", "device": ", ".join(devices),
            "equivalent": EQUIVALENT,
            "timing": f"{', '.join(clocks)} of warm frames (mirrorbox render --frames N --json)", "views": times,
            "scene_hashes": {view["name"]: view["scene_hash"] for view in views}}, indent=1))
        folder.parent.mkdir(parents=True, exist_ok=True)
        shutil.rmtree(folder, ignore_errors=True)
        staged.rename(folder)
    finally:
        shutil.rmtree(staged, ignore_errors=True)
    print(f"wrote {folder}: {len(views)} view(s); next: mirrorbox score {a.export} {a.run} -o OUT")


if __name__ == "__main__":
    main()
