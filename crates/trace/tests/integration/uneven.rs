//! The tracer at uneven mirrors (`docs/shading.md`, "Uneven mirrors"): a flat bump changes
//! nothing, bit for bit; a constant tilt moves a reflection by the closed-form amount; rays
//! sent behind the mirror are absorbed.

use glam::{DVec3, Vec3};
use mirrorbox_scene::bump::{MirrorBump, NormalMap, Ripple};
use mirrorbox_scene::load::{bundled_scene, parse_scene};
use mirrorbox_scene::{Ray, Scene};
use mirrorbox_trace::{SceneBvh, Termination, TraceSettings, Whitted, WhittedSettings, render};
use serde_json::json;
use std::path::Path;
use std::sync::Arc;

fn traced(scene: &Scene) -> Vec<[f32; 3]> {
    let bvh = SceneBvh::build(&scene.geometry);
    render(scene, &bvh, &TraceSettings::whitted(2), &|_| {})
        .image
        .pixels
}

#[test]
fn a_ripple_of_amplitude_zero_gives_the_flat_image_bit_for_bit() {
    let mut rippled = bundled_scene("bumpy_pair.json");
    rippled.resize(Some(96), Some(54)).unwrap();
    rippled.set_bump_amplitude(0.0);
    let mut flat = rippled.clone();
    flat.bumps = vec![None; flat.mirrors.len()];
    assert!(rippled.has_bumps() && !flat.has_bumps());
    assert_eq!(traced(&rippled), traced(&flat));
    // And a real ripple changes it.
    rippled.set_bump_amplitude(3.0);
    assert_ne!(traced(&rippled), traced(&flat));
}

/// A uniform normal map tilts mirror A (z = 0) by θ towards +y; a ray along −z from
/// (0, 0, 1) reflects to (0, sin 2θ, cos 2θ) and meets the flat mirror B at z = 2 at
/// y = 2·tan 2θ.
#[test]
fn a_constant_tilt_moves_the_reflection_by_the_closed_form() {
    let mut s = parse_scene(
        &json!({
            "camera": { "position": [0, 0, 1], "look_at": [0, 0, 0], "fov_y_deg": 40, "width": 8, "height": 8 },
            "mirrors": [
                { "center": [0, 0, 0], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 50, "height": 50 },
                { "center": [0, 0, 2], "normal": [0, 0, -1], "up": [0, 1, 0], "width": 50, "height": 50 }
            ]
        })
        .to_string(),
        Path::new("tilt.json"),
    )
    .unwrap();
    let texel = [128u8, 150, 250];
    s.bumps[0] = Some(MirrorBump {
        ripple: None,
        normal_map: Some(NormalMap {
            path: "uniform.png".into(),
            resolved: "uniform.png".into(),
            width: 1,
            height: 1,
            texels: Arc::new(mirrorbox_scene::bump::Texels::new(vec![texel])),
            tiling: [1.0, 1.0],
            strength: 1.5,
        }),
    });
    let m = |c: u8| f64::from(c) * 2.0 / 255.0 - 1.0;
    // Tilt in the y–z plane (the decoded x is 0.0039: its small tilt moves x likewise).
    let n = DVec3::new(1.5 * m(texel[0]), 1.5 * m(texel[1]), m(texel[2])).normalize();
    let d = DVec3::new(0.0, 0.0, -1.0);
    let r = d - 2.0 * d.dot(n) * n;
    let expected = DVec3::ZERO + r * (2.0 / r.z);
    let theta = n.y.atan2(n.z);
    assert!((expected.y - 2.0 * (2.0 * theta).tan()).abs() < 1e-3 + expected.x.abs());
    let bvh = SceneBvh::build(&s.geometry);
    let whitted = Whitted::new(
        &s,
        &bvh,
        WhittedSettings {
            max_depth: 2,
            min_throughput: 1e-4,
        },
    );
    let mut hits = Vec::new();
    whitted.trace(
        Ray {
            origin: Vec3::new(0.0, 0.0, 1.0),
            dir: Vec3::new(0.0, 0.0, -1.0),
        },
        |k, p, mirror| hits.push((k, p, mirror)),
    );
    assert_eq!(hits[0].2, 0);
    assert!(hits[0].1.length() < 1e-12, "{:?}", hits[0]);
    assert_eq!((hits[1].0, hits[1].2), (2, 1));
    assert!(
        (hits[1].1 - expected).length() < 1e-9,
        "{:?} vs {expected}",
        hits[1].1
    );
    assert!(expected.y > 0.3, "a visible move: {expected}");
}

#[test]
fn a_grazing_ray_sent_behind_the_mirror_is_absorbed() {
    let mut s = parse_scene(
        &json!({
            "camera": { "position": [0, 1, 3], "look_at": [0, 0, 0], "fov_y_deg": 40, "width": 8, "height": 8 },
            "mirrors": [ { "center": [0, 0, 0], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 50, "height": 50 } ],
            "terminal": [1, 1, 1], "background": [0.5, 0.5, 0.5]
        })
        .to_string(),
        Path::new("graze.json"),
    )
    .unwrap();
    // Tilted 20° towards +y everywhere (a ripple of phase 90° and a huge wavelength).
    s.bumps[0] = Some(MirrorBump {
        ripple: Some(Ripple {
            amplitude: 20f32.to_radians(),
            wavelength: 1e6,
            direction: 90f32.to_radians(),
            phase: 90f32.to_radians(),
        }),
        normal_map: None,
    });
    let bvh = SceneBvh::build(&s.geometry);
    let whitted = Whitted::new(&s, &bvh, WhittedSettings::default());
    // 10° above the plane, heading towards +y: the tilted facet sends it below the plane.
    let dir = Vec3::new(0.0, 10f32.to_radians().cos(), -(10f32.to_radians().sin()));
    let r = whitted.radiance(Ray {
        origin: Vec3::new(0.0, -1.0, 10f32.to_radians().tan()),
        dir,
    });
    assert_eq!(r.termination, Termination::Absorbed);
    assert_eq!(
        r.radiance,
        Vec3::ZERO,
        "absorbed: neither terminal nor background"
    );
    // Heading towards −y instead it reflects and escapes.
    let back = whitted.radiance(Ray {
        origin: Vec3::new(0.0, 1.0, 10f32.to_radians().tan()),
        dir: Vec3::new(0.0, -dir.y, dir.z),
    });
    assert_eq!(back.termination, Termination::Escaped);
}
