//! The packet kernel (issue 19) changes the speed of the truth, not the truth: `whitted`
//! renders every bundled scene to the same bits with packets as one ray at a time through
//! the BVH2 (the packets' hierarchy; the CWBVH misses some corner hits: see `bvh.rs`), at the
//! command line's 4×4 grid (two pixels per packet), at 3×3 and 2×2 (a call's rays, eight
//! packets' worth, cut into packets of 32 across pixels; at 3×3 rows of 48 pixels end in a
//! part-filled packet) and 1×1 (32 pixels per packet, the row's last one part-filled: the
//! sweeps' truths at one sample per pixel), with
//! shadow legs, uneven
//! mirrors, symmetry planes and stereo rigs' scenes among them. So does `path`, whose
//! samples (each with its own stream since issue 41) walk side by side, their coherent
//! queries traced as packets.

use mirrorbox_scene::load::bundled_scene;
use mirrorbox_trace::{BvhKind, PathSettings, SceneBvh, TraceSettings, WhittedSettings, render};

/// Renders `scene` through the BVH2 with packets and one ray at a time, and asserts the
/// same bits in every pixel, the same bounce counts and the same statistics.
fn same_with_and_without_packets(
    scene: &mirrorbox_scene::Scene,
    settings: &TraceSettings,
    what: &str,
) {
    let single = SceneBvh::build_with(&scene.geometry, BvhKind::Bvh2).with_packets(false);
    let packets = SceneBvh::build_with(&scene.geometry, BvhKind::Bvh2);
    assert!(packets.packets() && !single.packets());
    let a = render(scene, &single, settings, &|_| {});
    let b = render(scene, &packets, settings, &|_| {});
    let differing = a
        .image
        .pixels
        .iter()
        .zip(&b.image.pixels)
        .filter(|(p, q)| p.map(f32::to_bits) != q.map(f32::to_bits))
        .count();
    assert_eq!(differing, 0, "{what}: pixels differ");
    assert_eq!(a.bounces.pixels, b.bounces.pixels, "{what}");
    assert_eq!(a.stats, b.stats, "{what}");
    assert!(a.stats.rays > 0, "{what}");
}

/// The bundled scenes, by file name.
fn bundled_names() -> Vec<String> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let name = e.unwrap().file_name().into_string().unwrap();
            name.ends_with(".json").then_some(name)
        })
        .collect();
    names.sort();
    assert!(names.len() >= 10, "{names:?}");
    names
}

#[test]
fn whitted_renders_every_bundled_scene_to_the_same_bits_with_packets() {
    for name in &bundled_names() {
        let mut scene = bundled_scene(name);
        scene.camera = scene.camera.with_size(48, 27);
        for grid in [4, 3, 2, 1] {
            let what = format!("whitted, {name}, {grid}×{grid} grid");
            same_with_and_without_packets(&scene, &TraceSettings::whitted(grid), &what);
        }
        // Paths cut at a depth of 2 (the default never cuts a bundled scene by depth).
        let shallow = TraceSettings::whitted(4).with_integrator(WhittedSettings {
            max_depth: 2,
            ..Default::default()
        });
        same_with_and_without_packets(&scene, &shallow, &format!("whitted, {name}, depth 2"));
    }
}

/// `path` walks 32 samples side by side, each with its own stream split off its pixel's in
/// order, several pixels' at once (16, 28 and 64 pixels per call at these grids, eight
/// packets' worth, so at 3×3 a row of 32 ends in a part-filled call); the queries
/// of paths before their first diffuse vertex and that vertex's shadow rays go to the
/// packet kernel, the rest one at a time. Its images are the same bits as one sample at a
/// time, one pixel per call, through the same hierarchy.
#[test]
fn path_renders_every_bundled_scene_to_the_same_bits_with_packets() {
    for name in &bundled_names() {
        let mut scene = bundled_scene(name);
        scene.camera = scene.camera.with_size(32, 18);
        for (grid, max_segments) in [(4, 10), (3, 10), (2, 66)] {
            let settings = TraceSettings::path(
                grid,
                PathSettings {
                    max_segments,
                    ..Default::default()
                },
            );
            let what = format!("path, {name}, {grid}×{grid} grid, {max_segments} segments");
            same_with_and_without_packets(&scene, &settings, &what);
        }
    }
}
