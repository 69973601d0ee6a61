//! `symmetry-baked`: seed 001's symmetry planes baked on the CPU — the objects split and
//! mirrored once ([`mirrorbox_scene::symmetry::split_and_mirror_with_origins`], the same exact
//! bake the tracer's truth comes from) — and the mesh drawn in one draw. The seed's advice for
//! many planes: "split and mirror the mesh whenever the configuration of planes changes … The
//! new mesh can then be rendered once."
//!
//! The bake runs while planning and is timed there: `BuiltFrame::bake_ms` (and `render`'s
//! output) reports it apart from the frame time, which covers drawing only — a renderer
//! rebakes only when the planes change. Nothing is clipped (`Clipping::None`) and nothing
//! culled: the bake's triangles are wound as seen from their front, but the mesh is drawn as
//! the tracer sees it, two-sided. `FrameStats::copies` counts the copies the bake holds a
//! triangle of (`drawn`) of the 2^p; the rest were empty. Mirrors are drawn as by `symmetry`,
//! at reflection depth 0. With `--copy-ids` each pixel shows the copy its triangle came from,
//! as the bake records it.

use crate::gpu::{Gpu, RasterError};
use crate::method::{
    Advise, BuiltFrame, Clipping, CopyCounts, FrameStats, MethodEntry, PlannedFrame, RasterMethod,
};
use crate::methods::symmetry::{
    CLIP_DISTANCE_SHADER, COPY_IDS, SHADER, SymmetryFrame, SymmetryInput, copy_id_warning,
    gpu_structs, parts_of,
};
use crate::pipeline::{BindGroupBuilder, ScenePipeline, depth_state, pipeline_layout};
use crate::plan::PlanError;
use crate::projection::NEARER;
use crate::shading::{SceneBuffers, VERTEX_LAYOUT};
use crate::symmetry_cells::copy_count;
use crate::targets::{DEPTH_FORMAT, RenderTarget};
use crate::timing::FrameEncoder;
use glam::Vec3;
use mirrorbox_scene::symmetry::split_and_mirror_with_origins;
use mirrorbox_scene::{Geometry, Scene};
use std::ops::Range;
use std::time::Instant;

/// The CPU split-and-mirror mesh, drawn once.
pub static SYMMETRY_BAKED: MethodEntry = MethodEntry {
    name: "symmetry-baked",
    help: "Seed 001's symmetry planes baked on the CPU (split and mirrored, timed apart as bake_ms), the mesh drawn once.",
    exact: true,
    depth_limited: true,
    options: crate::method_options![&COPY_IDS],
    swept: None,
    optional_features: wgpu::Features::empty(),
    required_features: wgpu::Features::empty(),
    shaders: &[&SHADER, &CLIP_DISTANCE_SHADER],
    gpu_structs,
    configure: |p| {
        Box::new(SymmetryBakedMethod {
            copy_ids: p.switch(&COPY_IDS),
        })
    },
    advise: Advise::Skip,
};

/// The typed settings of `symmetry-baked`.
struct SymmetryBakedMethod {
    copy_ids: bool,
}

impl RasterMethod for SymmetryBakedMethod {
    fn plan(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
    ) -> Result<Box<dyn PlannedFrame>, PlanError> {
        let input = SymmetryInput::of(scene);
        let mirrors: Vec<_> = parts_of(&scene.geometry, true).collect();
        let mirror_triangles: usize = mirrors.iter().map(|(_, _, t, _)| t.len()).sum();
        let budget = mirrorbox_scene::limits::MAX_TRIANGLES.saturating_sub(mirror_triangles);
        let started = Instant::now();
        let (mut geometry, origins) =
            split_and_mirror_with_origins(&input.source, &input.planes, budget)
                .map_err(|e| PlanError::Bake(e.to_string()))?;
        let bake_ms = started.elapsed().as_secs_f64() * 1e3;
        let objects = 3 * geometry.triangles.len() as u32;
        for (name, surface, triangles, uvs) in mirrors {
            geometry.push_textured_part(name, surface, triangles, uvs);
        }
        let all = 3 * geometry.triangles.len() as u32;
        let p = input.planes.len();
        let mut holds = vec![false; copy_count(p)];
        for o in &origins {
            holds[o.copy as usize] = true;
        }
        let drawn = holds.iter().filter(|&&h| h).count();
        let parts = parts_of(&geometry, false).count();
        Ok(Box::new(PlannedBake {
            frame: SymmetryFrame::new(scene, width, height, &input.planes),
            // Per vertex, the copy its triangle came from (objects first, as SceneBuffers
            // lays them out).
            copy_of_vertex: self
                .copy_ids
                .then(|| origins.iter().flat_map(|o| [o.copy; 3]).collect()),
            geometry,
            objects: 0..objects,
            mirrors: objects..all,
            copies: CopyCounts {
                planes: p,
                total: copy_count(p),
                drawn,
                pruned_empty: copy_count(p) - drawn,
                pruned_outside_view: 0,
                culled_parts: 0,
                parts,
            },
            bake_ms,
        }))
    }
}

/// The baked mesh, ready for the GPU.
struct PlannedBake {
    frame: SymmetryFrame,
    geometry: Geometry,
    copy_of_vertex: Option<Vec<u32>>,
    objects: Range<u32>,
    mirrors: Range<u32>,
    copies: CopyCounts,
    bake_ms: f64,
}

impl PlannedFrame for PlannedBake {
    /// The baked mesh's scene buffers (every copy's split triangles and the mirrors), the
    /// frame uniform and, with `--copy-ids`, one id per vertex; on the host the baked mesh.
    fn memory(&self, scene: &Scene, _color_bytes_per_texel: u64) -> crate::memory::MemoryEstimate {
        use crate::memory::buffer_bytes;
        let ids = self.copy_of_vertex.as_ref().map_or(0, |v| v.len() as u64);
        let lower = "the scene's symmetry planes, or use --method symmetry-pruned";
        let mut e = crate::memory::MemoryEstimate::new();
        e.gpu(
            "the baked mesh",
            lower,
            SceneBuffers::memory_bytes(scene, &self.geometry)
                + buffer_bytes(std::mem::size_of::<SymmetryFrame>() as u64)
                + if self.copy_of_vertex.is_some() {
                    buffer_bytes(4 * ids.max(1))
                } else {
                    0
                },
        );
        e.host(
            "the baked mesh",
            lower,
            crate::methods::symmetry::geometry_host_bytes(&self.geometry) + 4 * ids,
        );
        e
    }

    fn build(
        self: Box<Self>,
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
    ) -> Result<BuiltFrame, RasterError> {
        let bake_ms = self.bake_ms;
        let warnings = copy_id_warning(gpu, self.copy_of_vertex.is_some(), self.copies.total)
            .into_iter()
            .collect();
        let frame = BakedFrame::new(gpu, scene, shadows, *self)?;
        Ok(BuiltFrame {
            stats: frame.stats,
            encoder: Box::new(frame),
            warnings,
            bake_ms: Some(bake_ms),
        })
    }
}

struct BakedFrame {
    scene_buffers: SceneBuffers,
    bind_group: wgpu::BindGroup,
    /// `--copy-ids`: each vertex's copy (vertex buffer 1).
    copy_ids: Option<wgpu::Buffer>,
    objects: Range<u32>,
    mirrors: Range<u32>,
    object_pipeline: wgpu::RenderPipeline,
    mirror_pipeline: wgpu::RenderPipeline,
    clear: Vec3,
    stats: FrameStats,
}

impl BakedFrame {
    fn new(
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
        planned: PlannedBake,
    ) -> Result<Self, RasterError> {
        use wgpu::util::DeviceExt;
        let device = &gpu.device;
        SceneBuffers::check_fits_geometry(gpu, scene, &planned.geometry)?;
        let scene_buffers =
            SceneBuffers::for_geometry(gpu, scene, &planned.geometry, shadows.binding());
        let frame_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("symmetry-baked frame"),
            contents: bytemuck::bytes_of(&planned.frame),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let (layout, bind_group) = BindGroupBuilder::new("symmetry-baked")
            .buffer(
                wgpu::ShaderStages::VERTEX_FRAGMENT,
                wgpu::BufferBindingType::Uniform,
                &frame_buffer,
            )
            .build(gpu);
        let copy_ids = planned.copy_of_vertex.as_ref().map(|ids| {
            let mut ids = ids.clone();
            if ids.is_empty() {
                ids.push(0); // a buffer may not be empty; no draw reads it
            }
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("symmetry-baked copy ids"),
                contents: bytemuck::cast_slice(&ids),
                usage: wgpu::BufferUsages::VERTEX,
            })
        });
        let pipeline_layout =
            pipeline_layout(gpu, "symmetry-baked", &[&scene_buffers.layout, &layout]);
        let module = gpu.shader_module(&SHADER, scene_buffers.textured);
        const COPY_ID_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
            array_stride: 4,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![3 => Uint32],
        };
        let pipeline = |label: &str, vertex: &str, fragment: &str, buffers: &[Option<_>]| {
            ScenePipeline {
                label,
                layout: &pipeline_layout,
                module: &module,
                vertex,
                fragment,
                buffers,
                depth_stencil: depth_state(DEPTH_FORMAT, true, NEARER, Default::default()),
                color_writes: wgpu::ColorWrites::ALL,
            }
            .build(gpu)
        };
        let (object_pipeline, mirror_pipeline) = if copy_ids.is_some() {
            (
                pipeline(
                    "symmetry-baked copy ids",
                    "vs_baked_copy_id",
                    "fs_baked_copy_id",
                    &[Some(VERTEX_LAYOUT), Some(COPY_ID_LAYOUT)],
                ),
                pipeline(
                    "symmetry-baked mirrors",
                    "vs_unmoved",
                    "fs_mirror_copy_id",
                    &[Some(VERTEX_LAYOUT)],
                ),
            )
        } else {
            (
                pipeline(
                    "symmetry-baked objects",
                    "vs_unmoved",
                    "fs_unmoved_object",
                    &[Some(VERTEX_LAYOUT)],
                ),
                pipeline(
                    "symmetry-baked mirrors",
                    "vs_unmoved",
                    "fs_mirror",
                    &[Some(VERTEX_LAYOUT)],
                ),
            )
        };
        let stats = FrameStats {
            passes: 1,
            texture_renders: 0,
            draws: usize::from(!planned.objects.is_empty())
                + usize::from(!planned.mirrors.is_empty())
                + 1,
            depth: 0,
            triangles: (planned.mirrors.end / 3) as usize,
            paths: None,
            clipping: Clipping::None,
            depth_format: DEPTH_FORMAT,
            copies: Some(planned.copies),
        };
        Ok(BakedFrame {
            scene_buffers,
            bind_group,
            copy_ids,
            objects: planned.objects,
            mirrors: planned.mirrors,
            object_pipeline,
            mirror_pipeline,
            clear: if planned.copy_of_vertex.is_some() {
                Vec3::ZERO
            } else {
                scene.background
            },
            stats,
        })
    }
}

impl FrameEncoder for BakedFrame {
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let mut pass = target.begin_pass(encoder, "symmetry-baked pass", self.clear, first_pass);
        pass.set_bind_group(0, &self.scene_buffers.bind_group, &[]);
        pass.set_bind_group(1, &self.bind_group, &[]);
        pass.set_vertex_buffer(0, self.scene_buffers.vertices.slice(..));
        if let Some(ids) = &self.copy_ids {
            pass.set_vertex_buffer(1, ids.slice(..));
        }
        if !self.objects.is_empty() {
            pass.set_pipeline(&self.object_pipeline);
            pass.draw(self.objects.clone(), 0..1);
        }
        if !self.mirrors.is_empty() {
            pass.set_pipeline(&self.mirror_pipeline);
            pass.draw(self.mirrors.clone(), 0..1);
        }
    }
}
