//! Which pixels show a mirror: the mask the reports' "error over the mirror pixels" is taken
//! over (issue 38). A pixel is a mirror pixel when the primary ray of any of its sub-pixel
//! samples (the truth's grid) first hits the front of a mirror — the pixels where a method's
//! reflections are seen, and where its error lives; every other pixel is shaded the same way
//! by every method (the comparison's floor).

use crate::bvh::SceneBvh;
use mirrorbox_scene::camera::SubpixelGrid;
use mirrorbox_scene::geometry::Surface;
use mirrorbox_scene::{Ray, Scene};
use rayon::prelude::*;

/// The mirror whose front `ray` first hits, if its first hit is one.
fn front_mirror(scene: &Scene, bvh: &SceneBvh, ray: &Ray) -> Option<usize> {
    let g = &scene.geometry;
    let hit = bvh.closest_hit(ray, 0.0, f32::INFINITY, None)?;
    let [a, b, c] = g.triangles[hit.triangle];
    let front = (b - a).cross(c - a).dot(ray.dir) < 0.0;
    match *g.surface(hit.triangle) {
        Surface::Mirror { mirror, .. } if front => Some(mirror),
        _ => None,
    }
}

/// One flag per pixel of `scene`'s camera, row-major, in parallel: `flag` of the pixel's
/// primary rays on the sub-pixel grid `grid`.
fn per_pixel(
    scene: &Scene,
    grid: SubpixelGrid,
    flag: impl Fn(&mut dyn Iterator<Item = Ray>) -> bool + Sync,
) -> Vec<bool> {
    let camera = &scene.camera;
    let (w, h) = (camera.width, camera.height);
    let rays = camera.ray_generator();
    let offsets: Vec<_> = grid.offsets().collect();
    (0..h)
        .into_par_iter()
        .flat_map_iter(|y| {
            let (offsets, flag) = (&offsets, &flag);
            (0..w).map(move |x| {
                let mut samples = offsets
                    .iter()
                    .map(|o| rays.ray(x as f32 + o.x, y as f32 + o.y));
                flag(&mut samples)
            })
        })
        .collect()
}

/// One flag per pixel, row-major: true where a sample's primary ray first hits the front of
/// a mirror of `scene`, seen from its camera on the sub-pixel grid `grid`.
pub fn mirror_mask(scene: &Scene, bvh: &SceneBvh, grid: SubpixelGrid) -> Vec<bool> {
    per_pixel(scene, grid, |samples| {
        let mut samples = samples;
        Iterator::any(&mut samples, |ray| front_mirror(scene, bvh, &ray).is_some())
    })
}

/// One flag per pixel, row-major: true where most of the pixel's samples that first hit a
/// mirror's front see, in that mirror, something off screen — their reflected ray's first hit
/// (or, where it escapes, a point far along it) projects behind the camera or outside the
/// image. What screen-space reflections cannot show, whatever their march (issue 39); the
/// report plots `ssr`'s error against the share of mirror pixels flagged.
pub fn reflections_off_screen(scene: &Scene, bvh: &SceneBvh, grid: SubpixelGrid) -> Vec<bool> {
    let camera = &scene.camera;
    let planes = crate::mirror_bounce::MirrorPlanes::new(scene);
    let size = camera.size();
    let off_screen = |q: glam::Vec3| {
        camera
            .project_to_pixel(q)
            .is_none_or(|p| p.x < 0.0 || p.y < 0.0 || p.x >= size.x || p.y >= size.y)
    };
    per_pixel(scene, grid, |samples| {
        let (mut mirrored, mut away) = (0, 0);
        for ray in samples {
            let Some(mirror) = front_mirror(scene, bvh, &ray) else {
                continue;
            };
            mirrored += 1;
            let Some((at, dir)) = planes.reflect(mirror, ray.origin.as_dvec3(), ray.dir.as_dvec3())
            else {
                continue;
            };
            let reflected = Ray {
                origin: at.as_vec3(),
                dir: dir.as_vec3(),
            };
            let seen = match bvh.closest_hit(&reflected, 0.0, f32::INFINITY, Some(mirror)) {
                Some(h) => reflected.at(h.t),
                None => reflected.at(1e4),
            };
            away += usize::from(off_screen(seen));
        }
        mirrored > 0 && 2 * away > mirrored
    })
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

    /// The paper's box, seen towards one mirror: most of what it reflects lies behind the
    /// camera (off screen); only mirror pixels are flagged, and a scene without mirrors has
    /// none.
    #[test]
    fn reflections_behind_the_camera_are_off_screen() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mirror_box.json");
        let mut scene = mirrorbox_scene::load::load_scene(&path).unwrap();
        scene.camera.width = 64;
        scene.camera.height = 36;
        let bvh = SceneBvh::build(&scene.geometry);
        let grid = SubpixelGrid::new(1);
        let mask = mirror_mask(&scene, &bvh, grid);
        let off = reflections_off_screen(&scene, &bvh, grid);
        assert!(
            off.iter().zip(&mask).all(|(o, m)| !o || *m),
            "only mirror pixels"
        );
        let mirrors = mask.iter().filter(|m| **m).count();
        let away = off.iter().filter(|o| **o).count();
        assert!(
            2 * away > mirrors,
            "{away} of {mirrors} mirror pixels off screen"
        );
        let bare = scene.without_mirrors();
        let bvh = SceneBvh::build(&bare.geometry);
        assert!(!reflections_off_screen(&bare, &bvh, grid).contains(&true));
    }
}
