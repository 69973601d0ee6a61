//! `symmetry`: seed 001's symmetry planes — the objects drawn 2^p times, one copy per bitmask
//! of the p planes, as instances of one draw. Entry points: `shaders/symmetry.wgsl`
//! (+ `shaders/symmetry_clip_distances.wgsl`).
//!
//! Copy `b` moves a source vertex through the seed's cascade (for plane i in order,
//! `d_i = n_i·x_i − offset_i` on the position already moved by the earlier planes, then
//! `x_{i+1} = x_i − 2 d_i n_i` if bit i of `b` is set) and reflects its normal with it; it keeps
//! only what has every `d_i ≥ 0`. The distances are affine in the source position, so clipping
//! at them is exact: hardware clip distances where the adapter has `CLIP_DISTANCES` and p ≤ 8,
//! else (or with `--fragment-clipping`) interpolated distances and discard. The result is
//! exactly the CPU split-and-mirror bake the tracer traces (`mirrorbox_scene::symmetry`).
//!
//! **Winding groups and back-face culling.** An odd number of reflections reverses a copy's
//! winding, so even and odd copies are drawn apart, with front faces `Ccw` and `Cw` (the seed's
//! suggestion; its own code turns culling off). Culling back faces is exact only where the
//! first surface along every ray from the eye is a front face: a closed, consistently wound
//! mesh seen from outside. The cascade keeps a mesh closed — each plane keeps the front part,
//! whose open cut lies on the plane, and adds its mirror image, which closes it along the same
//! cut — so a part is drawn culled when its source is closed (every directed edge matched by
//! its reverse, once) and the eye lies outside its bounds in every copy drawn (the eye pulled
//! back through the copy's reflections); any other part (a quad, an open mesh, the eye inside)
//! is drawn without culling, in the same draws' winding groups. `CopyCounts::culled_parts`
//! says how many were culled.
//!
//! **Draws.** `--symmetry-draws instanced` (default): per winding group, one instanced draw
//! of the culled parts and one of the others (instance i draws the copy `masks[i]`; each
//! group's masks are contiguous). `--symmetry-draws per-copy`: the seed's cost model, one draw
//! per copy (and culling class) with the copy's bitmask in a uniform at a dynamic offset.
//!
//! **Mirrors.** The symmetry planes act on the objects only. The scene's mirrors are drawn
//! once, as they are, at reflection depth 0: a mirror's front shows the terminal radiance (as
//! every method shows a mirror it cannot follow), its back is diffuse — exactly the truth
//! traced at depth 0. `FrameStats::depth` is 0.

use crate::gpu::{Gpu, RasterError};
use crate::method::{
    Advise, BuiltFrame, Clipping, CopyCounts, FrameStats, MethodEntry, OptionKind, OptionSpec,
    ParamValue, Params, PlannedFrame, RasterMethod,
};
use crate::methods::unrolled::FRAGMENT_CLIPPING;
use crate::pipeline::{
    ScenePipeline, UniformArena, depth_state, dynamic_uniform_entry, pipeline_layout,
    record_binding,
};
use crate::plan::PlanError;
use crate::projection::{NEARER, camera_projection};
use crate::shading::{SceneBuffers, VERTEX_LAYOUT};
use crate::symmetry_cells::{CopySelection, copy_count, reverses_winding};
use crate::targets::{DEPTH_FORMAT, RenderTarget};
use crate::timing::FrameEncoder;
use crate::wgsl::{HostLayout, WgslSource};
use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Mat4, Vec3};
use mirrorbox_scene::{Geometry, Plane, Scene, Surface};
use std::borrow::Cow;
use std::collections::HashMap;
use std::ops::Range;

/// Seed 001: every copy an instance of one draw.
pub static SYMMETRY: MethodEntry = MethodEntry {
    name: "symmetry",
    help: "Seed 001's symmetry planes: the objects drawn 2^p times, each copy an instance clipped to its cell; even and odd copies with opposite front faces.",
    exact: true,
    depth_limited: true,
    options: crate::method_options![&SYMMETRY_DRAWS, &FRAGMENT_CLIPPING, &COPY_IDS],
    swept: None,
    optional_features: wgpu::Features::CLIP_DISTANCES,
    required_features: wgpu::Features::empty(),
    shaders: &[&SHADER, &CLIP_DISTANCE_SHADER],
    gpu_structs,
    configure: |p| {
        Box::new(SymmetryMethod {
            settings: CopySettings::of(p),
        })
    },
    advise: Advise::Skip,
};

/// `--symmetry-draws`: the copies as instances, or one draw each (the seed's cost model).
pub static SYMMETRY_DRAWS: OptionSpec = OptionSpec {
    name: "symmetry-draws",
    help: "How the copies are drawn: as instances (two draws per winding group), or per-copy: one \
           draw per copy with its bitmask in a uniform (the seed's cost model).",
    kind: OptionKind::Choice {
        values: &["instanced", "per-copy"],
    },
    default: ParamValue::Choice("instanced"),
    sweep: None,
    in_key: true,
};

/// `--copy-ids`: which copy each pixel shows, instead of radiance.
pub static COPY_IDS: OptionSpec = OptionSpec {
    name: "copy-ids",
    help: "Debug: write which copy each pixel shows instead of radiance (red = copy bitmask + 1, \
           0 where no copy shows), to compare the copies reaching the screen between methods.",
    kind: OptionKind::Switch,
    default: ParamValue::Switch(false),
    sweep: None,
    in_key: true,
};

const ENTRY_POINTS: &str = include_str!("../../../../shaders/symmetry.wgsl");

/// Fragment discard, the mirrors and the baked mesh: every adapter.
pub(crate) static SHADER: WgslSource = WgslSource {
    label: "symmetry",
    enable: &[],
    parts: &[
        crate::wgsl::SHADING,
        crate::wgsl::SCENE_VERTEX,
        ENTRY_POINTS,
    ],
};

/// Adds the hardware clip-distance stage, for adapters with `CLIP_DISTANCES` (p ≤ 8).
pub(crate) static CLIP_DISTANCE_SHADER: WgslSource = WgslSource {
    label: "symmetry clip distances",
    enable: &["clip_distances"],
    parts: &[
        crate::wgsl::SHADING,
        crate::wgsl::SCENE_VERTEX,
        ENTRY_POINTS,
        include_str!("../../../../shaders/symmetry_clip_distances.wgsl"),
    ],
};

pub(crate) fn gpu_structs() -> Vec<HostLayout> {
    vec![
        crate::host_layout!(SymmetryFrame as "SymmetryFrame" {
            clip_from_world, eye, plane_count, planes
        }),
        crate::host_layout!(CopyRecord as "CopyRecord" { mask, _pad0, _pad1, _pad2 }),
    ]
}

/// Most symmetry planes the shaders take (the scene format's limit).
pub const MAX_PLANES: usize = 16;
/// Most planes hardware clip distances take (wgpu allows 8); beyond, fragments discard.
pub const MAX_CLIP_DISTANCE_PLANES: usize = 8;
/// Most triangles (copies counted) a frame submits — a time bound, as `unrolled`'s (about
/// 10 s on lavapipe, 2 cores); refused beyond, before any GPU work.
pub const MAX_TRIANGLES_PER_FRAME: usize = 50_000_000;

/// The options `symmetry` and `symmetry-pruned` share.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CopySettings {
    pub per_copy: bool,
    pub fragment_clipping: bool,
    pub copy_ids: bool,
}

impl CopySettings {
    pub(crate) fn of(p: &Params) -> CopySettings {
        CopySettings {
            per_copy: p.choice(&SYMMETRY_DRAWS) == "per-copy",
            fragment_clipping: p.switch(&FRAGMENT_CLIPPING),
            copy_ids: p.switch(&COPY_IDS),
        }
    }
}

/// The typed settings of `symmetry`.
struct SymmetryMethod {
    settings: CopySettings,
}

impl RasterMethod for SymmetryMethod {
    fn plan(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
    ) -> Result<Box<dyn PlannedFrame>, PlanError> {
        let input = SymmetryInput::of(scene);
        let selection = CopySelection::all(input.planes.len());
        plan_copies(scene, &input, width, height, selection, self.settings)
    }
}

/// What the symmetry methods draw: the planes in cascade order and the objects before them
/// (`Scene::symmetry`); a scene without planes gives p = 0 and its objects.
pub(crate) struct SymmetryInput<'a> {
    pub planes: Vec<Plane>,
    pub source: Cow<'a, Geometry>,
}

impl<'a> SymmetryInput<'a> {
    pub(crate) fn of(scene: &'a Scene) -> SymmetryInput<'a> {
        match &scene.symmetry {
            Some(s) => SymmetryInput {
                planes: s.plane_list(),
                source: Cow::Borrowed(&s.source),
            },
            None => {
                let mut objects = scene.geometry.empty_like();
                for (name, surface, triangles, uvs) in parts_of(&scene.geometry, false) {
                    objects.push_textured_part(name, surface, triangles, uvs);
                }
                SymmetryInput {
                    planes: Vec::new(),
                    source: Cow::Owned(objects),
                }
            }
        }
    }
}

/// A part of a geometry, copied out: name, surface, triangles and their texture coordinates.
pub(crate) type PartCopy = (String, Surface, Vec<[Vec3; 3]>, Vec<[glam::Vec2; 3]>);

/// The diffuse parts (`mirrors` false) or the mirror parts of `g`, copied out (into a
/// geometry made by `g.empty_like()`, which keeps the textures their surfaces index).
pub(crate) fn parts_of(g: &Geometry, mirrors: bool) -> impl Iterator<Item = PartCopy> + '_ {
    g.parts.iter().filter_map(move |part| {
        let surface = &g.surfaces[part.surface as usize];
        (matches!(surface, Surface::Mirror { .. }) == mirrors).then(|| {
            (
                part.name.clone(),
                surface.clone(),
                g.triangles[part.triangles.clone()].to_vec(),
                g.uvs[part.triangles.clone()].to_vec(),
            )
        })
    })
}

/// The GPU twin of `SymmetryFrame` (shaders/symmetry.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct SymmetryFrame {
    clip_from_world: [[f32; 4]; 4],
    eye: [f32; 3],
    plane_count: u32,
    /// Plane i as `(n_i, −offset_i)`.
    planes: [[f32; 4]; MAX_PLANES],
}

impl SymmetryFrame {
    /// The camera's projection (infinite reversed Z) · view at `width × height`, its eye, and
    /// `planes` (at most [`MAX_PLANES`]).
    pub(crate) fn new(scene: &Scene, width: u32, height: u32, planes: &[Plane]) -> SymmetryFrame {
        let mut frame = SymmetryFrame {
            clip_from_world: (camera_projection(&scene.camera, width, height)
                * scene.camera.view())
            .to_cols_array_2d(),
            eye: scene.camera.position.to_array(),
            plane_count: planes.len().min(MAX_PLANES) as u32,
            planes: [[0.0; 4]; MAX_PLANES],
        };
        for (slot, plane) in frame.planes.iter_mut().zip(planes) {
            *slot = plane.coefficients().to_array();
        }
        frame
    }

    pub(crate) fn clip_from_world(&self) -> Mat4 {
        Mat4::from_cols_array_2d(&self.clip_from_world)
    }
}

/// One copy's record of `--symmetry-draws per-copy` (a uniform at a dynamic offset).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct CopyRecord {
    mask: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

/// Whether `triangles` form a closed, consistently wound surface: every directed edge
/// (vertices compared bit for bit) appears once and its reverse once. Then the surface
/// bounds a volume and, seen from outside, the first surface along any ray is a front face.
pub fn is_closed(triangles: &[[Vec3; 3]]) -> bool {
    if triangles.is_empty() {
        return false;
    }
    // +0.0 for −0.0, so the two zeros are one vertex.
    let key = |v: Vec3| (v + Vec3::ZERO).to_array().map(f32::to_bits);
    let mut edges: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            *edges.entry((key(t[k]), key(t[(k + 1) % 3]))).or_default() += 1;
        }
    }
    edges
        .iter()
        .all(|(&(a, b), &count)| count == 1 && edges.get(&(b, a)) == Some(&1))
}

/// Whether the eye, pulled back through each of `masks`' reflections into the source space,
/// lies outside the box `lo..hi` (by a margin relative to the scene's size): then no copy of
/// what the box holds surrounds the eye.
fn eye_outside_every_copy(planes: &[Plane], masks: &[u32], eye: Vec3, lo: Vec3, hi: Vec3) -> bool {
    let scale = lo
        .abs()
        .max(hi.abs())
        .max_element()
        .max(eye.abs().max_element())
        .max(1.0);
    let margin = 1e-4 * scale as f64;
    let (lo, hi) = (lo.as_dvec3() - margin, hi.as_dvec3() + margin);
    masks.iter().all(|&mask| {
        let mut x = eye.as_dvec3();
        for (i, plane) in planes.iter().enumerate().rev() {
            if mask >> i & 1 == 1 {
                let n: DVec3 = plane.normal.as_dvec3();
                x -= 2.0 * (n.dot(x) - plane.offset as f64) * n;
            }
        }
        x.cmplt(lo).any() || x.cmpgt(hi).any()
    })
}

/// Which pipeline an object draw uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ObjectPipeline {
    /// Back faces culled, front faces wound `Ccw` (even copies) or `Cw` (odd copies).
    Culled { odd: bool },
    /// No culling.
    Unculled,
}

/// One object draw: a vertex range for instances `instances` (of `masks`), or, per copy, one
/// instance of copy record `record`.
struct ObjectDraw {
    pipeline: ObjectPipeline,
    vertices: Range<u32>,
    instances: Range<u32>,
    record: Option<usize>,
}

/// A symmetry frame planned on the CPU.
pub(crate) struct PlannedCopies {
    geometry: Geometry,
    frame: SymmetryFrame,
    /// The drawn copies' masks: even copies first, then odd ones.
    masks: Vec<u32>,
    draws: Vec<ObjectDraw>,
    /// Vertex range of the mirrors (after the objects).
    mirrors: Range<u32>,
    settings: CopySettings,
    plane_count: usize,
    stats: CopyCounts,
    triangles: usize,
}

/// Plans the copies `selection` of `input` (objects) and the scene's mirrors. Refuses a frame
/// above [`MAX_TRIANGLES_PER_FRAME`] or with more than [`MAX_PLANES`] planes.
pub(crate) fn plan_copies(
    scene: &Scene,
    input: &SymmetryInput<'_>,
    width: u32,
    height: u32,
    selection: CopySelection,
    settings: CopySettings,
) -> Result<Box<dyn PlannedFrame>, PlanError> {
    let planes = &input.planes;
    if planes.len() > MAX_PLANES {
        // The scene format allows no more; a scene built in code might.
        return Err(PlanError::TooManySymmetryPlanes {
            planes: planes.len(),
            limit: MAX_PLANES,
        });
    }
    let eye = scene.camera.position;
    let mut even: Vec<u32> = Vec::new();
    let mut odd: Vec<u32> = Vec::new();
    for &mask in &selection.drawn {
        if reverses_winding(mask) {
            odd.push(mask);
        } else {
            even.push(mask);
        }
    }
    let mut masks = even.clone();
    masks.extend(&odd);

    // The object parts, culled ones first (one contiguous vertex range each class).
    let mut culled_parts = Vec::new();
    let mut unculled_parts = Vec::new();
    for (name, surface, triangles, uvs) in parts_of(&input.source, false) {
        if triangles.is_empty() {
            continue;
        }
        let (lo, hi) = triangles
            .iter()
            .flatten()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| {
                (a.min(*p), b.max(*p))
            });
        let culled = is_closed(&triangles) && eye_outside_every_copy(planes, &masks, eye, lo, hi);
        if culled {
            culled_parts.push((name, surface, triangles, uvs));
        } else {
            unculled_parts.push((name, surface, triangles, uvs));
        }
    }
    let part_count = culled_parts.len() + unculled_parts.len();
    let culled_part_count = culled_parts.len();
    let mut geometry = input.source.empty_like();
    for (name, surface, triangles, uvs) in culled_parts {
        geometry.push_textured_part(name, surface, triangles, uvs);
    }
    let culled_vertices = 3 * geometry.triangles.len() as u32;
    for (name, surface, triangles, uvs) in unculled_parts {
        geometry.push_textured_part(name, surface, triangles, uvs);
    }
    let object_vertices = 3 * geometry.triangles.len() as u32;
    for (name, surface, triangles, uvs) in parts_of(&scene.geometry, true) {
        geometry.push_textured_part(name, surface, triangles, uvs);
    }
    let all_vertices = 3 * geometry.triangles.len() as u32;

    let per_copy = (object_vertices / 3) as usize;
    let mirror_triangles = ((all_vertices - object_vertices) / 3) as usize;
    let triangles = masks.len() * per_copy + mirror_triangles;
    if triangles > MAX_TRIANGLES_PER_FRAME {
        return Err(PlanError::TooManyCopyTriangles {
            triangles,
            copies: masks.len(),
            per_copy,
            limit: MAX_TRIANGLES_PER_FRAME,
        });
    }

    let classes = [
        (0..culled_vertices, true),
        (culled_vertices..object_vertices, false),
    ];
    let draws = object_draws(&classes, &masks, even.len(), settings.per_copy);
    let stats = CopyCounts {
        planes: planes.len(),
        total: copy_count(planes.len()),
        drawn: masks.len(),
        pruned_empty: selection.pruned_empty,
        pruned_outside_view: selection.pruned_outside_view,
        culled_parts: culled_part_count,
        parts: part_count,
    };
    Ok(Box::new(PlannedCopies {
        geometry,
        frame: SymmetryFrame::new(scene, width, height, planes),
        masks,
        draws,
        mirrors: object_vertices..all_vertices,
        settings,
        plane_count: planes.len(),
        stats,
        triangles,
    }))
}

/// The object draws of a frame: per vertex class (closed parts culled per copy's winding,
/// the rest unculled), the copies `masks` (the even ones first, `even` of them) instanced
/// by winding, or with `per_copy` one draw per copy with its own record.
fn object_draws(
    classes: &[(Range<u32>, bool); 2],
    masks: &[u32],
    even: usize,
    per_copy: bool,
) -> Vec<ObjectDraw> {
    let mut draws = Vec::new();
    let mut add = |odd: bool, instances: Range<u32>, record: Option<usize>| {
        for (vertices, culled) in classes {
            if vertices.is_empty() {
                continue;
            }
            draws.push(ObjectDraw {
                pipeline: if *culled {
                    ObjectPipeline::Culled { odd }
                } else {
                    ObjectPipeline::Unculled
                },
                vertices: vertices.clone(),
                instances: instances.clone(),
                record,
            });
        }
    };
    if per_copy {
        for (k, &mask) in masks.iter().enumerate() {
            add(reverses_winding(mask), 0..1, Some(k));
        }
    } else {
        let n_even = even as u32;
        if even > 0 {
            add(false, 0..n_even, None);
        }
        if even < masks.len() {
            add(true, n_even..masks.len() as u32, None);
        }
    }
    draws
}

/// Host bytes of a geometry copy a plan keeps: each triangle's corners and surface id.
pub(crate) fn geometry_host_bytes(g: &Geometry) -> u64 {
    g.triangles.len() as u64 * (std::mem::size_of::<[glam::Vec3; 3]>() + 4) as u64
}

impl PlannedFrame for PlannedCopies {
    /// The scene buffers of the objects before the planes and the mirrors, the frame
    /// uniform, the copies' masks (4 bytes each) and copy records (one, or one per copy with
    /// `--symmetry-draws per-copy`); on the host the geometry and the masks.
    fn memory(&self, scene: &Scene, _color_bytes_per_texel: u64) -> crate::memory::MemoryEstimate {
        use crate::memory::{buffer_bytes, uniform_arena_bytes};
        let copies = self.masks.len() as u64;
        let records = if self.settings.per_copy { copies } else { 1 };
        let mut e = SceneBuffers::memory_estimate(scene, &self.geometry);
        e.gpu(
            "the copies",
            "the scene's symmetry planes, or use --method symmetry-pruned",
            buffer_bytes(std::mem::size_of::<SymmetryFrame>() as u64)
                + buffer_bytes(4 * copies.max(1))
                + uniform_arena_bytes(records),
        );
        e.host(
            "the copies",
            "the scene's symmetry planes, or use --method symmetry-pruned",
            geometry_host_bytes(&self.geometry) + 4 * copies,
        );
        e
    }

    fn build(
        self: Box<Self>,
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
    ) -> Result<BuiltFrame, RasterError> {
        let warnings = copy_id_warning(gpu, self.settings.copy_ids, self.stats.total)
            .into_iter()
            .collect();
        let frame = CopiesFrame::new(gpu, scene, shadows, *self)?;
        Ok(BuiltFrame {
            stats: frame.stats,
            encoder: Box::new(frame),
            warnings,
            bake_ms: None,
        })
    }
}

/// Copy ids up to this value are exact in an RGBA16F target (11 significant bits).
const LARGEST_EXACT_HALF_INTEGER: usize = 2048;

/// `--copy-ids` into RGBA16F targets (wgpu's GL backend) cannot tell copies above 2047 apart.
pub(crate) fn copy_id_warning(gpu: &Gpu, copy_ids: bool, copies: usize) -> Option<String> {
    (copy_ids
        && gpu.color_format == crate::color_format::ColorFormat::Rgba16Float
        && copies > LARGEST_EXACT_HALF_INTEGER)
        .then(|| {
            format!(
                "--copy-ids writes copy bitmask + 1 into {} targets, exact only up to \
                 {LARGEST_EXACT_HALF_INTEGER}: ids of the {copies} copies above it are rounded",
                gpu.color_format
            )
        })
}

/// The symmetry methods' bind group layout: the frame (binding 0), the masks (1) and a copy
/// record at a dynamic offset (2).
fn copies_layout(gpu: &Gpu) -> wgpu::BindGroupLayout {
    let visibility = wgpu::ShaderStages::VERTEX_FRAGMENT;
    gpu.bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("symmetry"),
        entries: &[
            uniform_entry(0),
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            dynamic_uniform_entry(2, visibility),
        ],
    })
}

/// A plain uniform buffer binding (the frame record).
pub(crate) fn uniform_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A frame of `symmetry` or `symmetry-pruned` on the GPU.
struct CopiesFrame {
    scene_buffers: SceneBuffers,
    bind_group: wgpu::BindGroup,
    /// Dynamic offset of each copy record (per-copy draws), or one offset.
    record_offsets: Vec<u32>,
    draws: Vec<ObjectDraw>,
    mirrors: Range<u32>,
    pipelines: CopyPipelines,
    clear: Vec3,
    stats: FrameStats,
}

impl CopiesFrame {
    fn new(
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
        planned: PlannedCopies,
    ) -> Result<Self, RasterError> {
        use wgpu::util::DeviceExt;
        let device = &gpu.device;
        SceneBuffers::check_fits_geometry(gpu, scene, &planned.geometry)?;
        let masks_bytes = 4 * planned.masks.len().max(1) as u64;
        gpu.check_buffer("copy mask", masks_bytes, true)?;
        let scene_buffers =
            SceneBuffers::for_geometry(gpu, scene, &planned.geometry, shadows.binding());
        let settings = planned.settings;
        let clip_distances = gpu.features.contains(wgpu::Features::CLIP_DISTANCES)
            && planned.plane_count <= MAX_CLIP_DISTANCE_PLANES
            && !settings.fragment_clipping;

        let frame_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("symmetry frame"),
            contents: bytemuck::bytes_of(&planned.frame),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let mut masks = planned.masks.clone();
        if masks.is_empty() {
            masks.push(0); // a storage buffer may not be empty; no draw reads it
        }
        let masks_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("symmetry copy masks"),
            contents: bytemuck::cast_slice(&masks),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let mut arena = UniformArena::new(device);
        let record_offsets: Vec<u32> = if settings.per_copy {
            planned
                .masks
                .iter()
                .map(|&mask| {
                    arena.push(&CopyRecord {
                        mask,
                        ..Zeroable::zeroed()
                    })
                })
                .collect()
        } else {
            vec![arena.push(&CopyRecord::zeroed())]
        };
        let records = arena.buffer(device, "symmetry copy records");
        let layout = copies_layout(gpu);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("symmetry"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: frame_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: masks_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: record_binding::<CopyRecord>(&records),
                },
            ],
        });
        let pipeline_layout = pipeline_layout(gpu, "symmetry", &[&scene_buffers.layout, &layout]);
        let pipelines = CopyPipelines::new(
            gpu,
            &pipeline_layout,
            scene_buffers.textured,
            clip_distances,
            settings,
        );

        let draws = planned.draws;
        let stats = FrameStats {
            passes: 1,
            texture_renders: 0,
            draws: draws.len() + usize::from(!planned.mirrors.is_empty()) + 1,
            depth: 0,
            triangles: planned.triangles,
            paths: None,
            clipping: if clip_distances {
                Clipping::ClipDistances
            } else {
                Clipping::FragmentDiscard
            },
            depth_format: DEPTH_FORMAT,
            copies: Some(planned.stats),
        };
        Ok(CopiesFrame {
            scene_buffers,
            bind_group,
            record_offsets,
            draws,
            mirrors: planned.mirrors,
            pipelines,
            clear: if settings.copy_ids {
                Vec3::ZERO
            } else {
                scene.background
            },
            stats,
        })
    }
}

/// The copies' pipelines: closed parts culled by each copy's winding (even, odd), the rest
/// unculled, and the mirrors (drawn once, unmoved); by clip distances where the adapter has
/// them for this many planes, else by a discard per fragment.
struct CopyPipelines {
    culled_even: wgpu::RenderPipeline,
    culled_odd: wgpu::RenderPipeline,
    unculled: wgpu::RenderPipeline,
    mirror: wgpu::RenderPipeline,
}

impl CopyPipelines {
    fn new(
        gpu: &Gpu,
        pipeline_layout: &wgpu::PipelineLayout,
        textured: bool,
        clip_distances: bool,
        settings: CopySettings,
    ) -> Self {
        let module = gpu.shader_module(
            if clip_distances {
                &CLIP_DISTANCE_SHADER
            } else {
                &SHADER
            },
            textured,
        );
        let vertex = match (settings.per_copy, clip_distances) {
            (false, false) => "vs_instanced",
            (true, false) => "vs_per_copy",
            (false, true) => "vs_instanced_clipped",
            (true, true) => "vs_per_copy_clipped",
        };
        let fragment = match (settings.copy_ids, clip_distances) {
            (false, false) => "fs_object_discard",
            (true, false) => "fs_copy_id_discard",
            (false, true) => "fs_object_clipped",
            (true, true) => "fs_copy_id_clipped",
        };
        let pipeline =
            |label: &'static str, vertex: &'static str, fragment: &'static str| ScenePipeline {
                label,
                layout: pipeline_layout,
                module: &module,
                vertex,
                fragment,
                buffers: &[Some(VERTEX_LAYOUT)],
                depth_stencil: depth_state(DEPTH_FORMAT, true, NEARER, Default::default()),
                color_writes: wgpu::ColorWrites::ALL,
            };
        let culled_even = pipeline("symmetry even copies (culled)", vertex, fragment)
            .build_culling_back_faces(gpu, wgpu::FrontFace::Ccw);
        let culled_odd = pipeline("symmetry odd copies (culled)", vertex, fragment)
            .build_culling_back_faces(gpu, wgpu::FrontFace::Cw);
        let unculled = pipeline("symmetry copies (not culled)", vertex, fragment).build(gpu);
        let mirror_fragment = if settings.copy_ids {
            "fs_mirror_copy_id"
        } else {
            "fs_mirror"
        };
        let mirror_pipeline =
            pipeline("symmetry mirrors", "vs_unmoved", mirror_fragment).build(gpu);

        CopyPipelines {
            culled_even,
            culled_odd,
            unculled,
            mirror: mirror_pipeline,
        }
    }
}

impl FrameEncoder for CopiesFrame {
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let mut pass = target.begin_pass(encoder, "symmetry pass", self.clear, first_pass);
        pass.set_bind_group(0, &self.scene_buffers.bind_group, &[]);
        pass.set_bind_group(1, &self.bind_group, &[self.record_offsets[0]]);
        pass.set_vertex_buffer(0, self.scene_buffers.vertices.slice(..));
        let mut bound: Option<ObjectPipeline> = None;
        for d in &self.draws {
            if bound != Some(d.pipeline) {
                pass.set_pipeline(match d.pipeline {
                    ObjectPipeline::Culled { odd: false } => &self.pipelines.culled_even,
                    ObjectPipeline::Culled { odd: true } => &self.pipelines.culled_odd,
                    ObjectPipeline::Unculled => &self.pipelines.unculled,
                });
                bound = Some(d.pipeline);
            }
            if let Some(k) = d.record {
                pass.set_bind_group(1, &self.bind_group, &[self.record_offsets[k]]);
            }
            pass.draw(d.vertices.clone(), d.instances.clone());
        }
        if !self.mirrors.is_empty() {
            pass.set_pipeline(&self.pipelines.mirror);
            pass.draw(self.mirrors.clone(), 0..1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_meshes_are_told_from_open_ones() {
        let scene = mirrorbox_scene::load::bundled_scene("mirror_box.json");
        let parts: Vec<(String, bool)> = parts_of(&scene.geometry, false)
            .map(|(name, _, t, _)| (name, is_closed(&t)))
            .collect();
        // The floor is a quad (open); boxes and spheres are closed.
        assert!(parts.iter().any(|(_, closed)| *closed), "{parts:?}");
        assert!(parts.iter().any(|(_, closed)| !*closed), "{parts:?}");
        let quad = [
            [Vec3::ZERO, Vec3::X, Vec3::Y],
            [Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
        ];
        assert!(!is_closed(&quad));
        // A tetrahedron, consistently wound, is closed; one face flipped, it is not.
        let (a, b, c, d) = (Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z);
        let mut tetra = vec![[a, c, b], [a, b, d], [b, c, d], [c, a, d]];
        assert!(is_closed(&tetra));
        tetra[0] = [a, b, c];
        assert!(!is_closed(&tetra));
    }

    /// 16 planes through a 1 280-triangle sphere: `symmetry` would submit 2^16 copies of it
    /// (84 M triangles) and is refused while planning, naming the alternatives;
    /// `symmetry-pruned` draws only the copies whose cells hold part of the sphere.
    #[test]
    fn a_frame_of_too_many_copies_is_refused_while_planning() {
        let planes: Vec<serde_json::Value> = (0..16)
            .map(|k| {
                let a = k as f32 * 0.7;
                serde_json::json!({ "point": [0, 0, 0], "normal": [a.cos(), a.sin(), 0.3] })
            })
            .collect();
        let text = serde_json::json!({
            "camera": { "position": [0, 0, 4], "look_at": [0, 0, 0], "fov_y_deg": 50, "width": 32, "height": 18 },
            "symmetry_planes": planes,
            "objects": [ { "type": "sphere", "radius": 1, "subdivisions": 3 } ],
        });
        let scene =
            mirrorbox_scene::load::parse_scene(&text.to_string(), std::path::Path::new("s.json"))
                .unwrap();
        let plan = |name: &str| {
            let settings = crate::RenderSettings::new(crate::Method::named(name).unwrap());
            crate::plan_frame(&scene, &settings).map(|_| ())
        };
        let refused = plan("symmetry").unwrap_err();
        assert!(
            matches!(
                refused,
                PlanError::TooManyCopyTriangles { copies: 65536, .. }
            ),
            "{refused}"
        );
        assert!(refused.to_string().contains("symmetry-pruned"), "{refused}");
        plan("symmetry-pruned").unwrap();
        plan("symmetry-baked").unwrap();
    }

    #[test]
    fn the_eye_is_pulled_back_through_each_copy() {
        let planes = [Plane::from_point_normal(Vec3::ZERO, Vec3::X)];
        let (lo, hi) = (Vec3::new(1.0, -1.0, -1.0), Vec3::new(3.0, 1.0, 1.0));
        // The eye at x = −2 is outside the box; pulled back through the plane x = 0 it lies
        // at x = 2, inside: the reflected copy surrounds it.
        let eye = Vec3::new(-2.0, 0.0, 0.0);
        assert!(eye_outside_every_copy(&planes, &[0], eye, lo, hi));
        assert!(!eye_outside_every_copy(&planes, &[0, 1], eye, lo, hi));
    }
}
