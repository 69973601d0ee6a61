//! Shadows and mirrored lights (`docs/shading.md`) in the tracer, against answers computed
//! independently: images and legs unfolded by hand, occluders by a slab test, and the `path`
//! integrator finding a small emitter through a mirror by its own sampling.

use glam::Vec3;
use mirrorbox_scene::load::parse_scene;
use mirrorbox_scene::{Ray, Scene};
use mirrorbox_trace::{PathSettings, SceneBvh, TraceSettings, Whitted, WhittedSettings, render};
use serde_json::{Value, json};
use std::path::Path;

fn scene(v: Value) -> Scene {
    parse_scene(&v.to_string(), Path::new("lighting.json")).unwrap()
}

const RHO: f32 = 0.8;
const LIGHT: Vec3 = Vec3::new(0.0, 1.5, 0.5);
const INTENSITY: f32 = 3.0;
const FLOOR_ALBEDO: f32 = 0.5;
const DEPTH: i32 = 4;

/// Two wide mirrors at z = ±2 facing each other, a floor between them at y = 0, a light, an
/// axis-aligned box (`centre`, `half` extents) and the given lighting.
fn pair_with_box(centre: Vec3, half: f32, shadows: bool) -> Scene {
    scene(json!({
        "camera": { "position": [0, 3, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov_y_deg": 40, "width": 8, "height": 8 },
        "mirrors": [
            { "center": [0, 0, -2], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 200, "height": 200,
              "reflectance": [RHO, RHO, RHO] },
            { "center": [0, 0, 2], "normal": [0, 0, -1], "up": [0, 1, 0], "width": 200, "height": 200,
              "reflectance": [RHO, RHO, RHO] } ],
        "objects": [
            { "type": "quad", "size": [20, 3.9], "transform": { "rotate_deg": [-90, 0, 0] },
              "albedo": [FLOOR_ALBEDO, FLOOR_ALBEDO, FLOOR_ALBEDO] },
            { "type": "box", "size": [2.0 * half, 2.0 * half, 2.0 * half],
              "transform": { "translate": centre.to_array() }, "albedo": [0, 0, 0] } ],
        "lights": [ { "position": LIGHT.to_array(), "intensity": [INTENSITY, INTENSITY, INTENSITY] } ],
        "lighting": { "shadows": shadows, "mirrored_lights": DEPTH }
    }))
}

/// Whether the segment from `a` to `b` passes through the axis-aligned box (slab test).
fn segment_hits_box(a: Vec3, b: Vec3, centre: Vec3, half: f32) -> bool {
    let (lo, hi) = (centre - half, centre + half);
    let d = b - a;
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    for axis in 0..3 {
        if d[axis].abs() < 1e-12 {
            if a[axis] < lo[axis] || a[axis] > hi[axis] {
                return false;
            }
            continue;
        }
        let (mut u, mut v) = (
            (lo[axis] - a[axis]) / d[axis],
            (hi[axis] - a[axis]) / d[axis],
        );
        if u > v {
            std::mem::swap(&mut u, &mut v);
        }
        t0 = t0.max(u);
        t1 = t1.min(v);
    }
    t0 <= t1
}

/// The legs from `x` to the light through the image at depth `j` and height `z` along the
/// mirrors' axis, unfolded by hand: walk towards the image, reflect it in each plane met.
fn legs(x: Vec3, image_z: f32, j: i32) -> Vec<(Vec3, Vec3)> {
    let mut out = Vec::new();
    let mut from = x;
    let mut target = Vec3::new(LIGHT.x, LIGHT.y, image_z);
    for _ in 0..j {
        let plane = if target.z > from.z { 2.0 } else { -2.0 };
        let s = (plane - from.z) / (target.z - from.z);
        let hit = from + (target - from) * s;
        out.push((from, hit));
        from = hit;
        target.z = 2.0 * plane - target.z;
    }
    assert!(
        target.abs_diff_eq(LIGHT, 1e-4),
        "unfolding must end at the light"
    );
    out.push((from, LIGHT));
    out
}

/// The floor's radiance at `x` (seen from above): ρ_f/π·Σ over the light and its images
/// with ≤ DEPTH reflections (period 8 for mirrors 4 apart: images at 8m + z₀ after |2m|
/// reflections, 8m + 4 − z₀ after |2m + 1|), leaving out those with a leg through the box.
/// Returns the radiance and how many terms the box removed.
fn floor_radiance(x: Vec3, centre: Vec3, half: f32) -> (f32, usize) {
    let mut sum = 0.0;
    let mut blocked = 0;
    for m in -DEPTH..=DEPTH {
        for (z, j) in [
            (8.0 * m as f32 + LIGHT.z, (2 * m).abs()),
            (8.0 * m as f32 + 4.0 - LIGHT.z, (2 * m + 1).abs()),
        ] {
            if j > DEPTH {
                continue;
            }
            if legs(x, z, j)
                .iter()
                .any(|&(a, b)| segment_hits_box(a, b, centre, half))
            {
                blocked += 1;
                continue;
            }
            let to = Vec3::new(LIGHT.x, LIGHT.y, z) - x;
            sum += RHO.powi(j) * INTENSITY * (to.y / to.length()).max(0.0) / to.length_squared();
        }
    }
    (FLOOR_ALBEDO / std::f32::consts::PI * sum, blocked)
}

fn traced_floor(s: &Scene, x: Vec3) -> f32 {
    let bvh = SceneBvh::build(&s.geometry);
    let whitted = Whitted::new(s, &bvh, WhittedSettings::default());
    let origin = x + Vec3::new(0.01, 0.25, 0.013);
    let ray = Ray {
        origin,
        dir: (x - origin).normalize(),
    };
    whitted.radiance(ray).radiance.x
}

#[test]
fn shadows_remove_exactly_the_legs_a_box_blocks() {
    let x = Vec3::new(0.6, 0.0, -0.4);
    let mut removed_some = 0;
    // A box on the direct segment; one near the far mirror on some images' legs; one off
    // every leg.
    for (centre, half) in [
        ((x + LIGHT) * 0.5, 0.1),
        (Vec3::new(0.3, 1.0, -1.7), 0.12),
        (Vec3::new(1.5, 0.3, 1.5), 0.1),
    ] {
        let (want, blocked) = floor_radiance(x, centre, half);
        let got = traced_floor(&pair_with_box(centre, half, true), x);
        assert!(
            (got - want).abs() <= 1e-5 * want,
            "box at {centre}: traced {got}, closed form {want} ({blocked} terms blocked)"
        );
        // Without shadows the box removes nothing.
        let (all, _) = floor_radiance(x, Vec3::splat(100.0), 0.1);
        let unshadowed = traced_floor(&pair_with_box(centre, half, false), x);
        assert!((unshadowed - all).abs() <= 1e-5 * all);
        if blocked > 0 {
            removed_some += 1;
            assert!(
                blocked < 2 * DEPTH as usize + 1,
                "the test needs lit terms left"
            );
        }
    }
    assert_eq!(removed_some, 2, "two boxes must block some legs");
}

/// A small emissive sphere that `path` finds through a mirror by its own sampling carries the
/// light that `whitted` computes by the image-source method for a point light of the same
/// intensity. A convex emitter of uniform radiance L has intensity L·(projected area) in
/// every direction, its mean projected area is a quarter of its surface (Cauchy), and a
/// sphere wholly above a surface's horizon lights it as a point at its centre does; so the
/// point light's intensity is L·A/4. The sphere sits high enough (h > r·D/d, D the patch's
/// and d its distance from the mirror) that its own body hides none of its image from the
/// patch. The mirrored part of `path` is isolated exactly: the same
/// seed with the mirror's reflectance at 0 gives the same direct-light samples.
#[test]
fn path_finds_the_mirrored_light_that_whitted_computes() {
    let centre = [0.0, 0.7, -0.3];
    let with_reflectance = |rho: f32| {
        json!({
            "camera": { "position": [0, 2.0, 0.6], "look_at": [0, 0, 0.6], "up": [0, 0, -1],
                        "fov_y_deg": 30, "width": 24, "height": 24 },
            "mirrors": [ { "center": [0, 1.5, -1], "normal": [0, 0, 1], "up": [0, 1, 0],
                           "width": 4, "height": 3, "reflectance": [rho, rho, rho] } ],
            "objects": [ { "type": "quad", "size": [2, 2.6],
                           "transform": { "translate": [0, 0, 0.3], "rotate_deg": [-90, 0, 0] },
                           "albedo": [0.6, 0.6, 0.6] } ],
        })
    };
    let radiance = 2.0f32;
    let emitter = |rho: f32| {
        let mut v = with_reflectance(rho);
        v["objects"].as_array_mut().unwrap().push(json!(
            { "type": "sphere", "radius": 0.2, "subdivisions": 4,
              "transform": { "translate": centre }, "albedo": [0, 0, 0],
              "emission": [radiance, radiance, radiance] }));
        scene(v)
    };
    let lit = emitter(1.0);
    let sphere = lit
        .geometry
        .parts
        .iter()
        .find(|p| p.name.contains("sphere"))
        .unwrap();
    let area: f32 = lit.geometry.triangles[sphere.triangles.clone()]
        .iter()
        .map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length())
        .sum();
    let intensity = radiance * area / 4.0;
    let point = |mirrored: u32| {
        let mut v = with_reflectance(1.0);
        v["lights"] =
            json!([{ "position": centre, "intensity": [intensity, intensity, intensity] }]);
        v["lighting"] = json!({ "shadows": true, "mirrored_lights": mirrored });
        scene(v)
    };
    let mean = |s: &Scene, settings: TraceSettings| {
        let bvh = SceneBvh::build(&s.geometry);
        let image = render(s, &bvh, &settings, &|_| {}).image;
        image.pixels.iter().map(|p| p[0] as f64).sum::<f64>() / image.pixels.len() as f64
    };
    let whitted_mirrored =
        mean(&point(1), TraceSettings::whitted(2)) - mean(&point(0), TraceSettings::whitted(2));
    // Depth 3: camera → floor → mirror → emitter; no diffuse interreflection reaches it.
    let path = |s: &Scene| {
        mean(
            s,
            TraceSettings::path(
                96,
                PathSettings {
                    max_segments: 3,
                    rr_from: 1000,
                    seed: 7,
                },
            ),
        )
    };
    let path_mirrored = path(&lit) - path(&emitter(0.0));
    eprintln!("mirrored light: path {path_mirrored}, whitted {whitted_mirrored}");
    assert!(whitted_mirrored > 0.0);
    assert!(
        (path_mirrored - whitted_mirrored).abs() <= 0.04 * whitted_mirrored,
        "light through the mirror: path {path_mirrored}, whitted {whitted_mirrored}"
    );
}
