//! Conservative screen-space geometry shared by the methods: the pixel rectangle of a
//! footprint (mirror textures, scissors), and culling of scene parts against a reflection
//! path's portal (`portal_stencil`, `unrolled`).

use glam::{Mat4, Vec2, Vec3};

/// Integer pixel rectangle at render resolution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rect {
    pub x: u32,
    pub y: u32,
    pub w: u32,
    pub h: u32,
}

/// The pixels covering the screen-space bounds `lo..hi` (pixels) of a footprint, with one
/// pixel of margin against CPU/GPU rounding at its edge, clamped to the `size` screen; `None`
/// when nothing of it is on screen.
pub fn footprint_rect(lo: Vec2, hi: Vec2, size: Vec2) -> Option<Rect> {
    let x0 = (lo.x.floor() - 1.0).clamp(0.0, size.x) as u32;
    let y0 = (lo.y.floor() - 1.0).clamp(0.0, size.y) as u32;
    let x1 = (hi.x.ceil() + 1.0).clamp(0.0, size.x) as u32;
    let y1 = (hi.y.ceil() + 1.0).clamp(0.0, size.y) as u32;
    (x1 > x0 && y1 > y0).then_some(Rect {
        x: x0,
        y: y0,
        w: x1 - x0,
        h: y1 - y0,
    })
}

/// The 8 corners of the box `lo..hi`.
pub fn box_corners(lo: Vec3, hi: Vec3) -> [Vec3; 8] {
    std::array::from_fn(|i| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// Whether the box `lo..hi` can project into the screen rectangle `portal` (pixels) through
/// `clip_from_world` (reversed Z: a point nearer than the near plane has `z > w`) —
/// conservative: a box reaching behind the eye counts as visible.
pub fn box_may_touch(
    clip_from_world: Mat4,
    lo: Vec3,
    hi: Vec3,
    portal: (Vec2, Vec2),
    size: Vec2,
) -> bool {
    let mut min = Vec2::splat(f32::INFINITY);
    let mut max = Vec2::splat(f32::NEG_INFINITY);
    let mut all_behind_near = true;
    for p in box_corners(lo, hi) {
        let c = clip_from_world * p.extend(1.0);
        if c.w <= 1e-6 {
            return true;
        }
        all_behind_near &= c.z > c.w;
        let px = mirrorbox_scene::camera::ndc_to_pixel(Vec2::new(c.x / c.w, c.y / c.w), size);
        min = min.min(px);
        max = max.max(px);
    }
    !all_behind_near
        && max.x >= portal.0.x
        && min.x <= portal.1.x
        && max.y >= portal.0.y
        && min.y <= portal.1.y
}
