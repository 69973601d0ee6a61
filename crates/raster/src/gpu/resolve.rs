//! The SSAA resolve: box-filters the `factor × factor` supersampled view into the output
//! image (`shaders/resolve.wgsl`).

use crate::gpu::Gpu;
use crate::pipeline::fragment_buffer_entry;
use crate::targets::{RenderTarget, texture_entry};

/// Box-filters the `factor × factor` supersampled view into the output image.
pub struct Resolve {
    pipeline: wgpu::RenderPipeline,
    bind_group: wgpu::BindGroup,
    pub output: wgpu::Texture,
    output_view: wgpu::TextureView,
    /// The SSAA factor it filters by.
    pub factor: u32,
}

impl Resolve {
    /// The resolve of `source` on `gpu`; the output has `gpu`'s colour format.
    pub fn new(gpu: &Gpu, source: &RenderTarget, factor: u32) -> Self {
        use wgpu::util::DeviceExt;
        let device = &gpu.device;
        let module = gpu.shader_module(&crate::wgsl::RESOLVE, false);
        let layout = gpu.bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("resolve"),
            entries: &[
                fragment_buffer_entry(0, wgpu::BufferBindingType::Uniform),
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
        let pipeline = crate::pipeline::full_screen_pipeline(
            gpu,
            "resolve",
            &[&layout],
            &module,
            gpu.color_format.texture_format(),
        );
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
            format: gpu.color_format.texture_format(),
            // Read back (`render`), or read by the display tone map (`view`).
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        Resolve {
            pipeline,
            bind_group,
            output_view: output.create_view(&Default::default()),
            output,
            factor,
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
