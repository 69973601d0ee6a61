//! Writes the viewer's current camera back into a copy of the scene file, so that a view
//! found by hand is a reproducible `render` / `trace` / `sweep` input.
//!
//! The copy is the original JSON with `camera.position`, `camera.look_at`, `camera.up` and
//! `camera.fov_y_deg` replaced (everything else, size, exposure and stereo rig included, is
//! kept as written); paths inside it (`mesh` files) stay relative to the original's folder,
//! so the copy is written beside the original unless a path is given.

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
    let mut out = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?;
    out.push('\n');
    Ok(out)
}

/// Writes [`scene_with_camera`] to `to`, atomically.
pub fn save_camera(original: &Path, camera: &Camera, to: &Path) -> Result<(), String> {
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
        let dir = std::env::temp_dir().join(format!("mirrorbox-scene-copy-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let to = dir.join("view.json");
        save_camera(&original, &camera, &to).unwrap();
        let copy = mirrorbox_scene::load_scene(&to).unwrap();
        assert_eq!(copy.camera.position, camera.position);
        assert_eq!(copy.camera.look_at, camera.look_at);
        assert_eq!(copy.camera.fov_y_deg, 60.0);
        assert_eq!(copy.mirrors.len(), scene.mirrors.len());
        assert_eq!(
            copy.geometry.triangles.len(),
            scene.geometry.triangles.len()
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
