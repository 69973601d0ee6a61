//! The exchange (issue 53, docs/exchange.md) end to end: `export-views` writes a glTF that
//! traces back to its truth bit for bit, and `score` of our own `render` output, passed
//! through the exchange as if an external client drew it, gives `sweep`'s numbers exactly;
//! bad runs are refused naming the file, with nothing written.

use crate::common::{mirrorbox, repo};
use serde_json::Value;
use std::path::Path;

/// `mirrorbox score EXPORT RUN -o OUT` with `more` arguments.
fn run_score(export: &Path, run: &Path, out: &Path, more: &[&str]) -> crate::common::Output {
    let mut args = vec![
        "score",
        export.to_str().unwrap(),
        run.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(more);
    mirrorbox(&args, &[])
}

const SIZE: [&str; 4] = ["--width", "64", "--height", "36"];

fn export(dir: &Path) {
    export_with(dir, &[]);
}

/// [`export`] with more flags (a view list).
fn export_with(dir: &Path, more: &[&str]) {
    let mut args = vec![
        "export-views",
        "scenes/mirror_box.json",
        "-o",
        dir.to_str().unwrap(),
        "--alpha",
        "0.9",
    ];
    args.extend(more);
    args.extend(SIZE);
    let out = mirrorbox(&args, &[]);
    assert_eq!(out.code, 0, "{}", out.stderr);
}

/// `RUN/mirrorbox/naive/`, where [`our_run`] writes.
fn variant_dir(run: &Path) -> std::path::PathBuf {
    run.join("mirrorbox/naive")
}

fn timing(views: &str) -> String {
    format!(
        r#"{{"format":"mirrorbox-timing","version":1,"engine":"mirrorbox","engine_version":"test",
        "device":"the test's adapter","timing":"GPU timestamps","parameters":{{"method":"naive"}},
        "equivalent":"naive","views":{{{views}}}}}"#
    )
}

/// `RUN/mirrorbox/naive/`: `render --method naive` of the export's view, with a timing file.
fn our_run(run: &Path) -> std::path::PathBuf {
    let variant = run.join("mirrorbox/naive");
    std::fs::create_dir_all(&variant).unwrap();
    let png = variant.join("camera.png");
    let mut args = vec![
        "render",
        "scenes/mirror_box.json",
        "--method",
        "naive",
        "--alpha",
        "0.9",
        "-o",
        png.to_str().unwrap(),
    ];
    args.extend(SIZE);
    let out = mirrorbox(&args, &[]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    std::fs::remove_file(&png).unwrap(); // the EXR beside it is read first anyway
    std::fs::write(
        variant.join("timing.json"),
        timing(r#""camera":[1,1.1,0.9,1,1.2,1]"#),
    )
    .unwrap();
    variant
}

/// `sweep` of `naive` at the export's size and α into `out`: its point's record.
fn sweep_naive(out: &Path) -> Value {
    sweep_naive_of("scenes/mirror_box.json", "0.9", out)
}

/// `sweep SCENE` of `naive` at α `alpha` and the exports' size into `out`: its point's record.
fn sweep_naive_of(scene: &str, alpha: &str, out: &Path) -> Value {
    let mut args = vec!["sweep", scene, "--methods", "naive", "--alpha", alpha];
    args.extend(["--frames", "1", "--out", out.to_str().unwrap()]);
    args.extend(SIZE);
    let done = mirrorbox(&args, &[]);
    assert_eq!(done.code, 0, "{}", done.stderr);
    records(out)
        .into_iter()
        .find(|r| r["method"] == "naive")
        .unwrap()
}

/// `mirrorbox score EXPORT RUN -o OUT`, which must succeed; the records it wrote.
fn score(export: &Path, run: &Path, out: &Path) -> Vec<Value> {
    let path = |p: &Path| p.to_str().unwrap().to_string();
    let (export, run, out_s) = (path(export), path(run), path(out));
    let done = mirrorbox(&["score", &export, &run, "-o", &out_s], &[]);
    assert_eq!(done.code, 0, "{}", done.stderr);
    records(out)
}

fn records(folder: &Path) -> Vec<Value> {
    std::fs::read_to_string(folder.join("results.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn an_export_traces_back_to_its_truth_and_our_render_scores_as_the_sweep_does() {
    let tmp = tempfile::tempdir().unwrap();
    let ex = tmp.path().join("export");
    export(&ex);
    let views: Value =
        serde_json::from_str(&std::fs::read_to_string(ex.join("views.json")).unwrap()).unwrap();
    assert_eq!(views["views"][0]["width"], 64);
    assert_eq!(views["contract"]["version"], 1);
    // The glTF read back through scene.json traces to the exported truth, bit for bit.
    let traced = tmp.path().join("traced.exr");
    let out = mirrorbox(
        &[
            "trace",
            ex.join("scene.json").to_str().unwrap(),
            "-o",
            traced.to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    let out = mirrorbox(
        &[
            "compare",
            ex.join("truth/camera.exr").to_str().unwrap(),
            traced.to_str().unwrap(),
            "--json",
        ],
        &[],
    );
    let c: Value = serde_json::from_str(out.stdout.trim()).unwrap();
    assert_eq!(c["max_abs"], 0.0, "{c}");
    // Our own render, scored through the exchange, against the sweep of the same point.
    let run = tmp.path().join("run");
    our_run(&run);
    let scored = tmp.path().join("scored");
    let ours = &score(&ex, &run, &scored)[0];
    let swept = sweep_naive(&tmp.path().join("sweep"));
    assert_eq!(ours["method"], "mirrorbox-naive");
    assert_eq!(ours["metrics"], swept["metrics"]);
    assert_eq!(ours["mirror_metrics"], swept["mirror_metrics"]);
    assert_eq!(ours["ms_median"], 1.0);
    // The copyable minimal client (clients/minimal/client.py) draws the same through the
    // exchange.
    let minimal_run = tmp.path().join("minimal-run");
    crate::common::succeed(
        std::process::Command::new("python3")
            .arg(repo().join("clients/minimal/client.py"))
            .args([ex.as_os_str(), minimal_run.as_os_str()])
            .args([
                "--frames",
                "1",
                "--mirrorbox",
                env!("CARGO_BIN_EXE_mirrorbox"),
            ]),
        "clients/minimal/client.py",
    );
    let minimal = &score(&ex, &minimal_run, &tmp.path().join("minimal-scored"))[0];
    assert_eq!(minimal["key"], "minimal/naive|camera|a0.9|64x36|ssaa1");
    // Its timing names the adapter that drew, as `render` reports it.
    let timing: Value = serde_json::from_str(
        &std::fs::read_to_string(minimal_run.join("minimal/naive/timing.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(timing["device"], minimal["adapter"], "{timing}");
    // A bad --frames is refused (exit 2); a renderer that fails is named with its own
    // status; neither leaves a folder for `score` to refuse.
    let failed_run = tmp.path().join("failed-run");
    let client = |args: &[&str]| {
        std::process::Command::new("python3")
            .arg(repo().join("clients/minimal/client.py"))
            .args([ex.as_os_str(), failed_run.as_os_str()])
            .args(args)
            .output()
            .unwrap()
    };
    let bad = client(&[
        "--frames",
        "101",
        "--mirrorbox",
        env!("CARGO_BIN_EXE_mirrorbox"),
    ]);
    assert_eq!(bad.status.code(), Some(2));
    let failing = client(&["--frames", "1", "--mirrorbox", "false"]);
    let stderr = String::from_utf8_lossy(&failing.stderr);
    assert!(
        !failing.status.success() && stderr.contains("mirrorbox render exited 1"),
        "{stderr}"
    );
    assert!(!failed_run.join("minimal").exists());
    // Drawn from the scene read back from the glTF (mirrors rebuilt from their rectangles),
    // the raster differs from the sweep's in the last bits only (every metric within 1e-6 of it).
    for (name, want) in swept["metrics"].as_object().unwrap() {
        let (have, want) = (
            minimal["metrics"][name].as_f64().unwrap(),
            want.as_f64().unwrap(),
        );
        assert!(
            (have - want).abs() <= 1e-6 * want.abs().max(1e-12),
            "{name}: {have} vs {want}"
        );
    }
    assert!(
        std::fs::read_to_string(scored.join("report.md"))
            .unwrap()
            .contains("mirrorbox-naive")
    );
}

#[test]
fn a_bad_run_is_refused_naming_the_file_and_nothing_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let ex = tmp.path().join("export");
    export(&ex);
    let run = tmp.path().join("run");
    let variant = our_run(&run);
    let scored = tmp.path().join("scored");
    let score = || run_score(&ex, &run, &scored, &[]);
    let refused = |what: &str, needle: &str| {
        let out = score();
        assert_eq!(out.code, 2, "{what}: {}", out.stderr);
        assert!(out.stderr.contains(needle), "{what}: {}", out.stderr);
        assert!(
            !scored.exists() && !tmp.path().join("scored.partial").exists(),
            "{what}"
        );
    };
    let exr = variant.join("camera.exr");
    let good = std::fs::read(&exr).unwrap();
    // A missing view.
    std::fs::rename(&exr, tmp.path().join("aside.exr")).unwrap();
    refused("missing view", "no image of view \"camera\"");
    // A wrong size.
    let small = mirrorbox_image::RgbImage {
        width: 32,
        height: 18,
        pixels: vec![[0.1; 3]; 32 * 18],
    };
    mirrorbox_image::write_exr(&exr, &small, &[]).unwrap();
    refused("wrong size", "is 32×18; view \"camera\" is 64×36");
    // A NaN and a negative pixel.
    for bad in [f32::NAN, -1.0] {
        let mut img = mirrorbox_image::RgbImage {
            width: 64,
            height: 36,
            pixels: vec![[0.1; 3]; 64 * 36],
        };
        img.pixels[64 * 2 + 5] = [0.1, bad, 0.1];
        mirrorbox_image::write_exr(&exr, &img, &[]).unwrap();
        refused("bad pixel", "pixel (5, 2)");
    }
    // A PNG saved under the EXR's name: said so (the EXR crate had said "file identifier
    // missing").
    let png_bytes = tmp.path().join("as.png");
    mirrorbox_image::write_png(&png_bytes, &small, 1.0).unwrap();
    std::fs::copy(&png_bytes, &exr).unwrap();
    refused("png as exr", "is a PNG file by its first bytes");
    // A folder in the picture's place: said so.
    std::fs::remove_file(&exr).unwrap();
    std::fs::create_dir(&exr).unwrap();
    refused(
        "a folder",
        "view \"camera\"'s picture is not a regular file",
    );
    std::fs::remove_dir(&exr).unwrap();
    // A picture without an extension, and one misnamed alone: each named in the refusal.
    std::fs::write(variant.join("camera"), &good).unwrap();
    refused(
        "no extension",
        "camera is in a format score does not read, or has no extension",
    );
    std::fs::remove_file(variant.join("camera")).unwrap();
    std::fs::write(variant.join("cam.exr"), &good).unwrap();
    refused("misnamed alone", "cam.exr: an image of no view");
    std::fs::remove_file(variant.join("cam.exr")).unwrap();
    std::fs::write(&exr, &good).unwrap();
    // An image of no view (a misnamed view's): it had been skipped unsaid.
    let stray = variant.join("c.exr");
    std::fs::write(&stray, &good).unwrap();
    refused("an image of no view", "c.exr: an image of no view");
    std::fs::remove_file(&stray).unwrap();
    // Two images of one view: the PNG had been ignored unsaid.
    let png = variant.join("camera.png");
    std::fs::write(&png, b"not read").unwrap();
    refused("exr and png", "two images of view \"camera\"");
    std::fs::remove_file(&png).unwrap();
    // No timing file (a run nested a level too deep looks so): the layout is said.
    let timing_file = variant.join("timing.json");
    let timing_text = std::fs::read(&timing_file).unwrap();
    std::fs::remove_file(&timing_file).unwrap();
    refused(
        "no timing",
        "no timing.json: a variant folder RUN/<client>/<variant>/",
    );
    std::fs::write(&timing_file, timing_text).unwrap();
    // An unreadable timing file, one without the view, a negative time, a huge one and a 0.
    for (text, needle) in [
        ("{not json".to_string(), "timing.json"),
        (timing(r#""other":[1]"#), "no frames for view \"camera\""),
        (timing(r#""camera":[1,-2]"#), "-2 ms is not a frame's time"),
        // 1e300 ms had been accepted, and the figures' log axis then hung on it.
        (
            timing(r#""camera":[1e300]"#),
            "ms is not a frame's time (finite, > 0, at most",
        ),
        (
            timing(r#""camera":[1,0]"#),
            "0 ms is not a frame's time (finite, > 0",
        ),
        (
            timing(r#""camera":[1]"#).replace(
                r#""views":{"#,
                r#""scene_hashes":{"camera":"0000000000000000"},"views":{"#,
            ),
            "the run was drawn from another export",
        ),
        (
            timing(r#""camera":[1]"#).replace(r#""equivalent":"naive""#, r#""equivalent":"nave""#),
            "equivalent: \"nave\" is no mirrorbox method",
        ),
    ] {
        std::fs::write(&timing_file, text).unwrap();
        refused("timing", needle);
    }
    std::fs::write(&timing_file, timing(r#""camera":[1]"#)).unwrap();
    // A run that is not there, a run without variants, and an export without views.json.
    let out = run_score(&ex, &tmp.path().join("no-run"), &scored, &[]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(
        out.stderr.contains("no-run: is not a folder"),
        "{}",
        out.stderr
    );
    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let out = run_score(&ex, &empty, &scored, &[]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(
        out.stderr.contains("holds no <client>/<variant>/ folder"),
        "{}",
        out.stderr
    );
    let out = run_score(&run, &run, &scored, &[]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(out.stderr.contains("views.json"), "{}", out.stderr);
    // Two variants whose pictures would share a file (`x_y/z` and `x/y_z`).
    for (client, variant) in [("x_y", "z"), ("x", "y_z")] {
        let copy = run.join(client).join(variant);
        std::fs::create_dir_all(&copy).unwrap();
        for f in ["camera.exr", "timing.json"] {
            std::fs::copy(variant_dir(&run).join(f), copy.join(f)).unwrap();
        }
    }
    refused("shared pictures", "would share images/x_y_z_camera.png");
    std::fs::remove_dir_all(run.join("x_y")).unwrap();
    std::fs::remove_dir_all(run.join("x")).unwrap();
    // Two variants that would be one method (`x-y/z` and `x/y-z`), and a variant named as
    // one of ours (`path/textures`): their rows had been told apart by nothing.
    let copy_variant = |client: &str, variant: &str| {
        let copy = run.join(client).join(variant);
        std::fs::create_dir_all(&copy).unwrap();
        for f in ["camera.exr", "timing.json"] {
            std::fs::copy(variant_dir(&run).join(f), copy.join(f)).unwrap();
        }
    };
    copy_variant("x-y", "z");
    copy_variant("x", "y-z");
    refused("one method", "would both be method \"x-y-z\"");
    std::fs::remove_dir_all(run.join("x-y")).unwrap();
    std::fs::remove_dir_all(run.join("x")).unwrap();
    copy_variant("path", "textures");
    refused("our method's name", "the name of mirrorbox's own method");
    std::fs::remove_dir_all(run.join("path")).unwrap();
    // A client's hidden staging folder (being written, or left by a killed client) is no
    // client: it had been refused as a name with a dot.
    copy_variant(".x.tmp-123", "v");
    // A client named as the report's own pictures begin.
    let reserved = run.join("truth").join("v");
    std::fs::create_dir_all(&reserved).unwrap();
    for f in ["camera.exr", "timing.json"] {
        std::fs::copy(variant_dir(&run).join(f), reserved.join(f)).unwrap();
    }
    refused(
        "reserved client",
        "client name \"truth\" is the report's own",
    );
    std::fs::remove_dir_all(run.join("truth")).unwrap();
    // Now it scores.
    assert_eq!(score().code, 0);
    // A sweep's folder as OUT is refused, not replaced: a sweep has a sweep.json too.
    let sweep = tmp.path().join("sweep");
    sweep_naive(&sweep);
    let before = std::fs::read(sweep.join("results.jsonl")).unwrap();
    let out = run_score(&ex, &run, &sweep, &[]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(
        out.stderr.contains("holds a sweep of") && out.stderr.contains("not an earlier score"),
        "{}",
        out.stderr
    );
    assert_eq!(std::fs::read(sweep.join("results.jsonl")).unwrap(), before);
    // Also a sweep stopped before its first point (no records to load): its sweep.json says
    // it is no score.
    std::fs::write(sweep.join("results.jsonl"), "").unwrap();
    let out = run_score(&ex, &run, &sweep, &[]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(
        out.stderr.contains("not an earlier score"),
        "{}",
        out.stderr
    );
    std::fs::write(sweep.join("results.jsonl"), &before).unwrap();
    // And an earlier score is no sweep to set beside a run.
    let out = run_score(&ex, &run, &scored, &["--with", scored.to_str().unwrap()]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(
        out.stderr.contains("an earlier score, not a sweep of ours"),
        "{}",
        out.stderr
    );
    let _ = repo();
}

/// A folder is replaced only when it holds an earlier export: a user's own `views.json` (a
/// `--views` list kept beside their notes) had been taken for one, and the folder replaced
/// whole. An earlier export is replaced.
#[test]
fn an_export_replaces_only_an_earlier_export() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("mine");
    std::fs::create_dir(&dir).unwrap();
    std::fs::write(dir.join("notes.txt"), "keep").unwrap();
    let list = r#"{"views":[{"name":"a","position":[0,1.5,0],"look_at":[0,1.5,-1]}]}"#;
    std::fs::write(dir.join("views.json"), list).unwrap();
    let mut args = vec![
        "export-views",
        "scenes/mirror_box.json",
        "-o",
        dir.to_str().unwrap(),
    ];
    args.extend(SIZE);
    crate::common::assert_refused(&args, "holds no earlier export (its views.json)");
    assert!(dir.join("notes.txt").is_file());
    assert_eq!(
        std::fs::read_to_string(dir.join("views.json")).unwrap(),
        list
    );
    let earlier = tmp.path().join("earlier");
    export(&earlier);
    export(&earlier);
    // Views `score` could not compare within its memory budget: refused before tracing.
    let huge = tmp.path().join("huge");
    crate::common::assert_refused(
        &[
            "export-views",
            "scenes/mirror_box.json",
            "-o",
            huge.to_str().unwrap(),
            "--width",
            "8192",
            "--height",
            "8192",
        ],
        "8192×8192 would need about 7.5 GB to score",
    );
    assert!(!huge.exists() && !tmp.path().join("huge.partial").exists());
}

/// The export is an input too: a views.json an export could not have written (no view, a
/// name used as a path) and a truth that is missing, of another size or not radiance are
/// refused naming the export's file, exit 2, before anything is written. (An empty list
/// panicked; the truths were read only while writing, failed with exit 1 naming `.partial`
/// files, and a NaN in a truth gave `"rmse": null` records.)
#[test]
fn a_bad_export_is_refused_naming_its_file_before_anything_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let ex = tmp.path().join("export");
    export(&ex);
    let run = tmp.path().join("run");
    our_run(&run);
    let scored = tmp.path().join("scored");
    let refused = |what: &str, needles: &[&str]| {
        let out = run_score(&ex, &run, &scored, &[]);
        assert_eq!(out.code, 2, "{what}: {}", out.stderr);
        for needle in needles {
            assert!(out.stderr.contains(needle), "{what}: {}", out.stderr);
        }
        assert!(!out.stderr.contains(".partial"), "{what}: {}", out.stderr);
        assert!(
            !scored.exists() && !tmp.path().join("scored.partial").exists(),
            "{what}"
        );
    };
    let views_file = ex.join("views.json");
    let good_views = std::fs::read_to_string(&views_file).unwrap();
    let mut views: Value = serde_json::from_str(&good_views).unwrap();
    views["views"] = serde_json::json!([]);
    std::fs::write(&views_file, views.to_string()).unwrap();
    refused("no view", &["views.json", "views: 0 views; 1 to 64"]);
    let mut views: Value = serde_json::from_str(&good_views).unwrap();
    views["alpha"] = serde_json::json!(5);
    std::fs::write(&views_file, views.to_string()).unwrap();
    refused("alpha", &["views.json", "alpha 5: a reflectance, 0 to 1"]);
    // Views larger than a comparison fits in the memory budget (compare's default).
    let mut views: Value = serde_json::from_str(&good_views).unwrap();
    views["views"][0]["width"] = 8192.into();
    views["views"][0]["height"] = 8192.into();
    std::fs::write(&views_file, views.to_string()).unwrap();
    refused(
        "huge",
        &["views.json", "views[0]: 8192×8192 would need about 7.5 GB"],
    );
    let mut views: Value = serde_json::from_str(&good_views).unwrap();
    views["views"][0]["name"] = "../../x".into();
    std::fs::write(&views_file, views.to_string()).unwrap();
    refused(
        "a name that is a path",
        &["views.json", "views[0].name \"../../x\""],
    );
    std::fs::write(&views_file, &good_views).unwrap();
    let truth = ex.join("truth/camera.exr");
    let good_truth = std::fs::read(&truth).unwrap();
    std::fs::remove_file(&truth).unwrap();
    refused("a missing truth", &["views[0].truth", "truth/camera.exr"]);
    let small = mirrorbox_image::RgbImage {
        width: 32,
        height: 18,
        pixels: vec![[0.1; 3]; 32 * 18],
    };
    mirrorbox_image::write_exr(&truth, &small, &[]).unwrap();
    refused(
        "a truth of another size",
        &["truth/camera.exr", "is 32×18; view \"camera\" is 64×36"],
    );
    for bad in [f32::NAN, f32::INFINITY] {
        let mut img = mirrorbox_image::RgbImage {
            width: 64,
            height: 36,
            pixels: vec![[0.1; 3]; 64 * 36],
        };
        img.pixels[64 * 3 + 7] = [bad, 0.1, 0.1];
        mirrorbox_image::write_exr(&truth, &img, &[]).unwrap();
        refused(
            "a truth that is not radiance",
            &["truth/camera.exr", "pixel (7, 3)"],
        );
    }
    std::fs::write(&truth, &good_truth).unwrap();
    let picture = ex.join("truth/camera.png");
    std::fs::rename(&picture, tmp.path().join("aside.png")).unwrap();
    refused(
        "a truth without its picture",
        &["views[0].truth", "truth/camera.png"],
    );
    std::fs::rename(tmp.path().join("aside.png"), &picture).unwrap();
    // The floor truth is read for a variant named `floor` only.
    let floor_variant = run.join("mirrorbox/floor");
    std::fs::create_dir_all(&floor_variant).unwrap();
    for f in ["camera.exr", "timing.json"] {
        std::fs::copy(run.join("mirrorbox/naive").join(f), floor_variant.join(f)).unwrap();
    }
    std::fs::remove_file(ex.join("truth/camera_floor.exr")).unwrap();
    refused(
        "a missing floor truth",
        &["views[0].floor", "truth/camera_floor.exr"],
    );
}

/// `score --with SWEEP` copies the pictures SWEEP's records name into its report: a name
/// outside SWEEP's images/ (it copied any file, `../../secret`) or one that is not there is
/// refused, exit 2, naming the record, before anything is written.
#[test]
fn a_with_sweep_naming_pictures_outside_its_images_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let ex = tmp.path().join("export");
    export(&ex);
    let run = tmp.path().join("run");
    our_run(&run);
    let sweep = tmp.path().join("sweep");
    sweep_naive(&sweep);
    let results = sweep.join("results.jsonl");
    let good = std::fs::read_to_string(&results).unwrap();
    std::fs::write(tmp.path().join("secret"), "not a picture").unwrap();
    // A link inside images/ to a file outside it: `is_file` followed it.
    std::os::unix::fs::symlink(tmp.path().join("secret"), sweep.join("images/link.png")).unwrap();
    let scored = tmp.path().join("scored");
    // SWEEP's records with their truth picture named `picture` (as they are: None).
    let with = |picture: Option<&str>| {
        let lines: Vec<String> = good
            .lines()
            .map(|l| {
                let mut r: Value = serde_json::from_str(l).unwrap();
                if let Some(picture) = picture {
                    r["truth_image"] = picture.into();
                }
                r.to_string()
            })
            .collect();
        std::fs::write(&results, lines.join("\n") + "\n").unwrap();
        run_score(&ex, &run, &scored, &["--with", sweep.to_str().unwrap()])
    };
    for (picture, message) in [
        // Refused as the sweep's records are read, by every command that reads them.
        (
            "../secret",
            "is not a path inside the sweep folder (relative, without `..`)",
        ),
        ("/etc/passwd", "is not a path inside the sweep folder"),
        ("images/missing.png", "which is not a file there"),
        ("images/link.png", "not a link"),
    ] {
        let out = with(Some(picture));
        assert_eq!(out.code, 2, "{picture}: {}", out.stderr);
        assert!(out.stderr.contains(message), "{picture}: {}", out.stderr);
        assert!(out.stderr.contains(picture), "{picture}: {}", out.stderr);
        assert!(
            !scored.exists() && !tmp.path().join("scored.partial").exists(),
            "{picture}"
        );
    }
    let out = with(None);
    assert_eq!(out.code, 0, "{}", out.stderr);
    // A sweep of another scene (by content: another hash, even under the exported file's
    // name), or of another α than the export's: refused (before, its floor and points were
    // set beside the variants as if comparable). The same scene under another path is the
    // exported one.
    std::fs::remove_dir_all(&scored).unwrap();
    let changed = |field: &str, value: &Value, all: bool| {
        let lines: Vec<String> = good
            .lines()
            .map(|l| {
                let mut r: Value = serde_json::from_str(l).unwrap();
                if r["kind"] == "point" || all {
                    r[field] = value.clone();
                }
                r.to_string()
            })
            .collect();
        std::fs::write(&results, lines.join("\n") + "\n").unwrap();
        run_score(&ex, &run, &scored, &["--with", sweep.to_str().unwrap()])
    };
    for (field, value, message) in [
        (
            "scene_hash",
            Value::from("00000000deadbeef"),
            "not of the scene exported",
        ),
        (
            "ssaa",
            Value::from(2),
            "ssaa 2; view \"camera\" is 64×36, ssaa 1",
        ),
        (
            "axes",
            serde_json::json!({"camera_yaw_deg": 10.0}),
            "swept along camera_yaw_deg",
        ),
        ("alpha", Value::from(0.5), "not the export's α"),
    ] {
        let out = changed(field, &value, field != "alpha");
        assert_eq!(out.code, 2, "{field}: {}", out.stderr);
        assert!(out.stderr.contains(message), "{field}: {}", out.stderr);
        assert!(!scored.exists(), "{field}: nothing written");
    }
    let out = changed("scene", &Value::from("elsewhere/a_copy.json"), true);
    assert_eq!(out.code, 0, "{}", out.stderr);
    // An export of a view elsewhere, under the scene camera's name: no sweep shows it.
    std::fs::write(&results, &good).unwrap();
    let list = tmp.path().join("list.json");
    std::fs::write(
        &list,
        r#"{"views": [{"name": "camera", "position": [0.5, 1.2, 3], "look_at": [0, 1, 0]}]}"#,
    )
    .unwrap();
    let elsewhere = tmp.path().join("elsewhere");
    export_with(&elsewhere, &["--views", list.to_str().unwrap()]);
    let out = run_score(
        &elsewhere,
        &run,
        &scored,
        &["--with", sweep.to_str().unwrap()],
    );
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(
        out.stderr
            .contains("no view of the export is the scene's own camera"),
        "{}",
        out.stderr
    );
}

/// An export without `--alpha` of a scene whose mirrors share one grey reflectance says that
/// reflectance as its α (`score` labels its records with it and holds `--with` sweeps to it);
/// one whose mirrors differ says none.
#[test]
fn an_export_without_alpha_says_the_scenes_own() {
    let tmp = tempfile::tempdir().unwrap();
    let alpha_of = |scene: &str| {
        let dir = tmp.path().join(scene.replace('/', "_"));
        let mut args = vec!["export-views", scene, "-o", dir.to_str().unwrap()];
        args.extend(SIZE);
        let out = mirrorbox(&args, &[]);
        assert_eq!(out.code, 0, "{}", out.stderr);
        let doc: Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("views.json")).unwrap())
                .unwrap();
        assert!(doc["sweep_scene_hash"].is_string() && doc["views"][0]["scene_camera"] == true);
        doc["alpha"].clone()
    };
    assert_eq!(alpha_of("scenes/mirror_box.json"), Value::from(0.9));
    let uneven = tmp.path().join("uneven.json");
    let box_scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mirror_box.json");
    let text = std::fs::read_to_string(box_scene).unwrap();
    let text = text.replacen("[0.9, 0.9, 0.9]", "[0.8, 0.8, 0.8]", 1);
    std::fs::write(&uneven, text).unwrap();
    assert_eq!(alpha_of(uneven.to_str().unwrap()), Value::Null);
    // A sweep (one α for every mirror) is no view of that export's scene: refused beside it.
    let sweep = tmp.path().join("sweep");
    sweep_naive_of(uneven.to_str().unwrap(), "0.8", &sweep);
    let run = tmp.path().join("run");
    our_run(&run);
    let export = tmp.path().join(uneven.to_str().unwrap().replace('/', "_"));
    let out = run_score(
        &export,
        &run,
        &tmp.path().join("scored"),
        &["--with", sweep.to_str().unwrap()],
    );
    assert_eq!(out.code, 2, "{}", out.stderr);
    assert!(
        out.stderr.contains("have different reflectances"),
        "{}",
        out.stderr
    );
    // Scored alone, its records say their α is per mirror, not the 1 they carry.
    let scored = tmp.path().join("scored_alone");
    let records = score(&export, &run, &scored);
    assert!(!records.is_empty());
    assert!(
        records
            .iter()
            .all(|r| r["values"]["alpha_per_mirror"] == 1.0),
        "{records:?}"
    );
    let md = std::fs::read_to_string(scored.join("report.md")).unwrap();
    // Every row of "All points" says so in its α column, and no sentence says α = 1.
    let table: Vec<&str> = md
        .split("## All points")
        .nth(1)
        .unwrap()
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .collect();
    assert!(!table.is_empty(), "{md}");
    for row in table {
        assert_eq!(row.split('|').nth(2).unwrap().trim(), "per mirror", "{row}");
    }
    assert!(!md.contains("α = 1") && !md.contains("α=1"), "{md}");
}

#[test]
fn a_bad_view_list_is_refused_naming_the_field() {
    let tmp = tempfile::tempdir().unwrap();
    let list = tmp.path().join("views.json");
    let ex = tmp.path().join("export");
    for (text, needle) in [
        (r#"{"views": []}"#, "0 views; 1 to 64"),
        (
            r#"{"views": [{"name": "a b", "position": [0,1,2], "look_at": [0,0,0]}]}"#,
            "views[0].name",
        ),
        (
            r#"{"views": [{"name": "a", "position": [0,1,2], "look_at": [0,0,0]}, {"name": "a", "position": [0,1,2], "look_at": [0,0,0]}]}"#,
            "views[1].name \"a\" appears twice",
        ),
        // View a's floor truth is truth/a_floor.exr: view a_floor's truth overwrote it.
        (
            r#"{"views": [{"name": "a", "position": [0,1,2], "look_at": [0,0,0]}, {"name": "a_floor", "position": [0,1,3], "look_at": [0,0,0]}]}"#,
            "views[1].name \"a_floor\": the floor truth of views[0] \"a\" has that name",
        ),
        (
            r#"{"views": [{"name": "a", "position": [0,1,2], "look_at": [0,1,2]}]}"#,
            "views.json: views[0] (\"a\"): position and look_at must be apart",
        ),
        // Looking straight down without an up: only the scene's camera (up +y) shows the
        // problem, and the file and the view are named all the same.
        (
            r#"{"views": [{"name": "top", "position": [0,5,0], "look_at": [0,0,0]}]}"#,
            "views.json: views[0]: view \"top\": up must be finite and not along the view \
             direction (up is the scene camera's: the view gives none)",
        ),
    ] {
        std::fs::write(&list, text).unwrap();
        let out = mirrorbox(
            &[
                "export-views",
                "scenes/mirror_box.json",
                "-o",
                ex.to_str().unwrap(),
                "--views",
                list.to_str().unwrap(),
                "--width",
                "32",
                "--height",
                "18",
            ],
            &[],
        );
        assert_eq!(out.code, 2, "{text}: {}", out.stderr);
        assert!(out.stderr.contains(needle), "{text}: {}", out.stderr);
        assert!(
            !ex.exists() && !tmp.path().join("export.partial").exists(),
            "{text}"
        );
    }
}

/// The web clients (clients/web: three.js 0.187 and Babylon.js 9.28 in headless Chromium on
/// SwiftShader) draw mirror_box through the exchange: each floor (no mirrors) stays within
/// 10⁻² FLIP of the floor truth (three measured 5.2·10⁻³ at 64×36: SwiftShader snaps vertices
/// to 1/16 pixel), so both follow the shading contract; three's `Reflector` — two levels of
/// reflection, as `naive` — within 2.5× `naive`'s error over the mirror pixels (measured 1.7×:
/// its half-float, 4× MSAA target), and above its floor; Babylon's `MirrorTexture` above its
/// floor and below 0.5 (a mirror it drew black or left diffuse would not be). An export lit
/// with shadows is refused before any browser starts (its lighting would score as theirs).
#[test]
fn web_clients_score_within_their_stated_bounds() {
    let web = repo().join("clients/web");
    let present = mirrorbox_testing::on_path("node")
        && mirrorbox_testing::on_path("chromium-headless-shell")
        && web.join("node_modules/three/package.json").is_file()
        && web
            .join("node_modules/@babylonjs/core/package.json")
            .is_file()
        && web
            .join("node_modules/puppeteer-core/package.json")
            .is_file();
    if !mirrorbox_testing::require(
        mirrorbox_testing::WEB,
        present,
        "node, chromium-headless-shell or clients/web's packages (scripts/install-web-clients.sh) missing",
    ) {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let ex = tmp.path().join("export");
    export(&ex);
    let run = tmp.path().join("run");
    let out = std::process::Command::new("node")
        .arg(web.join("run.mjs"))
        .args([ex.as_os_str(), run.as_os_str()])
        .args([
            "--clients",
            "three,babylon",
            "--variants",
            "floor,reflector,mirrortexture",
            "--frames",
            "1",
            "--warmup",
            "1",
        ])
        .output()
        .expect("node runs");
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let scored = score(&ex, &run, &tmp.path().join("scored"));
    let floor_of = |client: &str| {
        scored
            .iter()
            .find(|r| r["kind"] == "floor" && r["method"] == client)
            .unwrap_or_else(|| panic!("no {client} floor"))
    };
    let floor = floor_of("three");
    let reflector = scored
        .iter()
        .find(|r| r["method"] == "three-reflector")
        .unwrap();
    assert!(
        reflector["method_options"]
            .as_str()
            .unwrap()
            .contains("equivalent=naive")
    );
    let floor_flip = floor["metrics"]["flip_mean"].as_f64().unwrap();
    assert!(floor_flip <= 1e-2, "three's floor FLIP {floor_flip}");
    let naive = sweep_naive(&tmp.path().join("naive"));
    let mirror_flip = |r: &Value| r["mirror_metrics"]["flip_mean"].as_f64().unwrap();
    let (theirs, ours) = (mirror_flip(reflector), mirror_flip(&naive));
    assert!(
        theirs <= 2.5 * ours,
        "Reflector {theirs} against naive {ours}"
    );
    assert!(
        theirs > floor_flip,
        "Reflector {theirs} against its floor {floor_flip}"
    );
    let babylon_floor = floor_of("babylon")["metrics"]["flip_mean"]
        .as_f64()
        .unwrap();
    assert!(
        babylon_floor <= 1e-2,
        "Babylon's floor FLIP {babylon_floor}"
    );
    let mirror_texture = scored
        .iter()
        .find(|r| r["method"] == "babylon-mirrortexture")
        .unwrap();
    let babylon = mirror_flip(mirror_texture);
    assert!(
        babylon > babylon_floor && babylon < 0.5,
        "MirrorTexture {babylon} against its floor {babylon_floor}"
    );
    // A lit export: refused, exit 2, nothing written.
    let lit = tmp.path().join("lit");
    let out = mirrorbox(
        &[
            "export-views",
            "scenes/mirror_box_lit.json",
            "-o",
            lit.to_str().unwrap(),
            "--width",
            "32",
            "--height",
            "18",
        ],
        &[],
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    let lit_run = tmp.path().join("lit_run");
    let out = std::process::Command::new("node")
        .arg(web.join("run.mjs"))
        .args([lit.as_os_str(), lit_run.as_os_str()])
        .output()
        .expect("node runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--allow-unsupported-lighting"), "{stderr}");
    assert!(!lit_run.exists());
}

/// The mistakes a client makes that score as a large error and nothing else are said: a
/// picture upside down, an EXR holding sRGB-encoded values (scored as given, exit 0, a
/// warning and a line in variants.md); and the pictures that cannot be read as the docs say
/// are refused: a 16-bit PNG (it had been cut to 8 bits unsaid), an EXR of unsigned integers
/// (scored as radiance), a file named in another case (named in the error).
#[test]
fn a_picture_upside_down_or_srgb_encoded_is_said_and_an_unreadable_one_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let ex = tmp.path().join("export");
    export(&ex);
    let run = tmp.path().join("run");
    let variant = our_run(&run);
    let exr = variant.join("camera.exr");
    let good = mirrorbox_image::read_image(&exr).unwrap();
    let (w, h) = (good.width as usize, good.height as usize);
    let write = |img: &mirrorbox_image::RgbImage| {
        mirrorbox_image::write_exr(&exr, img, &[]).unwrap();
    };
    let mut flipped = good.clone();
    for y in 0..h {
        flipped.pixels[y * w..(y + 1) * w]
            .copy_from_slice(&good.pixels[(h - 1 - y) * w..(h - y) * w]);
    }
    let mut encoded = good.clone();
    for p in &mut encoded.pixels {
        *p = p.map(mirrorbox_image::srgb::encode);
    }
    for (picture, says) in [
        (&good, None),
        (&flipped, Some("upside down?")),
        (&encoded, Some("sRGB-encoded?")),
    ] {
        write(picture);
        let scored = tmp.path().join("scored");
        let out = run_score(&ex, &run, &scored, &[]);
        assert_eq!(out.code, 0, "{}", out.stderr);
        let variants = std::fs::read_to_string(scored.join("variants.md")).unwrap();
        match says {
            None => assert!(
                !out.stderr.contains("warning") && !variants.contains("mis-encoded"),
                "{}",
                out.stderr
            ),
            Some(says) => {
                assert!(
                    out.stderr
                        .contains(&format!("warning: {}: {says}", exr.display())),
                    "{}",
                    out.stderr
                );
                assert!(variants.contains(says), "{variants}");
            }
        }
    }
    write(&good);
    // Each refused exit 2, naming the file and why, and writing nothing.
    let refused = |name: &str, says: &[&str]| {
        let scored = tmp.path().join(name);
        let out = run_score(&ex, &run, &scored, &[]);
        assert_eq!(out.code, 2, "{name}: {}", out.stderr);
        for s in says {
            assert!(out.stderr.contains(s), "{name}: {s}: {}", out.stderr);
        }
        assert!(!scored.exists(), "{name}");
    };
    // A JPEG beside it is no view's picture, and harmless.
    std::fs::write(variant.join("camera.jpg"), b"not read").unwrap();
    let out = run_score(&ex, &run, &tmp.path().join("beside"), &[]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    // The view's picture as a JPEG only: named.
    std::fs::rename(&exr, tmp.path().join("kept.exr")).unwrap();
    refused(
        "jpg",
        &[
            "no image of view \"camera\"",
            "camera.jpg is in a format score does not read",
        ],
    );
    std::fs::rename(tmp.path().join("kept.exr"), &exr).unwrap();
    std::fs::remove_file(variant.join("camera.jpg")).unwrap();
    // A 16-bit PNG in its place.
    std::fs::remove_file(&exr).unwrap();
    let png = variant.join("camera.png");
    image::ImageBuffer::<image::Rgb<u16>, _>::from_pixel(
        w as u32,
        h as u32,
        image::Rgb([30000u16; 3]),
    )
    .save(&png)
    .unwrap();
    refused("s16", &["a PNG is read as 8 bits a channel", "camera.png"]);
    // Named in another case.
    std::fs::rename(&png, variant.join("Camera.PNG")).unwrap();
    refused(
        "case",
        &["Camera.PNG: an image of no view (it differs only in case from view \"camera\")"],
    );
    std::fs::remove_file(variant.join("Camera.PNG")).unwrap();
    // An EXR of unsigned integers.
    {
        use exr::prelude::*;
        let channels = SpecificChannels::rgb(|_: Vec2<usize>| (1u32, 1u32, 1u32));
        Image::from_channels((w, h), channels)
            .write()
            .to_file(&exr)
            .unwrap();
    }
    refused("u32", &["holds unsigned integers"]);
}
