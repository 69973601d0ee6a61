//! Tests of the tracer against answers known in closed form.

use glam::{DVec3, Vec3};
use mirrorbox_scene::load::parse_scene;
use mirrorbox_scene::{Plane, Ray, Scene, SubpixelGrid};
use mirrorbox_trace::{
    Sampling, SceneBvh, Termination, TraceSettings, Whitted, WhittedSettings, render,
};
use serde_json::json;
use std::path::Path;

fn scene(value: serde_json::Value) -> Scene {
    parse_scene(&value.to_string(), Path::new("test.json")).unwrap()
}

fn camera(position: [f32; 3], look_at: [f32; 3], size: u32) -> serde_json::Value {
    json!({ "position": position, "look_at": look_at, "fov_y_deg": 40, "width": size, "height": size })
}

/// Two large parallel mirrors of reflectance `rho` at z = ±2 facing each other.
fn parallel_mirrors(rho: f32, size: f32) -> serde_json::Value {
    json!([
        { "center": [0, 0, -2], "normal": [0, 0, 1], "up": [0, 1, 0], "width": size, "height": size,
          "reflectance": [rho, rho, rho] },
        { "center": [0, 0, 2], "normal": [0, 0, -1], "up": [0, 1, 0], "width": size, "height": size,
          "reflectance": [rho, rho, rho] }
    ])
}

/// A path 10 000 bounces deep between two R = 1 mirrors stays on the closed-form zig-zag:
/// the k-th hit lies on the mirror at z = ∓2 at distance s_k = (2 + 4(k−1))/|d_z| along the
/// unfolded ray, so x_k = o_x + d_x·s_k, y_k = o_y + d_y·s_k. It never hits the same mirror
/// twice in a row (no self-intersection) and is cut by the depth rule exactly at 10 000.
#[test]
fn deep_path_follows_the_closed_form_without_drift() {
    let s = scene(json!({
        "camera": camera([0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 8),
        "mirrors": parallel_mirrors(1.0, 100.0),
    }));
    let bvh = SceneBvh::build(&s.geometry);
    let whitted = Whitted::new(
        &s,
        &bvh,
        WhittedSettings {
            max_depth: 10_000,
            min_throughput: 1e-4,
        },
    );
    let origin = Vec3::new(0.3, 1.5, 0.0);
    let dir = Vec3::new(0.001, 0.0005, -1.0).normalize();
    let (o, d) = (origin.as_dvec3(), dir.as_dvec3());
    let mut worst = 0.0f64;
    let mut last_mirror = usize::MAX;
    let mut count = 0;
    let result = whitted.trace(Ray { origin, dir }, |k, p, mirror| {
        assert_ne!(mirror, last_mirror, "bounce {k} hit the mirror it left");
        last_mirror = mirror;
        let s_k = (2.0 + 4.0 * (k as f64 - 1.0)) / d.z.abs();
        let z = if k % 2 == 1 { -2.0 } else { 2.0 };
        let expected = DVec3::new(o.x + d.x * s_k, o.y + d.y * s_k, z);
        worst = worst.max((p - expected).length());
        count += 1;
    });
    assert_eq!(count, 10_000);
    assert_eq!(result.bounces, 10_000);
    assert_eq!(result.termination, Termination::Depth);
    // After 10 000 bounces (40 000 units of travel) the position is still exact to 1e-6.
    assert!(worst < 1e-6, "drifted by {worst}");
}

/// The k-th reflection of a lit patch is ρ^k times as bright as the patch itself.
#[test]
fn kth_reflection_is_rho_to_the_k() {
    let rho = 0.8f32;
    let e = 2.5f32;
    let s = scene(json!({
        "camera": camera([0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 8),
        "mirrors": parallel_mirrors(rho, 8.0),
        "objects": [ { "type": "box", "size": [0.05, 0.05, 0.05], "albedo": [0, 0, 0],
                       "emission": [e, e, e], "transform": { "translate": [1.0, 0.0, 0.0] } } ],
    }));
    let bvh = SceneBvh::build(&s.geometry);
    let whitted = Whitted::new(&s, &bvh, WhittedSettings::default());
    let (front, back) = (s.mirrors[0].plane(), s.mirrors[1].plane());
    let patch = Vec3::new(1.0, 0.0, 0.0);
    let eye = Vec3::ZERO;
    for k in 0..=8u32 {
        // Image of the patch seen via k reflections, the first in the front mirror:
        // P_k = R_front(R_back(R_front(...p))) with k factors, innermost applied first.
        let planes: Vec<&Plane> = (0..k)
            .map(|i| if i % 2 == 0 { &front } else { &back })
            .collect();
        let image = planes
            .iter()
            .rev()
            .fold(patch, |p, plane| plane.reflect_point(p));
        let ray = Ray {
            origin: eye,
            dir: (image - eye).normalize(),
        };
        let r = whitted.radiance(ray);
        assert_eq!(r.termination, Termination::Diffuse, "k={k}");
        assert_eq!(r.bounces, k);
        let expected = e * rho.powi(k as i32);
        assert!(
            (r.radiance.x - expected).abs() < 1e-5 * expected.max(1.0),
            "k={k}: {} vs {expected}",
            r.radiance.x
        );
    }
}

/// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Every pixel of the R = 1 mirror box is at most what the contract allows any surface:
/// max(background, terminal, E + ρ/π·Σ I/d_min² + ρ·A) per channel, with d_min the smallest
/// distance from each light to any diffuse triangle (mirrors only redirect, never add).
#[test]
fn nothing_is_brighter_than_the_contract_allows() {
    let mut s = mirrorbox_scene::load::bundled_scene("mirror_box.json");
    s.set_reflectance(Vec3::ONE).unwrap();
    s.camera = s.camera.with_size(96, 54);
    let g = &s.geometry;
    let mut bound = s.background.max(s.terminal);
    for (i, tri) in g.triangles.iter().enumerate() {
        let (albedo, emission) = match g.surface(i) {
            mirrorbox_scene::Surface::Diffuse {
                albedo, emission, ..
            } => (*albedo, *emission),
            mirrorbox_scene::Surface::Mirror { back_albedo, .. } => (*back_albedo, Vec3::ZERO),
        };
        let mut irradiance = Vec3::ZERO;
        for light in &s.lighting.lights {
            let q = closest_point_on_triangle(light.position, tri[0], tri[1], tri[2]);
            irradiance += light.intensity / (light.position - q).length_squared();
        }
        bound =
            bound.max(emission + albedo * (irradiance / std::f32::consts::PI + s.lighting.ambient));
    }
    let bvh = SceneBvh::build(&s.geometry);
    let settings = TraceSettings::whitted(2);
    let out = render(&s, &bvh, &settings, &|_| {});
    let mut brightest = Vec3::ZERO;
    for p in &out.image.pixels {
        let p = Vec3::from_array(*p);
        assert!(p.cmple(bound * (1.0 + 1e-5)).all(), "{p} exceeds {bound}");
        brightest = brightest.max(p);
    }
    // The bound is tight enough to mean something: the brightest pixel gets within 25% of it.
    assert!(
        brightest.max_element() > 0.75 * bound.max_element(),
        "{brightest} vs {bound}"
    );
}

#[test]
fn image_is_identical_whatever_the_thread_count() {
    let mut s = mirrorbox_scene::load::bundled_scene("mirror_room.json");
    s.camera = s.camera.with_size(64, 36);
    let bvh = SceneBvh::build(&s.geometry);
    let settings = TraceSettings::default().with_sampling(Sampling::Jittered {
        grid: SubpixelGrid::new(2),
        seed: 3,
    });
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| render(&s, &bvh, &settings, &|_| {}))
    };
    let (a, b) = (run(1), run(3));
    assert_eq!(a.image, b.image);
    assert_eq!(a.bounces, b.bounces);
    assert_eq!(a.stats, b.stats);
    assert!(
        a.stats.deepest > 10,
        "the mirror room should produce deep paths"
    );
}

/// A tilted mirror filling the view reflects a bright emitter behind the camera; its
/// diagonal seam crosses the image. A leak through the seam would show the red background.
/// This checks the whole pipeline; the test that singles out seam rays (and fails with a
/// non-watertight triangle test) is `watertight::tests::shared_edges_do_not_leak`.
#[test]
fn rays_along_the_mirror_seam_do_not_leak() {
    let s = scene(json!({
        "camera": { "position": [0.7, 0.4, 5], "look_at": [0, 0, 0], "fov_y_deg": 30, "width": 64, "height": 64 },
        "mirrors": [ { "center": [0, 0, 0], "normal": [0.3, 0.2, 1], "up": [0.1, 1, 0], "width": 8, "height": 8,
                       "reflectance": [0.5, 0.5, 0.5] } ],
        "objects": [ { "type": "quad", "size": [200, 200], "albedo": [0, 0, 0], "emission": [1, 1, 1],
                       "transform": { "translate": [0, 0, 10], "rotate_deg": [0, 180, 0] } } ],
        "background": [1, 0, 0],
    }));
    let bvh = SceneBvh::build(&s.geometry);
    let settings = TraceSettings::whitted(3);
    let out = render(&s, &bvh, &settings, &|_| {});
    for (i, p) in out.image.pixels.iter().enumerate() {
        assert_eq!(*p, [0.5, 0.5, 0.5], "pixel {} {} leaks", i % 64, i / 64);
    }
}

/// Without mirrors the tracer must equal a brute-force reference (every triangle tested,
/// the contract evaluated directly) bit for bit: BVH traversal, integrator, sampling and
/// averaging add nothing.
#[test]
fn scene_without_mirrors_equals_the_contract_reference_exactly() {
    let mut s = mirrorbox_scene::load::bundled_scene("single_mirror.json");
    s.camera = s.camera.with_size(48, 27);
    let s = s.without_mirrors();
    assert!(s.mirrors.is_empty() && s.geometry.mirror_triangle_count() == 0);
    let grid = SubpixelGrid::new(2);
    let bvh = SceneBvh::build(&s.geometry);
    let out = render(&s, &bvh, &TraceSettings::whitted(grid.per_axis), &|_| {});
    let cam = &s.camera;
    for y in 0..cam.height {
        for x in 0..cam.width {
            let mut sum = Vec3::ZERO;
            for o in grid.offsets() {
                let ray = cam.primary_ray(x as f32 + o.x, y as f32 + o.y);
                let wt = mirrorbox_trace::watertight::WatertightRay::new(ray.origin, ray.dir);
                let closest = s
                    .geometry
                    .triangles
                    .iter()
                    .enumerate()
                    .map(|(i, t)| (wt.intersect(t[0], t[1], t[2], 0.0, f32::INFINITY), i))
                    .filter(|(t, _)| t.is_finite())
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                sum += match closest {
                    None => s.background,
                    Some((_, i)) => {
                        let mirrorbox_scene::Surface::Diffuse {
                            albedo, emission, ..
                        } = s.geometry.surface(i)
                        else {
                            unreachable!()
                        };
                        // The hit point on the triangle's plane, solved in f64 from the ray
                        // (the contract's hit point, `hit_point`), not `ray.at(t)`.
                        let [a, b, c] = s.geometry.triangles[i].map(|v| v.as_dvec3());
                        let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
                        let n = (b - a).cross(c - a);
                        let p = o + d * (n.dot(a - o) / n.dot(d));
                        s.lighting.diffuse_radiance(
                            p.as_vec3(),
                            s.geometry.face_normal(i),
                            -ray.dir,
                            *albedo,
                            *emission,
                        )
                    }
                };
            }
            let want = (sum / grid.samples_per_pixel() as f32).to_array();
            assert_eq!(out.image.get(x, y), want, "pixel ({x},{y})");
        }
    }
}
