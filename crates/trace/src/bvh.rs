//! One obvhs CWBVH over all of a scene's triangles (objects and mirrors).
//!
//! obvhs reports hits by *BVH primitive slot*: the id passed to the intersection closure and
//! stored in `RayHit::primitive_id` indexes `bvh.primitive_indices`, not the input list. We
//! therefore copy the triangles once into slot order (`slots`) and keep, per slot, the index of
//! the original triangle (`original`), so traversal reads memory in BVH order and every hit
//! maps back to [`mirrorbox_scene::Geometry`]'s numbering.

use glam::{Vec3, Vec3A};
use mirrorbox_scene::{Geometry, Ray};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::RayHit;
use obvhs::triangle::Triangle;
use std::time::Duration;

/// A closest hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the (unit-direction) ray.
    pub t: f32,
    /// Index of the triangle in the scene's [`Geometry`].
    pub triangle: usize,
}

pub struct SceneBvh {
    bvh: CwBvh,
    slots: Vec<Triangle>,
    original: Vec<u32>,
    /// Time obvhs spent building the hierarchy.
    pub build_time: Duration,
}

fn to_obvhs(t: &[Vec3; 3]) -> Triangle {
    Triangle {
        v0: Vec3A::from(t[0]),
        v1: Vec3A::from(t[1]),
        v2: Vec3A::from(t[2]),
    }
}

impl SceneBvh {
    pub fn build(geometry: &Geometry) -> Self {
        let tris: Vec<Triangle> = geometry.triangles.iter().map(to_obvhs).collect();
        let mut build_time = Duration::ZERO;
        if tris.is_empty() {
            return SceneBvh {
                bvh: CwBvh::default(),
                slots: Vec::new(),
                original: Vec::new(),
                build_time,
            };
        }
        let bvh = obvhs::cwbvh::builder::build_cwbvh_from_tris(
            &tris,
            BvhBuildParams::medium_build(),
            &mut build_time,
        );
        let original = bvh.primitive_indices.clone();
        let slots = original.iter().map(|&i| tris[i as usize]).collect();
        SceneBvh {
            bvh,
            slots,
            original,
            build_time,
        }
    }

    /// The closest triangle hit by `ray` with `t` in `[t_min, t_max]`.
    pub fn closest_hit(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
        if self.slots.is_empty() {
            return None;
        }
        let r = obvhs::ray::Ray::new(Vec3A::from(ray.origin), Vec3A::from(ray.dir), t_min, t_max);
        let mut hit = RayHit::none();
        self.bvh
            .ray_traverse(r, &mut hit, |r, slot| self.slots[slot].intersect(r))
            .then(|| Hit {
                t: hit.t,
                triangle: self.original[hit.primitive_id as usize] as usize,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_scene::load::parse_scene;
    use std::path::Path;

    const SCENE: &str = r#"{
        "camera": { "position": [0.5, 1.5, 3], "look_at": [0, 0.5, 0], "fov_y_deg": 50,
                    "width": 48, "height": 32 },
        "objects": [
            { "type": "quad", "size": [6, 6], "transform": { "rotate_deg": [-90, 0, 0] } },
            { "type": "box", "transform": { "translate": [-0.5, 0.5, 0], "rotate_deg": [0, 25, 0] } },
            { "type": "sphere", "radius": 0.4, "transform": { "translate": [0.8, 0.4, 0.3] } }
        ]
    }"#;

    /// Brute force over every triangle, for comparison.
    fn brute_force(g: &Geometry, ray: &Ray) -> Option<Hit> {
        let r = obvhs::ray::Ray::new(
            Vec3A::from(ray.origin),
            Vec3A::from(ray.dir),
            0.0,
            f32::INFINITY,
        );
        g.triangles
            .iter()
            .enumerate()
            .map(|(i, t)| Hit {
                t: to_obvhs(t).intersect(&r),
                triangle: i,
            })
            .filter(|h| h.t.is_finite())
            .min_by(|a, b| a.t.total_cmp(&b.t))
    }

    #[test]
    fn bvh_hits_match_brute_force_in_the_scene_numbering() {
        let scene = parse_scene(SCENE, Path::new("inline.json")).unwrap();
        let bvh = SceneBvh::build(&scene.geometry);
        let cam = &scene.camera;
        let mut hits = 0;
        for y in 0..cam.height {
            for x in 0..cam.width {
                let ray = cam.primary_ray(x as f32 + 0.5, y as f32 + 0.5);
                let got = bvh.closest_hit(&ray, 0.0, f32::INFINITY);
                let want = brute_force(&scene.geometry, &ray);
                assert_eq!(
                    got.map(|h| h.triangle),
                    want.map(|h| h.triangle),
                    "pixel ({x},{y})"
                );
                hits += got.is_some() as usize;
            }
        }
        assert!(hits > 0);
    }

    /// The primary ray through a sub-pixel position hits the scene point that the camera's
    /// projection maps back to that same position.
    #[test]
    fn primary_ray_hit_projects_to_its_subpixel_position() {
        let scene = parse_scene(SCENE, Path::new("inline.json")).unwrap();
        let bvh = SceneBvh::build(&scene.geometry);
        let cam = &scene.camera;
        let grid = mirrorbox_scene::SubpixelGrid::new(4);
        for (x, y) in [(3u32, 28u32), (24, 16), (40, 27), (10, 20)] {
            for offset in grid.offsets() {
                let (px, py) = (x as f32 + offset.x, y as f32 + offset.y);
                let ray = cam.primary_ray(px, py);
                let hit = bvh
                    .closest_hit(&ray, 0.0, f32::INFINITY)
                    .expect("scene covers these pixels");
                let p = ray.at(hit.t);
                let back = cam.project_to_pixel(p).unwrap();
                assert!(
                    (back - glam::Vec2::new(px, py)).length() < 1e-3,
                    "({px},{py}) → {back}"
                );
            }
        }
    }

    #[test]
    fn empty_scene_hits_nothing() {
        let bvh = SceneBvh::build(&Geometry::default());
        let ray = Ray {
            origin: Vec3::ZERO,
            dir: Vec3::Z,
        };
        assert_eq!(bvh.closest_hit(&ray, 0.0, f32::INFINITY), None);
    }
}
