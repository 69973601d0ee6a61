//! End-to-end tests of issue #12: inputs that used to panic, abort for memory, block or write
//! half a file. Every case runs the real binary; each must end with a clear message and exit 2
//! (or just work), never a panic (101), an abort (134) or a signal.

use crate::common;
use crate::common::{Output, mirrorbox};
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

fn scene() -> Value {
    common::valid_scene()
}

fn write_scene(dir: &Path, name: &str, scene: &Value) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_string_pretty(scene).unwrap()).unwrap();
    path
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn assert_refused(args: &[&str], out: &Output, fragments: &[&str]) {
    assert_eq!(
        out.code, 2,
        "{args:?} should be refused (exit 2):\n{}",
        out.stderr
    );
    assert!(!out.stderr.contains("panicked"), "{args:?}: {}", out.stderr);
    for f in fragments {
        assert!(
            out.stderr.contains(f),
            "{args:?}: missing {f:?} in:\n{}",
            out.stderr
        );
    }
}

/// The edge-case table: command lines that must be refused with these words, nothing written.
#[test]
fn edge_cases_are_refused_with_a_clear_message_and_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let ok = write_scene(d, "ok.json", &scene());
    let mut far = scene();
    far["objects"][0]["transform"] = json!({ "translate": [3.4e38, 0, 0] });
    let far = write_scene(d, "far.json", &far);
    let mut heavy = scene();
    heavy["objects"] = Value::Array(vec![json!({ "type": "sphere", "subdivisions": 7 }); 20]);
    let heavy = write_scene(d, "heavy.json", &heavy);
    let mut zero_obj = scene();
    zero_obj["objects"] = json!([{ "type": "mesh", "path": "/dev/zero" }]);
    let zero_obj = write_scene(d, "zero_obj.json", &zero_obj);
    let mut random_obj = scene();
    random_obj["objects"] = json!([{ "type": "mesh", "path": "/dev/urandom" }]);
    let random_obj = write_scene(d, "random_obj.json", &random_obj);
    let random_obj = random_obj.to_str().unwrap().to_string();
    let mut deep_lights = scene();
    deep_lights["lighting"] = json!({ "mirrored_lights": 99 });
    let deep_lights = write_scene(d, "deep_lights.json", &deep_lights);
    let deep_lights = deep_lights.to_str().unwrap().to_string();
    let out = d.join("out");
    std::fs::create_dir(&out).unwrap();
    let (ok, far, heavy, zero_obj) = (
        ok.to_str().unwrap(),
        far.to_str().unwrap(),
        heavy.to_str().unwrap(),
        zero_obj.to_str().unwrap(),
    );
    let exr = out.join("t.exr");
    let png = out.join("r.png");
    let sweep_out = out.join("sweep");
    let (exr, png, sweep_out) = (
        exr.to_str().unwrap(),
        png.to_str().unwrap(),
        sweep_out.to_str().unwrap(),
    );
    let sweep = |extra: &[&'static str]| -> Vec<String> {
        let mut a = vec!["sweep", ok, "--out", sweep_out, "--methods", "naive"];
        a.extend_from_slice(extra);
        a.into_iter().map(String::from).collect()
    };
    let own = |a: &[&str]| -> Vec<String> { a.iter().map(|s| s.to_string()).collect() };
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        // An object near the float limit used to panic inside obvhs (exit 101).
        (
            own(&["trace", far, "-o", exr]),
            vec!["objects[0].transform", "scene extent"],
        ),
        (
            own(&["render", far, "-o", png]),
            vec!["objects[0].transform"],
        ),
        // 6.5 M triangles in a 1.3 KB file: refused before tessellating, with the memory.
        (
            own(&["check", heavy]),
            vec!["objects[12]", "at most 4194304", "GiB"],
        ),
        (own(&["render", heavy, "-o", png]), vec!["objects[12]"]),
        // A folder that takes no file: refused before the work (it had failed after it).
        (
            own(&["trace", ok, "-o", "/proc/x.exr"]),
            vec!["folder /proc takes no new file"],
        ),
        // A mirror texture beyond the device's largest side: the advice names the flags
        // that set its size (it had said "lower --ssaa", which was 1).
        (
            own(&[
                "render",
                "scenes/bumpy_pair.json",
                "--method",
                "naive",
                "--width",
                "16384",
                "--height",
                "16",
                "--texture-scale",
                "4",
                "--texture-margin",
                "4096",
                "-o",
                png,
            ]),
            vec!["render target", "lower --texture-scale or --texture-margin"],
        ),
        // Sizes that used to abort for memory.
        (
            own(&["trace", ok, "-o", exr, "--spp", "4294836225"]),
            vec!["--spp must be a positive perfect square", "got 4294836225"],
        ),
        (
            own(&["trace", ok, "-o", exr, "--spp", "0"]),
            vec!["a positive perfect square"],
        ),
        (
            own(&["render", ok, "-o", png, "--frames", "4294967295"]),
            vec!["--frames must be in [1, 10000]"],
        ),
        (
            own(&["render", ok, "-o", png, "--warmup", "4294967295"]),
            vec!["--warmup must be in [0, 1000]"],
        ),
        (
            own(&[
                "render",
                ok,
                "-o",
                png,
                "--method",
                "auxiliary",
                "--n",
                "4294967295",
            ]),
            vec!["--n", "4294967295"],
        ),
        (
            own(&["render", ok, "-o", png, "--width", "16384", "--ssaa", "8"]),
            vec!["--ssaa must be such that the render"],
        ),
        (
            own(&[
                "trace", ok, "-o", exr, "--width", "16384", "--height", "16384",
            ]),
            vec!["--width × --height must be at most 67108864 pixels"],
        ),
        // Mirror textures beyond the frame's budget: refused before they are created.
        (
            own(&[
                "render",
                ok,
                "-o",
                png,
                "--method",
                "auxiliary",
                "--texture-scale",
                "4",
                "--width",
                "8192",
                "--height",
                "4608",
            ]),
            vec!["mirror textures", "lower --texture-scale"],
        ),
        // A device or FIFO as an input: refused without reading.
        (
            own(&["check", zero_obj]),
            vec!["objects[0].path", "character device"],
        ),
        (
            own(&["check", &random_obj]),
            vec!["objects[0].path", "character device"],
        ),
        (
            own(&["check", "/dev/zero"]),
            vec!["/dev/zero", "must be a regular file"],
        ),
        // Sweeps validate exactly as trace and render do.
        // (the range of the commands that compare with a truth: SSIM's window, 11, is the least)
        (
            sweep(&["--width", "0"]),
            vec!["--width must be in [11, 16384] pixels where an image is compared"],
        ),
        (
            sweep(&["--width", "2147483648"]),
            vec!["--width must be in [11, 16384] pixels", "got 2147483648"],
        ),
        (
            sweep(&["--height", "100000"]),
            vec!["--height must be in [11, 16384]"],
        ),
        (
            sweep(&["--width", "1"]),
            vec!["--width must be in [11, 16384] pixels where an image is compared with its truth"],
        ),
        // --ssaa of the commands that compare with a truth: s × s overflowed (a panic).
        (
            own(&["export-views", ok, "-o", sweep_out, "--ssaa", "70000"]),
            vec!["--ssaa must be in [1, 8], got 70000"],
        ),
        (
            own(&["export-views", ok, "-o", sweep_out, "--ssaa", "9"]),
            vec!["--ssaa must be in [1, 8], got 9"],
        ),
        (
            own(&[
                "advise",
                ok,
                "--budget-ms",
                "10",
                "-o",
                sweep_out,
                "--ssaa",
                "70000",
            ]),
            vec!["--ssaa must be in [1, 8], got 70000"],
        ),
        (
            sweep(&["--min-throughput", "nan"]),
            vec!["--min-throughput must be in [0, 1), got NaN"],
        ),
        (
            sweep(&["--alpha", "nan"]),
            vec!["--alpha must be in [0, 1], got NaN"],
        ),
        (
            sweep(&["--frames", "0"]),
            vec!["--frames must be in [1, 10000]"],
        ),
        (sweep(&["--ssaa", "9"]), vec!["--ssaa must be in [1, 8]"]),
        (
            sweep(&["--mirrored-lights", "0,65"]),
            vec![
                "--mirrored-lights must be mirrored-light depths each in [0, 64], whole numbers, got 65",
            ],
        ),
        (
            own(&["trace", &deep_lights, "-o", exr]),
            vec![
                "deep_lights.json: lighting.mirrored_lights: must be in [0, 64]",
                "got 99",
            ],
        ),
        (
            sweep(&["--methods", "auxiliary", "--n", "0..4294967295"]),
            vec!["--n \"0..4294967295\""],
        ),
        (
            sweep(&["--methods", "portal", "--depth", "0..4294967295"]),
            vec!["--depth \"0..4294967295\""],
        ),
        // Outputs that collide.
        (
            own(&["trace", ok, "-o", exr, "--bounces", exr]),
            vec!["--bounces and -o would both write this file"],
        ),
    ];
    for (args, fragments) in &cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let started = std::time::Instant::now();
        let r = mirrorbox(&args, &[]);
        assert_refused(&args, &r, fragments);
        assert!(
            started.elapsed().as_secs() < 20,
            "{args:?} took {:?} to refuse",
            started.elapsed()
        );
        assert!(
            files_in(&out).is_empty(),
            "{args:?} wrote {:?}",
            files_in(&out)
        );
    }
}

#[test]
fn a_fifo_as_obj_file_is_refused_instead_of_blocking() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("mesh.obj");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo");
    let mut s = scene();
    s["objects"] = json!([{ "type": "mesh", "path": "mesh.obj" }]);
    let path = write_scene(dir.path(), "s.json", &s);
    let args = ["check", path.to_str().unwrap()];
    let r = mirrorbox(&args, &[]);
    assert_refused(&args, &r, &["objects[0].path", "FIFO"]);
}

/// `compare` reads an EXR's recorded attributes before its pixels: a FIFO named as an image
/// had blocked there, before the pixel reader's own check.
#[test]
fn a_fifo_as_compared_image_is_refused_instead_of_blocking() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("a.exr");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo");
    // Should the check regress, a writer opens the FIFO again and again after a while, so
    // that each blocked read gets an end of file instead of hanging the test; a writer's open
    // succeeds only while a reader waits, and says so.
    let (writer, unblocked) = (fifo.clone(), std::sync::Arc::new(AtomicBool::new(false)));
    let said = unblocked.clone();
    std::thread::spawn(move || {
        std::thread::sleep(std::time::Duration::from_secs(10));
        loop {
            if std::fs::OpenOptions::new()
                .write(true)
                .open(&writer)
                .is_ok()
            {
                said.store(true, Ordering::SeqCst);
            }
            std::thread::sleep(std::time::Duration::from_millis(100));
        }
    });
    let args = ["compare", fifo.to_str().unwrap(), fifo.to_str().unwrap()];
    let r = mirrorbox(&args, &[]);
    assert!(
        !unblocked.load(Ordering::SeqCst),
        "compare waited on the FIFO until a writer opened it"
    );
    assert_refused(&args, &r, &["a.exr", "FIFO"]);
}

/// `compare` refuses images whose comparison would need more memory than its budget, from
/// their headers, before reading a pixel: the 2 GiB default refuses a 4480² pair (2.2 GB
/// by 112 bytes a pixel; an 8192² pair had needed 7 GB and been killed), and a budget of
/// 1 MiB a 128² pair; a 64² pair fits it.
#[test]
fn compare_refuses_what_its_memory_budget_cannot_hold() {
    let dir = tempfile::tempdir().unwrap();
    let png = |side: u32| {
        let path = dir.path().join(format!("{side}.png"));
        // Written row by row by the PNG encoder: a flat grey compresses to a few KB.
        let img = mirrorbox_image::RgbImage {
            width: side,
            height: side,
            pixels: vec![[0.2; 3]; (side * side) as usize],
        };
        mirrorbox_image::write_png(&path, &img, 1.0).unwrap();
        path
    };
    let big = png(4480);
    let args = ["compare", big.to_str().unwrap(), big.to_str().unwrap()];
    let r = mirrorbox(&args, &[]);
    assert_refused(
        &args,
        &r,
        &[
            "comparing 4480×4480 images needs about 2.2 GB",
            "--memory-budget",
        ],
    );
    let (small, fits) = (png(128), png(64));
    for (image, refused) in [(&small, true), (&fits, false)] {
        let args = [
            "compare",
            image.to_str().unwrap(),
            image.to_str().unwrap(),
            "--memory-budget",
            "1M",
        ];
        let r = mirrorbox(&args, &[]);
        assert_eq!(
            r.code,
            if refused { 2 } else { 0 },
            "{args:?}: {}",
            r.stderr
        );
    }
}

/// An output named like an existing folder is refused before the trace, nothing written.
/// (A write that fails later leaves nothing either: every output is staged and renamed
/// together, `mirrorbox_files::StagedFiles`.)
#[test]
fn an_output_that_is_a_folder_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let ok = write_scene(d, "ok.json", &scene());
    std::fs::create_dir(d.join("b.exr")).unwrap();
    let (exr, bounces) = (d.join("t.exr"), d.join("b.exr"));
    let args = [
        "trace",
        ok.to_str().unwrap(),
        "-o",
        exr.to_str().unwrap(),
        "--bounces",
        bounces.to_str().unwrap(),
    ];
    let r = mirrorbox(&args, &[]);
    assert_refused(&args, &r, &["--bounces", "b.exr", "is a folder"]);
    assert_eq!(files_in(d), ["b.exr", "ok.json"], "nothing else written");
    // The PNG written beside an output, too: `t.png` a folder refuses `-o t.exr`.
    std::fs::create_dir(d.join("t.png")).unwrap();
    let args = ["trace", ok.to_str().unwrap(), "-o", exr.to_str().unwrap()];
    let r = mirrorbox(&args, &[]);
    assert_refused(
        &args,
        &r,
        &[
            "t.png",
            "-o (its PNG) would write this file, but it is a folder",
        ],
    );
    let png = d.join("t.png");
    let args = ["render", ok.to_str().unwrap(), "-o", png.to_str().unwrap()];
    let r = mirrorbox(&args, &[]);
    assert_refused(&args, &r, &["t.png", "is a folder"]);
    assert_eq!(
        files_in(d),
        ["b.exr", "ok.json", "t.png"],
        "nothing else written"
    );
}

/// A scene with only a camera renders its background with every method, as the tracer does.
#[test]
fn an_empty_scene_renders_its_background_with_every_method() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let empty = json!({
        "camera": { "position": [0, 1, 3], "look_at": [0, 1, 0], "fov_y_deg": 60,
                    "width": 16, "height": 12 },
        "background": [0.25, 0.5, 0.75]
    });
    let path = write_scene(d, "empty.json", &empty);
    let listed = mirrorbox(&["render", "--help"], &[]);
    let methods: Vec<String> = mirrorbox_raster::METHODS
        .iter()
        .map(|e| e.name.to_string())
        .collect();
    assert!(methods.iter().all(|m| listed.stdout.contains(m.as_str())));
    for method in &methods {
        let png = d.join(format!("{method}.png"));
        let args = [
            "render",
            path.to_str().unwrap(),
            "--method",
            method,
            "-o",
            png.to_str().unwrap(),
        ];
        let r = mirrorbox(&args, &[]);
        assert_eq!(r.code, 0, "{method}: {}", r.stderr);
        let image = mirrorbox_image::read_image(&png.with_extension("exr")).unwrap();
        for p in &image.pixels {
            for c in 0..3 {
                assert!(
                    (p[c] - [0.25, 0.5, 0.75][c]).abs() < 1e-6,
                    "{method}: {p:?}"
                );
            }
        }
    }
}

fn small_sweep(scene: &Path, out: &Path, depth: &str) -> std::process::Command {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_mirrorbox"));
    cmd.args([
        "sweep",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--methods",
        "portal",
        "--depth",
        depth,
        "--alpha",
        "0.7",
        "--width",
        "24",
        "--height",
        "16",
        "--frames",
        "1",
        "--warmup",
        "0",
    ]);
    cmd
}

fn keys(out: &Path) -> Vec<String> {
    std::fs::read_to_string(out.join("results.jsonl"))
        .unwrap()
        .lines()
        .map(|l| {
            serde_json::from_str::<Value>(l).unwrap()["key"]
                .as_str()
                .unwrap()
                .to_string()
        })
        .collect()
}

/// A sweep into a folder another process holds is refused at once, naming that process;
/// once free, it runs.
#[test]
fn a_sweep_into_a_folder_in_use_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = write_scene(d, "s.json", &scene());
    let out = d.join("results");
    std::fs::create_dir(&out).unwrap();
    // This test process holds the folder, as a running sweep would.
    let held = mirrorbox_files::FolderLock::try_acquire(&out).unwrap();
    let second = small_sweep(&s, &out, "1").output().unwrap();
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert_eq!(second.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "in use by another process (pid {})",
            std::process::id()
        )),
        "{stderr}"
    );
    assert!(!out.join("results.jsonl").exists(), "nothing measured");
    drop(held);
    let free = small_sweep(&s, &out, "1").output().unwrap();
    assert!(
        free.status.success(),
        "{}",
        String::from_utf8_lossy(&free.stderr)
    );
}

/// A value listed twice is one point (`--depth 1,1`, `--alpha 0.7,0.7`).
#[test]
fn a_value_listed_twice_is_one_point() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = write_scene(d, "s.json", &scene());
    let out = d.join("sweep");
    let mut cmd = small_sweep(&s, &out, "1,1,2,1");
    cmd.args(["--alpha", "0.7,0.7"]);
    let run = cmd.output().unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let k = keys(&out);
    assert_eq!(k.len(), 3, "floor, depth 1, depth 2: {k:?}");
    // Each point timed in its own render worker, interleaved, with its peak memory.
    for line in std::fs::read_to_string(out.join("results.jsonl"))
        .unwrap()
        .lines()
    {
        let r: Value = serde_json::from_str(line).unwrap();
        assert_eq!(r["timing_order"], "interleaved", "{r}");
        assert_eq!(r["frames_ms"].as_array().unwrap().len(), 1, "{r}");
        assert!(r["peak_memory_bytes"].as_u64().unwrap() > 1_000_000, "{r}");
        assert!(r["plan_ms"].as_f64().unwrap() >= 0.0, "{r}");
    }
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3, "{csv}");
}

/// Issue 16: an uneven mirror's bump is checked field by field, its normal map read bounded
/// and decoded before anything renders; every refusal names the field and what is allowed.
#[test]
fn bad_bumps_are_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A grey PNG (not RGB), an RGB map whose texel points into the mirror, a text file.
    let grey = image::GrayImage::from_pixel(4, 4, image::Luma([128]));
    grey.save(d.join("grey.png")).unwrap();
    let mut inward = image::RgbImage::from_pixel(4, 4, image::Rgb([128, 128, 255]));
    inward.put_pixel(2, 1, image::Rgb([128, 128, 100]));
    inward.save(d.join("inward.png")).unwrap();
    std::fs::write(d.join("text.png"), "not a png").unwrap();
    let cases: [(Value, &[&str]); 7] = [
        (json!({}), &["mirrors[0].bump", "needs a \"ripple\""]),
        (
            json!({ "ripple": { "amplitude_deg": 90, "wavelength": 1 } }),
            &["mirrors[0].bump.ripple.amplitude_deg", "[0, 90)"],
        ),
        (
            json!({ "ripple": { "amplitude_deg": 5, "wavelength": 0 } }),
            &["mirrors[0].bump.ripple.wavelength", "greater than 0"],
        ),
        (
            json!({ "normal_map": { "path": "missing.png" } }),
            &["mirrors[0].bump.normal_map.path", "missing.png"],
        ),
        (
            json!({ "normal_map": { "path": "grey.png" } }),
            &["grey.png", "8-bit RGB or RGBA"],
        ),
        (
            json!({ "normal_map": { "path": "inward.png" } }),
            &["inward.png", "texel (2, 1)", "blue 100"],
        ),
        (
            json!({ "normal_map": { "path": "text.png", "strength": 2 } }),
            &["text.png", "not a readable PNG"],
        ),
    ];
    for (k, (bump, fragments)) in cases.iter().enumerate() {
        let mut s = scene();
        s["mirrors"][0]["bump"] = bump.clone();
        let path = write_scene(d, &format!("bump{k}.json"), &s);
        let out = mirrorbox(&["check", path.to_str().unwrap()], &[]);
        assert_refused(&["check", path.to_str().unwrap()], &out, fragments);
    }
    // Mirrored lights are defined for flat mirrors only.
    let mut s = scene();
    s["mirrors"][0]["bump"] = json!({ "ripple": { "amplitude_deg": 5, "wavelength": 1 } });
    s["lighting"] = json!({ "mirrored_lights": 2 });
    let path = write_scene(d, "lit_bump.json", &s);
    let out = mirrorbox(&["check", path.to_str().unwrap()], &[]);
    assert_refused(
        &["check"],
        &out,
        &["lighting.mirrored_lights", "uneven mirrors"],
    );
    // A valid bump loads.
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/textures/hammered.png"),
        d.join("hammered.png"),
    )
    .unwrap();
    let mut s = scene();
    s["mirrors"][1]["bump"] = json!({ "normal_map": { "path": "hammered.png", "tiling": [2, 2] } });
    let path = write_scene(d, "ok_bump.json", &s);
    let out = mirrorbox(&["check", path.to_str().unwrap()], &[]);
    assert_eq!(out.code, 0, "{}", out.stderr);
}
