//! Shadow maps for the contract's `lighting.shadows` (issue 15; seed 002's "mirrored light
//! sources", `docs/shading.md`, "Shadow maps"), shared by every raster method: `--shadows map`.
//!
//! **Layers.** One `R32Float` layer stores, per texel, the distance from a light (or light
//! image) to the nearest surface along that texel's ray:
//! - a real light: six cube faces, 90° each (face `f`: axis `a = f / 2`, sign `+` for even
//!   `f`; clip `x, y, w = d_{a+1}, d_{a+2}, ±d_a` for `d = x − L`, so the shader finds a
//!   point's face and texel without a matrix);
//! - a light image `L′ = R_j⋯R₁·L`: one perspective layer from `L′` through its last mirror's
//!   rectangle (the frustum fitted to the rectangle), keeping only what lies in front of that
//!   mirror and not the mirror itself — what light through the mirror can reach.
//!
//! **Test** (`shaders/shading.wgsl`, `unshadowed`): a point `x` lit by an image is lit only if
//! every leg is clear: `x` against the image's layer, then the point `c_j` where the segment
//! `x → L′` meets the last mirror against the parent image's layer, …, then `c₁` against the
//! real light's cube. A leg is clear when its length is at most the stored distance plus the
//! bias `b + r·t·min(tan θ, 8)`: `b` the constant `--shadow-bias`, `r` the distance, `t` the
//! layer's texel size in tangent units, `θ` the incidence (one texel's depth footprint).
//! Nearest texel, no filtering: the error a map leaves is what the lighting sweep measures.
//!
//! Every layer is rendered every frame, before the method's passes, and counted in its cost.

use crate::gpu::Gpu;
use crate::pipeline::{UniformArena, dynamic_uniform_entry, pipeline_layout, record_binding};
use crate::shading::VERTEX_LAYOUT;
use crate::wgsl::WgslSource;
use mirrorbox_scene::Scene;

pub use crate::shadow_plan::{
    GpuShadowView, LightShadow, MAX_SHADOW_BYTES, ShadowPlan, ShadowSettings, TooManyShadowLayers,
};

/// The layout of [`GpuShadowView`] as the WGSL declares it (checked by [`crate::wgsl`]'s tests).
pub fn gpu_structs() -> Vec<crate::wgsl::HostLayout> {
    vec![crate::host_layout!(GpuShadowView as "ShadowView" {
        clip_from_world, keep, origin, skip_surface
    })]
}

/// The shadow-map pass's WGSL.
pub static SHADER: WgslSource = WgslSource {
    label: "shadow_map",
    enable: &[],
    parts: &[include_str!("../../../shaders/shadow_map.wgsl")],
};

/// The layers' format: one 32-bit float distance per texel, where the device renders 32-bit
/// float colour (`rgba32float` targets); else half floats (wgpu's GL backend: 2⁻¹¹ relative,
/// 0.005 at a distance of 10 scene units, under the default bias).
pub fn format(gpu: &Gpu) -> wgpu::TextureFormat {
    match gpu.color_format {
        crate::color_format::ColorFormat::Rgba32Float => wgpu::TextureFormat::R32Float,
        _ => wgpu::TextureFormat::Rgba16Float,
    }
}

/// A texel no surface covers (the clear value): farther than anything.
pub const FAR: f32 = 1e30;

/// A frame's shadow maps on the GPU: the layers, the pass that fills them, and the view the
/// shading contract binds. Without `--shadows map`, one unused 1×1 layer (the binding must
/// exist).
pub struct ShadowMaps {
    pub plan: Option<ShadowPlan>,
    /// Every layer, as the shading contract samples them.
    pub array_view: wgpu::TextureView,
    pass: Option<ShadowPass>,
}

struct ShadowPass {
    layer_views: Vec<wgpu::TextureView>,
    depth_view: wgpu::TextureView,
    pipeline: wgpu::RenderPipeline,
    bind_group: wgpu::BindGroup,
    offsets: Vec<u32>,
    vertices: wgpu::Buffer,
    vertex_count: u32,
}

impl ShadowMaps {
    /// The layers of `plan` (none: the placeholder), checked against the device's limits.
    pub fn new(
        gpu: &Gpu,
        scene: &Scene,
        plan: Option<ShadowPlan>,
    ) -> Result<Self, crate::RasterError> {
        let device = &gpu.device;
        let Some(plan) = plan else {
            // Sampled only, never drawn into.
            let texture = layers_texture(
                device,
                wgpu::TextureFormat::R32Float,
                wgpu::TextureUsages::TEXTURE_BINDING,
                1,
                1,
            );
            let array_view = texture.create_view(&array_descriptor());
            return Ok(ShadowMaps {
                plan: None,
                array_view,
                pass: None,
            });
        };
        let limits = device.limits();
        let layers = plan.views.len() as u32;
        if layers > limits.max_texture_array_layers {
            return Err(crate::RasterError::ExceedsDevice {
                what: "the shadow-map layers".into(),
                needed: format!("{layers} layers"),
                limit: format!("{} layers", limits.max_texture_array_layers),
                adapter: gpu.report.name.clone(),
                advice: "; lower lighting.mirrored_lights (--mirrored-lights)",
            });
        }
        gpu.check_target(
            plan.settings.size,
            plan.settings.size,
            "; lower --shadow-map-size",
        )?;
        let size = plan.settings.size;
        let texture = layers_texture(
            device,
            format(gpu),
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            size,
            layers.max(1),
        );
        let array_view = texture.create_view(&array_descriptor());
        let layer_views = (0..layers)
            .map(|i| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("shadow map layer"),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: i,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow map depth"),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: crate::targets::DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let depth_view = depth.create_view(&Default::default());
        let mut arena = UniformArena::new(device);
        let offsets = plan.views.iter().map(|v| arena.push(v)).collect();
        let uniforms = arena.buffer(device, "shadow views");
        let layout = gpu.bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow view"),
            entries: &[dynamic_uniform_entry(
                0,
                wgpu::ShaderStages::VERTEX_FRAGMENT,
            )],
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow view"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: record_binding::<GpuShadowView>(&uniforms),
            }],
        });
        let module = gpu.shader_module(&SHADER, false);
        let pipeline_layout = pipeline_layout(gpu, "shadow map", &[&layout]);
        let pipeline = gpu.render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow map"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_shadow"),
                compilation_options: Default::default(),
                buffers: &[Some(VERTEX_LAYOUT)],
            },
            // Both faces occlude (mirrors' backs included), as in the tracer.
            primitive: Default::default(),
            depth_stencil: Some(crate::pipeline::depth_state(
                crate::targets::DEPTH_FORMAT,
                true,
                wgpu::CompareFunction::Greater,
                Default::default(),
            )),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_shadow"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: format(gpu),
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let (vertices, vertex_count) = crate::shading::all_vertices(device, scene);
        Ok(ShadowMaps {
            plan: Some(plan),
            array_view,
            pass: Some(ShadowPass {
                layer_views,
                depth_view,
                pipeline,
                bind_group,
                offsets,
                vertices,
                vertex_count,
            }),
        })
    }

    /// What the shading contract binds ([`crate::shading::SceneBuffers`]).
    pub fn binding(&self) -> crate::shadow_plan::ShadowBinding<'_> {
        crate::shadow_plan::ShadowBinding {
            plan: self.plan.as_ref(),
            layers: &self.array_view,
        }
    }

    /// Layers rendered per frame (scene passes added to the method's).
    pub fn layers(&self) -> usize {
        self.plan.as_ref().map_or(0, |p| p.views.len())
    }

    /// Triangles the layers draw per frame.
    pub fn triangles(&self) -> usize {
        self.pass
            .as_ref()
            .map_or(0, |p| p.layer_views.len() * p.vertex_count as usize / 3)
    }

    /// Renders every layer; the first pass carries `first_pass`'s timestamp write (the frame's
    /// start).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        mut first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let Some(pass) = &self.pass else { return };
        for (view, &offset) in pass.layer_views.iter().zip(&pass.offsets) {
            let mut rp = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow map layer"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: f64::from(FAR),
                            g: 0.0,
                            b: 0.0,
                            a: 0.0,
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &pass.depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: first_pass.take(),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            rp.set_pipeline(&pass.pipeline);
            rp.set_bind_group(0, &pass.bind_group, &[offset]);
            rp.set_vertex_buffer(0, pass.vertices.slice(..));
            rp.draw(0..pass.vertex_count, 0..1);
        }
    }
}

fn layers_texture(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    size: u32,
    layers: u32,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("shadow maps"),
        size: wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

fn array_descriptor() -> wgpu::TextureViewDescriptor<'static> {
    wgpu::TextureViewDescriptor {
        label: Some("shadow maps"),
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    }
}

/// The frame encoder of a method with shadow maps: the layers first, then the method.
pub struct WithShadowMaps {
    pub shadows: ShadowMaps,
    pub method: Box<dyn crate::timing::FrameEncoder>,
}

impl crate::timing::FrameEncoder for WithShadowMaps {
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &crate::targets::RenderTarget,
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        self.shadows.encode(encoder, first_pass);
        self.method.encode(encoder, target, None);
    }

    fn preroll_frames(&self) -> u32 {
        self.method.preroll_frames()
    }

    fn advance(&self) {
        self.method.advance()
    }

    fn drawn_depth(&self) -> Option<usize> {
        self.method.drawn_depth()
    }

    fn history(&self) -> Option<crate::timing::FrameHistory> {
        self.method.history()
    }
}
