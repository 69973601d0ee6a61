//! `portal`: exact mirrors by stencil recursion (SGI course notes '99, §11.1.5.1), over the
//! reflection paths of [`mirrorbox_scene::reflection_paths`]. Entry points:
//! `shaders/portal_stencil.wgsl`.
//!
//! Everything happens in one render pass. A path's region of the screen holds its stencil
//! value; its world (the scene through `view · R₁ · … · Rₖ` and the camera's projection,
//! clipped to the front of its last mirror by a clip distance or per fragment, winding
//! flipped on odd depth — culling is off — colours × the product of the reflectances) is
//! drawn there. For each kept child the child's mirror is drawn from the
//! parent's camera with the depth test against the parent's world (so it is marked only where
//! it is really visible) and its stencil incremented; depth is then reset to far inside the
//! child's region, and the child's world drawn and recursed into. Finished regions are set
//! to 0. For a path's last child the parent's remainder is retired first and the child's
//! value decremented back, so a chain of any length uses one stencil value: only branches
//! that still have siblings to draw hold one — at most 254 (refused beyond, before any work).
//!
//! Depth is the camera's infinite reversed Z ([`crate::projection`]) in every path — the
//! unfolded distance along the pixel's ray — in a `Depth32FloatStencil8` attachment where the
//! adapter has that format (an optional feature); elsewhere `Depth24PlusStencil8`, which the
//! frame's stats and warnings state (far surfaces closer than `t²·2⁻²⁴/NEAR` may swap).

use crate::culling::{box_corners, box_may_touch, footprint_rect};
use crate::exact_options::{DEPTH, MIN_ATTENUATION, MIN_PORTAL_AREA};
use crate::exact_paths::{PlannedPaths, plan_paths};
use crate::gpu::{Gpu, RasterError};
use crate::method::{
    Advise, BuiltFrame, Clipping, FrameStats, MethodEntry, PathCounts, PlannedFrame, RasterMethod,
};
use crate::pipeline::{
    BindGroupBuilder, ScenePipeline, UniformArena, depth_state, pipeline_layout,
};
use crate::plan::PlanError;
use crate::projection::NEARER_OR_EQUAL;
use crate::shading::{OnePass, OnePassFrame, SceneBuffers, VERTEX_LAYOUT};
use crate::targets::{DEPTH_STENCIL_FORMAT, depth_stencil_format};
use crate::wgsl::HostLayout;
use bytemuck::{Pod, Zeroable};
use glam::{Vec3, Vec4};
use mirrorbox_scene::Scene;
use mirrorbox_scene::reflection_paths::{PathLimits, PathSet};

/// Exact: stencil recursion over the reflection paths in one pass, cost linear in depth.
pub static PORTAL: MethodEntry = MethodEntry {
    name: "portal",
    help: "Exact: stencil recursion over the reflection paths, one pass, cost linear in depth.",
    exact: true,
    depth_limited: true,
    options: crate::method_options![&DEPTH, &MIN_PORTAL_AREA, &MIN_ATTENUATION],
    swept: Some(&DEPTH),
    optional_features: wgpu::Features::CLIP_DISTANCES.union(wgpu::Features::DEPTH32FLOAT_STENCIL8),
    required_features: wgpu::Features::empty(),
    shaders: &[&SHADER, &CLIP_DISTANCE_SHADER],
    gpu_structs,
    configure: |p| Box::new(Portal(crate::exact_options::limits(p))),
    advise: Advise::Knob {
        option: &DEPTH,
        coarse: crate::exact_options::DEPTHS_COARSE,
        variants: &[""],
    },
};

const ENTRY_POINTS: &str = include_str!("../../../../shaders/portal_stencil.wgsl");

crate::mirror_plane_shaders!("portal stencil", ENTRY_POINTS);

fn gpu_structs() -> Vec<HostLayout> {
    vec![crate::host_layout!(PathUniform as "Path" {
        clip_from_world, eye, _pad0, attenuation, _pad1, plane
    })]
}

/// The typed settings of `portal`: its path limits.
struct Portal(PathLimits);

impl RasterMethod for Portal {
    fn plan(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
    ) -> Result<Box<dyn PlannedFrame>, PlanError> {
        let planned = plan_paths(scene, width, height, &self.0)?;
        let ops = schedule(&planned.paths)?;
        Ok(Box::new(PlannedPortal { planned, ops }))
    }
}

struct PlannedPortal {
    planned: PlannedPaths,
    ops: Vec<Op>,
}

impl PlannedFrame for PlannedPortal {
    /// The scene buffers, one depth-stencil target at the render size (counted at 8 bytes a
    /// texel), one uniform record per path; on the host the paths and the frame's steps.
    fn memory(&self, scene: &Scene, _color_bytes_per_texel: u64) -> crate::memory::MemoryEstimate {
        use crate::memory::{DEPTH_STENCIL_BYTES, texture_bytes, uniform_arena_bytes};
        let paths = self.planned.paths.paths.len() as u64;
        let mut e = SceneBuffers::memory_estimate(scene, &scene.geometry);
        e.gpu(
            "the depth-stencil target",
            "the image size (--width/--height) or --ssaa",
            texture_bytes(self.planned.width, self.planned.height, DEPTH_STENCIL_BYTES),
        );
        e.gpu(
            "the path uniforms",
            "--depth, or raise --min-portal-area or --min-attenuation",
            uniform_arena_bytes(paths),
        );
        crate::exact_paths::paths_memory(&mut e, &self.planned.paths);
        e.host(
            "the reflection paths",
            "--depth, or raise --min-portal-area or --min-attenuation",
            (self.ops.len() * std::mem::size_of::<Op>()) as u64,
        );
        e
    }

    fn build(
        self: Box<Self>,
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
    ) -> Result<BuiltFrame, RasterError> {
        let m = PortalStencil::new(gpu, scene, shadows, &self.planned, self.ops)?;
        let depth_format = m.stats.depth_format;
        let mut warnings = Vec::new();
        if depth_format != DEPTH_STENCIL_FORMAT {
            warnings.push(format!(
                "this adapter lacks {DEPTH_STENCIL_FORMAT:?} (DEPTH32FLOAT_STENCIL8): portal's depth \
                 is {depth_format:?}, which resolves only t²·6e-6 at distance t (6 cm at 100 \
                 units), so far surfaces that close may swap"
            ));
        }
        Ok(BuiltFrame {
            stats: m.stats,
            encoder: Box::new(m),
            warnings,
            bake_ms: None,
        })
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct PathUniform {
    clip_from_world: [[f32; 4]; 4],
    eye: [f32; 3],
    _pad0: f32,
    attenuation: [f32; 3],
    _pad1: f32,
    plane: [f32; 4],
}

/// One step of the frame, in order.
#[derive(Clone, Copy, Debug)]
enum Op {
    /// Draw path `path`'s world where the stencil equals `value`.
    World { path: usize, value: u32 },
    /// Increment the stencil (from `value`) where scene mirror `mirror` is visible from `path`;
    /// `child` is the path it opens.
    Mark {
        path: usize,
        child: usize,
        mirror: usize,
        value: u32,
    },
    /// Reset depth to far and colour to the attenuated background in path `path`'s region.
    ClearRegion { path: usize, value: u32 },
    /// Set `value` to 0 inside path `path`'s portal (its region is finished).
    Retire { path: usize, value: u32 },
    /// Lower `value` by one inside path `path`'s portal.
    Decrement { path: usize, value: u32 },
}

/// Orders the frame's steps (see the module docs).
fn schedule(paths: &PathSet) -> Result<Vec<Op>, PlanError> {
    fn process(paths: &PathSet, p: usize, v: u32, ops: &mut Vec<Op>) -> Result<(), PlanError> {
        let children = &paths.paths[p].children;
        if children.is_empty() {
            ops.push(Op::Retire { path: p, value: v });
            return Ok(());
        }
        for (i, &c) in children.iter().enumerate() {
            let mirror = *paths.paths[c]
                .mirrors
                .last()
                .expect("a child path looks through a mirror");
            ops.push(Op::Mark {
                path: p,
                child: c,
                mirror,
                value: v,
            });
            let cv = if i + 1 == children.len() {
                ops.push(Op::Retire { path: p, value: v });
                ops.push(Op::Decrement {
                    path: c,
                    value: v + 1,
                });
                v
            } else {
                v + 1
            };
            if cv > 254 {
                return Err(PlanError::StencilTooDeep(cv));
            }
            ops.push(Op::ClearRegion { path: c, value: cv });
            ops.push(Op::World { path: c, value: cv });
            process(paths, c, cv, ops)?;
        }
        Ok(())
    }
    let mut ops = vec![Op::World { path: 0, value: 1 }];
    process(paths, 0, 1, &mut ops)?;
    Ok(ops)
}

/// A frame may draw at most this many triangles — a memory bound: lavapipe records every draw of the one
/// pass and holds it until the pass ends, about 1 KB per triangle here (mirror_room, depth 64,
/// 160×90: 6.5 M triangles, 6.1 GB peak; splitting the frame into several passes did not
/// lower it), so 8 M keeps a frame under ~8 GB.
pub const MAX_TRIANGLES_IN_ONE_PASS: usize = 8_000_000;

pub struct PortalStencil {
    scene_buffers: SceneBuffers,
    /// Per path: its portal's bounding rectangle (x, y, w, h) at render resolution; every
    /// operation on a path is scissored to it, so deep bounces cost in proportion to their size.
    scissors: Vec<[u32; 4]>,
    /// Per path: the non-mirror parts that can be seen through its portal.
    visible_parts: Vec<Vec<usize>>,
    depth_stencil: wgpu::TextureView,
    path_bind_group: wgpu::BindGroup,
    offsets: Vec<u32>,
    /// Last mirror of each path (not drawn in its own world: it is the near plane).
    last_mirror: Vec<Option<usize>>,
    ops: Vec<Op>,
    pipelines: Pipelines,
    background: Vec3,
    mirror_count: usize,
    pub stats: FrameStats,
}

fn stencil(compare: wgpu::CompareFunction, pass_op: wgpu::StencilOperation) -> wgpu::StencilState {
    let face = wgpu::StencilFaceState {
        compare,
        fail_op: wgpu::StencilOperation::Keep,
        depth_fail_op: wgpu::StencilOperation::Keep,
        pass_op,
    };
    wgpu::StencilState {
        front: face,
        back: face,
        read_mask: 0xff,
        write_mask: 0xff,
    }
}

impl PortalStencil {
    fn new(
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
        planned: &PlannedPaths,
        ops: Vec<Op>,
    ) -> Result<Self, RasterError> {
        let device = &gpu.device;
        let paths = &planned.paths;
        let scene_buffers = SceneBuffers::new(gpu, scene, shadows.binding());
        let records = PathRecords::of(gpu, planned, &scene_buffers);
        let (path_layout, path_bind_group) = BindGroupBuilder::new("portal path")
            .record::<PathUniform>(wgpu::ShaderStages::VERTEX_FRAGMENT, &records.uniforms)
            .build(gpu);
        let layout = pipeline_layout(gpu, "portal", &[&scene_buffers.layout, &path_layout]);
        let clipping = Clipping::for_features(gpu.features);
        let depth_format = depth_stencil_format(gpu.features);
        let pipelines =
            Pipelines::new(gpu, &layout, scene_buffers.textured, clipping, depth_format);
        let depth_stencil = crate::targets::texture_2d(
            device,
            "portal depth-stencil",
            planned.width,
            planned.height,
            depth_format,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
        let mirror_count = scene.mirrors.len();
        let PathRecords {
            offsets,
            visible_parts,
            scissors,
            ..
        } = records;
        let stats = frame_stats(
            paths,
            &ops,
            &visible_parts,
            &scene_buffers,
            (clipping, depth_format),
        )?;
        Ok(PortalStencil {
            scene_buffers,
            scissors,
            visible_parts,
            depth_stencil,
            path_bind_group,
            offsets,
            last_mirror: paths
                .paths
                .iter()
                .map(|p| p.mirrors.last().copied())
                .collect(),
            ops,
            pipelines,
            background: scene.background,
            mirror_count,
            stats,
        })
    }
}

/// Per path, what its operations need: its uniform record's offset (the records in one
/// buffer), the parts visible through its portal, and its portal's scissor rectangle.
struct PathRecords {
    uniforms: wgpu::Buffer,
    offsets: Vec<u32>,
    visible_parts: Vec<Vec<usize>>,
    scissors: Vec<[u32; 4]>,
}

impl PathRecords {
    fn of(gpu: &Gpu, planned: &PlannedPaths, scene_buffers: &SceneBuffers) -> Self {
        let device = &gpu.device;
        let (paths, projection) = (&planned.paths, planned.projection);
        let size = glam::Vec2::new(planned.width as f32, planned.height as f32);
        let mut arena = UniformArena::new(device);
        let mut offsets = Vec::with_capacity(paths.paths.len());
        let mut visible_parts = Vec::with_capacity(paths.paths.len());
        let mut scissors = Vec::with_capacity(paths.paths.len());
        for p in &paths.paths {
            let clip = projection * p.view.view;
            let plane = p.plane.map_or(Vec4::W, |pl| pl.coefficients());
            let bbox = mirrorbox_scene::polygon::bounds(&p.portal);
            scissors.push(
                footprint_rect(bbox.0, bbox.1, size).map_or([0, 0, 1, 1], |r| [r.x, r.y, r.w, r.h]),
            );
            visible_parts.push(
                (0..scene_buffers.parts.len())
                    .filter(|&k| {
                        let (_, lo, hi) = &scene_buffers.parts[k];
                        let behind_plane = box_corners(*lo, *hi)
                            .iter()
                            .all(|q| plane.dot(q.extend(1.0)) < 0.0);
                        !behind_plane && box_may_touch(clip, *lo, *hi, bbox, size)
                    })
                    .collect::<Vec<usize>>(),
            );
            let u = PathUniform {
                clip_from_world: clip.to_cols_array_2d(),
                eye: p.view.eye().to_array(),
                _pad0: 0.0,
                attenuation: p.attenuation.to_array(),
                _pad1: 0.0,
                plane: plane.to_array(),
            };
            offsets.push(arena.push(&u));
        }
        PathRecords {
            uniforms: arena.buffer(device, "portal paths"),
            offsets,
            visible_parts,
            scissors,
        }
    }
}

/// The pass's pipelines: a path's world (objects, mirrors), the stencil marks of its
/// children, and the full-screen region clear, retire and decrement.
struct Pipelines {
    objects: wgpu::RenderPipeline,
    mirrors: wgpu::RenderPipeline,
    mark: wgpu::RenderPipeline,
    clear_region: wgpu::RenderPipeline,
    retire: wgpu::RenderPipeline,
    decrement: wgpu::RenderPipeline,
}

impl Pipelines {
    fn new(
        gpu: &Gpu,
        layout: &wgpu::PipelineLayout,
        textured: bool,
        clipping: Clipping,
        depth_format: wgpu::TextureFormat,
    ) -> Self {
        let shader = gpu.shader_module(
            match clipping {
                Clipping::ClipDistances => &CLIP_DISTANCE_SHADER,
                Clipping::FragmentDiscard | Clipping::None => &SHADER,
            },
            textured,
        );
        // Scene draws clip at the path's last mirror: by clip distance, or per fragment.
        let (scene_vertex, fs_object, fs_mirror, fs_mark) = match clipping {
            Clipping::ClipDistances => ("vs_clip_distances", "fs_object", "fs_mirror", "fs_none"),
            Clipping::FragmentDiscard | Clipping::None => (
                "vs_main",
                "fs_object_discard",
                "fs_mirror_discard",
                "fs_mark_discard",
            ),
        };
        let pipeline = |label: &str,
                        vertex: &str,
                        fragment: &str,
                        color: bool,
                        depth_write: bool,
                        depth_compare,
                        st: wgpu::StencilState| {
            let buffers: &[Option<wgpu::VertexBufferLayout>] = if vertex == scene_vertex {
                &[Some(VERTEX_LAYOUT)]
            } else {
                &[]
            };
            ScenePipeline {
                label,
                layout,
                module: &shader,
                vertex,
                fragment,
                buffers,
                depth_stencil: depth_state(depth_format, depth_write, depth_compare, st),
                color_writes: if color {
                    wgpu::ColorWrites::ALL
                } else {
                    wgpu::ColorWrites::empty()
                },
            }
            .build(gpu)
        };
        use wgpu::{CompareFunction as C, StencilOperation as S};
        let keep_equal = stencil(C::Equal, S::Keep);
        let objects = pipeline(
            "portal objects",
            scene_vertex,
            fs_object,
            true,
            true,
            NEARER_OR_EQUAL,
            keep_equal.clone(),
        );
        let mirrors = pipeline(
            "portal mirrors",
            scene_vertex,
            fs_mirror,
            true,
            true,
            NEARER_OR_EQUAL,
            keep_equal.clone(),
        );
        // Marks where the child's mirror is the nearest surface of the parent's world (which
        // drew it: equal depth passes).
        let mark = pipeline(
            "portal mark",
            scene_vertex,
            fs_mark,
            false,
            false,
            NEARER_OR_EQUAL,
            stencil(C::Equal, S::IncrementClamp),
        );
        let clear_region = pipeline(
            "portal region clear",
            "vs_fullscreen",
            "fs_background",
            true,
            true,
            C::Always,
            keep_equal,
        );
        let retire = pipeline(
            "portal retire",
            "vs_fullscreen",
            "fs_none",
            false,
            false,
            C::Always,
            stencil(C::Equal, S::Zero),
        );
        let decrement = pipeline(
            "portal decrement",
            "vs_fullscreen",
            "fs_none",
            false,
            false,
            C::Always,
            stencil(C::Equal, S::DecrementClamp),
        );
        Pipelines {
            objects,
            mirrors,
            mark,
            clear_region,
            retire,
            decrement,
        }
    }
}

/// The frame's triangles (refused past [`MAX_TRIANGLES_IN_ONE_PASS`]) and draws.
fn frame_stats(
    paths: &PathSet,
    ops: &[Op],
    visible_parts: &[Vec<usize>],
    scene_buffers: &SceneBuffers,
    (clipping, depth_format): (Clipping, wgpu::TextureFormat),
) -> Result<FrameStats, RasterError> {
    let mirror_count = scene_buffers.mirrors.len();
    let world_triangles = |path: usize| -> usize {
        visible_parts[path]
            .iter()
            .map(|&k| scene_buffers.parts[k].0.len() / 3)
            .sum::<usize>()
            + 2 * mirror_count
    };
    let triangles: usize = ops
        .iter()
        .map(|op| {
            if let Op::World { path, .. } = op {
                world_triangles(*path)
            } else {
                1
            }
        })
        .sum();
    if triangles > MAX_TRIANGLES_IN_ONE_PASS {
        return Err(RasterError::Plan(
            crate::plan::PlanError::TooManyTriangles {
                triangles,
                limit: MAX_TRIANGLES_IN_ONE_PASS,
            },
        ));
    }
    let draws = ops
        .iter()
        .map(|op| match op {
            Op::World { path, .. } => {
                visible_parts[*path].len() + mirror_count
                    - usize::from(paths.paths[*path].plane.is_some())
            }
            _ => 1,
        })
        .sum::<usize>()
        + 1;
    Ok(FrameStats {
        passes: 1,
        texture_renders: 0,
        draws,
        depth: paths.deepest,
        triangles,
        paths: Some(PathCounts::of(paths)),
        clipping,
        depth_format,
        copies: None,
    })
}

impl OnePassFrame for PortalStencil {
    fn pass(&self) -> OnePass<'_> {
        OnePass {
            scene: &self.scene_buffers,
            label: "portal stencil pass",
            clear: self.background,
            depth: &self.depth_stencil,
            stencil: Some(1),
            group1: (&self.path_bind_group, &self.offsets[..1]),
        }
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_vertex_buffer(0, self.scene_buffers.vertices.slice(..));
        let scissor = |pass: &mut wgpu::RenderPass<'_>, path: usize| {
            let [x, y, w, h] = self.scissors[path];
            pass.set_scissor_rect(x, y, w, h);
        };
        for op in &self.ops {
            match *op {
                Op::World { path, value } => {
                    scissor(pass, path);
                    pass.set_stencil_reference(value);
                    pass.set_bind_group(1, &self.path_bind_group, &[self.offsets[path]]);
                    pass.set_pipeline(&self.pipelines.objects);
                    for &k in &self.visible_parts[path] {
                        pass.draw(self.scene_buffers.parts[k].0.clone(), 0..1);
                    }
                    pass.set_pipeline(&self.pipelines.mirrors);
                    for m in 0..self.mirror_count {
                        if self.last_mirror[path] != Some(m) {
                            pass.draw(self.scene_buffers.mirrors[m].clone(), 0..1);
                        }
                    }
                }
                Op::Mark {
                    path,
                    child,
                    mirror,
                    value,
                } => {
                    scissor(pass, child);
                    pass.set_stencil_reference(value);
                    pass.set_bind_group(1, &self.path_bind_group, &[self.offsets[path]]);
                    pass.set_pipeline(&self.pipelines.mark);
                    pass.draw(self.scene_buffers.mirrors[mirror].clone(), 0..1);
                }
                Op::ClearRegion { path, value } => {
                    scissor(pass, path);
                    pass.set_stencil_reference(value);
                    pass.set_bind_group(1, &self.path_bind_group, &[self.offsets[path]]);
                    pass.set_pipeline(&self.pipelines.clear_region);
                    pass.draw(0..3, 0..1);
                }
                Op::Retire { path, value } | Op::Decrement { path, value } => {
                    scissor(pass, path);
                    pass.set_stencil_reference(value);
                    pass.set_pipeline(if matches!(op, Op::Retire { .. }) {
                        &self.pipelines.retire
                    } else {
                        &self.pipelines.decrement
                    });
                    pass.draw(0..3, 0..1);
                }
            }
        }
    }
}
