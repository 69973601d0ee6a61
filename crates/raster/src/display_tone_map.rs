//! The linear image tone-mapped to 8-bit sRGB on the GPU, into a texture a window shows —
//! the bytes [`RgbImage::to_srgb8`](mirrorbox_image::RgbImage::to_srgb8) writes, without
//! reading the image back (`mirrorbox view`'s panes).
//!
//! `to_srgb8` computes `srgb::encode8(c × exposure)` per channel. The shader
//! (`shaders/display_tone_map.wgsl`) does the same IEEE multiply, then counts the
//! thresholds of [`encode8_thresholds`](mirrorbox_image::srgb::encode8_thresholds) the value
//! reaches by a binary search (8 comparisons, no `pow`): `encode8` is monotone, so that count
//! is its byte for every input (tested for every f32 in [0, 1] in `mirrorbox-image`, and
//! end to end by the viewer tests that compare a pane with `render`'s PNG). A compute pass
//! writes one packed RGBA8 word per pixel into a buffer, copied into the texture: bytes all
//! the way, no float-to-unorm conversion whose rounding the driver would choose (Vulkan
//! only *recommends* rounding to nearest). Measured on lavapipe at 640×360: 2.4 ms, the
//! same as a full-screen fragment pass writing k / 255 into the texture.

use crate::gpu::Gpu;
use wgpu::util::DeviceExt;

/// The WGSL of the pass.
pub static SHADER: crate::wgsl::WgslSource = crate::wgsl::WgslSource {
    label: "display tone map",
    enable: &[],
    parts: &[include_str!("../../../shaders/display_tone_map.wgsl")],
};

/// The shader's `ToneMap` uniform.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ToneMapUniform {
    pub exposure: f32,
    pub width: u32,
    pub height: u32,
    pub row_words: u32,
}

/// The pass's layout for `crate::wgsl`'s test against the WGSL struct.
pub fn gpu_structs() -> Vec<crate::wgsl::HostLayout> {
    vec![crate::host_layout!(ToneMapUniform as "ToneMap" {
        exposure, width, height, row_words
    })]
}

/// The format of the textures it writes (what egui samples: not sRGB-aware, so the bytes
/// are shown as they are).
pub const PANE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

const WORKGROUP: u32 = 8;

/// The pipeline and the threshold table, made once per device.
pub struct DisplayToneMap {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    thresholds: wgpu::Buffer,
}

/// What one source image needs: its bind group, the uniform and the packed-pixel buffer.
/// Made again only when the source texture changes (a rebuilt frame of another size).
pub struct ToneMapSource {
    source: wgpu::Texture,
    bind_group: wgpu::BindGroup,
    uniform: wgpu::Buffer,
    pixels: wgpu::Buffer,
    row_bytes: u32,
}

impl ToneMapSource {
    /// Whether this binding reads `texture`.
    pub fn reads(&self, texture: &wgpu::Texture) -> bool {
        &self.source == texture
    }

    /// The image's size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.source.width(), self.source.height())
    }
}

impl DisplayToneMap {
    pub fn new(gpu: &Gpu) -> Self {
        let device = &gpu.device;
        let storage = |binding, read_only| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = gpu.bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("display tone map"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ..crate::targets::texture_entry(1)
                },
                storage(2, true),
                storage(3, false),
            ],
        });
        let pipeline_layout = crate::pipeline::pipeline_layout(gpu, "display tone map", &[&layout]);
        let module = gpu.shader_module(&SHADER, false);
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("display tone map"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("cs_main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let thresholds = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
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
        let device = &gpu.device;
        let (w, h) = (source.width(), source.height());
        let row_bytes = (4 * w).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("display tone map"),
            size: std::mem::size_of::<ToneMapUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let pixels = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("display tone map pixels"),
            size: u64::from(row_bytes) * u64::from(h),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let view = source.create_view(&Default::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
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
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: pixels.as_entire_binding(),
                },
            ],
        });
        ToneMapSource {
            source: source.clone(),
            bind_group,
            uniform,
            pixels,
            row_bytes,
        }
    }

    /// Encodes the tone map of `source` at `exposure` into `pane` (a [`PANE_FORMAT`]
    /// texture of the source's size with `COPY_DST` usage), after whatever `encoder` holds.
    pub fn encode(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        source: &ToneMapSource,
        exposure: f32,
        pane: &wgpu::Texture,
    ) {
        let (w, h) = source.size();
        assert_eq!(
            (pane.width(), pane.height()),
            (w, h),
            "the pane is the image's size"
        );
        gpu.queue.write_buffer(
            &source.uniform,
            0,
            bytemuck::bytes_of(&ToneMapUniform {
                exposure,
                width: w,
                height: h,
                row_words: source.row_bytes / 4,
            }),
        );
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("display tone map"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &source.bind_group, &[]);
            pass.dispatch_workgroups(w.div_ceil(WORKGROUP), h.div_ceil(WORKGROUP), 1);
        }
        encoder.copy_buffer_to_texture(
            wgpu::TexelCopyBufferInfo {
                buffer: &source.pixels,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(source.row_bytes),
                    rows_per_image: Some(h),
                },
            },
            pane.as_image_copy(),
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
    }
}
