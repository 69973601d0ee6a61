//! Agreement with Mitsuba 3 at tiny resolution, both integrators, on `mirror_box`.
//! Needs `tools/mitsuba/setup.sh`; `scripts/test.sh` runs it and sets
//! `MIRRORBOX_MITSUBA_PYTHON`. Without it the tests fail, unless `MIRRORBOX_TEST_SKIP` names
//! `mitsuba` (`mirrorbox_testing`).

use mirrorbox_image::{RgbImage, read_image};
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Mitsuba's Python (`MIRRORBOX_MITSUBA_PYTHON`); where it is not there, a failure, or `None`
/// where `MIRRORBOX_TEST_SKIP` names `mitsuba`.
fn python() -> Option<String> {
    let (present, reason) = match std::env::var("MIRRORBOX_MITSUBA_PYTHON") {
        Ok(p) if Path::new(&p).is_file() => return Some(p),
        Ok(p) => (
            false,
            format!("MIRRORBOX_MITSUBA_PYTHON names {p}, which is not a file"),
        ),
        Err(_) => (false, "MIRRORBOX_MITSUBA_PYTHON is not set".to_string()),
    };
    mirrorbox_testing::require(mirrorbox_testing::MITSUBA, present, &reason);
    None
}

fn run(program: &str, args: &[&str]) {
    let what = format!("{program} {args:?}");
    crate::common::succeed(Command::new(program).args(args).current_dir(repo()), &what);
}

/// Renders `mirror_box` with both renderers and returns (ours, Mitsuba).
fn both(py: &str, dir: &Path, integrator: &str, spp: &str, depth: &str) -> (RgbImage, RgbImage) {
    both_of(py, "scenes/mirror_box.json", dir, integrator, spp, depth)
}

/// Renders `scene` with both renderers at 64×36 and returns (ours, Mitsuba).
fn both_of(
    py: &str,
    scene: &str,
    dir: &Path,
    integrator: &str,
    spp: &str,
    depth: &str,
) -> (RgbImage, RgbImage) {
    let bin = env!("CARGO_BIN_EXE_mirrorbox");
    let d = dir.join(integrator);
    // An output's folder must exist (every command's rule).
    std::fs::create_dir_all(&d).unwrap();
    let xml = d.join("scene.xml");
    let (ours, theirs) = (d.join("ours.exr"), d.join("mitsuba.exr"));
    let size = ["--width", "64", "--height", "36"];
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (xml_s, ours_s, theirs_s) = (s(&xml), s(&ours), s(&theirs));
    let mut export = vec!["export-mitsuba", scene, "-o", &xml_s, "--spp", spp];
    export.extend(size);
    run(bin, &export);
    let mut trace = vec![
        "trace",
        scene,
        "-o",
        &ours_s,
        "--spp",
        spp,
        "--integrator",
        integrator,
    ];
    // Whitted's cut counts reflections; path's counts segments (Mitsuba's max_depth), with
    // Russian roulette kept out of the comparison.
    // Jittered, as Mitsuba's `path` samples independently (render.py): both then estimate
    // the pixel's box filter over its area (the unjittered grid is a quadrature of its own).
    if integrator == "path" {
        trace.extend(["--max-segments", depth, "--rr-from", "1000000", "--jitter"]);
    } else {
        trace.extend(["--max-depth", depth]);
    }
    trace.extend(size);
    run(bin, &trace);
    run(
        py,
        &[
            "tools/mitsuba/render.py",
            &xml_s,
            "-o",
            &theirs_s,
            "--integrator",
            integrator,
            "--max-depth",
            depth,
            "--runs",
            "0",
        ],
    );
    (read_image(&ours).unwrap(), read_image(&theirs).unwrap())
}

#[test]
fn whitted_agrees_with_mitsuba() {
    let Some(py) = python() else { return };
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = both(&py, dir.path(), "whitted", "4", "10000");
    // Deterministic, same sub-pixel grid: only silhouette samples that land on another
    // triangle may differ (measured: 0.03 % of pixels at 160×90, mean |d| 8e-6).
    let d = channel_differences(&a, &b);
    let mean = d.iter().sum::<f32>() / d.len() as f32;
    let off = d.iter().filter(|&&x| x > 1e-3).count();
    assert!(mean < 1e-4, "mean |d| {mean}");
    assert!(
        off * 100 < d.len(),
        "{off} of {} pixels differ by > 1e-3",
        d.len()
    );
}

/// The benchmark's Mitsuba baseline (issue 41) is the leanest formulation of the contract
/// found (`tools/mitsuba/render.py`'s `whitted`: coherent camera rays, no sampler draws, one
/// reflectance lookup per hit for all point lights); it must be the same image as the
/// contract in Mitsuba's general form (`whitted-bsdf`), or the benchmark would measure a
/// different picture. Scenes with point lights, an area emitter, textures and uneven
/// mirrors; equal to f32 rounding (measured at 640×360: max |d| 3.6e-7 on `mirror_box`,
/// 3.0e-7 on `mirror_room`; at 64×36 relative 2.2e-7 on `mirror_box_lit`'s lamp).
#[test]
fn lean_whitted_formulation_is_the_same_image() {
    let Some(py) = python() else { return };
    let bin = env!("CARGO_BIN_EXE_mirrorbox");
    let dir = tempfile::tempdir().unwrap();
    for scene in [
        "scenes/mirror_box.json",
        "scenes/mirror_box_lit.json",
        "scenes/textured_box.json",
        "scenes/bumpy_pair.json",
    ] {
        let d = dir.path().join(scene.replace('/', "_"));
        std::fs::create_dir_all(&d).unwrap();
        let xml = d.join("scene.xml").to_str().unwrap().to_string();
        let size = ["--width", "64", "--height", "36"];
        let mut export = vec!["export-mitsuba", scene, "-o", &xml, "--spp", "4"];
        export.extend(size);
        run(bin, &export);
        let render = |integrator: &str| {
            let out = d.join(format!("{integrator}.exr"));
            let out_s = out.to_str().unwrap().to_string();
            run(
                &py,
                &[
                    "tools/mitsuba/render.py",
                    &xml,
                    "-o",
                    &out_s,
                    "--integrator",
                    integrator,
                    "--runs",
                    "0",
                ],
            );
            read_image(&out).unwrap()
        };
        let (lean, general) = (render("whitted"), render("whitted-bsdf"));
        // Relative above 1: a lamp seen directly is ~550, where f32 rounding is ~6e-5.
        let max = lean
            .pixels
            .iter()
            .flatten()
            .zip(general.pixels.iter().flatten())
            .map(|(&a, &b)| (a - b).abs() / b.abs().max(1.0))
            .fold(0.0f32, f32::max);
        println!("{scene}: lean vs general Whitted formulation: max |d| / max(1, |v|) {max:.2e}");
        assert!(max < 1e-5, "{scene}: max relative |d| {max}");
    }
}

/// Textures (`docs/shading.md`, "Textures") through Mitsuba's `bitmap`: the project's textured
/// glTF scene (base colour and emissive textures, a texture transform, repeat, mirrored-repeat
/// and clamped samplers, a mirror and a point light from the asset) agrees in the mean as the
/// untextured Whitted check does (measured 6.5e-5 at 64×36; the export with the transform's
/// translation lost, a bug this test found, gave 4.8e-3). More pixels differ by > 1e-3 than
/// there (1.6 % at 64×36, 1.1 % at 320×180, measured): minified textures deep in the
/// reflections, where a hit point 1e-6 away in the other renderer's arithmetic reads other
/// texels (no mip-maps, by the contract); hence 3 %.
#[test]
fn textured_gltf_agrees_with_mitsuba() {
    let Some(py) = python() else { return };
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = both_of(
        &py,
        "scenes/textured_box.json",
        dir.path(),
        "whitted",
        "4",
        "10000",
    );
    let d = channel_differences(&a, &b);
    let mean = d.iter().sum::<f32>() / d.len() as f32;
    let off = d.iter().filter(|&&x| x > 1e-3).count();
    println!(
        "textured_box: mean |d| {mean:.3e}, {off} of {} pixels off by > 1e-3",
        d.len()
    );
    assert!(mean < 1e-4, "mean |d| {mean}");
    assert!(
        off * 100 < 3 * d.len(),
        "{off} of {} pixels differ by > 1e-3",
        d.len()
    );
}

/// Per pixel, the largest |difference| of its three channels.
fn channel_differences(a: &RgbImage, b: &RgbImage) -> Vec<f32> {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0, f32::max))
        .collect()
}

/// Block means of the per-pixel difference (k×k blocks, all channels).
fn block_differences(a: &RgbImage, b: &RgbImage, k: u32) -> Vec<f64> {
    let mut out = Vec::new();
    for by in 0..a.height / k {
        for bx in 0..a.width / k {
            let mut s = 0.0f64;
            for y in by * k..(by + 1) * k {
                for x in bx * k..(bx + 1) * k {
                    let (p, q) = (a.get(x, y), b.get(x, y));
                    s += (0..3).map(|c| (p[c] - q[c]) as f64).sum::<f64>();
                }
            }
            out.push(s / (3 * k * k) as f64);
        }
    }
    out
}

/// Monte Carlo: the two image means must agree within a tolerance set by measured noise.
/// Both renderers take unbiased samples (render.py's `path` an independent sampler, ours
/// `--jitter`; Mitsuba's unjittered grid had put `mirror_room` 0.12 % low, docs/mitsuba.md).
/// Independent samples are noisier than the old grid: at this size the image mean of one
/// Mitsuba render varies by 0.22 % at 256 spp and 0.074 % at 1024 (standard deviations over 16
/// and 8 seeds, 2026-12-01), ours by 0.032 % at 256: at 1024 spp the 0.5 % tolerance is ~6.7σ
/// (at 256 it had been ~2.3σ, a failure every few dozen runs). The block t statistic is held
/// loosely (|t| < 4.5).
#[test]
fn path_agrees_with_mitsuba_within_monte_carlo_noise() {
    let Some(py) = python() else { return };
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = both(&py, dir.path(), "path", "1024", "66");
    assert_means_agree("mirror_box", &a, &b, 0.005);
}

/// Light through mirrors checked by an independent renderer (issue 15): `mirror_box_lit`
/// lit only by its emissive lamp (its point light removed), whose light reaches the floor and
/// the objects through the mirrors by each renderer's own sampling — the area-light version
/// of the scene whose point light `whitted` mirrors by images.
#[test]
fn light_through_mirrors_agrees_with_mitsuba() {
    let Some(py) = python() else { return };
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(repo().join("scenes/mirror_box_lit.json")).unwrap();
    let mut scene: serde_json::Value = serde_json::from_str(&text).unwrap();
    scene["lights"] = serde_json::json!([]);
    let path = dir.path().join("lamp_only.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    let (a, b) = both_of(
        &py,
        path.to_str().unwrap(),
        dir.path(),
        "path",
        "2304",
        "66",
    );
    // A small emitter found through mirrors by BSDF sampling alone is noisier than the point
    // light of `mirror_box`: 2304 spp (Mitsuba's image mean then varies by about 0.09 %
    // between seeds, 8 seeds, 2026-12-01), 1 %.
    assert_means_agree("mirror_box_lit, lamp only", &a, &b, 0.01);
}

/// The two image means agree within `tolerance` (relative), with the block t statistic
/// checked loosely (see the doc of the test above).
fn assert_means_agree(what: &str, a: &RgbImage, b: &RgbImage, tolerance: f64) {
    let d = block_differences(a, b, 4);
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let sd = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let t = mean / (sd / n.sqrt());
    let image_mean = a
        .pixels
        .iter()
        .flat_map(|p| p.iter())
        .map(|&v| v as f64)
        .sum::<f64>()
        / (3 * a.pixels.len()) as f64;
    println!(
        "{what}: path vs Mitsuba: {} blocks, mean difference {mean:.3e} ({:.3} % of {image_mean:.4}), t = {t:.2}",
        d.len(),
        100.0 * mean / image_mean
    );
    assert!(t.abs() < 4.5, "{what}: t = {t}");
    assert!(
        (mean / image_mean).abs() < tolerance,
        "{what}: relative mean difference {}",
        mean / image_mean
    );
}

/// Uneven mirrors (issue 16) against Mitsuba's `normalmap` BSDF wrapping the `conductor`:
/// the hammered single mirror (a normal map, exported exactly) and the rippled box (the
/// ripple baked at 48 texels per wavelength), Whitted, 16 spp. Both renderers follow the
/// same rule where a reflection would leave behind the mirror (docs/shading.md). Measured
/// 2026-11-24 at 64×36: mean |d| 5.3e-7 (single), 1.5e-4 with 0.48 % of pixels off by more
/// than 1e-2 (the baked ripple). The bump must matter: the flat scene's truth is far from
/// Mitsuba's uneven one.
#[test]
fn uneven_mirrors_agree_with_mitsuba() {
    let Some(py) = python() else { return };
    let dir = tempfile::tempdir().unwrap();
    let mean_off = |a: &RgbImage, b: &RgbImage| {
        let d = channel_differences(a, b);
        let mean = d.iter().sum::<f32>() / d.len() as f32;
        let off = d.iter().filter(|&&x| x > 1e-2).count() as f32 / d.len() as f32;
        (mean, off)
    };
    for (scene, mean_limit, off_limit) in [
        ("scenes/bumpy_single.json", 1e-4, 0.005),
        ("scenes/bumpy_pair.json", 1e-3, 0.02),
    ] {
        let sub = dir.path().join(scene.replace('/', "_"));
        let (a, b) = both_of(&py, scene, &sub, "whitted", "16", "10000");
        let (mean, off) = mean_off(&a, &b);
        println!(
            "{scene}: mean |d| {mean:.3e}, {:.2} % of pixels off by > 1e-2",
            100.0 * off
        );
        assert!(mean < mean_limit, "{scene}: mean |d| {mean}");
        assert!(
            off < off_limit,
            "{scene}: {off} of the pixels differ by > 1e-2"
        );
        // The same scene with its mirrors flat, traced by us: the bump's own effect.
        let text = std::fs::read_to_string(repo().join(scene)).unwrap();
        let mut flat: serde_json::Value = serde_json::from_str(&text).unwrap();
        for m in flat["mirrors"].as_array_mut().unwrap() {
            m.as_object_mut().unwrap().remove("bump");
        }
        let flat_path = repo().join(scene).with_file_name(format!(
            ".flat_{}_{}.json",
            std::process::id(),
            scene.replace('/', "_")
        ));
        std::fs::write(&flat_path, flat.to_string()).unwrap();
        let flat_exr = sub.join("flat.exr");
        let bin = env!("CARGO_BIN_EXE_mirrorbox");
        let out = Command::new(bin)
            .args([
                "trace",
                flat_path.to_str().unwrap(),
                "-o",
                flat_exr.to_str().unwrap(),
            ])
            .args(["--spp", "16", "--width", "64", "--height", "36"])
            .output()
            .unwrap();
        let _ = std::fs::remove_file(&flat_path);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let (flat_mean, _) = mean_off(&read_image(&flat_exr).unwrap(), &b);
        println!("{scene}: flat vs Mitsuba's uneven: mean |d| {flat_mean:.3e}");
        assert!(
            flat_mean > 1e-3 && flat_mean > 10.0 * mean,
            "{scene}: the bump changes little ({flat_mean} against {mean})"
        );
    }
}

/// `tools/mitsuba/agreement.py`, which writes docs/mitsuba.md's table, runs against the
/// current CLI (it had called `trace` with flags since renamed, and failed on every scene).
#[test]
fn the_agreement_table_script_runs() {
    let Some(py) = python() else { return };
    let out = Command::new(&py)
        .args([
            "tools/mitsuba/agreement.py",
            "scenes/single_mirror.json",
            "--width",
            "16",
            "--height",
            "12",
            "--whitted-spp",
            "1",
            "--path-spp",
            "4",
            "--bin",
            env!("CARGO_BIN_EXE_mirrorbox"),
        ])
        .current_dir(repo())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("| single_mirror.json | "), "{stdout}");
}
