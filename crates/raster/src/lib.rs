//! The wgpu rasterizer of mirrorbox.
//!
//! - [`adapter`]: the one adapter rule (Vulkan, then GL; `WGPU_BACKEND` overrides).
//! - [`gpu`]: the device, with timestamp queries when available.
//! - [`shading`]: the shading contract in WGSL and the scene buffers it reads.
//! - [`plan`]: the seed paper's recursion (naive and auxiliary), planned on the CPU.
//! - [`recursive_texture`]: executes that plan with render-to-texture mirror cameras.
//! - [`frame`]: targets, SSAA resolve, GPU timing, readback.

pub mod adapter;
pub mod frame;
pub mod gpu;
pub mod plan;
pub mod recursive_texture;
pub mod shading;

pub use adapter::{AdapterError, AdapterReport, SelectedAdapter, select_adapter};
pub use frame::{FrameTiming, TimingSource};
pub use gpu::{Gpu, RasterError};
pub use plan::Method;
pub use recursive_texture::FrameStats;

use mirrorbox_image::RgbImage;
use mirrorbox_scene::Scene;

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
}

pub struct RenderOutput {
    pub image: RgbImage,
    pub timing: FrameTiming,
    pub stats: FrameStats,
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
    let plan = plan::plan(scene, settings.method, w, h, settings.max_passes)?;
    let method =
        recursive_texture::RecursiveTexture::new(gpu, scene, &plan, settings.texture_scale);
    let target = frame::RenderTarget::new(
        &gpu.device,
        "view",
        w,
        h,
        wgpu::TextureUsages::TEXTURE_BINDING,
    );
    let resolve = frame::Resolve::new(&gpu.device, &target, settings.ssaa);
    gpu.check()?;
    let (image, timing) = frame::run_frames(
        gpu,
        &method,
        &target,
        &resolve,
        settings.warmup,
        settings.frames,
    )?;
    Ok(RenderOutput {
        image,
        timing,
        stats: method.stats,
    })
}
