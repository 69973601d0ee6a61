//! The camera of the methods that follow rays from it (`ray-query`, `ssr`) as their shaders
//! read it: `shaders/camera_rays.wgsl`'s `CameraRays` — the raster transform and the frame
//! of the CPU's primary rays (`mirrorbox_scene::camera::RayGenerator`), so that a ray the GPU
//! follows from a pixel is the ray the tracer follows from it.

use bytemuck::{Pod, Zeroable};
use mirrorbox_scene::Camera;

/// `shaders/camera_rays.wgsl`.
pub const WGSL: &str = include_str!("../../../../shaders/camera_rays.wgsl");

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CameraRays {
    clip_from_world: [[f32; 4]; 4],
    eye: [f32; 3],
    shift_x: f32,
    forward: [f32; 3],
    near: f32,
    right: [f32; 3],
    _pad0: f32,
    up: [f32; 3],
    _pad1: f32,
    size: [f32; 2],
    _pad2: [f32; 2],
}

impl CameraRays {
    /// `camera` rendered at `width × height` (the render target: image × SSAA).
    pub fn new(camera: &Camera, width: u32, height: u32) -> CameraRays {
        let (forward, right, up, shift_x) = camera.with_size(width, height).ray_generator().frame();
        let clip = crate::projection::camera_projection(camera, width, height) * camera.view();
        CameraRays {
            clip_from_world: clip.to_cols_array_2d(),
            eye: camera.position.to_array(),
            shift_x,
            forward: forward.to_array(),
            near: crate::projection::NEAR,
            right: right.to_array(),
            up: up.to_array(),
            size: [width as f32, height as f32],
            ..Zeroable::zeroed()
        }
    }

    /// Its layout, for the WGSL layout test.
    pub fn layout() -> crate::wgsl::HostLayout {
        crate::host_layout!(CameraRays as "CameraRays" {
            clip_from_world, eye, shift_x, forward, near, right, _pad0, up, _pad1, size, _pad2
        })
    }
}
