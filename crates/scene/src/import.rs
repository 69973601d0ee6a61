//! `mirrorbox import`: a glTF asset placed in a mirror box sized to its bounds, written as a
//! scene file that `trace`, `render`, `sweep` and `view` read (`docs/gltf.md`).
//!
//! The asset keeps its own units and place; the box is built around it, in proportion to
//! the paper's box (`scenes/mirror_box.json`: two facing mirrors 4 wide and 3 high, 4 apart,
//! a light 15 W/sr near the ceiling):
//! - `d` = the asset's largest extent; `h` = half its largest horizontal extent + `d/2`;
//! - two mirrors facing each other across z at `c.z ± h` (`c` the bounds' centre), `2h`
//!   wide and `e.y + d` high, standing on a floor quad `2h × 2h` just below the asset;
//! - a camera near the back mirror looking at the front one, as in the paper's box; one
//!   light above the asset, its intensity scaled by `(h/2)²` so that the floor's irradiance
//!   is the paper box's; the asset's own lights are kept.

use crate::gltf_asset::{self, GltfError, GltfOptions};
use crate::limits::MAX_TRIANGLES;
use crate::texture::MAX_TEXTURE_TEXELS;
use glam::{Mat4, Vec3};
use std::path::Path;

/// The paper box's light intensity (W/sr) at its half-width 2.
const PAPER_BOX_INTENSITY: f32 = 15.0;

/// A scene file's text holding the asset at `asset` (written into the scene as `asset_ref`,
/// the path the scene file will use) in a mirror box, `width × height` pixels.
pub fn mirror_box_scene(
    asset: &Path,
    asset_ref: &str,
    scene: Option<usize>,
    width: u32,
    height: u32,
) -> Result<String, GltfError> {
    let loaded = gltf_asset::load_gltf(
        asset,
        &GltfOptions {
            scene,
            triangle_budget: MAX_TRIANGLES as u64,
            texel_budget: MAX_TEXTURE_TEXELS,
            transform: Mat4::IDENTITY,
            curved_mirrors: gltf_asset::CurvedMirrors::Refuse,
        },
    )?;
    let points = loaded
        .parts
        .iter()
        .flat_map(|p| p.triangles.iter().flatten().copied())
        .chain(loaded.mirrors.iter().flat_map(|m| m.corners()));
    let (lo, hi) = points.fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
    let extent = (hi - lo).max(Vec3::splat(1e-6));
    let c = (lo + hi) * 0.5;
    let d = extent.max_element();
    let h = 0.5 * extent.x.max(extent.z) + 0.5 * d;
    let wall = extent.y + d;
    let floor = lo.y - 1e-3 * d;
    let mirror_y = floor + 0.5 * wall;
    // Five decimals, printed from f64: no f32 noise in the file.
    let r = |v: f32| ((f64::from(v) * 1e5).round() / 1e5).to_string();
    let v3 = |v: Vec3| format!("[{}, {}, {}]", r(v.x), r(v.y), r(v.z));
    let intensity = r(PAPER_BOX_INTENSITY * (h / 2.0) * (h / 2.0));
    let scene_field = scene.map_or(String::new(), |i| format!(", \"scene\": {i}"));
    let camera = v3(Vec3::new(
        c.x + 0.35 * h,
        floor + 0.7 * wall,
        c.z + 0.95 * h,
    ));
    let look_at = v3(Vec3::new(c.x - 0.1 * h, floor + 0.3 * wall, c.z - h));
    let front = v3(Vec3::new(c.x, mirror_y, c.z - h));
    let back = v3(Vec3::new(c.x, mirror_y, c.z + h));
    let side = r(2.0 * h);
    let wall = r(wall);
    let floor_at = v3(Vec3::new(c.x, floor, c.z));
    let light = v3(Vec3::new(c.x, floor + 0.93 * (extent.y + d), c.z));
    let asset_ref = serde_json::to_string(asset_ref).unwrap_or_default();
    Ok(format!(
        r#"{{
  "camera": {{
    "position": {camera},
    "look_at": {look_at},
    "up": [0, 1, 0],
    "fov_y_deg": 45,
    "width": {width},
    "height": {height}
  }},
  "mirrors": [
    {{ "name": "front", "center": {front}, "normal": [0, 0, 1], "up": [0, 1, 0],
      "width": {side}, "height": {wall}, "reflectance": [0.9, 0.9, 0.9] }},
    {{ "name": "back", "center": {back}, "normal": [0, 0, -1], "up": [0, 1, 0],
      "width": {side}, "height": {wall}, "reflectance": [0.9, 0.9, 0.9] }}
  ],
  "objects": [
    {{ "type": "quad", "name": "floor", "size": [{side}, {side}],
      "transform": {{ "translate": {floor_at}, "rotate_deg": [-90, 0, 0] }}, "albedo": [0.6, 0.55, 0.5] }},
    {{ "type": "gltf", "name": "asset", "path": {asset_ref}{scene_field} }}
  ],
  "lights": [
    {{ "position": {light}, "intensity": [{intensity}, {intensity}, {intensity}] }}
  ],
  "ambient": [0.05, 0.05, 0.05],
  "background": [0.02, 0.02, 0.03],
  "terminal": [0, 0, 0]
}}
"#
    ))
}
