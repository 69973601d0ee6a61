//! The CPU half of the shadow maps (`crate::shadow_maps`, `docs/shading.md`, "Shadow
//! maps"): which layers a frame draws, each one's transform, and the per-light facts the
//! shading contract's test reads. Planned before any GPU resource, so an over-budget frame is
//! refused first (exit 2).

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec4};
use mirrorbox_scene::{Scene, Surface};

/// What the shading contract binds of a frame's shadow maps: the plan (none without
/// `--shadows map`) and every layer as one array view.
#[derive(Clone, Copy)]
pub struct ShadowBinding<'a> {
    pub plan: Option<&'a ShadowPlan>,
    pub layers: &'a wgpu::TextureView,
}

/// Most bytes the shadow-map layers of one frame may take: `layers × size² × 4`. Keeps a
/// mirror room's hundreds of light images at a large size from exhausting an 8 GB machine.
pub const MAX_SHADOW_BYTES: u64 = 1 << 30;

/// `--shadow-map-size` and `--shadow-bias`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowSettings {
    pub size: u32,
    pub bias: f32,
}

/// One layer as the shadow pass draws it (`ShadowView` in `shaders/shadow_map.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuShadowView {
    pub clip_from_world: [[f32; 4]; 4],
    pub keep: [f32; 4],
    pub origin: [f32; 3],
    pub skip_surface: u32,
}

/// Near plane of the cube faces, scene units: far below any gap between a light and a surface
/// in a scene of a few units.
const CUBE_NEAR: f32 = 1e-3;

/// The per-light facts the shading contract's WGSL needs to test a leg against its layer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightShadow {
    /// First layer (a real light's six faces start here).
    pub layer: u32,
    /// Light images: the layer's `clip_from_world`; real lights use the cube rule.
    pub clip_from_world: Mat4,
    /// Texel size in tangent units (one texel spans `t·r` at distance `r`).
    pub texel: f32,
}

/// Every layer of a frame, planned on the CPU.
#[derive(Debug)]
pub struct ShadowPlan {
    pub settings: ShadowSettings,
    pub views: Vec<GpuShadowView>,
    /// Per entry of the shading list: the real lights, then the light images.
    pub lights: Vec<LightShadow>,
}

/// Why shadow maps cannot be made for a frame.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error(
    "--shadows map: {layers} layers of {size}×{size} texels ({needed}) exceed {what} ({limit}); \
     lower --shadow-map-size or lighting.mirrored_lights (--mirrored-lights)"
)]
pub struct TooManyShadowLayers {
    pub layers: u64,
    pub size: u32,
    pub needed: String,
    pub what: &'static str,
    pub limit: String,
}

impl ShadowPlan {
    /// The layers for `scene`'s lights and light images; refuses more than
    /// [`MAX_SHADOW_BYTES`] before anything is allocated.
    pub fn new(scene: &Scene, settings: ShadowSettings) -> Result<Self, TooManyShadowLayers> {
        let l = &scene.lighting;
        let layers = 6 * l.lights.len() as u64 + l.images.images.len() as u64;
        let bytes = layers * u64::from(settings.size).pow(2) * 4;
        if bytes > MAX_SHADOW_BYTES {
            return Err(TooManyShadowLayers {
                layers,
                size: settings.size,
                needed: mirrorbox_files::human_bytes(bytes),
                what: "the shadow-map budget",
                limit: mirrorbox_files::human_bytes(MAX_SHADOW_BYTES),
            });
        }
        let mut views = Vec::with_capacity(layers as usize);
        let mut lights = Vec::with_capacity(l.lights.len() + l.images.images.len());
        for light in &l.lights {
            lights.push(LightShadow {
                layer: views.len() as u32,
                clip_from_world: Mat4::IDENTITY,
                texel: 2.0 / settings.size as f32,
            });
            for face in 0..6 {
                views.push(GpuShadowView {
                    clip_from_world: cube_face(light.position, face).to_cols_array_2d(),
                    keep: [0.0, 0.0, 0.0, 1.0],
                    origin: light.position.to_array(),
                    skip_surface: u32::MAX,
                });
            }
        }
        for image in &l.images.images {
            let mirror = &scene.mirrors[image.mirror];
            let (clip_from_world, texel) =
                through_rectangle(image.position, &mirror.corners(), settings.size);
            lights.push(LightShadow {
                layer: views.len() as u32,
                clip_from_world,
                texel,
            });
            views.push(GpuShadowView {
                clip_from_world: clip_from_world.to_cols_array_2d(),
                keep: image.beam[0].to_array(),
                origin: image.position.to_array(),
                skip_surface: mirror_surface(scene, image.mirror),
            });
        }
        Ok(ShadowPlan {
            settings,
            views,
            lights,
        })
    }
}

/// The surface id of mirror `m`'s triangles (`u32::MAX` if it has none).
fn mirror_surface(scene: &Scene, m: usize) -> u32 {
    scene
        .geometry
        .surfaces
        .iter()
        .position(|s| matches!(s, Surface::Mirror { mirror, .. } if *mirror == m))
        .map_or(u32::MAX, |i| i as u32)
}

/// Cube face `face` of a light at `origin`: axis `a = face / 2`, looking along `+e_a` for
/// even faces and `−e_a` for odd ones; clip `(d_{a+1}, d_{a+2}, near, ±d_a)` for
/// `d = x − origin` (reversed Z: depth `near / w`, nearer is larger).
pub fn cube_face(origin: Vec3, face: u32) -> Mat4 {
    let a = (face / 2) as usize;
    let sign = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
    let e = |i: usize| Vec3::AXES[i];
    // Rows of the matrix acting on (x, 1): each row is (coefficients, −coefficients·origin).
    let row = |v: Vec3| Vec4::new(v.x, v.y, v.z, -v.dot(origin));
    let rows = [
        row(e(b)),
        row(e(c)),
        Vec4::new(0.0, 0.0, 0.0, CUBE_NEAR),
        row(e(a) * sign),
    ];
    Mat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose()
}

/// A perspective from `eye` whose frustum is fitted to the rectangle `corners` (off axis:
/// the rectangle's projection fills the layer's bounding square), reversed Z with its near
/// plane at half the eye's distance to the rectangle's plane; and the texel size in tangent
/// units (the larger of the two axes).
pub fn through_rectangle(eye: Vec3, corners: &[Vec3; 4], size: u32) -> (Mat4, f32) {
    let center = corners.iter().copied().sum::<Vec3>() / 4.0;
    let forward = (center - eye).normalize();
    let helper = if forward.x.abs() < 0.9 {
        Vec3::X
    } else {
        Vec3::Y
    };
    let right = forward.cross(helper).normalize();
    let up = right.cross(forward);
    // Tangent coordinates of the corners (all in front: the eye is a mirror image, strictly
    // behind the mirror's plane, so every corner is ahead of it).
    let tangents = corners.map(|p| {
        let d = p - eye;
        let z = d.dot(forward);
        (d.dot(right) / z, d.dot(up) / z, z)
    });
    let (mut x0, mut x1, mut y0, mut y1) = (f32::MAX, f32::MIN, f32::MAX, f32::MIN);
    let mut near = f32::MAX;
    for (x, y, z) in tangents {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
        near = near.min(z);
    }
    // One texel of margin on each side keeps the rectangle's edge texels inside.
    let (sx, sy) = (x1 - x0, y1 - y0);
    let margin = 1.0 / size as f32;
    let (x0, x1) = (x0 - margin * sx, x1 + margin * sx);
    let (y0, y1) = (y0 - margin * sy, y1 + margin * sy);
    let near = 0.5 * near;
    // clip = (2(tx − x0)/(x1 − x0) − 1)·z, …, near, z with tx = d·right / z, z = d·forward.
    let kx = 2.0 / (x1 - x0);
    let ky = 2.0 / (y1 - y0);
    let cx = -(x0 + x1) / (x1 - x0);
    let cy = -(y0 + y1) / (y1 - y0);
    let row = |v: Vec3| Vec4::new(v.x, v.y, v.z, -v.dot(eye));
    let rows = [
        row(right * kx + forward * cx),
        row(up * ky + forward * cy),
        Vec4::new(0.0, 0.0, 0.0, near),
        row(forward),
    ];
    let m = Mat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose();
    let texel = (x1 - x0).max(y1 - y0) / size as f32;
    (m, texel)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Where a point lands in a layer: NDC (x, y) and depth.
    fn project(m: Mat4, p: Vec3) -> (f32, f32, f32) {
        let c = m * p.extend(1.0);
        (c.x / c.w, c.y / c.w, c.z / c.w)
    }

    #[test]
    fn a_cube_face_sees_its_axis_and_nearer_is_deeper() {
        let origin = Vec3::new(1.0, 2.0, 3.0);
        for face in 0..6u32 {
            let a = (face / 2) as usize;
            let sign = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
            let m = cube_face(origin, face);
            let ahead = origin + Vec3::AXES[a] * sign * 2.0;
            let (x, y, z) = project(m, ahead);
            assert!(x.abs() < 1e-6 && y.abs() < 1e-6, "face {face}: ({x}, {y})");
            let (_, _, z_far) = project(m, origin + Vec3::AXES[a] * sign * 4.0);
            assert!(z > z_far && z_far > 0.0, "reversed Z: {z} {z_far}");
            // A point 45° off the axis lies on the face's edge.
            let b = (a + 1) % 3;
            let (x, _, _) = project(m, ahead + Vec3::AXES[b] * 2.0);
            assert!((x - 1.0).abs() < 1e-6, "face {face}: edge at {x}");
        }
    }

    #[test]
    fn a_layer_through_a_rectangle_frames_it() {
        let corners = [
            Vec3::new(-1.0, -0.5, 0.0),
            Vec3::new(1.0, -0.5, 0.0),
            Vec3::new(1.0, 0.5, 0.0),
            Vec3::new(-1.0, 0.5, 0.0),
        ];
        // An eye off to one side: the fit is off axis.
        let eye = Vec3::new(0.7, 0.2, -2.0);
        let (m, texel) = through_rectangle(eye, &corners, 256);
        let (mut lo, mut hi) = ((f32::MAX, f32::MAX), (f32::MIN, f32::MIN));
        for p in corners {
            let (x, y, z) = project(m, p);
            assert!(x.abs() <= 1.0 && y.abs() <= 1.0, "{p}: ({x}, {y})");
            assert!(z > 0.0 && z < 1.0, "{p}: depth {z}");
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
        // The fit is tight: the rectangle spans the layer but for a texel of margin.
        for v in [lo.0, lo.1] {
            assert!(v < -0.98, "{lo:?}");
        }
        for v in [hi.0, hi.1] {
            assert!(v > 0.98, "{hi:?}");
        }
        assert!(texel > 0.0 && texel < 0.01, "{texel}");
    }
}
