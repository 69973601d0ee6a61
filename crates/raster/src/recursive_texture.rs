//! The seed paper's methods (`naive`, `auxiliary`): recursive render-to-texture mirrors,
//! executing a [`Plan`] of `MIRRORTEXTURE` calls. Entry points: `shaders/recursive_texture.wgsl`.
//!
//! Each call renders the scene from its mirror camera (seed 002: the view composed with the
//! mirror's reflection, so the image is not flipped but the winding is — culling is off and
//! shading is two-sided) with the mirror plane as oblique near plane (Lengyel, depth 0..1),
//! into a texture covering the mirror's footprint on screen. Because every camera shares the
//! screen's projection, texel (x, y) of a texture is screen pixel footprint-origin + (x, y):
//! the mirror looks its texture up by screen position, with no resampling at the default
//! `texture_scale` of 1. Textures are rendered depth first (children before the pass that
//! applies them) and recycled by exact size once applied.

use crate::frame::{
    COLOR_FORMAT, DEPTH_FORMAT, FrameEncoder, FrameStats, RenderTarget, texture_entry,
};
use crate::gpu::Gpu;
use crate::plan::{Plan, Rect, TextureNode};
use crate::shading::{SceneBuffers, VERTEX_LAYOUT, module};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3};
use mirrorbox_scene::reflection::{ReflectedView, oblique_near_plane};
use mirrorbox_scene::{Plane, Scene};
use std::collections::HashMap;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct PassUniform {
    clip_from_world: [[f32; 4]; 4],
    eye: [f32; 3],
    _pad0: f32,
    origin: [f32; 2],
    pixels_per_texel: [f32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct MirrorUniform {
    origin: [f32; 2],
    size: [f32; 2],
    texels_per_pixel: [f32; 2],
    exact: u32,
    has_texture: u32,
}

enum Target {
    Slot(usize),
    Main,
}

struct MirrorDraw {
    mirror: usize,
    bind_group: usize,
    offset: u32,
}

struct PassSpec {
    target: Target,
    offset: u32,
    draws: Vec<MirrorDraw>,
}

pub struct RecursiveTexture {
    scene_buffers: SceneBuffers,
    objects_pipeline: wgpu::RenderPipeline,
    mirror_pipeline: wgpu::RenderPipeline,
    pass_bind_group: wgpu::BindGroup,
    mirror_bind_groups: Vec<wgpu::BindGroup>,
    slots: Vec<RenderTarget>,
    passes: Vec<PassSpec>,
    background: Vec3,
    pub stats: FrameStats,
}

/// Builds the uniform records and pass list from the plan.
struct Builder<'a> {
    scene: &'a Scene,
    plan: &'a Plan,
    texture_scale: f32,
    alignment: usize,
    uniforms: Vec<u8>,
    /// Free slots by exact texture size.
    free: HashMap<(u32, u32), Vec<usize>>,
    slot_sizes: Vec<(u32, u32)>,
    passes: Vec<PassSpec>,
    /// (uniform offset, slot or None for the "no texture" binding) per mirror bind group.
    mirror_bindings: Vec<(u32, Option<usize>)>,
}

impl Builder<'_> {
    fn push_uniform<T: Pod>(&mut self, value: &T) -> u32 {
        let offset = self.uniforms.len().next_multiple_of(self.alignment);
        self.uniforms.resize(offset, 0);
        self.uniforms.extend_from_slice(bytemuck::bytes_of(value));
        offset as u32
    }

    fn texture_size(&self, r: Rect) -> (u32, u32) {
        let s = |v: u32| ((v as f32 * self.texture_scale).round() as u32).max(1);
        (s(r.w), s(r.h))
    }

    fn alloc(&mut self, size: (u32, u32)) -> usize {
        if let Some(slot) = self.free.get_mut(&size).and_then(Vec::pop) {
            return slot;
        }
        self.slot_sizes.push(size);
        self.slot_sizes.len() - 1
    }

    /// Emits the passes of `node`'s subtree (children first); returns its texture slot.
    fn emit(&mut self, node: &TextureNode) -> usize {
        let children: Vec<(&TextureNode, usize)> =
            node.children.iter().map(|c| (c, self.emit(c))).collect();
        let size = self.texture_size(node.footprint);
        let slot = self.alloc(size);
        let clip = mirror_camera_clip(self.plan, &node.view, &node.plane, node.footprint);
        let offset = self.push_uniform(&PassUniform {
            clip_from_world: clip.to_cols_array_2d(),
            eye: node.view.eye().to_array(),
            _pad0: 0.0,
            origin: [node.footprint.x as f32, node.footprint.y as f32],
            pixels_per_texel: [
                node.footprint.w as f32 / size.0 as f32,
                node.footprint.h as f32 / size.1 as f32,
            ],
        });
        let draws = self.mirror_draws(&node.hidden, Some(&node.plane), &children);
        self.passes.push(PassSpec {
            target: Target::Slot(slot),
            offset,
            draws,
        });
        for (c, s) in children {
            let size = self.texture_size(c.footprint);
            self.free.entry(size).or_default().push(s);
        }
        slot
    }

    /// The mirror draws of a pass: every unhidden instance, textured when the pass applies a
    /// texture for it; instances lying in the pass's own mirror plane (the mirror and its
    /// coincident auxiliaries) are the portal itself and are not drawn.
    fn mirror_draws(
        &mut self,
        hidden: &[usize],
        plane: Option<&Plane>,
        children: &[(&TextureNode, usize)],
    ) -> Vec<MirrorDraw> {
        let mut draws = Vec::new();
        for (i, inst) in self.plan.instances.iter().enumerate() {
            if hidden.contains(&i) {
                continue;
            }
            let mirror = &self.scene.mirrors[inst.mirror];
            if let Some(p) = plane
                && mirror
                    .corners()
                    .iter()
                    .all(|c| p.signed_distance(*c).abs() < 1e-5)
            {
                continue;
            }
            let binding = match children.iter().find(|(c, _)| c.instance == i) {
                Some((child, slot)) => {
                    let (tw, th) = self.texture_size(child.footprint);
                    let f = child.footprint;
                    let texels_per_pixel = [tw as f32 / f.w as f32, th as f32 / f.h as f32];
                    let exact = texels_per_pixel == [1.0, 1.0];
                    let offset = self.push_uniform(&MirrorUniform {
                        origin: [f.x as f32, f.y as f32],
                        size: [f.w as f32, f.h as f32],
                        texels_per_pixel,
                        exact: exact as u32,
                        has_texture: 1,
                    });
                    (offset, Some(*slot))
                }
                None => (self.push_uniform(&MirrorUniform::zeroed()), None),
            };
            self.mirror_bindings.push(binding);
            draws.push(MirrorDraw {
                mirror: inst.mirror,
                bind_group: self.mirror_bindings.len() - 1,
                offset: binding.0,
            });
        }
        draws
    }
}

/// `crop(footprint) · oblique(P, mirror plane) · view`: the mirror camera's clip transform,
/// with the screen region of its texture mapped onto the whole texture.
fn mirror_camera_clip(plan: &Plan, view: &ReflectedView, plane: &Plane, footprint: Rect) -> Mat4 {
    let oblique = oblique_near_plane(plan.projection, plane.coefficients_in(view.view));
    crop(footprint, plan.width, plan.height) * oblique * view.view
}

/// Maps the NDC rectangle of screen region `r` (of a `w × h` screen) onto [−1, 1]².
fn crop(r: Rect, w: u32, h: u32) -> Mat4 {
    let size = Vec2::new(w as f32, h as f32);
    let lo = mirrorbox_scene::camera::pixel_to_ndc(Vec2::new(r.x as f32, (r.y + r.h) as f32), size);
    let hi = mirrorbox_scene::camera::pixel_to_ndc(Vec2::new((r.x + r.w) as f32, r.y as f32), size);
    let scale = 2.0 / (hi - lo);
    let shift = -(hi + lo) / (hi - lo);
    Mat4::from_cols(
        glam::Vec4::new(scale.x, 0.0, 0.0, 0.0),
        glam::Vec4::new(0.0, scale.y, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 1.0, 0.0),
        glam::Vec4::new(shift.x, shift.y, 0.0, 1.0),
    )
}

fn dynamic_uniform(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: true,
            min_binding_size: None,
        },
        count: None,
    }
}

impl RecursiveTexture {
    pub fn new(gpu: &Gpu, scene: &Scene, plan: &Plan, texture_scale: f32) -> Self {
        use wgpu::util::DeviceExt;
        let device = &gpu.device;
        let scene_buffers = SceneBuffers::new(device, scene);
        let alignment = device.limits().min_uniform_buffer_offset_alignment as usize;
        let mut b = Builder {
            scene,
            plan,
            texture_scale,
            alignment,
            uniforms: Vec::new(),
            free: HashMap::new(),
            slot_sizes: Vec::new(),
            passes: Vec::new(),
            mirror_bindings: Vec::new(),
        };
        let roots: Vec<(&TextureNode, usize)> = plan.roots.iter().map(|n| (n, b.emit(n))).collect();
        let camera = scene.camera.with_size(plan.width, plan.height);
        let main_offset = b.push_uniform(&PassUniform {
            clip_from_world: (plan.projection * camera.view()).to_cols_array_2d(),
            eye: camera.position.to_array(),
            _pad0: 0.0,
            origin: [0.0, 0.0],
            pixels_per_texel: [1.0, 1.0],
        });
        let main_draws = b.mirror_draws(&[], None, &roots);
        b.passes.push(PassSpec {
            target: Target::Main,
            offset: main_offset,
            draws: main_draws,
        });

        let uniforms = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("recursive texture uniforms"),
            contents: &b.uniforms,
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let pass_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pass"),
            entries: &[dynamic_uniform(0)],
        });
        let mirror_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mirror"),
            entries: &[dynamic_uniform(0), texture_entry(1)],
        });
        let binding = |size: usize| {
            wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &uniforms,
                offset: 0,
                size: std::num::NonZeroU64::new(size as u64),
            })
        };
        let pass_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pass"),
            layout: &pass_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: binding(std::mem::size_of::<PassUniform>()),
            }],
        });
        let slots: Vec<RenderTarget> = b
            .slot_sizes
            .iter()
            .map(|&(w, h)| {
                RenderTarget::new(
                    device,
                    "mirror texture",
                    w,
                    h,
                    wgpu::TextureUsages::TEXTURE_BINDING,
                )
            })
            .collect();
        let none = RenderTarget::new(
            device,
            "no texture",
            1,
            1,
            wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let mirror_bind_groups = b
            .mirror_bindings
            .iter()
            .map(|(_, slot)| {
                let view = slot.map_or(&none.color_view, |s| &slots[s].color_view);
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("mirror"),
                    layout: &mirror_layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: binding(std::mem::size_of::<MirrorUniform>()),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::TextureView(view),
                        },
                    ],
                })
            })
            .collect();

        let shader = module(
            device,
            "recursive texture",
            include_str!("../../../shaders/recursive_texture.wgsl"),
        );
        let pipeline = |label: &str, layouts: &[Option<&wgpu::BindGroupLayout>], fragment: &str| {
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: layouts,
                immediate_size: 0,
            });
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &shader,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(VERTEX_LAYOUT)],
                },
                // Reflections flip the winding and shading is two-sided: no culling.
                primitive: wgpu::PrimitiveState {
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    // LessEqual: of coincident mirror instances the last drawn wins, deterministically.
                    depth_compare: Some(wgpu::CompareFunction::LessEqual),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &shader,
                    entry_point: Some(fragment),
                    compilation_options: Default::default(),
                    targets: &[Some(COLOR_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let sl = &scene_buffers.layout;
        let objects_pipeline = pipeline("objects", &[Some(sl), Some(&pass_layout)], "fs_object");
        let mirror_pipeline = pipeline(
            "mirrors",
            &[Some(sl), Some(&pass_layout), Some(&mirror_layout)],
            "fs_mirror",
        );
        let draws: usize = b.passes.iter().map(|p| 1 + p.draws.len()).sum::<usize>() + 1;
        let object_triangles = scene_buffers.objects.len() / 3;
        let stats = FrameStats {
            passes: plan.passes,
            texture_renders: plan.passes - 1,
            draws,
            depth: plan.depth,
            triangles: b
                .passes
                .iter()
                .map(|p| object_triangles + 2 * p.draws.len())
                .sum(),
            paths: None,
            clipping: None,
        };
        RecursiveTexture {
            scene_buffers,
            objects_pipeline,
            mirror_pipeline,
            pass_bind_group,
            mirror_bind_groups,
            slots,
            passes: b.passes,
            background: scene.background,
            stats,
        }
    }
}

impl FrameEncoder for RecursiveTexture {
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        main: &RenderTarget,
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let mut first_pass = first_pass;
        for spec in &self.passes {
            let target = match spec.target {
                Target::Slot(s) => &self.slots[s],
                Target::Main => main,
            };
            let mut pass = target.begin_pass(encoder, self.background, first_pass.take());
            pass.set_vertex_buffer(0, self.scene_buffers.vertices.slice(..));
            pass.set_bind_group(0, &self.scene_buffers.bind_group, &[]);
            pass.set_bind_group(1, &self.pass_bind_group, &[spec.offset]);
            pass.set_pipeline(&self.objects_pipeline);
            pass.draw(self.scene_buffers.objects.clone(), 0..1);
            if !spec.draws.is_empty() {
                pass.set_pipeline(&self.mirror_pipeline);
                for d in &spec.draws {
                    pass.set_bind_group(2, &self.mirror_bind_groups[d.bind_group], &[d.offset]);
                    pass.draw(self.scene_buffers.mirrors[d.mirror].clone(), 0..1);
                }
            }
        }
    }
}
