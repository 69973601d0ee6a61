//! The wgpu rasterizer of mirrorbox.
//!
//! - [`adapter`]: the one adapter rule (Vulkan, then GL; `WGPU_BACKEND` overrides).
//! - [`gpu`]: the device, with timestamp queries when available.
//! - [`shading`]: the shading contract in WGSL and the scene buffers it reads.
//! - [`plan`]: the seed paper's recursion (naive and auxiliary), planned on the CPU.
//! - [`recursive_texture`]: executes that plan with render-to-texture mirror cameras.
//! - [`portal_stencil`]: exact mirrors by stencil recursion over the reflection paths.
//! - [`unrolled`]: exact mirrors with every reflection path an instance of the scene.
//! - [`culling`]: parts against a path's portal, for both exact methods.
//! - [`frame`]: targets, SSAA resolve, GPU timing, readback.

pub mod adapter;
pub mod culling;
pub mod frame;
pub mod gpu;
pub mod plan;
pub mod portal_stencil;
pub mod recursive_texture;
pub mod shading;
pub mod unrolled;

pub use adapter::{AdapterError, AdapterReport, SelectedAdapter, select_adapter};
pub use frame::{Clipping, FrameStats, PathCounts};
pub use frame::{FrameTiming, TimingSource};
pub use gpu::{Gpu, RasterError};
pub use plan::Method;

use mirrorbox_image::RgbImage;
use mirrorbox_scene::Scene;

/// Most triangles (instances counted) an exact method submits per frame: a time bound
/// (about 10 s on lavapipe, 2 cores); refused beyond with a hint.
pub const MAX_TRIANGLES_PER_FRAME: usize = 50_000_000;

/// Most reflection paths an exact method draws per frame (memory and time bound).
pub const MAX_PORTAL_PATHS: usize = 200_000;

/// How to render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    pub method: Method,
    /// Supersampling factor s (the s×s sub-pixel grid of the tracer's `--spp s²`).
    pub ssaa: u32,
    /// Timed frames, after `warmup` untimed ones.
    pub frames: u32,
    pub warmup: u32,
    pub max_passes: usize,
    /// Mirror texture resolution relative to the mirror's footprint (1 = exact).
    pub texture_scale: f32,
    /// Exact methods: prune reflection paths whose portal is smaller (pixels², at render
    /// resolution) or whose attenuation falls below `min_attenuation`.
    pub min_portal_area: f32,
    pub min_attenuation: f32,
    /// `unrolled`: clip per fragment even where the adapter has clip distances.
    pub fragment_clipping: bool,
}

pub struct RenderOutput {
    pub image: RgbImage,
    pub timing: FrameTiming,
    pub stats: FrameStats,
    /// Conditions under which the image may not be what the method promises.
    pub warnings: Vec<String>,
}

/// Plans, then renders `scene` at its camera's size with `settings`. The plan (and the
/// `max_passes` refusal) happens before any GPU resource is made.
pub fn render(
    gpu: &Gpu,
    scene: &Scene,
    settings: &RenderSettings,
) -> Result<RenderOutput, RasterError> {
    let (w, h) = (
        scene.camera.width * settings.ssaa,
        scene.camera.height * settings.ssaa,
    );
    let target = frame::RenderTarget::new(
        &gpu.device,
        "view",
        w,
        h,
        wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let resolve = frame::Resolve::new(&gpu.device, &target, settings.ssaa);
    let mut warnings = Vec::new();
    let (method, stats): (Box<dyn frame::FrameEncoder>, FrameStats) = match settings.method {
        Method::Portal { depth } | Method::Unrolled { depth } => {
            let projection = scene
                .camera
                .with_size(w, h)
                .projection(plan::NEAR, plan::FAR);
            let limits = mirrorbox_scene::reflection_paths::PathLimits {
                max_depth: depth,
                min_portal_area: settings.min_portal_area,
                min_attenuation: settings.min_attenuation,
                max_paths: MAX_PORTAL_PATHS,
            };
            let paths = mirrorbox_scene::reflection_paths::reflection_paths(
                scene, w, h, projection, &limits,
            );
            if paths.truncated {
                return Err(RasterError::Plan(plan::PlanError::TooManyPaths {
                    limit: MAX_PORTAL_PATHS,
                }));
            }
            if matches!(settings.method, Method::Portal { .. }) {
                let m = portal_stencil::PortalStencil::new(gpu, scene, &paths, w, h, projection)?;
                let stats = m.stats;
                (Box::new(m), stats)
            } else {
                let m = unrolled::Unrolled::new(
                    gpu,
                    scene,
                    &paths,
                    w,
                    h,
                    projection,
                    settings.fragment_clipping,
                )?;
                if m.overlapping_siblings > 0 {
                    warnings.push(format!(
                        "{} pairs of sibling portals overlap (a mirror hides part of another): \
                         unrolled may be wrong there; --method portal is exact",
                        m.overlapping_siblings
                    ));
                }
                let stats = m.stats;
                (Box::new(m), stats)
            }
        }
        method => {
            let plan = plan::plan(scene, method, w, h, settings.max_passes)?;
            let m =
                recursive_texture::RecursiveTexture::new(gpu, scene, &plan, settings.texture_scale);
            let stats = m.stats;
            (Box::new(m), stats)
        }
    };
    gpu.check()?;
    let (image, timing) = frame::run_frames(
        gpu,
        method.as_ref(),
        &target,
        &resolve,
        settings.warmup,
        settings.frames,
    )?;
    Ok(RenderOutput {
        image,
        timing,
        stats,
        warnings,
    })
}
