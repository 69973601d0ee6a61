//! The path integrator against answers known in closed form.

use glam::Vec3;
use mirrorbox_scene::Scene;
use mirrorbox_scene::load::parse_scene;
use mirrorbox_trace::{IntegratorSettings, PathSettings, SceneBvh, TraceSettings, render};
use serde_json::json;
use std::path::Path;

fn scene(v: serde_json::Value) -> Scene {
    parse_scene(&v.to_string(), Path::new("test.json")).unwrap()
}

fn trace(
    s: &Scene,
    spp_axis: u32,
    integrator: impl Into<IntegratorSettings>,
) -> mirrorbox_image::RgbImage {
    let bvh = SceneBvh::build(&s.geometry);
    let settings = TraceSettings::whitted(spp_axis).with_integrator(integrator);
    render(s, &bvh, &settings, &|_| {}).image
}

/// With depth 2 (direct light only), point lights only, nothing occluding and no ambient or
/// background, next-event estimation is deterministic and must equal the contract's Lambert
/// term — the Whitted image — exactly.
#[test]
fn direct_light_equals_the_contract() {
    let s = scene(json!({
        "camera": { "position": [0, 2, 3], "look_at": [0, 0, 0], "fov_y_deg": 50, "width": 24, "height": 16 },
        "objects": [ { "type": "quad", "size": [6, 6], "transform": { "rotate_deg": [-90, 0, 0] }, "albedo": [0.7, 0.5, 0.3] } ],
        "lights": [ { "position": [0.5, 1.5, 0.2], "intensity": [4, 4, 4] }, { "position": [-1, 2, -1], "intensity": [1, 2, 3] } ],
    }));
    let path = trace(
        &s,
        2,
        PathSettings {
            max_segments: 2,
            rr_from: 1000,
            seed: 0,
        },
    );
    let whitted = trace(&s, 2, IntegratorSettings::default());
    for (p, w) in path.pixels.iter().zip(&whitted.pixels) {
        for c in 0..3 {
            assert!(
                (p[c] - w[c]).abs() <= 1e-6 * w[c].max(1.0),
                "{p:?} vs {w:?}"
            );
        }
    }
}

/// Russian roulette ends are counted as such, never as `whitted`'s throughput cuts.
#[test]
fn roulette_ends_are_counted_separately() {
    let s = scene(json!({
        "camera": { "position": [0, 2, 3], "look_at": [0, 0, 0], "fov_y_deg": 50, "width": 16, "height": 12 },
        "objects": [ { "type": "quad", "size": [6, 6], "transform": { "rotate_deg": [-90, 0, 0] }, "albedo": [0.7, 0.5, 0.3] } ],
        "lights": [ { "position": [0.5, 1.5, 0.2], "intensity": [4, 4, 4] } ],
    }));
    let bvh = SceneBvh::build(&s.geometry);
    let path = PathSettings {
        max_segments: 100,
        rr_from: 1,
        seed: 2,
    };
    let stats = render(&s, &bvh, &TraceSettings::path(2, path), &|_| {}).stats;
    assert!(stats.cut_by_roulette > 0, "{stats:?}");
    assert_eq!(stats.cut_by_throughput, 0, "{stats:?}");
    assert_eq!(
        stats.paths,
        stats.diffuse + stats.escaped + stats.cut_by_depth + stats.cut_by_roulette
    );
    let whitted = render(&s, &bvh, &TraceSettings::whitted(2), &|_| {}).stats;
    assert_eq!(whitted.cut_by_roulette, 0, "{whitted:?}");
}

/// A white furnace: a closed box of inward-facing quads, all emitting E with albedo ρ. Every
/// path sees L = E + ρL, so L = E/(1 − ρ) everywhere. Holds only if emitter sampling, BSDF
/// sampling, their MIS weights and Russian roulette are all unbiased.
#[test]
fn white_furnace_converges_to_e_over_one_minus_rho() {
    let (e, rho) = (0.5f32, 0.6f32);
    // Six 2×2 quads facing the inside of the cube [−1, 1]³ (a quad faces +z before rotation).
    let faces = [
        [0, 0, 0, -1],
        [0, 180, 0, 1],
        [0, 90, 0, 0],
        [0, -90, 0, 0],
        [-90, 0, 0, 0],
        [90, 0, 0, 0],
    ];
    let offsets = [
        [0.0, 0.0, -1.0],
        [0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let objects: Vec<serde_json::Value> = faces
        .iter()
        .zip(offsets)
        .map(|(f, t)| json!({ "type": "quad", "size": [2, 2], "albedo": [rho, rho, rho], "emission": [e, e, e],
                              "transform": { "rotate_deg": [f[0], f[1], f[2]], "translate": t } }))
        .collect();
    let s = scene(json!({
        "camera": { "position": [0.1, 0.2, 0.3], "look_at": [0.5, -0.3, -1], "fov_y_deg": 70, "width": 16, "height": 16 },
        "objects": objects,
    }));
    // Every quad faces inwards: the camera sees only fronts.
    for i in 0..s.geometry.triangles.len() {
        let c = s.geometry.triangles[i].iter().copied().sum::<Vec3>() / 3.0;
        assert!(
            s.geometry.face_normal(i).dot(-c) > 0.0,
            "face {i} points outwards"
        );
    }
    let img = trace(
        &s,
        8,
        PathSettings {
            max_segments: 10_000,
            rr_from: 3,
            seed: 1,
        },
    );
    let mean = img.pixels.iter().map(|p| p[0] as f64).sum::<f64>() / img.pixels.len() as f64;
    let expected = (e / (1.0 - rho)) as f64;
    // 16×16 px × 64 spp = 16 384 paths; the per-path spread is about the mean, so the
    // standard error of the image mean is ~1 %: 3 % is 3σ.
    assert!(
        (mean - expected).abs() < 0.03 * expected,
        "furnace mean {mean}, expected {expected}"
    );
}
