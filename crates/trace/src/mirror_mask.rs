//! Which pixels show a mirror: the mask the reports' "error over the mirror pixels" is taken
//! over (issue 38). A pixel is a mirror pixel when the primary ray of any of its sub-pixel
//! samples (the truth's grid) first hits the front of a mirror — the pixels where a method's
//! reflections are seen, and where its error lives; every other pixel is shaded the same way
//! by every method (the comparison's floor).

use crate::bvh::SceneBvh;
use mirrorbox_scene::Scene;
use mirrorbox_scene::camera::SubpixelGrid;
use mirrorbox_scene::geometry::Surface;
use rayon::prelude::*;

/// One flag per pixel, row-major: true where a sample's primary ray first hits the front of
/// a mirror of `scene`, seen from its camera on the sub-pixel grid `grid`.
pub fn mirror_mask(scene: &Scene, bvh: &SceneBvh, grid: SubpixelGrid) -> Vec<bool> {
    let camera = &scene.camera;
    let (w, h) = (camera.width, camera.height);
    let rays = camera.ray_generator();
    let geometry = &scene.geometry;
    let offsets: Vec<_> = grid.offsets().collect();
    (0..h)
        .into_par_iter()
        .flat_map_iter(|y| {
            let offsets = &offsets;
            (0..w).map(move |x| {
                offsets.iter().any(|o| {
                    let ray = rays.ray(x as f32 + o.x, y as f32 + o.y);
                    bvh.closest_hit(&ray, 0.0, f32::INFINITY, None)
                        .is_some_and(|hit| {
                            let surface = geometry.surface_of[hit.triangle] as usize;
                            let [a, b, c] = geometry.triangles[hit.triangle];
                            let front = (b - a).cross(c - a).dot(ray.dir) < 0.0;
                            front && matches!(geometry.surfaces[surface], Surface::Mirror { .. })
                        })
                })
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mirror_box_shows_mirrors_in_part_of_the_image_only() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mirror_box.json");
        let mut scene = mirrorbox_scene::load::load_scene(&path).unwrap();
        scene.camera.width = 64;
        scene.camera.height = 36;
        let bvh = SceneBvh::build(&scene.geometry);
        let mask = mirror_mask(&scene, &bvh, SubpixelGrid::new(1));
        assert_eq!(mask.len(), 64 * 36);
        let share = mask.iter().filter(|m| **m).count() as f64 / mask.len() as f64;
        assert!(share > 0.05 && share < 0.95, "mirror share {share}");
        // Without its mirrors, no pixel is a mirror pixel.
        let bare = scene.without_mirrors();
        let bvh = SceneBvh::build(&bare.geometry);
        assert!(
            !mirror_mask(&bare, &bvh, SubpixelGrid::new(1))
                .iter()
                .any(|m| *m)
        );
    }
}
