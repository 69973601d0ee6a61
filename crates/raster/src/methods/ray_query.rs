//! `ray-query`: every mirror pixel follows its reflection chain with ray queries — what
//! engines ship as hardware ray-traced reflections (Unreal Lumen's hit lighting, Unity HDRP's
//! recursive rendering), here exact to `--depth`. Entry points: `shaders/ray_query.wgsl`.
//!
//! The scene is rasterized once for primary visibility (a depth pre-pass, then one shaded
//! fragment per pixel, in one render pass); a fragment on a mirror's front follows the chain
//! from there with ray queries against an acceleration structure — a BLAS per mesh (each part
//! of the scene's geometry), a TLAS of their instances; a ray skips the mirror it leaves, as
//! the tracer does, by restarting past a hit on it — to `--depth`
//! reflections or `--min-attenuation`, shading every hit with the contract
//! (`docs/shading.md`). Shadow legs, where the scene asks for shadows, are ray queries too:
//! no shadow map is drawn. Uneven mirrors reflect about their perturbed normal at every
//! depth, as the tracer does: the one raster-side method exact there.
//!
//! With `--primary rays` the first surface is found by a primary ray per pixel of the render
//! target instead (the camera's ray through its centre, the tracer's sub-pixel grid at
//! `--ssaa`): the tracer's `whitted` on the GPU, what `trace --device gpu` runs.
//!
//! The acceleration structures are built once per built frame and the build is timed apart
//! (wall clock, reported as the frame's one-off build, `bake_ms`): the scenes are static, and
//! an engine rebuilds a BLAS only when its mesh changes. Frames time the tracing.

use crate::exact_options::{DEPTH, MIN_ATTENUATION};
use crate::gpu::{Gpu, RasterError};
use crate::method::{
    Advise, BuiltFrame, Clipping, FrameStats, MethodEntry, OptionKind, OptionSpec, ParamValue,
    PlannedFrame, RasterMethod,
};
use crate::pipeline::{BindGroupBuilder, ScenePipeline, depth_state, pipeline_layout};
use crate::plan::PlanError;
use crate::projection::NEARER;
use crate::shading::{OnePass, OnePassFrame, SceneBuffers, VERTEX_LAYOUT};
use crate::targets::DEPTH_FORMAT;
use crate::wgsl::{HostLayout, WgslSource};
use bytemuck::{Pod, Zeroable};
use mirrorbox_scene::Scene;
use wgpu::util::DeviceExt;

/// Exact by ray queries: raster primary visibility, every reflection chain traced on the GPU.
pub static RAY_QUERY: MethodEntry = MethodEntry {
    name: "ray-query",
    help: "Exact by ray queries: the scene rasterized once, each mirror pixel's reflection chain \
           traced on the GPU (BLAS per mesh, TLAS), shadows traced where the scene asks; \
           needs EXPERIMENTAL_RAY_QUERY.",
    exact: true,
    depth_limited: true,
    options: crate::method_options![&DEPTH, &MIN_ATTENUATION, &PRIMARY],
    swept: Some(&DEPTH),
    optional_features: wgpu::Features::empty(),
    required_features: wgpu::Features::EXPERIMENTAL_RAY_QUERY,
    shaders: &[&SHADER],
    gpu_structs,
    configure: |p| {
        Box::new(RayQuery {
            settings: RayQuerySettings {
                max_depth: p.count(&DEPTH),
                min_attenuation: p.real(&MIN_ATTENUATION),
                primary_rays: p.choice(&PRIMARY) == "rays",
            },
            shadow_maps: crate::lighting::wants_shadow_maps(p),
        })
    },
    advise: Advise::Knob {
        option: &DEPTH,
        coarse: crate::exact_options::DEPTHS_COARSE,
        variants: &[""],
    },
};

/// `--primary raster|rays`: how the first surface of each pixel is found.
pub static PRIMARY: OptionSpec = OptionSpec {
    name: "primary",
    help: "ray-query: the first surface of each pixel by rasterization (raster, the method), or \
           by a primary ray per sub-pixel (rays: the tracer's whitted on the GPU, what trace \
           --device gpu runs).",
    kind: OptionKind::Choice {
        values: &["raster", "rays"],
    },
    default: ParamValue::Choice("raster"),
    sweep: None,
    in_key: true,
};

static SHADER: WgslSource = WgslSource {
    label: "ray query",
    enable: &["wgpu_ray_query"],
    parts: &[
        crate::wgsl::SHADING_CONTRACT,
        crate::wgsl::SCENE_VERTEX,
        crate::camera_rays::WGSL,
        include_str!("../../../../shaders/ray_query.wgsl"),
    ],
};

fn gpu_structs() -> Vec<HostLayout> {
    vec![
        crate::host_layout!(Params as "RayQueryParams" {
            camera, max_depth, min_attenuation, shadows, _pad
        }),
        crate::camera_rays::CameraRays::layout(),
        crate::host_layout!(TriangleRecord as "TriangleRecord" {
            normal, surface, offset, _pad0, uv0, uv1, uv2
        }),
    ]
}

/// What a ray-query frame follows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayQuerySettings {
    /// Most mirror reflections a path follows (`--depth`; the tracer's `--max-depth`).
    pub max_depth: u32,
    /// A path stops where the largest channel of its attenuation would fall below this.
    pub min_attenuation: f32,
    /// Primary rays instead of rasterized visibility (the GPU truth).
    pub primary_rays: bool,
}

struct RayQuery {
    settings: RayQuerySettings,
    /// `--shadows map` was asked for: refused (this method traces its shadow legs).
    shadow_maps: bool,
}

impl RasterMethod for RayQuery {
    fn plan(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
    ) -> Result<Box<dyn PlannedFrame>, PlanError> {
        if self.shadow_maps {
            return Err(PlanError::Setting(
                mirrorbox_scene::limits::SettingError::new(
                    "--shadows",
                    "none for ray-query (it traces every shadow leg by ray query wherever the \
                 scene's lighting.shadows asks; no shadow map is needed)",
                    "map",
                ),
            ));
        }
        Ok(Box::new(PlannedRayQuery {
            settings: self.settings,
            width,
            height,
            meshes: meshes(scene),
        }))
    }
}

/// The meshes of `scene` that get a BLAS each: its non-empty parts' triangle ranges.
fn meshes(scene: &Scene) -> Vec<std::ops::Range<usize>> {
    scene
        .geometry
        .parts
        .iter()
        .filter(|p| !p.triangles.is_empty())
        .map(|p| p.triangles.clone())
        .collect()
}

/// Bytes a device's acceleration structures are assumed to take per triangle, build scratch
/// included (an upper bound for the estimate; drivers do not say before building).
const ACCELERATION_BYTES_PER_TRIANGLE: u64 = 512;

/// The memory estimate's name for the acceleration structures: wgpu's counters do not include
/// them, so the memory test holds the rest of the estimate to the counters.
pub const ACCELERATION_STRUCTURES: &str = "the acceleration structures (not in wgpu's counters)";

struct PlannedRayQuery {
    settings: RayQuerySettings,
    width: u32,
    height: u32,
    meshes: Vec<std::ops::Range<usize>>,
}

impl PlannedFrame for PlannedRayQuery {
    /// The scene buffers, a depth target at the render size, the BLAS inputs (36 bytes a
    /// triangle), the triangle records (32), the acceleration structures
    /// ([`ACCELERATION_BYTES_PER_TRIANGLE`]) and the parameters.
    fn memory(&self, scene: &Scene, _color_bytes_per_texel: u64) -> crate::memory::MemoryEstimate {
        use crate::memory::{DEPTH_BYTES, buffer_bytes, texture_bytes};
        let triangles = scene.geometry.triangles.len().max(1) as u64;
        let mut e = SceneBuffers::memory_estimate(scene, &scene.geometry);
        e.gpu(
            "the depth target",
            "the image size (--width/--height) or --ssaa",
            texture_bytes(self.width, self.height, DEPTH_BYTES),
        );
        e.gpu(
            "the BLAS inputs and triangle records",
            "the scene's triangles",
            buffer_bytes(36 * triangles)
                + buffer_bytes(std::mem::size_of::<TriangleRecord>() as u64 * triangles)
                + buffer_bytes(std::mem::size_of::<Params>() as u64),
        );
        e.gpu(
            ACCELERATION_STRUCTURES,
            "the scene's triangles",
            ACCELERATION_BYTES_PER_TRIANGLE * triangles,
        );
        e
    }

    fn build(
        self: Box<Self>,
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
    ) -> Result<BuiltFrame, RasterError> {
        let frame = RayQueryFrame::new(gpu, scene, shadows, &self)?;
        Ok(BuiltFrame {
            stats: frame.stats,
            bake_ms: Some(frame.build_ms),
            encoder: Box::new(frame),
            warnings: Vec::new(),
        })
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Params {
    camera: crate::camera_rays::CameraRays,
    max_depth: u32,
    min_attenuation: f32,
    shadows: u32,
    _pad: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct TriangleRecord {
    normal: [f32; 3],
    surface: u32,
    offset: f32,
    _pad0: u32,
    /// The corners' texture coordinates (a textured surface's lookup at a traced hit).
    uv0: [f32; 2],
    uv1: [f32; 2],
    uv2: [f32; 2],
}

struct RayQueryFrame {
    scene_buffers: SceneBuffers,
    /// Kept alive: the bind group refers to the TLAS, which refers to the BLASes.
    _blas: Vec<wgpu::Blas>,
    _tlas: wgpu::Tlas,
    bind_group: wgpu::BindGroup,
    depth: wgpu::TextureView,
    pipelines: Pipelines,
    settings: RayQuerySettings,
    /// Draw ranges of every mesh (objects, then mirrors) in the scene's vertex buffer.
    draws: Vec<std::ops::Range<u32>>,
    background: glam::Vec3,
    build_ms: f64,
    stats: FrameStats,
}

impl RayQueryFrame {
    fn new(
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
        planned: &PlannedRayQuery,
    ) -> Result<Self, RasterError> {
        let device = &gpu.device;
        let g = &scene.geometry;
        let meshes = &planned.meshes;
        check_limits(gpu, meshes)?;
        let scene_buffers = SceneBuffers::new(gpu, scene, shadows.binding());
        let (positions, records) = triangle_records(g);
        let position_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("ray query BLAS vertices"),
            contents: bytemuck::cast_slice(&positions),
            usage: wgpu::BufferUsages::BLAS_INPUT,
        });
        let record_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("ray query triangles"),
            contents: bytemuck::cast_slice(&records),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let (blas, tlas, build_ms) = acceleration_structures(gpu, meshes, &position_buffer)?;
        let (w, h) = (planned.width, planned.height);
        let params = Params {
            camera: crate::camera_rays::CameraRays::new(&scene.camera, w, h),
            max_depth: planned.settings.max_depth,
            min_attenuation: planned.settings.min_attenuation,
            shadows: u32::from(scene.lighting.shadows),
            _pad: 0,
        };
        let params_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("ray query parameters"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let (layout, bind_group) = BindGroupBuilder::new("ray query")
            .binding(
                stages,
                wgpu::BindingType::AccelerationStructure {
                    vertex_return: false,
                },
                tlas.as_binding(),
            )
            .storage(stages, &record_buffer)
            .buffer(stages, wgpu::BufferBindingType::Uniform, &params_buffer)
            .build(gpu);
        let pipeline_layout = pipeline_layout(gpu, "ray query", &[&scene_buffers.layout, &layout]);
        let pipelines = Pipelines::new(gpu, &pipeline_layout, scene_buffers.textured);
        let depth = crate::targets::texture_2d(
            device,
            "ray query depth",
            w,
            h,
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
        let draws = scene_buffers.draw_ranges();
        let triangles = g.triangles.len();
        let stats = FrameStats {
            passes: 1,
            texture_renders: 0,
            draws: if planned.settings.primary_rays {
                2
            } else {
                2 * draws.len() + 1
            },
            depth: planned.settings.max_depth as usize,
            triangles: if planned.settings.primary_rays {
                1
            } else {
                2 * triangles
            },
            paths: None,
            clipping: Clipping::None,
            depth_format: DEPTH_FORMAT,
            copies: None,
        };
        gpu.check()?;
        Ok(RayQueryFrame {
            scene_buffers,
            _blas: blas,
            _tlas: tlas,
            bind_group,
            depth,
            pipelines,
            settings: planned.settings,
            draws,
            background: scene.background,
            build_ms,
            stats,
        })
    }
}

/// Refuses a scene past the device's acceleration-structure limits, naming them.
fn check_limits(gpu: &Gpu, meshes: &[std::ops::Range<usize>]) -> Result<(), RasterError> {
    let limits = gpu.device.limits();
    let too_many = |what: &str, needed: usize, limit: u32| RasterError::ExceedsDevice {
        what: what.into(),
        needed: needed.to_string(),
        limit: limit.to_string(),
        adapter: gpu.report.name.clone(),
        advice: "; use a scene with fewer meshes or triangles",
    };
    if meshes.len() > limits.max_tlas_instance_count as usize {
        return Err(too_many(
            "TLAS instances (one per mesh)",
            meshes.len(),
            limits.max_tlas_instance_count,
        ));
    }
    if let Some(big) = meshes.iter().map(|r| r.len()).max()
        && big > limits.max_blas_primitive_count as usize
    {
        return Err(too_many(
            "triangles in one BLAS",
            big,
            limits.max_blas_primitive_count,
        ));
    }
    Ok(())
}

/// Every triangle's corners (the BLAS input) and its record (what a hit shades), at least one
/// (a buffer may not be empty).
fn triangle_records(g: &mirrorbox_scene::Geometry) -> (Vec<[f32; 3]>, Vec<TriangleRecord>) {
    let mut positions: Vec<[f32; 3]> = Vec::with_capacity(3 * g.triangles.len().max(1));
    let mut records = Vec::with_capacity(g.triangles.len().max(1));
    for (i, t) in g.triangles.iter().enumerate() {
        positions.extend(t.map(|p| p.to_array()));
        let n = g.face_normal(i);
        records.push(TriangleRecord {
            normal: n.to_array(),
            surface: g.surface_of[i],
            offset: n.dot(t[0]),
            uv0: g.uvs[i][0].to_array(),
            uv1: g.uvs[i][1].to_array(),
            uv2: g.uvs[i][2].to_array(),
            ..Zeroable::zeroed()
        });
    }
    if positions.is_empty() {
        positions.push([0.0; 3]);
        records.push(Zeroable::zeroed());
    }
    (positions, records)
}

/// One BLAS per mesh and the TLAS over them, built once (timed apart from the frames: the
/// build's milliseconds are returned).
fn acceleration_structures(
    gpu: &Gpu,
    meshes: &[std::ops::Range<usize>],
    position_buffer: &wgpu::Buffer,
) -> Result<(Vec<wgpu::Blas>, wgpu::Tlas, f64), RasterError> {
    let device = &gpu.device;
    let sizes: Vec<wgpu::BlasTriangleGeometrySizeDescriptor> = meshes
        .iter()
        .map(|range| wgpu::BlasTriangleGeometrySizeDescriptor {
            vertex_format: wgpu::VertexFormat::Float32x3,
            vertex_count: 3 * range.len() as u32,
            index_format: None,
            index_count: None,
            // Opaque: no candidate comes to the shader (docs/ray-query.md).
            flags: wgpu::AccelerationStructureGeometryFlags::OPAQUE,
        })
        .collect();
    let blas: Vec<wgpu::Blas> = sizes
        .iter()
        .map(|size| {
            device.create_blas(
                &wgpu::CreateBlasDescriptor {
                    label: Some("ray query mesh"),
                    flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
                    update_mode: wgpu::AccelerationStructureUpdateMode::Build,
                },
                wgpu::BlasGeometrySizeDescriptors::Triangles {
                    descriptors: vec![size.clone()],
                },
            )
        })
        .collect();
    let mut tlas = device.create_tlas(&wgpu::CreateTlasDescriptor {
        label: Some("ray query scene"),
        max_instances: meshes.len().max(1) as u32,
        flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
        update_mode: wgpu::AccelerationStructureUpdateMode::Build,
    });
    const IDENTITY: [f32; 12] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    for (k, (range, b)) in meshes.iter().zip(&blas).enumerate() {
        // Custom data: the mesh's first triangle, so that a hit's triangle is it plus the
        // primitive index (24 bits: the scene limit of 4 M triangles fits).
        tlas[k] = Some(wgpu::TlasInstance::new(
            b,
            IDENTITY,
            range.start as u32,
            0xff,
        ));
    }
    // Build once, timed apart from the frames.
    let entries: Vec<wgpu::BlasBuildEntry> = meshes
        .iter()
        .zip(&blas)
        .zip(&sizes)
        .map(|((range, b), size)| wgpu::BlasBuildEntry {
            blas: b,
            geometry: wgpu::BlasGeometries::TriangleGeometries(vec![wgpu::BlasTriangleGeometry {
                size,
                vertex_buffer: position_buffer,
                first_vertex: 3 * range.start as u32,
                vertex_stride: 12,
                index_buffer: None,
                first_index: None,
                transform_buffer: None,
                transform_buffer_offset: None,
            }]),
        })
        .collect();
    gpu.wait()?;
    let start = std::time::Instant::now();
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("ray query acceleration structures"),
    });
    encoder.build_acceleration_structures(entries.iter(), std::iter::once(&tlas));
    gpu.queue.submit([encoder.finish()]);
    gpu.wait()?;
    let build_ms = start.elapsed().as_secs_f64() * 1e3;
    drop(entries);

    Ok((blas, tlas, build_ms))
}

/// The pipelines: the depth pre-pass and the shading pass of rasterized primary visibility,
/// and the full-screen pass of primary rays.
struct Pipelines {
    depth_prepass: wgpu::RenderPipeline,
    shade: wgpu::RenderPipeline,
    primary_rays: wgpu::RenderPipeline,
}

impl Pipelines {
    fn new(gpu: &Gpu, pipeline_layout: &wgpu::PipelineLayout, textured: bool) -> Self {
        let module = gpu.shader_module(&SHADER, textured);
        let scene_pipeline = |label, vertex, fragment, write, compare, colour| {
            let buffers: &[Option<wgpu::VertexBufferLayout>] = if vertex == "vs_main" {
                &[Some(VERTEX_LAYOUT)]
            } else {
                &[]
            };
            ScenePipeline {
                label,
                layout: pipeline_layout,
                module: &module,
                vertex,
                fragment,
                buffers,
                depth_stencil: depth_state(
                    DEPTH_FORMAT,
                    write,
                    compare,
                    wgpu::StencilState::default(),
                ),
                color_writes: if colour {
                    wgpu::ColorWrites::ALL
                } else {
                    wgpu::ColorWrites::empty()
                },
            }
            .build(gpu)
        };
        use wgpu::CompareFunction as C;
        let depth_prepass = scene_pipeline(
            "ray query depth",
            "vs_main",
            "fs_depth",
            true,
            NEARER,
            false,
        );
        // The pre-pass's depth is met exactly (invariant positions): one fragment per pixel.
        let shade = scene_pipeline(
            "ray query shade",
            "vs_main",
            "fs_main",
            false,
            C::Equal,
            true,
        );
        let primary_rays = scene_pipeline(
            "ray query primary rays",
            "vs_fullscreen",
            "fs_primary_rays",
            false,
            C::Always,
            true,
        );
        Pipelines {
            depth_prepass,
            shade,
            primary_rays,
        }
    }
}

impl OnePassFrame for RayQueryFrame {
    fn pass(&self) -> OnePass<'_> {
        OnePass {
            scene: &self.scene_buffers,
            label: "ray query pass",
            clear: self.background,
            depth: &self.depth,
            stencil: None,
            group1: (&self.bind_group, &[]),
        }
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.settings.primary_rays {
            pass.set_pipeline(&self.pipelines.primary_rays);
            pass.draw(0..3, 0..1);
            return;
        }
        pass.set_vertex_buffer(0, self.scene_buffers.vertices.slice(..));
        for pipeline in [&self.pipelines.depth_prepass, &self.pipelines.shade] {
            pass.set_pipeline(pipeline);
            for r in &self.draws {
                pass.draw(r.clone(), 0..1);
            }
        }
    }
}

/// Most reflections the GPU truth follows: `--depth`'s bound.
pub const MAX_GPU_TRUTH_DEPTH: u32 = 4096;

/// The tracer's `whitted` on the GPU (`trace --device gpu`): `ray-query --primary rays` at
/// `--ssaa per_axis` (the tracer's `per_axis × per_axis` sub-pixel grid), following at most
/// `max_depth` reflections (capped at [`MAX_GPU_TRUTH_DEPTH`]) down to `min_throughput`.
pub fn gpu_truth_settings(
    per_axis: u32,
    max_depth: u32,
    min_throughput: f32,
) -> Result<crate::RenderSettings, crate::method::ParamError> {
    let method = crate::Method::named(RAY_QUERY.name)?
        .with(&PRIMARY, ParamValue::Choice("rays"))?
        .with(
            &DEPTH,
            ParamValue::Count(max_depth.min(MAX_GPU_TRUTH_DEPTH)),
        )?
        .with(&MIN_ATTENUATION, ParamValue::Real(min_throughput))?;
    Ok(crate::RenderSettings {
        ssaa: per_axis,
        frames: 1,
        warmup: 0,
        ..crate::RenderSettings::new(method)
    })
}
