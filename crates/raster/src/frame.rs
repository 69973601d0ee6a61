//! What every raster method shares per frame: the render-resolution target it draws the
//! final view into, the SSAA resolve to the output size (`shaders/resolve.wgsl`), GPU timing
//! with timestamp queries, and reading the image back.
//!
//! **Timing.** A frame is every scene pass of the method plus the resolve. With
//! `TIMESTAMP_QUERY` the time is measured on the GPU from the start of the frame's first pass
//! to the end of the resolve; otherwise it is the wall clock from submission to completion.
//! Frames are submitted and waited for one by one, after `warmup` untimed frames.

use crate::gpu::{Gpu, RasterError};
use mirrorbox_image::RgbImage;
use std::time::Instant;

pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// A method that draws one frame's scene passes, ending with the full view in `target`.
/// Per-frame counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameStats {
    /// Scene passes: the main view plus one per texture render.
    pub passes: usize,
    pub texture_renders: usize,
    /// Draw calls, including the SSAA resolve's one.
    pub draws: usize,
    /// Deepest chain of textures or reflection path: the reflections the method can show.
    pub depth: usize,
    /// Triangles submitted per frame (each instance counted), before any clipping.
    pub triangles: usize,
    /// Exact methods: the reflection paths drawn and pruned.
    pub paths: Option<PathCounts>,
    /// `unrolled`: how instances are clipped to their cells.
    pub clipping: Option<Clipping>,
}

/// How the unrolled method clips an instance to its cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clipping {
    /// Hardware clip distances (plus the per-fragment guard where a part needs it).
    ClipDistances,
    /// Every test per fragment, with discard.
    FragmentDiscard,
}

impl Clipping {
    pub fn name(&self) -> &'static str {
        match self {
            Clipping::ClipDistances => "clip distances",
            Clipping::FragmentDiscard => "fragment discard",
        }
    }
}

/// How many reflection paths an exact method kept and why it dropped the others
/// (see `mirrorbox_scene::reflection_paths`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathCounts {
    /// Paths through at least one mirror that are drawn (the camera itself not counted).
    pub kept: usize,
    pub pruned_empty: usize,
    /// Portals holding no sample (exact pruning).
    pub pruned_no_sample: usize,
    /// Portals under `--min-portal-area` (lossy).
    pub pruned_small: usize,
    pub pruned_attenuation: usize,
    /// Paths cut by the depth cap.
    pub capped: usize,
}

impl PathCounts {
    pub fn of(set: &mirrorbox_scene::reflection_paths::PathSet) -> Self {
        PathCounts {
            kept: set.paths.len().saturating_sub(1),
            pruned_empty: set.pruned_empty,
            pruned_no_sample: set.pruned_no_sample,
            pruned_small: set.pruned_small,
            pruned_attenuation: set.pruned_attenuation,
            capped: set.capped,
        }
    }

    pub fn pruned(&self) -> usize {
        self.pruned_empty
            + self.pruned_no_sample
            + self.pruned_small
            + self.pruned_attenuation
            + self.capped
    }
}

pub trait FrameEncoder {
    /// `first_pass` carries the timestamp write the method must attach to its first pass.
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    );
}

/// A colour + depth pair.
pub struct RenderTarget {
    pub color: wgpu::Texture,
    pub color_view: wgpu::TextureView,
    pub depth_view: wgpu::TextureView,
    pub width: u32,
    pub height: u32,
}

/// A single-sample 2D texture of `width × height` (targets, depth and stencil attachments).
pub fn texture_2d(
    device: &wgpu::Device,
    label: &str,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

impl RenderTarget {
    pub fn new(
        device: &wgpu::Device,
        label: &str,
        width: u32,
        height: u32,
        extra: wgpu::TextureUsages,
    ) -> Self {
        let texture = |format, usage, suffix: &str| {
            texture_2d(
                device,
                &format!("{label} {suffix}"),
                width,
                height,
                format,
                usage,
            )
        };
        let color = texture(
            COLOR_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | extra,
            "colour",
        );
        let depth = texture(
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
            "depth",
        );
        RenderTarget {
            color_view: color.create_view(&Default::default()),
            depth_view: depth.create_view(&Default::default()),
            color,
            width,
            height,
        }
    }

    /// Begins a pass that clears colour to `clear` (linear radiance) and depth to 1.
    pub fn begin_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        clear: glam::Vec3,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        self.begin_pass_with(encoder, clear, &self.depth_view, 1.0, None, timestamps)
    }

    /// Begins a pass that clears colour to `clear` and the depth(-stencil) attachment `depth`
    /// to `depth_clear` (and its stencil to `stencil_clear`, if it has one). Depth and stencil
    /// are not kept after the pass.
    pub fn begin_pass_with<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        clear: glam::Vec3,
        depth: &wgpu::TextureView,
        depth_clear: f32,
        stencil_clear: Option<u32>,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: None,
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: clear.x as f64,
                        g: clear.y as f64,
                        b: clear.z as f64,
                        a: 1.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(depth_clear),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: stencil_clear.map(|v| wgpu::Operations {
                    load: wgpu::LoadOp::Clear(v),
                    store: wgpu::StoreOp::Discard,
                }),
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }
}

/// Box-filters the `factor × factor` supersampled view into the output image.
pub struct Resolve {
    pipeline: wgpu::RenderPipeline,
    bind_group: wgpu::BindGroup,
    pub output: wgpu::Texture,
    output_view: wgpu::TextureView,
}

impl Resolve {
    pub fn new(device: &wgpu::Device, source: &RenderTarget, factor: u32) -> Self {
        use wgpu::util::DeviceExt;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("resolve"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../../../shaders/resolve.wgsl").into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("resolve"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                texture_entry(1),
            ],
        });
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("resolve"),
            contents: bytemuck::cast_slice(&[factor, 0, 0, 0]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("resolve"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&source.color_view),
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("resolve"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("resolve"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(COLOR_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let output = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("output"),
            size: wgpu::Extent3d {
                width: source.width / factor,
                height: source.height / factor,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: COLOR_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        Resolve {
            pipeline,
            bind_group,
            output_view: output.create_view(&Default::default()),
            output,
        }
    }

    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("resolve"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.output_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// A sampled (not filtered) float texture binding for fragment shaders.
pub fn texture_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimingSource {
    GpuTimestamps,
    WallClock,
}

impl TimingSource {
    pub fn name(self) -> &'static str {
        match self {
            TimingSource::GpuTimestamps => "gpu-timestamps",
            TimingSource::WallClock => "wall-clock",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct FrameTiming {
    pub source: TimingSource,
    /// Milliseconds of each timed frame, in order.
    pub frames_ms: Vec<f64>,
}

impl FrameTiming {
    pub fn median_ms(&self) -> f64 {
        let mut v = self.frames_ms.clone();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        if n == 0 {
            f64::NAN
        } else if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    }
    pub fn min_ms(&self) -> f64 {
        self.frames_ms.iter().copied().fold(f64::INFINITY, f64::min)
    }
}

/// Renders `warmup + frames` frames, times the last `frames`, and reads the final image back.
pub fn run_frames(
    gpu: &Gpu,
    method: &dyn FrameEncoder,
    target: &RenderTarget,
    resolve: &Resolve,
    warmup: u32,
    frames: u32,
) -> Result<(RgbImage, FrameTiming), RasterError> {
    let device = &gpu.device;
    let queries = gpu.timestamps.then(|| {
        let set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("frame"),
            ty: wgpu::QueryType::Timestamp,
            count: 2,
        });
        let resolved = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps"),
            size: 16,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let read = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps read"),
            size: 16,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        (set, resolved, read)
    });
    let period_ns = gpu.queue.get_timestamp_period() as f64;
    let mut frames_ms = Vec::with_capacity(frames as usize);
    for frame in 0..warmup + frames.max(1) {
        let mut encoder = device.create_command_encoder(&Default::default());
        let begin = queries
            .as_ref()
            .map(|(set, _, _)| wgpu::RenderPassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(0),
                end_of_pass_write_index: None,
            });
        method.encode(&mut encoder, target, begin);
        let end = queries
            .as_ref()
            .map(|(set, _, _)| wgpu::RenderPassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: None,
                end_of_pass_write_index: Some(1),
            });
        resolve.encode(&mut encoder, end);
        if let Some((set, resolved, read)) = &queries {
            encoder.resolve_query_set(set, 0..2, resolved, 0);
            encoder.copy_buffer_to_buffer(resolved, 0, read, 0, 16);
        }
        let started = Instant::now();
        gpu.queue.submit([encoder.finish()]);
        gpu.wait()?;
        let wall_ms = started.elapsed().as_secs_f64() * 1e3;
        gpu.check()?;
        let ms = match &queries {
            Some((_, _, read)) => {
                let ticks: Vec<u64> = map_read(gpu, read)?;
                ticks[1].wrapping_sub(ticks[0]) as f64 * period_ns / 1e6
            }
            None => wall_ms,
        };
        if frame >= warmup {
            frames_ms.push(ms);
        }
    }
    let source = if queries.is_some() {
        TimingSource::GpuTimestamps
    } else {
        TimingSource::WallClock
    };
    let image = read_texture(gpu, &resolve.output)?;
    Ok((image, FrameTiming { source, frames_ms }))
}

fn map_read<T: bytemuck::Pod>(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<T>, RasterError> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    gpu.wait()?;
    rx.recv()
        .map_err(|e| RasterError::Gpu(e.to_string()))?
        .map_err(|e| RasterError::Gpu(e.to_string()))?;
    let view = buffer
        .get_mapped_range(..)
        .map_err(|e| RasterError::Gpu(e.to_string()))?;
    let data = bytemuck::cast_slice(&view).to_vec();
    drop(view);
    buffer.unmap();
    Ok(data)
}

/// Copies an `Rgba32Float` texture into a linear RGB image.
pub fn read_texture(gpu: &Gpu, texture: &wgpu::Texture) -> Result<RgbImage, RasterError> {
    let (w, h) = (texture.width(), texture.height());
    let row = w * 16;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (padded * h) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        texture.size(),
    );
    gpu.queue.submit([encoder.finish()]);
    let floats: Vec<f32> = map_read(gpu, &buffer)?;
    let per_row = (padded / 4) as usize;
    Ok(RgbImage::from_fn(w, h, |x, y| {
        let i = y as usize * per_row + x as usize * 4;
        [floats[i], floats[i + 1], floats[i + 2]]
    }))
}
