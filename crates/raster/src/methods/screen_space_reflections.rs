//! `ssr`: screen-space reflections, the reflections games ship by default (Unreal, Unity,
//! Godot): the scene drawn once, then every mirror pixel marches its reflected ray through
//! the depth buffer — a hierarchical-depth march (McGuire & Mara, "Efficient GPU Screen-Space
//! Ray Tracing", JCGT 2014, over a nearest-depth pyramid), a thickness, a step budget — and
//! shows the colour of the pixel it hits. What is not on screen cannot be reflected: a ray
//! that leaves the screen, passes behind a surface thicker than the thickness, runs out of
//! steps, or hits another mirror (one bounce) shows the fallback — `none` (the terminal
//! radiance × the reflectance), `cubemap` (the `cubemap` method's image there: a probe), or
//! `planar` (`path-textures depth=1`: the paper's one-bounce mirror texture). The fallback's
//! frame is drawn every frame before the method's own passes and counted in its cost.
//! Entry points: `shaders/screen_space_reflections.wgsl`, `shaders/ssr_depth_pyramid.wgsl`.
//!
//! Uneven mirrors reflect about their bumped normal (the contract's rule included), as
//! engines' SSR does with a normal map; the fallback is the fallback method's own trick.

use crate::gpu::{Gpu, RasterError};
use crate::method::{
    Advise, BuiltFrame, Clipping, FrameStats, MethodEntry, OptionKind, OptionSpec, ParamValue,
    PlannedFrame, RasterMethod,
};
use crate::pipeline::{BindGroupBuilder, ScenePipeline, depth_state, pipeline_layout};
use crate::plan::PlanError;
use crate::projection::{FAR_DEPTH, NEARER};
use crate::shading::{SceneBuffers, VERTEX_LAYOUT};
use crate::targets::{DEPTH_FORMAT, RenderTarget};
use crate::timing::FrameEncoder;
use crate::wgsl::{HostLayout, WgslSource};
use bytemuck::{Pod, Zeroable};
use mirrorbox_scene::Scene;
use wgpu::util::DeviceExt;

/// Screen-space reflections with a fallback for what the screen does not hold.
pub static SSR: MethodEntry = MethodEntry {
    name: "ssr",
    help: "Screen-space reflections as engines ship them: the scene drawn once, each mirror \
           pixel's reflected ray marched through a hierarchical depth buffer (one bounce); \
           misses show --ssr-fallback.",
    exact: false,
    // Its error is what the screen does not hold, at every depth (as `cubemap`'s parallax).
    depth_limited: false,
    options: crate::method_options![&FALLBACK, &STEPS, &THICKNESS],
    swept: None,
    optional_features: wgpu::Features::empty(),
    required_features: wgpu::Features::empty(),
    shaders: &[&SHADER, &PYRAMID_SHADER],
    gpu_structs,
    configure: |p| {
        Box::new(ScreenSpaceReflections {
            fallback: match p.choice(&FALLBACK) {
                "cubemap" => Fallback::Cubemap,
                "planar" => Fallback::Planar,
                _ => Fallback::None,
            },
            steps: p.count(&STEPS),
            thickness: p.real(&THICKNESS),
        })
    },
    advise: Advise::Fixed(&[
        "ssr-fallback=none",
        "ssr-fallback=cubemap",
        "ssr-fallback=planar",
    ]),
};

/// `--ssr-fallback none|cubemap|planar`.
pub static FALLBACK: OptionSpec = OptionSpec {
    name: "ssr-fallback",
    help: "ssr: what a mirror pixel shows where its reflected ray finds nothing on screen: none \
           (the terminal radiance), cubemap (the cubemap method's probe), planar (path-textures \
           depth=1, the paper's one-bounce mirror texture).",
    kind: OptionKind::Choice {
        values: &["none", "cubemap", "planar"],
    },
    default: ParamValue::Choice("cubemap"),
    sweep: None,
    in_key: true,
};

/// `--ssr-steps N`: the march's step budget.
pub static STEPS: OptionSpec = OptionSpec {
    name: "ssr-steps",
    help: "ssr: most depth-pyramid steps a reflected ray takes before it counts as a miss.",
    kind: OptionKind::Count { min: 1, max: 4096 },
    default: ParamValue::Count(256),
    sweep: None,
    in_key: true,
};

/// `--ssr-thickness T`: how far behind a depth-buffer surface a ray may pass and hit it.
pub static THICKNESS: OptionSpec = OptionSpec {
    name: "ssr-thickness",
    help: "ssr: how far (scene units, view depth) a ray may be behind the depth buffer's surface \
           and still hit it; thinner misses behind objects, thicker hits their backs.",
    kind: OptionKind::Real {
        min: 0.0,
        min_open: false,
        max: Some(1000.0),
    },
    default: ParamValue::Real(0.25),
    sweep: None,
    in_key: true,
};

static SHADER: WgslSource = WgslSource {
    label: "screen-space reflections",
    enable: &[],
    parts: &[
        crate::wgsl::SHADING,
        crate::wgsl::SCENE_VERTEX,
        crate::camera_rays::WGSL,
        include_str!("../../../../shaders/screen_space_reflections.wgsl"),
    ],
};

static PYRAMID_SHADER: WgslSource = WgslSource {
    label: "ssr depth pyramid",
    enable: &[],
    parts: &[include_str!("../../../../shaders/ssr_depth_pyramid.wgsl")],
};

fn gpu_structs() -> Vec<HostLayout> {
    vec![
        crate::host_layout!(Params as "SsrParams" {
            camera, steps, thickness, fallback, levels
        }),
        crate::camera_rays::CameraRays::layout(),
    ]
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Fallback {
    None,
    Cubemap,
    Planar,
}

impl Fallback {
    /// The method whose image a miss shows.
    fn method(self) -> Option<&'static str> {
        match self {
            Fallback::None => None,
            Fallback::Cubemap => Some("cubemap"),
            Fallback::Planar => Some("path-textures depth=1"),
        }
    }
}

struct ScreenSpaceReflections {
    fallback: Fallback,
    steps: u32,
    thickness: f32,
}

impl RasterMethod for ScreenSpaceReflections {
    fn plan(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
    ) -> Result<Box<dyn PlannedFrame>, PlanError> {
        let fallback = match self.fallback.method() {
            None => None,
            Some(key) => {
                let method = crate::Method::parse(key).expect("a registered fallback");
                Some(method.configure().plan(scene, width, height)?)
            }
        };
        Ok(Box::new(PlannedSsr {
            width,
            height,
            steps: self.steps,
            thickness: self.thickness,
            fallback,
        }))
    }
}

struct PlannedSsr {
    width: u32,
    height: u32,
    steps: u32,
    thickness: f32,
    fallback: Option<Box<dyn PlannedFrame>>,
}

/// Mip levels of a `width × height` pyramid down to 1×1.
fn pyramid_levels(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

impl PlannedFrame for PlannedSsr {
    /// The scene buffers, the scene pass's colour and depth, the depth pyramid (4 bytes a
    /// texel, 4/3 for its levels), and the fallback's own frame and target.
    fn memory(&self, scene: &Scene, color_bytes_per_texel: u64) -> crate::memory::MemoryEstimate {
        use crate::memory::{DEPTH_BYTES, buffer_bytes, target_bytes, texture_bytes};
        let (w, h) = (self.width, self.height);
        let mut e = SceneBuffers::memory_estimate(scene, &scene.geometry);
        e.gpu(
            "the scene pass and depth pyramid",
            "the image size (--width/--height) or --ssaa",
            texture_bytes(w, h, color_bytes_per_texel)
                + texture_bytes(w, h, DEPTH_BYTES)
                // The pyramid: 4 bytes a texel, levels summing to under 4/3 of level 0.
                + 2 * texture_bytes(w, h, 4)
                + buffer_bytes(std::mem::size_of::<Params>() as u64),
        );
        if let Some(f) = &self.fallback {
            e.gpu(
                "the fallback's target",
                "the image size (--width/--height) or --ssaa",
                target_bytes(w, h, color_bytes_per_texel),
            );
            e.merge(f.memory(scene, color_bytes_per_texel));
        }
        e
    }

    fn build(
        self: Box<Self>,
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
    ) -> Result<BuiltFrame, RasterError> {
        let PlannedSsr {
            width,
            height,
            steps,
            thickness,
            fallback,
        } = *self;
        let (fallback, mut stats, warnings) = match fallback {
            Some(f) => {
                let built = f.build(gpu, scene, shadows)?;
                let target = RenderTarget::new(
                    gpu,
                    "ssr fallback",
                    width,
                    height,
                    wgpu::TextureUsages::TEXTURE_BINDING,
                );
                (
                    Some((built.encoder, target)),
                    Some(built.stats),
                    built.warnings,
                )
            }
            None => (None, None, Vec::new()),
        };
        let frame = SsrFrame::new(
            gpu, scene, shadows, width, height, steps, thickness, fallback,
        )?;
        // The fallback's passes are part of the frame; the depth it shows is its own (one
        // bounce on screen at best).
        let own = frame.stats;
        let stats = match stats.take() {
            Some(f) => FrameStats {
                passes: f.passes + own.passes,
                texture_renders: f.texture_renders,
                draws: f.draws + own.draws,
                depth: f.depth.max(own.depth),
                triangles: f.triangles + own.triangles,
                ..own
            },
            None => own,
        };
        Ok(BuiltFrame {
            stats,
            encoder: Box::new(frame),
            warnings,
            bake_ms: None,
        })
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Params {
    camera: crate::camera_rays::CameraRays,
    steps: u32,
    thickness: f32,
    fallback: u32,
    levels: u32,
}

struct SsrFrame {
    scene_buffers: SceneBuffers,
    fallback: Option<(Box<dyn FrameEncoder>, RenderTarget)>,
    base_pipeline: wgpu::RenderPipeline,
    base_group: wgpu::BindGroup,
    base_colour: wgpu::TextureView,
    depth: wgpu::TextureView,
    /// Level views of the pyramid, and each coarser level's input (the level below).
    pyramid_levels: Vec<wgpu::TextureView>,
    pyramid_groups: Vec<wgpu::BindGroup>,
    reduce: wgpu::RenderPipeline,
    reflect_pipeline: wgpu::RenderPipeline,
    reflect_group: wgpu::BindGroup,
    draws: Vec<std::ops::Range<u32>>,
    background: glam::Vec3,
    stats: FrameStats,
}

impl SsrFrame {
    #[allow(clippy::too_many_arguments)]
    fn new(
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
        width: u32,
        height: u32,
        steps: u32,
        thickness: f32,
        fallback: Option<(Box<dyn FrameEncoder>, RenderTarget)>,
    ) -> Result<Self, RasterError> {
        let device = &gpu.device;
        check_mark_precision(gpu, scene)?;
        let scene_buffers = SceneBuffers::new(gpu, scene, shadows.binding());
        let levels = pyramid_levels(width, height);
        let params = Params {
            camera: crate::camera_rays::CameraRays::new(&scene.camera, width, height),
            steps,
            thickness,
            fallback: u32::from(fallback.is_some()),
            levels,
        };
        let params_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("ssr parameters"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let (vf, f) = (
            wgpu::ShaderStages::VERTEX_FRAGMENT,
            wgpu::ShaderStages::FRAGMENT,
        );
        let uniform = wgpu::BufferBindingType::Uniform;
        let (base_layout, base_group) = BindGroupBuilder::new("ssr scene pass")
            .buffer(vf, uniform, &params_buffer)
            .build(gpu);
        let colour_format = gpu.color_format.texture_format();
        let sampled = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let base_colour = crate::targets::texture_2d(
            device,
            "ssr scene colour",
            width,
            height,
            colour_format,
            sampled,
        )
        .create_view(&Default::default());
        let depth = crate::targets::texture_2d(
            device,
            "ssr depth",
            width,
            height,
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
        let module = gpu.shader_module(&SHADER, scene_buffers.textured);
        let base_layout_all = pipeline_layout(
            gpu,
            "ssr scene pass",
            &[&scene_buffers.layout, &base_layout],
        );
        let base_pipeline = base_pipeline(gpu, &module, &base_layout_all, colour_format);
        let DepthPyramid {
            levels: pyramid_levels,
            groups: pyramid_groups,
            reduce,
            whole: whole_pyramid,
        } = DepthPyramid::new(gpu, width, height, levels);
        let fallback_view = fallback
            .as_ref()
            .map_or(&base_colour, |(_, target)| &target.color_view);
        let (reflect_layout, reflect_group) = BindGroupBuilder::new("ssr reflect")
            .buffer(vf, uniform, &params_buffer)
            .texture(f, &base_colour)
            .texture(f, fallback_view)
            .binding(
                f,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Uint,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                wgpu::BindingResource::TextureView(&whole_pyramid),
            )
            .build(gpu);
        let reflect_pipeline =
            reflect_pipeline(gpu, &module, &[&scene_buffers.layout, &reflect_layout]);
        let draws = scene_buffers.draw_ranges();
        // The scene pass, the pyramid's coarser levels, the reflect pass.
        let stats = FrameStats {
            passes: 1 + levels as usize,
            texture_renders: 0,
            draws: draws.len() + levels as usize,
            depth: 1,
            triangles: scene.geometry.triangles.len() + levels as usize,
            paths: None,
            clipping: Clipping::None,
            depth_format: DEPTH_FORMAT,
            copies: None,
        };
        gpu.check()?;
        Ok(SsrFrame {
            scene_buffers,
            fallback,
            base_pipeline,
            base_group,
            base_colour,
            depth,
            pyramid_levels,
            pyramid_groups,
            reduce,
            reflect_pipeline,
            reflect_group,
            draws,
            background: scene.background,
            stats,
        })
    }
}

/// Mirror pixels carry their surface + 1 in the scene pass's alpha: exact in f16 up to
/// 2048 surfaces; a scene with more is refused on RGBA16F targets.
fn check_mark_precision(gpu: &Gpu, scene: &Scene) -> Result<(), RasterError> {
    let surfaces = scene.geometry.surfaces.len();
    if gpu.color_format.texel_bytes() < 16 && surfaces >= 2048 {
        return Err(RasterError::ExceedsDevice {
            what: "surfaces for ssr's mirror marks in an RGBA16F alpha".into(),
            needed: surfaces.to_string(),
            limit: "2047".into(),
            adapter: gpu.report.name.clone(),
            advice: "; use RGBA32F targets (MIRRORBOX_COLOR_FORMAT=rgba32float)",
        });
    }
    Ok(())
}

/// The scene pass's pipeline: two targets, the colour (mirror marks in alpha) and the depth
/// pyramid's level 0.
fn base_pipeline(
    gpu: &Gpu,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    colour_format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    gpu.render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("ssr scene pass"),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_scene"),
            compilation_options: Default::default(),
            buffers: &[Some(VERTEX_LAYOUT)],
        },
        primitive: Default::default(),
        depth_stencil: Some(depth_state(DEPTH_FORMAT, true, NEARER, Default::default())),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_base"),
            compilation_options: Default::default(),
            targets: &[
                Some(colour_format.into()),
                Some(wgpu::TextureFormat::R32Uint.into()),
            ],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The full-screen reflect pass's pipeline, bound to the scene's and the pass's `groups`.
fn reflect_pipeline(
    gpu: &Gpu,
    module: &wgpu::ShaderModule,
    groups: &[&wgpu::BindGroupLayout],
) -> wgpu::RenderPipeline {
    ScenePipeline {
        label: "ssr reflect",
        layout: &pipeline_layout(gpu, "ssr reflect", groups),
        module,
        vertex: "vs_fullscreen",
        fragment: "fs_reflect",
        buffers: &[],
        depth_stencil: depth_state(
            DEPTH_FORMAT,
            false,
            wgpu::CompareFunction::Always,
            Default::default(),
        ),
        color_writes: wgpu::ColorWrites::ALL,
    }
    .build(gpu)
}

/// The nearest-depth pyramid: its mip levels' views, the reduction pipeline and a bind group
/// per coarser level (reading the level below), and the whole pyramid's view (the reflect
/// pass's march reads it).
struct DepthPyramid {
    levels: Vec<wgpu::TextureView>,
    groups: Vec<wgpu::BindGroup>,
    reduce: wgpu::RenderPipeline,
    whole: wgpu::TextureView,
}

impl DepthPyramid {
    fn new(gpu: &Gpu, width: u32, height: u32, levels: u32) -> Self {
        let device = &gpu.device;
        let sampled = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let pyramid = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("ssr depth pyramid"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: levels,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R32Uint,
            usage: sampled,
            view_formats: &[],
        });
        let level_view = |level: u32| {
            pyramid.create_view(&wgpu::TextureViewDescriptor {
                base_mip_level: level,
                mip_level_count: Some(1),
                ..Default::default()
            })
        };
        let pyramid_levels: Vec<wgpu::TextureView> = (0..levels).map(level_view).collect();
        // The pyramid: level 0 written by the scene pass, each next level reduced from the last.
        let pyramid_module = gpu.shader_module(&PYRAMID_SHADER, false);
        let fullscreen = |label: &str, fragment: &str| {
            gpu.render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: None,
                vertex: wgpu::VertexState {
                    module: &pyramid_module,
                    entry_point: Some("vs_fullscreen"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &pyramid_module,
                    entry_point: Some(fragment),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::TextureFormat::R32Uint.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let reduce = fullscreen("ssr pyramid level", "fs_reduce");
        let pyramid_groups: Vec<wgpu::BindGroup> = (1..levels as usize)
            .map(|level| {
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("ssr pyramid level"),
                    layout: &reduce.get_bind_group_layout(0),
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&pyramid_levels[level - 1]),
                    }],
                })
            })
            .collect();
        DepthPyramid {
            levels: pyramid_levels,
            groups: pyramid_groups,
            reduce,
            whole: pyramid.create_view(&Default::default()),
        }
    }
}

impl FrameEncoder for SsrFrame {
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let mut first_pass = first_pass;
        if let Some((method, fallback_target)) = &self.fallback {
            method.encode(encoder, fallback_target, first_pass.take());
        }
        {
            let bg = self.background;
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("ssr scene pass"),
                color_attachments: &[
                    Some(wgpu::RenderPassColorAttachment {
                        view: &self.base_colour,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color {
                                r: bg.x as f64,
                                g: bg.y as f64,
                                b: bg.z as f64,
                                a: 0.0,
                            }),
                            store: wgpu::StoreOp::Store,
                        },
                    }),
                    // Far everywhere nothing is drawn: reversed depth 0.
                    Some(wgpu::RenderPassColorAttachment {
                        view: &self.pyramid_levels[0],
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            store: wgpu::StoreOp::Store,
                        },
                    }),
                ],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(FAR_DEPTH),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: first_pass.take(),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.base_pipeline);
            pass.set_vertex_buffer(0, self.scene_buffers.vertices.slice(..));
            pass.set_bind_group(0, &self.scene_buffers.bind_group, &[]);
            pass.set_bind_group(1, &self.base_group, &[]);
            for r in &self.draws {
                pass.draw(r.clone(), 0..1);
            }
        }
        for (view, group) in self.pyramid_levels[1..].iter().zip(&self.pyramid_groups) {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("ssr depth pyramid"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.reduce);
            pass.set_bind_group(0, group, &[]);
            pass.draw(0..3, 0..1);
        }
        let mut pass = target.begin_pass(encoder, "ssr reflect", self.background, None);
        pass.set_pipeline(&self.reflect_pipeline);
        pass.set_bind_group(0, &self.scene_buffers.bind_group, &[]);
        pass.set_bind_group(1, &self.reflect_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
