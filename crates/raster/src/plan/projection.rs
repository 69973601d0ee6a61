//! The one projection of every raster method: the camera's perspective with infinite reversed
//! Z, read through a 32-bit float depth buffer.
//!
//! x, y and w are the camera's own (`Camera::projection`), so every method covers exactly the
//! tracer's pixels. Depth is `z_ndc = NEAR / w`: 1 at the near plane, → 0 at infinity, so a
//! depth buffer clears to [`FAR_DEPTH`] and nearer is greater ([`NEARER`]). In a float
//! buffer its resolution is relative — `Δt ≈ 2⁻²³·t` at distance `t`, 0.5 mm at 4 km — where
//! standard Z resolves `t²·2⁻²⁴/near`: 6 cm at 100 m with the near plane at 0.01.
//!
//! Every view of a frame — the camera's, each mirror camera, each reflection path — uses this
//! one matrix after its (reflected) view: a mirror's plane does not become the near plane (an
//! oblique projection tilts the depth range and spends its precision unevenly, which let a box
//! leak through a thin shelf seen through a periscope); it clips like any other plane, with a
//! hardware clip distance or per fragment (`shaders/mirror_plane_clip_distances.wgsl`,
//! `shaders/unrolled*.wgsl`). Depth along a pixel's ray is then the unfolded distance in every
//! method, and the one depth buffer of `unrolled` compares reflections of any depth.

use glam::Mat4;
use mirrorbox_scene::Camera;

/// Distance of the near plane (scene units) of every raster view.
pub const NEAR: f32 = 0.01;

/// What a depth buffer clears to: infinitely far.
pub const FAR_DEPTH: f32 = 0.0;

/// The depth test keeping the nearer surface (reversed Z: nearer is greater).
pub const NEARER: wgpu::CompareFunction = wgpu::CompareFunction::Greater;

/// The depth test keeping the nearer surface, or the later one at equal depth.
pub const NEARER_OR_EQUAL: wgpu::CompareFunction = wgpu::CompareFunction::GreaterEqual;

/// The camera's projection at `width × height` with infinite reversed Z (module docs).
pub fn camera_projection(camera: &Camera, width: u32, height: u32) -> Mat4 {
    // Any far distance: the depth row is replaced.
    infinite_reversed_z(
        camera.with_size(width, height).projection(NEAR, 2.0 * NEAR),
        NEAR,
    )
}

/// A `[0, 1]`-depth perspective `projection` with its depth row replaced by infinite reversed
/// Z: `z_ndc = near / w`. x, y and w (hence every pixel's coverage) are unchanged.
fn infinite_reversed_z(projection: Mat4, near: f32) -> Mat4 {
    let mut m = projection;
    m.x_axis.z = 0.0;
    m.y_axis.z = 0.0;
    m.z_axis.z = 0.0;
    m.w_axis.z = near;
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec3, Vec4};

    #[test]
    fn reversed_z_keeps_coverage_and_orders_depth_far_to_zero() {
        let camera = Camera {
            position: Vec3::ZERO,
            look_at: -Vec3::Z,
            up: Vec3::Y,
            fov_y_deg: 50.0,
            width: 160,
            height: 90,
            exposure: 1.0,
            shift_x: 0.0,
        };
        let p = camera.projection(NEAR, 1e4);
        let r = camera_projection(&camera, 160, 90);
        for z in [-NEAR, -1.0, -10.0, -5000.0] {
            let v = Vec4::new(0.3, -0.2, z, 1.0);
            let (a, b) = (p * v, r * v);
            assert_eq!((a.x, a.y, a.w), (b.x, b.y, b.w));
        }
        let depth = |z: f32| {
            let c = r * Vec4::new(0.0, 0.0, z, 1.0);
            c.z / c.w
        };
        assert!((depth(-NEAR) - 1.0).abs() < 1e-6);
        // Strictly decreasing with distance, and still resolving 1 part in 1e5 at 4 km.
        assert!(depth(-1.0) > depth(-2.0));
        assert!(depth(-4000.0) > depth(-4000.05));
        // Nothing in front of the eye is beyond the far end.
        assert!(depth(-1e30) >= FAR_DEPTH);
    }
}
