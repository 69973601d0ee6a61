//! Render targets: the depth formats, and colour + depth pairs in the device's colour format
//! ([`crate::color_format::ColorFormat`]).

use crate::gpu::Gpu;

use crate::projection::FAR_DEPTH;

/// The one depth format of every depth-only attachment: 32-bit float, whose relative
/// precision is what reversed Z needs ([`crate::projection`]).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Depth with a stencil, for `portal`'s stencil recursion: 32-bit float depth, an optional
/// adapter feature (`DEPTH32FLOAT_STENCIL8`).
pub const DEPTH_STENCIL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32FloatStencil8;
/// Depth with a stencil where the adapter lacks [`DEPTH_STENCIL_FORMAT`]: 24 bits (or more —
/// the driver picks), uniform in `z_ndc`, so reversed Z resolves only `t²·2⁻²⁴/NEAR` at
/// distance `t` (6 cm at 100 m).
pub const DEPTH_STENCIL_FALLBACK: wgpu::TextureFormat = wgpu::TextureFormat::Depth24PlusStencil8;

/// The depth-stencil format a device with `features` gets.
pub fn depth_stencil_format(features: wgpu::Features) -> wgpu::TextureFormat {
    if features.contains(wgpu::Features::DEPTH32FLOAT_STENCIL8) {
        DEPTH_STENCIL_FORMAT
    } else {
        DEPTH_STENCIL_FALLBACK
    }
}

/// A depth(-stencil) attachment and the values a pass clears it to.
pub struct DepthClear<'a> {
    pub view: &'a wgpu::TextureView,
    pub depth: f32,
    /// The stencil's clear value, if the attachment has a stencil.
    pub stencil: Option<u32>,
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
    /// A target of `gpu`'s colour format with a depth attachment.
    pub fn new(
        gpu: &Gpu,
        label: &str,
        width: u32,
        height: u32,
        extra: wgpu::TextureUsages,
    ) -> Self {
        let texture = |format, usage, suffix: &str| {
            texture_2d(
                &gpu.device,
                &format!("{label} {suffix}"),
                width,
                height,
                format,
                usage,
            )
        };
        let color = texture(
            gpu.color_format.texture_format(),
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

    /// Begins a pass labelled `label` that clears colour to `clear` (linear radiance) and depth
    /// to far ([`FAR_DEPTH`]).
    pub fn begin_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        label: &str,
        clear: glam::Vec3,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        self.begin_pass_with_alpha(encoder, label, clear, 1.0, timestamps)
    }

    /// [`RenderTarget::begin_pass`] clearing alpha to `alpha` (a mirror texture whose alpha
    /// holds distances).
    pub fn begin_pass_with_alpha<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        label: &str,
        clear: glam::Vec3,
        alpha: f32,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        let depth = DepthClear {
            view: &self.depth_view,
            depth: FAR_DEPTH,
            stencil: None,
        };
        self.begin(encoder, label, clear.extend(alpha), depth, timestamps)
    }

    /// Begins a pass that clears colour to `clear` and the depth(-stencil) attachment as
    /// `depth` says. Depth and stencil are not kept after the pass.
    pub fn begin_pass_with<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        label: &str,
        clear: glam::Vec3,
        depth: DepthClear<'_>,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        self.begin(encoder, label, clear.extend(1.0), depth, timestamps)
    }

    fn begin<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        label: &str,
        clear: glam::Vec4,
        depth: DepthClear<'_>,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: clear.x as f64,
                        g: clear.y as f64,
                        b: clear.z as f64,
                        a: clear.w as f64,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth.view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(depth.depth),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: depth.stencil.map(|v| wgpu::Operations {
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
