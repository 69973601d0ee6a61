//! The linear image tone-mapped to 8-bit sRGB on the GPU, drawn into a rectangle of a
//! window's target — the bytes [`RgbImage::to_srgb8`](mirrorbox_image::RgbImage::to_srgb8)
//! writes, without reading the image back (`mirrorbox view`'s method pane, drawn inside the
//! window's paint as an engine tone-maps in its final pass).
//!
//! `to_srgb8` computes `srgb::encode8(c × exposure)` per channel. The shader
//! (`shaders/display_tone_map.wgsl`) does the same IEEE multiply, then finds the byte in the
//! table of [`encode8_thresholds`](mirrorbox_image::srgb::encode8_thresholds): `encode8` is
//! monotone, so the byte is the number of thresholds the value reaches, found from the
//! value's bits (sign and NaN first, then integer comparisons: exact whatever a compiler
//! assumes about floats). Tested three ways: the shader's search on the CPU
//! ([`encode8_by_thresholds`](mirrorbox_image::srgb::encode8_by_thresholds)) against
//! `encode8` around every threshold and, with `--ignored`, for every f32 in [0, 1]; this
//! pass on the GPU for every threshold ± 2 ulps and the special values
//! (`crates/raster/tests/integration/display_tone_map.rs`); and end to end by the viewer
//! tests, which compare the pane in a screenshot with `render`'s PNG.
//!
//! Measured on lavapipe (640×360, 2 cores): a pass of its own — compute into a buffer
//! copied into a texture egui then painted, or a full-screen pass into such a texture —
//! cost 2.3–2.5 ms a frame; drawn in the window's paint instead of egui's textured quad it
//! costs what the quad did plus the arithmetic.

use crate::gpu::Gpu;
use crate::pipeline::fragment_buffer_entry;
use wgpu::util::DeviceExt;

/// The WGSL of the pass.
pub static SHADER: crate::wgsl::WgslSource = crate::wgsl::WgslSource {
    label: "display tone map",
    enable: &[],
    parts: &[include_str!("../../../../shaders/display_tone_map.wgsl")],
};

/// The shader's `ToneMap` uniform.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ToneMapUniform {
    /// The rectangle's top-left corner in the target's pixels.
    pub origin: [f32; 2],
    /// Image pixels per target pixel, per axis: (1, 1) for the image shown 1:1 (its exact
    /// bytes).
    pub step: [f32; 2],
    pub exposure: f32,
    pub pad: f32,
}

/// The pass's layout for `crate::wgsl`'s test against the WGSL struct.
pub fn gpu_structs() -> Vec<crate::wgsl::HostLayout> {
    vec![crate::host_layout!(ToneMapUniform as "ToneMap" {
        origin, step, exposure, pad
    })]
}

/// The pipeline for one target format and the threshold table, made once per window.
pub struct DisplayToneMap {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    thresholds: wgpu::Buffer,
}

/// What one source image needs: its bind group and uniform. Made again only when the
/// source texture changes (a frame built at another size).
pub struct ToneMapSource {
    source: wgpu::Texture,
    bind_group: wgpu::BindGroup,
    uniform: wgpu::Buffer,
}

impl ToneMapSource {
    /// Whether this binding reads `texture`.
    pub fn reads(&self, texture: &wgpu::Texture) -> bool {
        &self.source == texture
    }

    /// Sets where and how the next [`DisplayToneMap::draw`] of this source draws.
    pub fn set(&self, queue: &wgpu::Queue, uniform: ToneMapUniform) {
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }
}

impl DisplayToneMap {
    /// Whether a target of `format` holds the bytes this pass writes: 8-bit unorm RGBA or
    /// BGRA, not sRGB (which would encode them again).
    pub fn exact_on(format: wgpu::TextureFormat) -> bool {
        matches!(
            format,
            wgpu::TextureFormat::Rgba8Unorm | wgpu::TextureFormat::Bgra8Unorm
        )
    }

    /// The pipeline drawing into targets of `format` (the window's surface; the bytes are
    /// `to_srgb8`'s where [`DisplayToneMap::exact_on`] holds).
    pub fn new(gpu: &Gpu, format: wgpu::TextureFormat) -> Self {
        let layout = gpu.bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("display tone map"),
            entries: &[
                fragment_buffer_entry(0, wgpu::BufferBindingType::Uniform),
                crate::targets::texture_entry(1),
                fragment_buffer_entry(2, wgpu::BufferBindingType::Storage { read_only: true }),
            ],
        });
        let module = gpu.shader_module(&SHADER, false);
        let pipeline = crate::pipeline::full_screen_pipeline(
            gpu,
            "display tone map",
            &[&layout],
            &module,
            format,
        );
        let thresholds = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("sRGB thresholds"),
                contents: bytemuck::cast_slice(&mirrorbox_image::srgb::encode8_thresholds()),
                usage: wgpu::BufferUsages::STORAGE,
            });
        DisplayToneMap {
            pipeline,
            layout,
            thresholds,
        }
    }

    /// The binding of `source` (a linear colour texture with `TEXTURE_BINDING` usage: a
    /// frame's [`crate::BuiltView::output`]).
    pub fn bind(&self, gpu: &Gpu, source: &wgpu::Texture) -> ToneMapSource {
        let uniform = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("display tone map"),
            size: std::mem::size_of::<ToneMapUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let view = source.create_view(&Default::default());
        let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("display tone map"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.thresholds.as_entire_binding(),
                },
            ],
        });
        ToneMapSource {
            source: source.clone(),
            bind_group,
            uniform,
        }
    }

    /// Draws `source` into the pass's viewport (the rectangle [`ToneMapSource::set`] named).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, source: &ToneMapSource) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &source.bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
