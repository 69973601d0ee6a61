//! The raster methods on lavapipe (or whatever `mirrorbox info` picks), against golden
//! images and against the tracer. On failure, actual and difference images are written to
//! `target/tmp/golden-failures/`; `MIRRORBOX_BLESS=1` rewrites the golden images.

use glam::Vec3;
use mirrorbox_image::{RgbImage, read_image, write_png};
use mirrorbox_raster::{Gpu, Method, RenderSettings, render};
use mirrorbox_scene::{Scene, SubpixelGrid, load_scene};
use mirrorbox_trace::{Sampling, SceneBvh, TraceSettings, WhittedSettings};
use std::path::{Path, PathBuf};

fn scene(name: &str, w: u32, h: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name);
    let mut s = load_scene(&path).unwrap();
    s.camera = s.camera.with_size(w, h);
    s
}

fn settings(method: Method, ssaa: u32) -> RenderSettings {
    RenderSettings {
        method,
        ssaa,
        frames: 1,
        warmup: 0,
        max_passes: 5000,
        texture_scale: 1.0,
        min_portal_area: 0.0,
        min_attenuation: 1e-4,
        fragment_clipping: false,
    }
}

fn raster(s: &Scene, method: Method, ssaa: u32) -> RgbImage {
    let gpu = Gpu::new()
        .expect("a wgpu adapter (install mesa-vulkan-drivers: scripts/install-system-deps.sh)");
    render(&gpu, s, &settings(method, ssaa)).unwrap().image
}

fn trace(s: &Scene, per_axis: u32) -> RgbImage {
    let bvh = SceneBvh::build(&s.geometry);
    let settings = TraceSettings {
        sampling: Sampling::Grid(SubpixelGrid::new(per_axis)),
        whitted: WhittedSettings::default(),
        path: None,
    };
    mirrorbox_trace::render(s, &bvh, &settings, &|_| {}).image
}

fn failures_dir() -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("golden-failures");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes `actual` and a ×16 amplified difference image for a failed comparison.
fn dump(name: &str, actual: &RgbImage, expected: &RgbImage) -> String {
    let dir = failures_dir();
    write_png(&dir.join(format!("{name}.actual.png")), actual, 1.0).unwrap();
    write_png(&dir.join(format!("{name}.expected.png")), expected, 1.0).unwrap();
    let diff = RgbImage::from_fn(actual.width, actual.height, |x, y| {
        let (a, e) = (actual.get(x, y), expected.get(x, y));
        [0, 1, 2].map(|c| 16.0 * (a[c] - e[c]).abs())
    });
    write_png(&dir.join(format!("{name}.diff.png")), &diff, 1.0).unwrap();
    format!("images written to {}", dir.display())
}

/// Per-pixel largest channel difference.
fn differences(a: &RgbImage, b: &RgbImage) -> Vec<f32> {
    assert_eq!((a.width, a.height), (b.width, b.height));
    a.pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0, f32::max))
        .collect()
}

/// Golden comparison on the 8-bit sRGB images. Tolerance: rasterizers may differ on samples
/// that fall exactly on triangle edges and in the last bits of shading arithmetic, so at most
/// 0.5 % of pixels may differ by more than 2 levels of 255; none may be wildly off in more
/// than 0.1 %.
fn assert_golden(name: &str, actual: &RgbImage) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("{name}.png"));
    if std::env::var_os("MIRRORBOX_BLESS").is_some() || !path.exists() {
        write_png(&path, actual, 1.0).unwrap();
        assert!(
            std::env::var_os("CI").is_none(),
            "golden image {name} missing in CI"
        );
        return;
    }
    let expected = read_image(&path).unwrap();
    let a8 = actual.to_srgb8(1.0);
    let e8 = expected.to_srgb8(1.0);
    let n = (actual.width * actual.height) as usize;
    let level = |k: usize| {
        (0..3)
            .map(|c| a8[3 * k + c].abs_diff(e8[3 * k + c]))
            .max()
            .unwrap()
    };
    let off = (0..n).filter(|&k| level(k) > 2).count();
    let wild = (0..n).filter(|&k| level(k) > 64).count();
    if off * 200 > n || wild * 1000 > n {
        let where_ = dump(name, actual, &expected);
        panic!("{name}: {off} pixels differ by > 2 levels, {wild} by > 64, of {n}; {where_}");
    }
}

#[test]
fn golden_naive_mirror_box() {
    let s = scene("mirror_box.json", 160, 90);
    assert_golden("naive_mirror_box", &raster(&s, Method::Naive, 1));
}

#[test]
fn golden_auxiliary_n2_alpha07_mirror_box() {
    let mut s = scene("mirror_box.json", 160, 90);
    s.set_reflectance(Vec3::splat(0.7));
    assert_golden(
        "auxiliary_n2_alpha0.7_mirror_box",
        &raster(&s, Method::Auxiliary { n: 2 }, 1),
    );
}

/// Without mirrors both renderers compute the shading contract at the same sub-pixel
/// positions, so they must agree up to rasterization. Justification of the thresholds:
/// shading differs only in float rounding (GPU vs CPU sqrt/division, ~1e-7 relative), so
/// 99 % of pixels must agree to 1e-4; samples that fall exactly on a triangle edge may be
/// claimed by different triangles (the rasterizer's top-left rule vs the tracer's inclusive
/// watertight test), which can only happen on silhouettes: at most 1 % of pixels.
#[test]
fn shading_contract_matches_the_tracer_without_mirrors() {
    for name in ["single_mirror.json", "mirror_room.json"] {
        let s = scene(name, 96, 54).without_mirrors();
        let r = raster(&s, Method::Naive, 2);
        let t = trace(&s, 2);
        let d = differences(&r, &t);
        let n = d.len();
        let off = d.iter().filter(|&&x| x > 1e-4).count();
        let mean: f32 = d.iter().sum::<f32>() / n as f32;
        let max = d.iter().copied().fold(0.0, f32::max);
        println!("{name}: {off} of {n} pixels differ by > 1e-4, mean {mean:.3e}, max {max:.3e}");
        if off * 100 > n || mean > 1e-3 {
            let where_ = dump(&format!("contract_{name}"), &r, &t);
            panic!("{name}: {off} of {n} pixels differ by > 1e-4 (mean {mean}); {where_}");
        }
    }
}

#[test]
fn auxiliary_with_no_auxiliary_mirrors_is_naive() {
    let s = scene("mirror_box.json", 96, 54);
    assert_eq!(
        raster(&s, Method::Auxiliary { n: 0 }, 1),
        raster(&s, Method::Naive, 1)
    );
}

/// More auxiliary mirrors show more reflections: each n reproduces the truth (traced at the
/// same reflectance, same sub-pixel grid) on strictly more pixels than n − 1.
#[test]
fn more_auxiliary_mirrors_show_more_reflections() {
    let mut s = scene("mirror_box.json", 128, 72);
    s.set_reflectance(Vec3::splat(0.7));
    let truth = trace(&s, 1);
    let matching: Vec<usize> = (0..=3)
        .map(|n| {
            differences(&raster(&s, Method::Auxiliary { n }, 1), &truth)
                .iter()
                .filter(|&&x| x < 1e-3)
                .count()
        })
        .collect();
    println!(
        "pixels matching the truth for n = 0..3: {matching:?} of {}",
        truth.pixels.len()
    );
    for w in matching.windows(2) {
        assert!(w[1] > w[0], "pixels matching the truth by n: {matching:?}");
    }
}

/// Geometry behind a mirror must never leak into it: a bright emissive box sits right behind
/// a single mirror that fills most of the view. The oblique near plane must cut it from the
/// mirror camera, so the raster image equals the trace (which can never see it) up to the
/// contract test's tolerance, and nothing of the box's colour appears.
#[test]
fn geometry_behind_a_mirror_does_not_leak() {
    let text = serde_json::json!({
        "camera": { "position": [0.3, 1.2, 2.5], "look_at": [0, 1, -2], "fov_y_deg": 50, "width": 64, "height": 48 },
        "mirrors": [ { "center": [0, 1.5, -2], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 4, "height": 3 } ],
        "objects": [
            { "type": "quad", "size": [4, 4], "transform": { "rotate_deg": [-90, 0, 0] } },
            { "type": "sphere", "radius": 0.4, "transform": { "translate": [0, 0.6, 0] }, "albedo": [0.2, 0.4, 0.8] },
            { "type": "box", "size": [1.5, 1.5, 0.5], "albedo": [0, 0, 0], "emission": [0, 50, 0],
              "transform": { "translate": [0, 1.5, -2.4] } }
        ],
        "lights": [ { "position": [0, 2.5, 1], "intensity": [10, 10, 10] } ],
    });
    let s = mirrorbox_scene::load::parse_scene(&text.to_string(), Path::new("leak.json")).unwrap();
    let r = raster(&s, Method::Naive, 1);
    let t = trace(&s, 1);
    let green = r.pixels.iter().filter(|p| p[1] > 5.0).count();
    assert_eq!(
        green, 0,
        "the emissive box behind the mirror leaked into {green} pixels"
    );
    let d = differences(&r, &t);
    let off = d.iter().filter(|&&x| x > 1e-4).count();
    if off * 100 > d.len() {
        let where_ = dump("leak", &r, &t);
        panic!(
            "{off} of {} pixels differ from the trace; {where_}",
            d.len()
        );
    }
}

// ---------------------------------------------------------------------------------------
// portal: exact stencil recursion

fn portal(depth: u32) -> RenderSettings {
    RenderSettings {
        min_portal_area: 0.5,
        ..settings(Method::Portal { depth }, 1)
    }
}

fn trace_depth(s: &Scene, depth: u32) -> RgbImage {
    let bvh = SceneBvh::build(&s.geometry);
    let settings = TraceSettings {
        sampling: Sampling::Grid(SubpixelGrid::new(1)),
        whitted: WhittedSettings {
            max_depth: depth,
            min_throughput: 1e-4,
        },
        path: None,
    };
    mirrorbox_trace::render(s, &bvh, &settings, &|_| {}).image
}

/// The portal method against the truth traced to the same depth and throughput cut. Only
/// samples on a mirror's edge may differ (the rasterizer's top-left rule vs the tracer's
/// inclusive watertight test decide them differently, which shifts them by one reflection);
/// measured at 160×90: mirror_box depth 64 FLIP 7e-5 (relMSE 8e-7), tilted_pair depth 64
/// FLIP 3e-4. The mirror room branches too much for depth 64 within the frame's triangle
/// budget on lavapipe; it is checked at depth 8.
#[test]
fn portal_matches_the_truth_at_depth() {
    let gpu = Gpu::new().unwrap();
    // The room's horizon is dense with reflected wall corners, where a sample on the line
    // between two mirrors goes to either: 10 of 14 400 pixels, FLIP 1.4e-3 (a missing path,
    // the bug this test was written against, gave FLIP 1.8e-2 and thousands of pixels).
    let cases = [
        ("mirror_box.json", 64, 1e-3),
        ("tilted_pair.json", 64, 1e-3),
        ("mirror_room.json", 8, 2e-3),
    ];
    for (name, depth, flip) in cases {
        let s = scene(name, 160, 90);
        let out = render(&gpu, &s, &portal(depth)).unwrap();
        assert_eq!(out.stats.passes, 1);
        let truth = trace_depth(&s, depth);
        let d = differences(&out.image, &truth);
        let off = d.iter().filter(|&&x| x > 1e-3).count();
        let m = mirrorbox_image::metrics::compare(&truth, &out.image, 1.0).unwrap();
        println!(
            "{name} depth {depth}: {off} of {} pixels off by > 1e-3, FLIP {:.2e}, relMSE {:.2e}",
            d.len(),
            m.flip_mean,
            m.relmse
        );
        if off * 200 > d.len() || m.flip_mean > flip {
            let where_ = dump(&format!("portal_{name}"), &out.image, &truth);
            panic!("{name}: {off} pixels off, FLIP {}; {where_}", m.flip_mean);
        }
    }
}

/// One pass whatever the depth, and draws growing linearly with it on a chain of mirrors.
#[test]
fn portal_cost_grows_linearly_with_depth() {
    let gpu = Gpu::new().unwrap();
    let s = scene("mirror_box.json", 64, 36);
    let draws: Vec<usize> = [8, 16, 32]
        .iter()
        .map(|&d| render(&gpu, &s, &portal(d)).unwrap().stats.draws)
        .collect();
    let (a, b) = (draws[1] - draws[0], draws[2] - draws[1]);
    assert_eq!(b, 2 * a, "draws at depth 8, 16, 32: {draws:?}");
}

#[test]
fn portal_keeps_geometry_behind_a_mirror_out() {
    let text = serde_json::json!({
        "camera": { "position": [0.3, 1.2, 2.5], "look_at": [0, 1, -2], "fov_y_deg": 50, "width": 64, "height": 48 },
        "mirrors": [ { "center": [0, 1.5, -2], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 4, "height": 3 },
                     { "center": [0, 1.5, 3], "normal": [0, 0, -1], "up": [0, 1, 0], "width": 4, "height": 3 } ],
        "objects": [
            { "type": "quad", "size": [4, 4], "transform": { "rotate_deg": [-90, 0, 0] } },
            { "type": "box", "size": [1.5, 1.5, 0.5], "albedo": [0, 0, 0], "emission": [0, 50, 0],
              "transform": { "translate": [0, 1.5, -2.4] } }
        ],
        "lights": [ { "position": [0, 2.5, 1], "intensity": [10, 10, 10] } ],
    });
    let s = mirrorbox_scene::load::parse_scene(&text.to_string(), Path::new("leak.json")).unwrap();
    let gpu = Gpu::new().unwrap();
    let r = render(&gpu, &s, &portal(16)).unwrap().image;
    assert_eq!(
        r.pixels.iter().filter(|p| p[1] > 5.0).count(),
        0,
        "the box behind the mirror leaked"
    );
}
