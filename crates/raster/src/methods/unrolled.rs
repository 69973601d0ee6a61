//! `unrolled`: exact mirrors with every reflection path drawn as an instance of the scene.
//! Entry points: `shaders/unrolled.wgsl` (+ `shaders/unrolled_clip_distances.wgsl`).
//!
//! A path `P = (m₁ … mₖ)` of [`mirrorbox_scene::reflection_paths`] sees the scene through the
//! composed reflection `R₁·…·Rₖ`; its instances draw the real scene with
//! `clip_from_world = proj · view · R₁·…·Rₖ` and keep only its *cell*: beyond `mₖ`'s plane
//! (distance `n·x − d ≥ 0` in scene space) and inside its visible region — its portal less
//! what nearer sibling mirrors hide, as convex screen pieces, one instance each (each edge a
//! half-plane `a·x_c + b·y_c + c·w_c ≥ 0` in clip space, i.e. a plane through the eye).
//! Colours are scaled by the product of the reflectances along the path. Every instance
//! shares one projection — the camera's, with infinite reversed Z in a 32-bit float buffer,
//! so depth stays precise a thousand reflections deep — and the depth test resolves
//! visibility between instances: the cells follow each other along every unfolded ray, and
//! inside a cell the ray meets that path's world only.
//!
//! Why pieces: where a small mirror hides part of a large one from the same cell, the large
//! mirror's portal (where it *could* be seen) covers the small one's, and behind the small
//! mirror along those rays lies the large mirror's cell too — often nearer than what the
//! small mirror shows (the sky it reflects, say). Depth cannot tell the two cells apart there;
//! cutting the hidden part out of the large mirror's visible region (and so out of every
//! path through it) can. The cut is CPU work on screen polygons, done only where sibling
//! portals share pixel centres: elsewhere a path is one piece, its portal, as before.
//!
//! Clipping uses hardware clip distances where the adapter has them (the mirror plane and up
//! to 7 piece edges); a piece with more edges, or a part that may lie behind some mirror,
//! goes to the *guarded* stage, which tests the same half-planes per fragment and also
//! discards points whose segment from the cell's entry crosses another mirror's front —
//! geometry behind a mirror never leaks into it.
//!
//! Draws: one per (part or mirror, stage) over the list of pieces whose path can see it
//! (culled by the portal's rectangle, as in `portal_stencil`), plus one for the pieces'
//! backgrounds — a handful whatever the depth or the overlaps. A mirror is drawn in a path's
//! world only where that mirror's own path was not kept (pruned or capped): its front then
//! shows the terminal radiance.

use crate::culling::{box_corners, box_may_touch};
use crate::exact_options::{DEPTH, MIN_ATTENUATION, MIN_PORTAL_AREA};
use crate::exact_paths::{PlannedPaths, plan_paths};
use crate::gpu::{Gpu, RasterError};
use crate::method::{
    Advise, BuiltFrame, Clipping, FrameStats, MethodEntry, OptionKind, OptionSpec, ParamValue,
    PathCounts, PlannedFrame, RasterMethod,
};
use crate::pipeline::{BindGroupBuilder, ScenePipeline, depth_state, pipeline_layout};
use crate::plan::PlanError;
use crate::projection::NEARER;
use crate::shading::{OnePass, OnePassFrame, SceneBuffers, VERTEX_LAYOUT};
use crate::targets::DEPTH_FORMAT;
use crate::wgsl::{HostLayout, WgslSource};
use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3, Vec4};
use mirrorbox_scene::Scene;
use mirrorbox_scene::camera::pixel_to_ndc;
use mirrorbox_scene::polygon::{bounds, orientation};
use mirrorbox_scene::reflection_paths::PathLimits;
use std::ops::Range;

/// Exact: every reflection path an instance of the scene, clipped to its cell.
pub static UNROLLED: MethodEntry = MethodEntry {
    name: "unrolled",
    help: "Exact: every reflection path an instance of the scene, clipped to its cell; a handful of draws.",
    exact: true,
    depth_limited: true,
    options: crate::method_options![
        &DEPTH,
        &MIN_PORTAL_AREA,
        &MIN_ATTENUATION,
        &FRAGMENT_CLIPPING
    ],
    swept: Some(&DEPTH),
    optional_features: wgpu::Features::CLIP_DISTANCES,
    required_features: wgpu::Features::empty(),
    shaders: &[&GUARDED_SHADER, &CLIP_DISTANCE_SHADER],
    gpu_structs,
    configure: |p| {
        Box::new(UnrolledMethod {
            limits: crate::exact_options::limits(p),
            fragment_clipping: p.switch(&FRAGMENT_CLIPPING),
        })
    },
    advise: Advise::Knob {
        option: &DEPTH,
        coarse: crate::exact_options::DEPTHS_COARSE,
        variants: &[""],
    },
};

/// `--fragment-clipping`: measure what hardware clip distances save.
pub static FRAGMENT_CLIPPING: OptionSpec = OptionSpec {
    name: "fragment-clipping",
    help: "Clip every instance per fragment (discard) even where the adapter has hardware clip \
           distances — to measure what they save.",
    kind: OptionKind::Switch,
    default: ParamValue::Switch(false),
    sweep: None,
    in_key: true,
};

const ENTRY_POINTS: &str = include_str!("../../../../shaders/unrolled.wgsl");

/// The guarded (per-fragment) stage, the background fans and the shading: every adapter.
static GUARDED_SHADER: WgslSource = WgslSource {
    label: "unrolled",
    enable: &[],
    parts: &[crate::wgsl::SHADING, ENTRY_POINTS],
};

/// Adds the hardware clip-distance stage, for adapters with `CLIP_DISTANCES`.
static CLIP_DISTANCE_SHADER: WgslSource = WgslSource {
    label: "unrolled clip distances",
    enable: &["clip_distances"],
    parts: &[
        crate::wgsl::SHADING,
        ENTRY_POINTS,
        include_str!("../../../../shaders/unrolled_clip_distances.wgsl"),
    ],
};

fn gpu_structs() -> Vec<HostLayout> {
    vec![
        crate::host_layout!(CellPiece as "CellPiece" {
            clip_from_world, plane, eye, edge_first, attenuation, edge_count
        }),
        crate::host_layout!(MirrorRect as "MirrorRect" {
            plane, center, half_width, right, half_height, up, _pad
        }),
    ]
}

/// The typed settings of `unrolled`.
struct UnrolledMethod {
    limits: PathLimits,
    fragment_clipping: bool,
}

impl RasterMethod for UnrolledMethod {
    fn plan(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
    ) -> Result<Box<dyn PlannedFrame>, PlanError> {
        Ok(Box::new(PlannedUnrolled {
            planned: plan_paths(scene, width, height, &self.limits)?,
            fragment_clipping: self.fragment_clipping,
        }))
    }
}

struct PlannedUnrolled {
    planned: PlannedPaths,
    fragment_clipping: bool,
}

impl PlannedFrame for PlannedUnrolled {
    /// The scene buffers, a depth target at the render size, and the instance storage
    /// buffers at their largest: per visible piece of every path one `CellPiece`, its edges
    /// (one per polygon vertex), one id per drawn item (every diffuse part and mirror at
    /// most) and its background triangles; on the host the paths.
    fn memory(&self, scene: &Scene, _color_bytes_per_texel: u64) -> crate::memory::MemoryEstimate {
        use crate::memory::{DEPTH_BYTES, buffer_bytes, texture_bytes};
        let paths = &self.planned.paths.paths;
        let pieces: u64 = paths.iter().map(|p| p.visible.len() as u64).sum();
        let corners: u64 = paths
            .iter()
            .flat_map(|p| &p.visible)
            .map(|v| v.len() as u64)
            .sum();
        let items = (scene.geometry.parts.len() + scene.mirrors.len()) as u64;
        let instances = buffer_bytes(pieces * std::mem::size_of::<CellPiece>() as u64)
            + buffer_bytes(corners * 16)
            + buffer_bytes(pieces * items * 4)
            + buffer_bytes(scene.mirrors.len() as u64 * std::mem::size_of::<MirrorRect>() as u64)
            + buffer_bytes(3 * corners * std::mem::size_of::<BackgroundVertex>() as u64);
        let mut e = SceneBuffers::memory_estimate(scene, &scene.geometry);
        e.gpu(
            "the depth target",
            "the image size (--width/--height) or --ssaa",
            texture_bytes(self.planned.width, self.planned.height, DEPTH_BYTES),
        );
        e.gpu(
            "the path instances",
            "--depth, or raise --min-portal-area or --min-attenuation",
            instances,
        );
        crate::exact_paths::paths_memory(&mut e, &self.planned.paths);
        e
    }

    fn build(
        self: Box<Self>,
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
    ) -> Result<BuiltFrame, RasterError> {
        let m = Unrolled::new(gpu, scene, shadows, &self.planned, self.fragment_clipping)?;
        Ok(BuiltFrame {
            stats: m.stats,
            encoder: Box::new(m),
            warnings: Vec::new(),
            bake_ms: None,
        })
    }
}

/// Most triangles (instances counted) `unrolled` submits per frame — a time bound (about
/// 10 s on lavapipe, 2 cores); refused beyond with a hint.
pub const MAX_TRIANGLES_PER_FRAME: usize = 50_000_000;

/// Portal edges the clip-distance stage handles (distance 0 is the mirror plane).
pub const CLIP_EDGES: usize = 7;

/// Scene-space tolerance of "in front of a mirror" (as `GUARD_EPSILON` in the shader).
const FRONT_EPSILON: f32 = 1e-5;

/// One convex piece of a path's visible region, drawn as one instance: the path's
/// transform, plane, eye and attenuation, and the piece's edges.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct CellPiece {
    clip_from_world: [[f32; 4]; 4],
    plane: [f32; 4],
    eye: [f32; 3],
    edge_first: u32,
    attenuation: [f32; 3],
    edge_count: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct MirrorRect {
    plane: [f32; 4],
    center: [f32; 3],
    half_width: f32,
    right: [f32; 3],
    half_height: f32,
    up: [f32; 3],
    _pad: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct BackgroundVertex {
    ndc: [f32; 2],
    attenuation: [f32; 3],
}

/// The clip-space half-planes `a·x + b·y + c·w ≥ 0` bounding a convex screen polygon
/// (pixels, any orientation) — each a plane through the eye.
pub fn portal_edges(portal: &[Vec2], size: Vec2) -> Vec<Vec4> {
    let ndc: Vec<Vec2> = portal.iter().map(|&p| pixel_to_ndc(p, size)).collect();
    let s = orientation(&ndc);
    (0..ndc.len())
        .filter_map(|i| {
            let (a, b) = (ndc[i], ndc[(i + 1) % ndc.len()]);
            // Inside: s · (b − a) × (p − a) ≥ 0.
            let n = s * Vec2::new(-(b.y - a.y), b.x - a.x);
            let len = n.length();
            (len > 0.0).then(|| {
                let n = n / len;
                Vec4::new(n.x, n.y, -n.dot(a), 0.0)
            })
        })
        .collect()
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    Clipped,
    Guarded,
}

/// One instanced draw: a vertex range for the cell pieces `ids[instances]`.
struct Draw {
    stage: Stage,
    mirror: bool,
    vertices: Range<u32>,
    instances: Range<u32>,
}

/// Something drawn per path: a diffuse part or a scene mirror.
struct Item {
    vertices: Range<u32>,
    lo: Vec3,
    hi: Vec3,
    mirror: Option<usize>,
    /// Lies in front of every mirror's plane: no ray can reach it through a mirror's front,
    /// so it needs no guard.
    in_front_of_all_mirrors: bool,
}

pub struct Unrolled {
    scene_buffers: SceneBuffers,
    bind_group: wgpu::BindGroup,
    draws: Vec<Draw>,
    background: Option<(wgpu::Buffer, u32)>,
    depth: wgpu::TextureView,
    pipelines: Pipelines,
    clear: Vec3,
    pub stats: FrameStats,
}

impl Unrolled {
    /// `planned` holds the paths and the camera's `[0, 1]` projection they were enumerated
    /// with; `fragment_clipping` forces the guarded stage everywhere.
    fn new(
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
        planned: &PlannedPaths,
        fragment_clipping: bool,
    ) -> Result<Self, RasterError> {
        use wgpu::util::DeviceExt;
        let device = &gpu.device;
        let paths = &planned.paths;
        let (width, height) = (planned.width, planned.height);
        let clip_distances =
            gpu.features.contains(wgpu::Features::CLIP_DISTANCES) && !fragment_clipping;
        let scene_buffers = SceneBuffers::new(gpu, scene, shadows.binding());
        let items = items(scene, &scene_buffers);
        let instances = Instances::of(planned, &items, clip_distances);
        let (ids, draws, item_triangles) = draw_lists(&items, &instances.lists);
        let background = instances.background;
        let triangles = background.len() / 3 + item_triangles;
        if triangles > MAX_TRIANGLES_PER_FRAME {
            return Err(RasterError::Plan(PlanError::TooManyTriangles {
                triangles,
                limit: MAX_TRIANGLES_PER_FRAME,
            }));
        }
        let (layout, bind_group) =
            storage_group(gpu, scene, &instances.cell_pieces, &instances.edges, &ids);
        let layout = pipeline_layout(gpu, "unrolled", &[&scene_buffers.layout, &layout]);
        let pipelines = Pipelines::new(gpu, &layout, scene_buffers.textured, clip_distances);
        let depth = crate::targets::texture_2d(
            device,
            "unrolled depth",
            width,
            height,
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
        let background = (!background.is_empty()).then(|| {
            (
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("unrolled backgrounds"),
                    contents: bytemuck::cast_slice(&background),
                    usage: wgpu::BufferUsages::VERTEX,
                }),
                background.len() as u32,
            )
        });
        let stats = FrameStats {
            passes: 1,
            texture_renders: 0,
            draws: draws.len() + usize::from(background.is_some()) + 1,
            depth: paths.deepest,
            triangles,
            paths: Some(PathCounts::of(paths)),
            clipping: if clip_distances {
                Clipping::ClipDistances
            } else {
                Clipping::FragmentDiscard
            },
            depth_format: DEPTH_FORMAT,
            copies: None,
        };
        Ok(Unrolled {
            scene_buffers,
            bind_group,
            draws,
            background,
            depth,
            pipelines,
            clear: scene.background,
            stats,
        })
    }
}

/// Every diffuse part and mirror a path may draw, with its bounds and whether it needs the
/// guard.
fn items(scene: &Scene, scene_buffers: &SceneBuffers) -> Vec<Item> {
    // Each distinct mirror plane once: every item is tested against every plane, and
    // stacked or coincident mirrors (a mosaic's coplanar facets, the degenerate scene of
    // 20 000 coincident mirrors) would make that items × mirrors (issue 51).
    let mut planes: Vec<Vec4> = scene
        .mirrors
        .iter()
        .map(|m| m.plane().coefficients())
        .collect();
    planes.sort_unstable_by_key(|p| p.to_array().map(f32::to_bits));
    planes.dedup_by_key(|p| p.to_array().map(f32::to_bits));
    let in_front_of_all = |lo: Vec3, hi: Vec3| {
        box_corners(lo, hi).iter().all(|p| {
            planes
                .iter()
                .all(|pl| pl.dot(p.extend(1.0)) >= -FRONT_EPSILON)
        })
    };
    let mut items: Vec<Item> = scene_buffers
        .parts
        .iter()
        .map(|(range, lo, hi)| Item {
            vertices: range.clone(),
            lo: *lo,
            hi: *hi,
            mirror: None,
            in_front_of_all_mirrors: in_front_of_all(*lo, *hi),
        })
        .collect();
    for (m, mirror) in scene.mirrors.iter().enumerate() {
        let c = mirror.corners();
        let lo = c.iter().fold(Vec3::INFINITY, |a, p| a.min(*p));
        let hi = c.iter().fold(Vec3::NEG_INFINITY, |a, p| a.max(*p));
        items.push(Item {
            vertices: scene_buffers.mirrors[m].clone(),
            lo,
            hi,
            mirror: Some(m),
            in_front_of_all_mirrors: in_front_of_all(lo, hi),
        });
    }
    items
}

/// Per path, per piece of its visible region: its data, its edges, and which items it
/// draws with which stage; and the portals' background triangles.
struct Instances {
    cell_pieces: Vec<CellPiece>,
    edges: Vec<Vec4>,
    /// Per item, the cell pieces that draw it, by stage (clipped, guarded).
    lists: Vec<[Vec<u32>; 2]>,
    background: Vec<BackgroundVertex>,
}

impl Instances {
    fn of(planned: &PlannedPaths, items: &[Item], clip_distances: bool) -> Self {
        let (paths, projection) = (&planned.paths, planned.projection);
        let size = Vec2::new(planned.width as f32, planned.height as f32);
        let mut cell_pieces = Vec::with_capacity(paths.paths.len());
        let mut edges: Vec<Vec4> = Vec::new();
        let mut lists: Vec<[Vec<u32>; 2]> = vec![[Vec::new(), Vec::new()]; items.len()];
        let mut background: Vec<BackgroundVertex> = Vec::new();
        for p in &paths.paths {
            let view_clip = projection * p.view.view;
            let plane = p.plane.map_or(Vec4::W, |pl| pl.coefficients());
            let portal_rect = bounds(&p.portal);
            let kept_mirrors: Vec<usize> = p
                .children
                .iter()
                .filter_map(|&c| paths.paths[c].mirrors.last().copied())
                .collect();
            // The items this path's world shows (bounds reaching its portal).
            let drawn: Vec<usize> = items
                .iter()
                .enumerate()
                .filter(|(_, item)| {
                    let own_or_kept = item
                        .mirror
                        .is_some_and(|m| p.mirrors.last() == Some(&m) || kept_mirrors.contains(&m));
                    let behind_plane = p.plane.is_some()
                        && box_corners(item.lo, item.hi)
                            .iter()
                            .all(|q| plane.dot(q.extend(1.0)) < 0.0);
                    !own_or_kept
                        && !behind_plane
                        && box_may_touch(view_clip, item.lo, item.hi, portal_rect, size)
                })
                .map(|(k, _)| k)
                .collect();
            let clip_from_world = view_clip.to_cols_array_2d();
            let eye = p.view.eye().to_array();
            for piece in &p.visible {
                let id = cell_pieces.len() as u32;
                let piece_edges = if p.plane.is_some() {
                    portal_edges(piece, size)
                } else {
                    Vec::new() // the camera's portal is the viewport
                };
                let edge_first = edges.len() as u32;
                let edge_count = piece_edges.len();
                edges.extend(&piece_edges);
                cell_pieces.push(CellPiece {
                    clip_from_world,
                    plane: plane.to_array(),
                    eye,
                    edge_first,
                    attenuation: p.attenuation.to_array(),
                    edge_count: edge_count as u32,
                });
                for &k in &drawn {
                    let stage = if clip_distances
                        && edge_count <= CLIP_EDGES
                        && items[k].in_front_of_all_mirrors
                    {
                        Stage::Clipped
                    } else {
                        Stage::Guarded
                    };
                    lists[k][stage as usize].push(id);
                }
                if p.plane.is_some() {
                    let ndc: Vec<Vec2> = piece.iter().map(|&q| pixel_to_ndc(q, size)).collect();
                    for i in 1..ndc.len().saturating_sub(1) {
                        for v in [ndc[0], ndc[i], ndc[i + 1]] {
                            background.push(BackgroundVertex {
                                ndc: v.to_array(),
                                attenuation: p.attenuation.to_array(),
                            });
                        }
                    }
                }
            }
        }
        Instances {
            cell_pieces,
            edges,
            lists,
            background,
        }
    }
}

/// The instanced draws, one per item and stage with any instance, their instance ids, and
/// the triangles they submit.
fn draw_lists(items: &[Item], lists: &[[Vec<u32>; 2]]) -> (Vec<u32>, Vec<Draw>, usize) {
    let mut ids: Vec<u32> = Vec::new();
    let mut draws = Vec::new();
    let mut triangles = 0;
    for (item, list) in items.iter().zip(lists) {
        for (stage, list) in [Stage::Clipped, Stage::Guarded].into_iter().zip(list) {
            if list.is_empty() {
                continue;
            }
            let first = ids.len() as u32;
            ids.extend(list);
            triangles += list.len() * item.vertices.len() / 3;
            draws.push(Draw {
                stage,
                mirror: item.mirror.is_some(),
                vertices: item.vertices.clone(),
                instances: first..ids.len() as u32,
            });
        }
    }
    (ids, draws, triangles)
}

/// The storage buffers the shaders read (cell pieces, edges, instance ids, mirror rectangles)
/// and their bind group.
fn storage_group(
    gpu: &Gpu,
    scene: &Scene,
    cell_pieces: &[CellPiece],
    edges: &[Vec4],
    ids: &[u32],
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    use wgpu::util::DeviceExt;
    let device = &gpu.device;
    let mirror_rects: Vec<MirrorRect> = scene
        .mirrors
        .iter()
        .map(|m| MirrorRect {
            plane: m.plane().coefficients().to_array(),
            center: m.center.to_array(),
            half_width: 0.5 * m.width,
            right: m.right().to_array(),
            half_height: 0.5 * m.height,
            up: m.up.to_array(),
            _pad: 0.0,
        })
        .collect();
    // Storage buffers may not be empty.
    let nonempty = |mut v: Vec<u8>| {
        if v.is_empty() {
            v.resize(16, 0);
        }
        v
    };
    let storage = |label: &str, bytes: Vec<u8>| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: &nonempty(bytes),
            usage: wgpu::BufferUsages::STORAGE,
        })
    };
    let buffers = [
        storage(
            "unrolled cell pieces",
            bytemuck::cast_slice(cell_pieces).to_vec(),
        ),
        storage(
            "unrolled edges",
            bytemuck::cast_slice(&edges.iter().map(|e| e.to_array()).collect::<Vec<_>>()).to_vec(),
        ),
        storage("unrolled ids", bytemuck::cast_slice(ids).to_vec()),
        storage(
            "unrolled mirrors",
            bytemuck::cast_slice(&mirror_rects).to_vec(),
        ),
    ];
    buffers
        .iter()
        .fold(BindGroupBuilder::new("unrolled"), |b, buffer| {
            b.storage(wgpu::ShaderStages::VERTEX_FRAGMENT, buffer)
        })
        .build(gpu)
}

/// The pipelines: guarded (every adapter), clipped (with clip distances), backgrounds.
struct Pipelines {
    guarded_object: wgpu::RenderPipeline,
    guarded_mirror: wgpu::RenderPipeline,
    background: wgpu::RenderPipeline,
    clipped_object: Option<wgpu::RenderPipeline>,
    clipped_mirror: Option<wgpu::RenderPipeline>,
}

impl Pipelines {
    fn new(gpu: &Gpu, layout: &wgpu::PipelineLayout, textured: bool, clip_distances: bool) -> Self {
        let guarded_module = gpu.shader_module(&GUARDED_SHADER, textured);
        let clipped_module =
            clip_distances.then(|| gpu.shader_module(&CLIP_DISTANCE_SHADER, textured));
        let background_layout = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<BackgroundVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x2, 1 => Float32x3],
        };
        let pipeline = |label: &str,
                        module: &wgpu::ShaderModule,
                        vertex: &str,
                        fragment: &str,
                        buffer: wgpu::VertexBufferLayout<'_>,
                        background: bool| {
            ScenePipeline {
                label,
                layout,
                module,
                vertex,
                fragment,
                buffers: &[Some(buffer)],
                // Reversed Z: nearer is greater. Backgrounds lie behind everything.
                depth_stencil: depth_state(
                    DEPTH_FORMAT,
                    !background,
                    if background {
                        wgpu::CompareFunction::Always
                    } else {
                        NEARER
                    },
                    Default::default(),
                ),
                color_writes: wgpu::ColorWrites::ALL,
            }
            .build(gpu)
        };
        let m = &guarded_module;
        let guarded_object = pipeline(
            "unrolled objects (guarded)",
            m,
            "vs_guarded",
            "fs_object_guarded",
            VERTEX_LAYOUT,
            false,
        );
        let guarded_mirror = pipeline(
            "unrolled mirrors (guarded)",
            m,
            "vs_guarded",
            "fs_mirror_guarded",
            VERTEX_LAYOUT,
            false,
        );
        let background_pipeline = pipeline(
            "unrolled backgrounds",
            m,
            "vs_background",
            "fs_background",
            background_layout,
            true,
        );
        let clipped_object = clipped_module.as_ref().map(|m| {
            pipeline(
                "unrolled objects (clip distances)",
                m,
                "vs_clipped",
                "fs_object_clipped",
                VERTEX_LAYOUT,
                false,
            )
        });
        let clipped_mirror = clipped_module.as_ref().map(|m| {
            pipeline(
                "unrolled mirrors (clip distances)",
                m,
                "vs_clipped",
                "fs_mirror_clipped",
                VERTEX_LAYOUT,
                false,
            )
        });
        Pipelines {
            guarded_object,
            guarded_mirror,
            background: background_pipeline,
            clipped_object,
            clipped_mirror,
        }
    }
}

impl OnePassFrame for Unrolled {
    fn pass(&self) -> OnePass<'_> {
        OnePass {
            scene: &self.scene_buffers,
            label: "unrolled pass",
            clear: self.clear,
            depth: &self.depth,
            stencil: None,
            group1: (&self.bind_group, &[]),
        }
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        if let Some((buffer, count)) = &self.background {
            pass.set_pipeline(&self.pipelines.background);
            pass.set_vertex_buffer(0, buffer.slice(..));
            pass.draw(0..*count, 0..1);
        }
        pass.set_vertex_buffer(0, self.scene_buffers.vertices.slice(..));
        for d in &self.draws {
            let pipeline = match (d.stage, d.mirror) {
                (Stage::Clipped, false) => self.pipelines.clipped_object.as_ref(),
                (Stage::Clipped, true) => self.pipelines.clipped_mirror.as_ref(),
                (Stage::Guarded, false) => Some(&self.pipelines.guarded_object),
                (Stage::Guarded, true) => Some(&self.pipelines.guarded_mirror),
            }
            .expect("clipped draws exist only with clip distances");
            pass.set_pipeline(pipeline);
            pass.draw(d.vertices.clone(), d.instances.clone());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn portal_edges_keep_the_inside_in_either_orientation() {
        let size = Vec2::new(100.0, 50.0);
        let square = [
            Vec2::new(10.0, 10.0),
            Vec2::new(30.0, 10.0),
            Vec2::new(30.0, 40.0),
            Vec2::new(10.0, 40.0),
        ];
        let mut reversed = square;
        reversed.reverse();
        for poly in [&square[..], &reversed[..]] {
            let edges = portal_edges(poly, size);
            assert_eq!(edges.len(), 4);
            let inside = |px: Vec2, w: f32| {
                let n = pixel_to_ndc(px, size);
                // The same point at clip w: (x·w, y·w, w).
                edges
                    .iter()
                    .all(|e| e.x * n.x * w + e.y * n.y * w + e.z * w >= 0.0)
            };
            assert!(inside(Vec2::new(20.0, 25.0), 1.0));
            assert!(inside(Vec2::new(20.0, 25.0), 7.5));
            assert!(!inside(Vec2::new(5.0, 25.0), 1.0));
            assert!(!inside(Vec2::new(20.0, 45.0), 3.0));
        }
    }
}
