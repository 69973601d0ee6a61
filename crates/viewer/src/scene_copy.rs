//! Writes the viewer's current camera back into a copy of the scene file, so that a view
//! found by hand is a reproducible `render` / `trace` / `sweep` input.
//!
//! The copy is the original JSON with `camera.position`, `camera.look_at`, `camera.up`,
//! `camera.fov_y_deg` and the view's `camera.width` and `camera.height` replaced (everything
//! else, exposure and stereo rig included, is kept as written; a `--alpha` given to the viewer
//! is not written). Paths inside it (meshes, textures, glTF files) stay relative to the
//! original's folder, so the copy is written beside the original: a path elsewhere is refused.

use mirrorbox_scene::Camera;
use std::path::Path;

/// Most bytes read from the scene file (the loader's own bound).
const MAX_SCENE_BYTES: u64 = mirrorbox_scene::limits::MAX_SCENE_FILE_BYTES;

/// The scene file at `original` with `camera`'s placement, as pretty JSON text.
pub fn scene_with_camera(original: &Path, camera: &Camera) -> Result<String, String> {
    let text = mirrorbox_files::read_bounded_text(original, MAX_SCENE_BYTES, "scene file")
        .map_err(|e| e.to_string())?;
    let mut json: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| format!("{}: not JSON: {e}", original.display()))?;
    let Some(cam) = json.get_mut("camera").and_then(|c| c.as_object_mut()) else {
        return Err(format!("{}: has no `camera` object", original.display()));
    };
    let v = |p: glam::Vec3| serde_json::json!([p.x, p.y, p.z]);
    cam.insert("position".into(), v(camera.position));
    cam.insert("look_at".into(), v(camera.look_at));
    cam.insert("up".into(), v(camera.up));
    cam.insert("fov_y_deg".into(), serde_json::json!(camera.fov_y_deg));
    // The view's size (`--width`/`--height`), so that a render of the copy is the panes.
    cam.insert("width".into(), serde_json::json!(camera.width));
    cam.insert("height".into(), serde_json::json!(camera.height));
    let mut out = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?;
    out.push('\n');
    Ok(out)
}

/// Whether `to` is in `original`'s folder (links followed), where a copy's relative paths
/// still resolve.
pub fn beside(original: &Path, to: &Path) -> Result<(), String> {
    let folder = |p: &Path| std::fs::canonicalize(mirrorbox_files::folder_of(p)).ok();
    if folder(original).is_none() || folder(original) != folder(to) {
        return Err(format!(
            "{}: a camera copy is written beside its scene, in {} (the scene's paths are \
             relative to that folder)",
            to.display(),
            mirrorbox_files::folder_of(original).display()
        ));
    }
    Ok(())
}

/// Writes [`scene_with_camera`] to `to`, atomically; `to` must be beside the original (a copy
/// elsewhere did not load: its relative paths named files that are not there).
pub fn save_camera(original: &Path, camera: &Camera, to: &Path) -> Result<(), String> {
    beside(original, to)?;
    let text = scene_with_camera(original, camera)?;
    mirrorbox_files::write_atomically(to, text.as_bytes()).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_copy_loads_with_the_new_camera_and_the_rest_unchanged() {
        let original = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mirror_box.json");
        let scene = mirrorbox_scene::load_scene(&original).unwrap();
        let mut camera = scene.camera.clone();
        camera.position = glam::Vec3::new(0.1, 1.2, 1.5);
        camera.look_at = glam::Vec3::new(0.3, 1.0, -2.0);
        camera.fov_y_deg = 60.0;
        camera.width = 96;
        camera.height = 54;
        let dir = tempfile::tempdir().unwrap();
        let beside_original = dir.path().join("scene.json");
        std::fs::copy(&original, &beside_original).unwrap();
        // Elsewhere than the scene: refused (its relative paths would not resolve).
        let elsewhere = dir.path().join("sub");
        std::fs::create_dir(&elsewhere).unwrap();
        let refused = save_camera(&beside_original, &camera, &elsewhere.join("view.json"));
        assert!(refused.is_err_and(|e| e.contains("beside its scene")));
        let to = dir.path().join("view.json");
        save_camera(&beside_original, &camera, &to).unwrap();
        let copy = mirrorbox_scene::load_scene(&to).unwrap();
        assert_eq!(copy.camera.position, camera.position);
        assert_eq!(copy.camera.look_at, camera.look_at);
        assert_eq!(copy.camera.fov_y_deg, 60.0);
        assert_eq!((copy.camera.width, copy.camera.height), (96, 54));
        assert_eq!(copy.mirrors.len(), scene.mirrors.len());
        assert_eq!(
            copy.geometry.triangles.len(),
            scene.geometry.triangles.len()
        );
    }
}
