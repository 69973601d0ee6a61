//! Issue 18, end to end: the real viewer in a real window (Xvfb, wgpu on the adapter `info`
//! reports — lavapipe here), driven by a `--script` as a person would drive it, and checked
//! against the batch commands:
//! - the method pane of the screenshot is the PNG `render` writes for the same camera (the
//!   scene's own, then one reached by walking and turning and saved with `save-camera`);
//! - the truth, once complete, is `trace --spp ssaa²` of that camera bit for bit, and its
//!   pane the trace's PNG;
//! - switching methods changes the passes the viewer reports; a resize does not crash;
//! - bad input (a script line, no display) is a clear error, not a panic.
//!
//! Needs Xvfb, and xdotool for the input test (`scripts/install-system-deps.sh` installs
//! both). Without them the window tests fail, unless `MIRRORBOX_TEST_SKIP` names `xvfb`
//! (`xdotool`) (`mirrorbox_testing`).
//! `MIRRORBOX_VIEWER_SCREENSHOT=PATH` keeps the last screenshot (the README's picture).

use crate::common::{mirrorbox, repo};
use serde_json::Value;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};

/// A virtual X display for the test's lifetime.
struct VirtualDisplay {
    server: Child,
    display: String,
}

impl VirtualDisplay {
    /// Starts Xvfb on a free display number (it prints the number it took); `None` where
    /// Xvfb is not installed and `MIRRORBOX_TEST_SKIP` names `xvfb` (a failure where it does
    /// not).
    fn start() -> Option<VirtualDisplay> {
        if !mirrorbox_testing::require(
            mirrorbox_testing::XVFB,
            mirrorbox_testing::on_path("Xvfb"),
            "Xvfb is not installed",
        ) {
            return None;
        }
        let mut server = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "1600x1000x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| panic!("Xvfb does not start: {e}"));
        let mut line = String::new();
        BufReader::new(server.stdout.take().expect("piped"))
            .read_line(&mut line)
            .expect("Xvfb prints its display number");
        let number = line.trim();
        assert!(!number.is_empty(), "Xvfb did not start");
        Some(VirtualDisplay {
            server,
            display: format!(":{number}"),
        })
    }
}

impl Drop for VirtualDisplay {
    fn drop(&mut self) {
        let _ = self.server.kill();
        let _ = self.server.wait();
    }
}

fn display_or_skip() -> Option<VirtualDisplay> {
    VirtualDisplay::start()
}

fn rgb(path: &Path) -> image::RgbImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8()
}

/// The pane `name` of a screenshot, cut out by the rectangle its JSON records.
fn pane(shot: &Path, name: &str) -> image::RgbImage {
    let meta: Value =
        serde_json::from_str(&std::fs::read_to_string(shot.with_extension("json")).unwrap())
            .unwrap();
    let r: Vec<u32> = meta["panes"][name]
        .as_array()
        .unwrap_or_else(|| panic!("no {name} pane in {meta}"))
        .iter()
        .map(|v| v.as_u64().unwrap() as u32)
        .collect();
    image::imageops::crop_imm(&rgb(shot), r[0], r[1], r[2], r[3]).to_image()
}

/// Asserts two 8-bit images are equal up to `tolerance` per channel (0: byte for byte);
/// writes both and their difference beside `shot` when not.
fn assert_same_pixels(
    shown: &image::RgbImage,
    expected: &image::RgbImage,
    tolerance: u8,
    what: &str,
    shot: &Path,
) {
    assert_eq!(shown.dimensions(), expected.dimensions(), "{what}: size");
    let worst = shown
        .pixels()
        .zip(expected.pixels())
        .flat_map(|(a, b)| (0..3).map(move |c| a[c].abs_diff(b[c])))
        .max()
        .unwrap_or(0);
    if worst > tolerance {
        let diff = image::RgbImage::from_fn(shown.width(), shown.height(), |x, y| {
            let (a, b) = (shown.get_pixel(x, y), expected.get_pixel(x, y));
            image::Rgb([0, 1, 2].map(|c| a[c].abs_diff(b[c]).saturating_mul(16)))
        });
        let stem = shot.with_extension("");
        let _ = shown.save(format!("{}.{what}.shown.png", stem.display()));
        let _ = diff.save(format!("{}.{what}.diff.png", stem.display()));
        panic!(
            "{what}: largest difference {worst} > {tolerance} (images beside {})",
            shot.display()
        );
    }
}

fn run_ok(args: &[&str], envs: &[(&str, &str)]) {
    let out = mirrorbox(args, envs);
    assert_eq!(
        out.code, 0,
        "mirrorbox {args:?}\nstdout: {}\nstderr: {}",
        out.stdout, out.stderr
    );
}

#[test]
fn the_viewer_shows_what_render_and_trace_write_and_survives_switching_and_resizing() {
    let Some(x) = display_or_skip() else { return };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = |name: &str| d.join(name).to_str().unwrap().to_string();
    let script = format!(
        "# the scene's own camera: the method pane must be `render`, the truth `trace`\n\
         wait-truth 300\n\
         screenshot {a}\n\
         # another method, then a view found by walking and turning\n\
         method unrolled depth=8\n\
         frames 2\n\
         walk 0.4 0.2 0.1\n\
         turn 12 -4\n\
         wait-truth 300\n\
         screenshot {b}\n\
         save-camera {bj}\n\
         # a refused setting is shown, not fatal; then back\n\
         method auxiliary n=3 max-passes=4\n\
         frames 2\n\
         method unrolled depth=8\n\
         error flip\n\
         resize 1100 640\n\
         frames 3\n\
         screenshot {c}\n\
         exit\n",
        a = p("a.png"),
        b = p("b.png"),
        c = p("c.png"),
        bj = p("b.scene.json"),
    );
    std::fs::write(d.join("tour.txt"), script).unwrap();
    // The scene copied beside the outputs: `save-camera` writes beside its scene.
    std::fs::copy(
        repo().join("scenes/mirror_box.json"),
        d.join("mirror_box.json"),
    )
    .unwrap();
    let scene_path = p("mirror_box.json");
    let scene = scene_path.as_str();
    let size = ["--width", "320", "--height", "180"];
    let env = [("DISPLAY", x.display.as_str())];
    let mut view = vec!["view", scene, "--method", "auxiliary", "--no-vsync"];
    view.extend(size);
    let (script_path, log) = (p("tour.txt"), p("log.jsonl"));
    view.extend(["--script", &script_path, "--log", &log]);
    run_ok(&view, &env);

    // 1. The scene's camera: the method pane is `render`'s PNG, the truth `trace`'s.
    let (render_a, trace_a) = (p("render_a.png"), p("trace_a.exr"));
    let mut render = vec!["render", scene, "--method", "auxiliary", "-o", &render_a];
    render.extend(size);
    run_ok(&render, &[]);
    let mut trace = vec!["trace", scene, "--spp", "1", "-o", &trace_a];
    trace.extend(size);
    run_ok(&trace, &[]);
    let a = d.join("a.png");
    assert_same_pixels(
        &pane(&a, "method"),
        &rgb(Path::new(&render_a)),
        0,
        "method_a",
        &a,
    );
    assert_same_pixels(
        &pane(&a, "truth"),
        &rgb(&d.join("trace_a.png")),
        0,
        "truth_a",
        &a,
    );
    let exr = |path: &str| mirrorbox_image::read_image(Path::new(path)).unwrap().pixels;
    assert_eq!(
        exr(&p("a.truth.exr")),
        exr(&p("trace_a.exr")),
        "the truth is the offline trace"
    );
    assert_eq!(
        exr(&p("a.method.exr")),
        exr(&p("render_a.exr")),
        "the method is the offline render"
    );

    // 2. The moved camera, saved into a scene copy: `render` and `trace` of the copy are what
    // the viewer showed.
    let (copy, render_b, trace_b) = (p("b.scene.json"), p("render_b.png"), p("trace_b.exr"));
    let mut render = vec![
        "render", &copy, "--method", "unrolled", "--depth", "8", "-o", &render_b,
    ];
    render.extend(size);
    run_ok(&render, &[]);
    let mut trace = vec!["trace", &copy, "--spp", "1", "-o", &trace_b];
    trace.extend(size);
    run_ok(&trace, &[]);
    let b = d.join("b.png");
    assert_same_pixels(
        &pane(&b, "method"),
        &rgb(Path::new(&render_b)),
        0,
        "method_b",
        &b,
    );
    assert_same_pixels(
        &pane(&b, "truth"),
        &rgb(&d.join("trace_b.png")),
        0,
        "truth_b",
        &b,
    );
    assert_eq!(exr(&p("b.truth.exr")), exr(&p("trace_b.exr")));
    // The walk moved the view: the two method panes differ.
    assert_ne!(
        pane(&a, "method"),
        pane(&b, "method"),
        "the camera did not move"
    );
    assert!(
        d.join("b.error.png").is_file(),
        "no heat map with a complete truth"
    );

    // 3. The log: switching methods changed the passes reported; the resize took.
    let records: Vec<Value> = std::fs::read_to_string(&log)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let passes = |method: &str| -> Vec<u64> {
        records
            .iter()
            .filter(|r| r["method"].as_str().is_some_and(|m| m.starts_with(method)))
            .filter_map(|r| r["passes"].as_u64())
            .collect()
    };
    let (aux, unrolled) = (passes("auxiliary"), passes("unrolled"));
    assert!(!aux.is_empty() && !unrolled.is_empty(), "{records:?}");
    assert!(
        aux.iter().all(|&p| p == 3) && unrolled.iter().all(|&p| p == 1),
        "{aux:?} {unrolled:?}"
    );
    let refused: Vec<&Value> = records
        .iter()
        .filter(|r| r["method"] == "auxiliary n=3")
        .collect();
    assert!(
        !refused.is_empty()
            && refused.iter().all(|r| r["method_error"]
                .as_str()
                .is_some_and(|e| e.contains("max-passes"))),
        "{refused:?}"
    );
    let last = records.last().unwrap();
    assert_eq!(
        last["window"],
        serde_json::json!([1100, 640]),
        "the resize was not applied"
    );
    // After the resize the panes are where the screenshot says, still 1:1.
    let c = d.join("c.png");
    assert_eq!(rgb(&c).dimensions(), (1100, 640));
    assert_same_pixels(
        &pane(&c, "method"),
        &rgb(Path::new(&render_b)),
        0,
        "method_c",
        &c,
    );
    assert!(last["gpu_ms"].as_f64().is_some_and(|ms| ms > 0.0));
    if let Some(keep) = std::env::var_os("MIRRORBOX_VIEWER_SCREENSHOT") {
        std::fs::copy(&c, keep).unwrap();
    }
}

#[test]
fn a_bad_script_line_is_refused_before_any_window_opens() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("s.txt");
    std::fs::write(&script, "frames 2\nresize 0 10\n").unwrap();
    let out = mirrorbox(
        &[
            "view",
            "scenes/mirror_box.json",
            "--script",
            script.to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(
        out.stderr.contains("s.txt:2:")
            && out
                .stderr
                .contains("the width must be a whole number in [64, 8192]"),
        "{}",
        out.stderr
    );
}

/// A screenshot's side file `X.json` (of `X.png`) or a `save-camera` target that is the scene
/// is refused before anything runs; before, the scene was replaced by the screenshot's
/// metadata. So is a script's output in a folder that does not exist (it failed, exit 1 and
/// no line named, after the window ran).
#[test]
fn outputs_that_would_overwrite_the_scene_or_miss_their_folder_are_refused_first() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.json");
    std::fs::copy(repo().join("scenes/mirror_box.json"), &scene).unwrap();
    let original = std::fs::read(&scene).unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let (scene_arg, script) = (p("s.json"), p("t.json"));
    let flag = mirrorbox(
        &[
            "view",
            &scene_arg,
            "--frames",
            "1",
            "--screenshot",
            &p("s.png"),
        ],
        &[],
    );
    assert_eq!(flag.code, 2, "{}", flag.stderr);
    assert!(
        flag.stderr.contains("--screenshot") && flag.stderr.contains("it is the scene"),
        "{}",
        flag.stderr
    );
    let dotted = format!("{}/./s.png", dir.path().display());
    let lines = [
        (format!("screenshot {dotted}"), "it is the scene"),
        (format!("save-camera {scene_arg}"), "it is the scene"),
        (format!("screenshot {}", p("t.png")), "it is the script"),
        (format!("screenshot {}", p("nope/a.png")), "does not exist"),
        (
            format!("save-camera {}", p("nope/a.json")),
            "does not exist",
        ),
        (
            format!("save-camera {}", repo().join("a.json").display()),
            "beside its scene",
        ),
    ];
    for (line, expected) in lines {
        std::fs::write(&script, format!("frames 1\n{line}\n")).unwrap();
        let out = mirrorbox(&["view", &scene_arg, "--script", &script], &[]);
        assert_eq!(out.code, 2, "{line}: {}", out.stderr);
        assert!(
            out.stderr.contains("t.json:2:") && out.stderr.contains(expected),
            "{line}: {}",
            out.stderr
        );
    }
    assert_eq!(std::fs::read(&scene).unwrap(), original);
    // `--log`, written when the window closes, must not be the script (nor miss its folder).
    let log_script = p("l.jsonl");
    std::fs::write(&log_script, "frames 1\n").unwrap();
    for (log, expected) in [
        (log_script.clone(), "it is the script"),
        (p("nope/l.jsonl"), "does not exist"),
    ] {
        let out = mirrorbox(
            &["view", &scene_arg, "--script", &log_script, "--log", &log],
            &[],
        );
        assert_eq!(out.code, 2, "{log}: {}", out.stderr);
        assert!(
            out.stderr.contains("--log") && out.stderr.contains(expected),
            "{log}: {}",
            out.stderr
        );
    }
    assert_eq!(std::fs::read_to_string(&log_script).unwrap(), "frames 1\n");
}

#[test]
fn without_a_display_the_viewer_says_what_it_needs() {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_mirrorbox"));
    cmd.args(["view", "scenes/mirror_box.json", "--frames", "1"])
        .current_dir(repo())
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET");
    let out = cmd.output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("cannot open a window") && stderr.contains("Xvfb"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}

fn xdotool(display: &str, args: &[&str]) -> String {
    let out = crate::common::succeed(
        Command::new("xdotool").args(args).env("DISPLAY", display),
        &format!("xdotool {args:?}"),
    );
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

fn camera(shot: &Path) -> (glam::Vec3, glam::Vec3) {
    let meta: Value =
        serde_json::from_str(&std::fs::read_to_string(shot.with_extension("json")).unwrap())
            .unwrap();
    let v = |key: &str| {
        let a: Vec<f32> = meta["camera"][key]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap() as f32)
            .collect();
        glam::Vec3::new(a[0], a[1], a[2])
    };
    (v("position"), v("look_at"))
}

/// Waits for a file the viewer writes (a screenshot's JSON), up to two minutes.
fn wait_for(path: &Path, viewer: &mut Child) {
    let start = std::time::Instant::now();
    while !path.is_file() {
        if let Ok(Some(status)) = viewer.try_wait() {
            panic!(
                "the viewer ended ({status}) before writing {}",
                path.display()
            );
        }
        assert!(
            start.elapsed().as_secs() < 120,
            "{} never came",
            path.display()
        );
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
}

/// Real input through the X server (XTEST, as a keyboard and a mouse send it): holding W
/// walks the camera forward along the view; dragging right on the method pane turns it right.
#[test]
fn held_keys_and_a_mouse_drag_move_the_camera() {
    if !mirrorbox_testing::require(
        mirrorbox_testing::XDOTOOL,
        mirrorbox_testing::on_path("xdotool"),
        "xdotool is not installed",
    ) {
        return;
    }
    let Some(x) = display_or_skip() else { return };
    let dir = tempfile::tempdir().unwrap();
    let shot = |name: &str| dir.path().join(name);
    // The viewer keeps drawing during `seconds`, while the test types and drags.
    let script = format!(
        "truth off\nframes 3\nscreenshot {}\nseconds 8\nscreenshot {}\nseconds 8\nscreenshot {}\nexit\n",
        shot("a.png").display(),
        shot("b.png").display(),
        shot("c.png").display()
    );
    std::fs::write(shot("input.txt"), script).unwrap();
    let mut viewer = Command::new(env!("CARGO_BIN_EXE_mirrorbox"))
        .args([
            "view",
            "scenes/mirror_box.json",
            "--width",
            "320",
            "--height",
            "180",
        ])
        .args(["--no-vsync", "--script"])
        .arg(shot("input.txt"))
        .current_dir(repo())
        .env("DISPLAY", &x.display)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for(&shot("a.json"), &mut viewer);
    let window = xdotool(&x.display, &["search", "--name", "mirrorbox view"]);
    let window = window
        .lines()
        .next()
        .expect("the viewer's window")
        .to_string();
    // Pointer over the method pane, keyboard focus on the window, then W held for 1.5 s (several frames even on a loaded machine).
    let meta: Value =
        serde_json::from_str(&std::fs::read_to_string(shot("a.json")).unwrap()).unwrap();
    let pane: Vec<u64> = meta["panes"]["method"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap())
        .collect();
    let (cx, cy) = (pane[0] + pane[2] / 2, pane[1] + pane[3] / 2);
    let at = |dx: u64| [(cx + dx).to_string(), cy.to_string()];
    let [x0, y0] = at(0);
    xdotool(&x.display, &["mousemove", "--window", &window, &x0, &y0]);
    xdotool(&x.display, &["windowfocus", "--sync", &window]);
    // Tab four times, once round the layouts: egui had taken Tab as a focus step, and with a
    // panel widget focused it claimed every later key (W then did nothing).
    xdotool(
        &x.display,
        &["key", "--delay", "150", "Tab", "Tab", "Tab", "Tab"],
    );
    xdotool(&x.display, &["keydown", "w", "sleep", "1.5", "keyup", "w"]);
    wait_for(&shot("b.json"), &mut viewer);
    let [x1, y1] = at(80);
    xdotool(&x.display, &["mousedown", "1"]);
    xdotool(&x.display, &["mousemove", "--window", &window, &x1, &y1]);
    xdotool(&x.display, &["mouseup", "1"]);
    wait_for(&shot("c.json"), &mut viewer);
    let out = viewer.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let (pa, la) = camera(&shot("a.png"));
    let (pb, lb) = camera(&shot("b.png"));
    let (pc, lc) = camera(&shot("c.png"));
    let (fa, fb, fc) = (
        (la - pa).normalize(),
        (lb - pb).normalize(),
        (lc - pc).normalize(),
    );
    // W: forward along the view, no turn.
    let walked = pb - pa;
    assert!(walked.dot(fa) > 0.1, "W did not walk forward: {walked}");
    assert!(
        walked.cross(fa).length() < 1e-3 * walked.length().max(1.0),
        "{walked} vs {fa}"
    );
    assert!(fb.dot(fa) > 0.9999, "W turned the view: {fa} → {fb}");
    // The drag: a turn to the right (towards view × up), no move.
    assert_eq!(pc, pb, "the drag moved the camera");
    let right = fa.cross(glam::Vec3::Y).normalize();
    assert!(
        fc.dot(right) > fb.dot(right) + 0.05,
        "the drag did not turn right: {fb} → {fc}"
    );
}

/// `feedback` in the viewer carries from frame to frame as in an engine: a still view's
/// reflections grow by one per drawn frame, and the frame shown is `render --history K`'s
/// bit for bit (K + 1 its reflections).
#[test]
fn feedback_grows_one_reflection_per_frame_in_the_viewer() {
    let Some(x) = display_or_skip() else { return };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = |name: &str| d.join(name).to_str().unwrap().to_string();
    std::fs::write(
        d.join("still.txt"),
        format!("frames 5\nscreenshot {}\nexit\n", p("f.png")),
    )
    .unwrap();
    let scene = "scenes/mirror_box.json";
    let size = ["--width", "320", "--height", "180"];
    let (script, log) = (p("still.txt"), p("log.jsonl"));
    let mut view = vec!["view", scene, "--method", "feedback", "--no-vsync"];
    view.extend(size);
    view.extend(["--script", &script, "--log", &log]);
    run_ok(&view, &[("DISPLAY", x.display.as_str())]);
    let reflections: Vec<u64> = std::fs::read_to_string(&log)
        .unwrap()
        .lines()
        .filter_map(|l| serde_json::from_str::<Value>(l).ok()?["reflections"].as_u64())
        .collect();
    assert!(reflections.len() >= 5, "{reflections:?}");
    assert!(
        reflections.windows(2).all(|w| w[1] == w[0] + 1) && reflections[0] == 1,
        "one more reflection per frame: {reflections:?}"
    );
    let meta: Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("f.json")).unwrap()).unwrap();
    let shown = meta["reflections"]
        .as_u64()
        .expect("the screenshot's reflections");
    let history = (shown - 1).to_string();
    let out = p("render.png");
    let mut render = vec![
        "render",
        scene,
        "--method",
        "feedback",
        "--history",
        &history,
        "-o",
        &out,
    ];
    render.extend(size);
    run_ok(&render, &[]);
    let exr = |path: &str| mirrorbox_image::read_image(Path::new(path)).unwrap().pixels;
    assert_eq!(
        exr(&p("f.method.exr")),
        exr(&p("render.exr")),
        "the viewer's frame with {shown} reflections is render --history {history}"
    );
}

/// With the truth off, a moved camera has no complete truth: the old view's traced image was
/// called "complete" against the new frame (a false error map, FLIP and truth EXR). A refused
/// method draws nothing, yet `wait-truth` ends when the truth is traced (it had failed,
/// saying the truth was not complete). A screenshot over an earlier one removes the
/// companions it does not write.
#[test]
fn a_moved_camera_is_never_scored_against_an_old_truth() {
    let Some(x) = display_or_skip() else { return };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = |name: &str| d.join(name).to_str().unwrap().to_string();
    std::fs::write(
        d.join("tour.txt"),
        format!(
            "wait-truth 120\nscreenshot {a}\nscreenshot {b}\ntruth off\nwalk 0.5 0 0\n\
             turn 30 0\nframes 3\nscreenshot {b}\ntruth on\nmethod auxiliary n=4 max-passes=2\n\
             wait-truth 120\nscreenshot {c}\nexit\n",
            a = p("a.png"),
            b = p("b.png"),
            c = p("c.png"),
        ),
    )
    .unwrap();
    let script = p("tour.txt");
    let view = [
        "view",
        "scenes/mirror_box.json",
        "--method",
        "auxiliary",
        "--no-vsync",
        "--width",
        "48",
        "--height",
        "27",
        "--script",
        &script,
    ];
    run_ok(&view, &[("DISPLAY", x.display.as_str())]);
    let meta = |name: &str| -> Value {
        serde_json::from_str(&std::fs::read_to_string(d.join(name)).unwrap()).unwrap()
    };
    let (a, b, c) = (meta("a.json"), meta("b.json"), meta("c.json"));
    assert_eq!(a["truth_complete"], true, "{a}");
    assert!(a["metrics"].is_object() && d.join("a.truth.exr").is_file());
    assert_eq!(b["truth_complete"], false, "{b}");
    assert!(b["metrics"].is_null(), "{b}");
    assert!(
        !d.join("b.truth.exr").exists() && !d.join("b.error.png").exists(),
        "the first b's truth and error map were left beside the second"
    );
    assert_eq!(
        c["truth_complete"], false,
        "a refused method has no frame: {c}"
    );
}
