//! Hit points as precise as the ray (issue 50).
//!
//! The watertight test ([`crate::watertight`]) finds *which* triangle a ray meets; its
//! distance `t` is a quotient of 2D cross products of the vertices taken relative to the ray's
//! origin, so its absolute error grows with the vertices' distance from the origin, not with
//! the hit's: on a 200-unit ground quad whose corners are ~100 units from the camera, the hit
//! point of a ray meeting the quad 5 units away moved by ~5·10⁻⁴ units (0.008 px at 160×90,
//! 90° across), and the shading of the image's sides, where it changes fastest, by 2·10⁻⁴
//! relative.
//!
//! So the point a diffuse hit is shaded at is re-solved in f64 against the triangle's plane:
//! `n = (b − a) × (c − a)` (exact to one rounding: the f32 vertices' differences and products
//! fit f64), `t = n·(a − o) / n·d`, `p = o + t·d`. Its error is then that of the ray and of
//! one f32 rounding of `p`, whatever the triangle's size. A triangle without area (no plane)
//! keeps the traversal's `t`.

use glam::{DVec3, Vec3};
use mirrorbox_scene::Geometry;

/// The point where the ray `o + t·d` (f64, as the integrator carries it) meets the plane of
/// `geometry`'s triangle `triangle`; `t_traversal` (the BVH's distance) where the triangle has
/// no plane.
#[inline(always)]
pub fn on_triangle_plane(
    geometry: &Geometry,
    triangle: usize,
    o: DVec3,
    d: DVec3,
    t_traversal: f32,
) -> Vec3 {
    let [a, b, c] = geometry.triangles[triangle].map(Vec3::as_dvec3);
    let n = (b - a).cross(c - a);
    let t = n.dot(a - o) / n.dot(d);
    if t.is_finite() {
        (o + d * t).as_vec3()
    } else {
        (o + d * f64::from(t_traversal)).as_vec3()
    }
}

/// [`on_triangle_plane`] for every lane of `o`, `d` (f64 lanes) on one triangle, into `p`:
/// the same arithmetic in a loop over the lanes, the plane's normal computed once.
#[inline(always)]
pub fn on_triangle_plane_lanes<const L: usize>(
    geometry: &Geometry,
    triangle: usize,
    o: &[[f64; L]; 3],
    d: &[[f64; L]; 3],
    t_traversal: &[f32; L],
    p: &mut [[f32; L]; 3],
) {
    let [a, b, c] = geometry.triangles[triangle].map(Vec3::as_dvec3);
    let n = (b - a).cross(c - a);
    for lane in 0..L {
        let o = DVec3::new(o[0][lane], o[1][lane], o[2][lane]);
        let d = DVec3::new(d[0][lane], d[1][lane], d[2][lane]);
        let t = n.dot(a - o) / n.dot(d);
        let t = if t.is_finite() {
            t
        } else {
            f64::from(t_traversal[lane])
        };
        let q = (o + d * t).as_vec3();
        for k in 0..3 {
            p[k][lane] = q[k];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_scene::load::parse_scene;
    use std::path::Path;

    fn ground(size: f32) -> mirrorbox_scene::Scene {
        let json = serde_json::json!({
            "camera": { "position": [0, 1, 0], "look_at": [0.2, 0, 0], "up": [0.1, 0, -1],
                        "fov_y_deg": 58.7, "width": 160, "height": 90 },
            "objects": [{ "type": "quad", "size": [size, 1.9],
                          "transform": { "rotate_deg": [-90, 0, 0] } }],
            "lights": [{ "position": [0, 2, 0], "intensity": [1, 1, 1] }]
        });
        parse_scene(&json.to_string(), Path::new("ground.json")).unwrap()
    }

    /// On a 200-unit quad the point lies on the plane y = 0 to f32 rounding of the point
    /// itself, and on the ray; the traversal's own distance does not (the mutation check:
    /// `ray.at(t)` misses the plane by far more).
    #[test]
    fn the_point_is_on_the_plane_and_the_ray_whatever_the_triangle_size() {
        let scene = ground(200.0);
        let bvh = crate::SceneBvh::build(&scene.geometry);
        let rays = scene.camera.ray_generator();
        let mut worst_traversal = 0.0f64;
        for x in 0..160 {
            let ray = rays.ray(x as f32 + 0.5, 45.5);
            let hit = bvh.closest_hit(&ray, 0.0, f32::INFINITY, None).unwrap();
            let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
            let p = on_triangle_plane(&scene.geometry, hit.triangle, o, d, hit.t).as_dvec3();
            // On the plane: |y| within one f32 ulp of p's largest coordinate.
            let ulp = f64::from(f32::EPSILON) * p.abs().max_element();
            assert!(p.y.abs() <= ulp, "x {x}: p {p:?}");
            // On the ray: the exact hit is o − (o.y/d.y)·d.
            let exact = o + d * (-o.y / d.y);
            assert!(
                (p - exact).length() <= 2.0 * ulp,
                "x {x}: {p:?} vs {exact:?}"
            );
            worst_traversal = worst_traversal.max((ray.at(hit.t).as_dvec3() - exact).length());
        }
        // Measured: 3.3e-5 units, ~300 times the rounding of the point re-solved here.
        println!("traversal off by {worst_traversal:.2e}");
        assert!(
            worst_traversal > 1e-5,
            "the traversal's t is {worst_traversal} off"
        );
    }

    /// The lane form is the one-ray form bit for bit, lane by lane: rays from many origins
    /// meeting a large quad's plane at many angles, and a triangle without area (its lanes keep
    /// the traversal's distance).
    #[test]
    fn the_lane_form_is_the_one_ray_form() {
        const L: usize = 16;
        let mut scene = ground(200.0);
        let mut rng = crate::sampler::SplitMix64::for_pixel(0x5eed, 0);
        let mut next = || f64::from(rng.next_unit());
        let (mut o, mut d) = ([[0.0f64; L]; 3], [[0.0f64; L]; 3]);
        let mut t = [0.0f32; L];
        for round in 0..50 {
            if round == 40 {
                let [a, _, _] = scene.geometry.triangles[1];
                scene.geometry.triangles[1] = [a, a, a];
            }
            for lane in 0..L {
                let origin = DVec3::new(
                    next() * 20.0 - 10.0,
                    next() * 5.0 + 0.1,
                    next() * 20.0 - 10.0,
                );
                let dir = DVec3::new(next() - 0.5, -next(), next() - 0.5).normalize();
                for k in 0..3 {
                    o[k][lane] = origin[k];
                    d[k][lane] = dir[k];
                }
                t[lane] = next() as f32 * 10.0;
            }
            for triangle in 0..2 {
                let mut p = [[0.0f32; L]; 3];
                on_triangle_plane_lanes(&scene.geometry, triangle, &o, &d, &t, &mut p);
                for lane in 0..L {
                    let origin = DVec3::new(o[0][lane], o[1][lane], o[2][lane]);
                    let dir = DVec3::new(d[0][lane], d[1][lane], d[2][lane]);
                    let one = on_triangle_plane(&scene.geometry, triangle, origin, dir, t[lane]);
                    let lanes = Vec3::new(p[0][lane], p[1][lane], p[2][lane]);
                    assert_eq!(
                        lanes.to_array().map(f32::to_bits),
                        one.to_array().map(f32::to_bits),
                        "round {round}, triangle {triangle}, lane {lane}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_triangle_without_area_keeps_the_traversal_distance() {
        let mut scene = ground(2.0);
        let [a, _, _] = scene.geometry.triangles[0];
        scene.geometry.triangles[0] = [a, a, a];
        let p = on_triangle_plane(&scene.geometry, 0, DVec3::ZERO, DVec3::X, 2.0);
        assert_eq!(p, Vec3::new(2.0, 0.0, 0.0));
    }
}
