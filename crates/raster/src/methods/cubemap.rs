//! `cubemap`: cube-map reflections, the other trick real-time demos ship (issue 22;
//! docs/methods.md, "Cube-map reflections").
//!
//! Every frame renders a cube map — six 90° faces from one point — per mirror at the
//! mirror's centre (keeping what lies in front of it), or one for the scene at the centre of
//! its bounds (`--cube-centre scene`). A mirror fragment shows its cube looked up by the
//! reflected view direction r: the radiance arriving at the cube's centre from direction r,
//! as if everything reflected were infinitely far away. Exact only at the centre itself;
//! anything near the mirror is displaced (parallax), which is what the method's error
//! measures. The cube's own mirrors show the previous frame's cube maps (two sets,
//! ping-pong; the recursive variant), so the reflections deepen by one per frame as with
//! `feedback` (`--history K` pre-rolls K frames; a sequence carries the cubes, which do not
//! depend on the camera). The first frame's cubes show the depth cap in their mirrors.

use crate::gpu::{Gpu, RasterError};
use crate::method::{
    Advise, BuiltFrame, FrameStats, MethodEntry, OptionKind, OptionSpec, ParamValue, PlannedFrame,
    RasterMethod, SweepAxis,
};
use crate::methods::feedback::HISTORY;
use crate::methods::recursive_texture::{
    TexturePipelines, check_mirror_textures, texture_frame_stats,
};
use crate::ping_pong::{Carried, PingPong, Source};
use crate::pipeline::{UniformArena, dynamic_uniform_entry, record_binding};
use crate::plan::PlanError;
use crate::projection::camera_projection;
use crate::shading::SceneBuffers;
use crate::targets::{RenderTarget, texture_entry};
use crate::timing::{FrameEncoder, FrameHistory};
use crate::wgsl::HostLayout;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec4};
use mirrorbox_scene::{Camera, Plane, Scene};
use std::sync::Arc;

/// Cube-map reflections (issue 22).
pub static CUBEMAP: MethodEntry = MethodEntry {
    name: "cubemap",
    help: "Cube-map reflections: a cube map per mirror (or one for the scene) rendered every frame, looked up by the reflected direction (parallax-wrong near the mirror); its mirrors show last frame's cube maps.",
    exact: false,
    depth_limited: false,
    options: crate::method_options![&CUBE_SIZE, &CUBE_CENTRE, &HISTORY],
    swept: Some(&CUBE_SIZE),
    optional_features: wgpu::Features::CLIP_DISTANCES,
    required_features: wgpu::Features::empty(),
    shaders: &[&SHADER, &CLIP_DISTANCE_SHADER],
    gpu_structs,
    configure: |p| {
        Box::new(Cubemap {
            size: p.count(&CUBE_SIZE),
            per_mirror: p.choice(&CUBE_CENTRE) == "mirror",
            history: p.count(&HISTORY),
        })
    },
    advise: Advise::Knob {
        option: &CUBE_SIZE,
        coarse: &[32, 64, 128, 256, 512, 1024],
        variants: &["history=16"],
    },
};

const ENTRY_POINTS: &str = include_str!("../../../../shaders/cubemap.wgsl");

crate::mirror_plane_shaders!("cubemap", ENTRY_POINTS, crate::wgsl::PASS_VIEW);

fn gpu_structs() -> Vec<HostLayout> {
    vec![
        crate::host_layout!(PassUniform as "Pass" { clip_from_world, eye, _pad0, plane }),
        crate::host_layout!(CubeUniform as "CubeDraw" {
            faces, centre, has_cube, face_size, _pad0, _pad1, _pad2
        }),
    ]
}

/// `--cube-size N`: texels per side of each cube face.
pub static CUBE_SIZE: OptionSpec = OptionSpec {
    name: "cube-size",
    help: "cubemap: texels per side of each cube face.",
    kind: OptionKind::Count { min: 8, max: 2048 },
    default: ParamValue::Count(256),
    sweep: Some(SweepAxis {
        default: "64,128,256,512",
        range_example: "64..66",
        list_example: "64,256,1024",
        noun: "face sizes",
    }),
    in_key: true,
};

/// `--cube-centre mirror|scene`: where the cube maps are rendered from.
pub static CUBE_CENTRE: OptionSpec = OptionSpec {
    name: "cube-centre",
    help: "cubemap: one cube per mirror at its centre (mirror), or one at the centre of the scene's bounds (scene).",
    kind: OptionKind::Choice {
        values: &["mirror", "scene"],
    },
    default: ParamValue::Choice("mirror"),
    sweep: None,
    in_key: true,
};

struct Cubemap {
    size: u32,
    per_mirror: bool,
    history: u32,
}

/// One cube map: where it is rendered from, what it keeps, and its faces' cameras.
#[derive(Clone, Debug)]
struct Cube {
    centre: Vec3,
    /// The owning mirror's plane (front kept) for a per-mirror cube.
    plane: Option<Plane>,
    /// Face k's camera, world to clip space (+X, −X, +Y, −Y, +Z, −Z).
    faces: [Mat4; 6],
}

/// The six faces' cameras at `centre`: 90° square views along ±X, ±Y, ±Z.
fn face_cameras(centre: Vec3, size: u32, exposure: f32) -> [Mat4; 6] {
    let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    axes.map(|a| {
        let up = if a.y != 0.0 { Vec3::Z } else { Vec3::Y };
        let camera = Camera {
            position: centre,
            look_at: centre + a,
            up,
            fov_y_deg: 90.0,
            width: size,
            height: size,
            exposure,
            shift_x: 0.0,
        };
        camera_projection(&camera, size, size) * camera.view()
    })
}

/// The cube maps of `scene`: one per mirror at its centre, or one at the centre of the
/// bounds of everything in the scene.
fn cubes(scene: &Scene, size: u32, per_mirror: bool) -> Vec<Cube> {
    let exposure = scene.camera.exposure;
    if per_mirror {
        scene
            .mirrors
            .iter()
            .map(|m| Cube {
                centre: m.center,
                plane: Some(m.plane()),
                faces: face_cameras(m.center, size, exposure),
            })
            .collect()
    } else {
        let (lo, hi) = scene
            .geometry
            .triangles
            .iter()
            .flatten()
            .chain(
                scene
                    .mirrors
                    .iter()
                    .flat_map(|m| m.corners())
                    .collect::<Vec<_>>()
                    .iter(),
            )
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| {
                (a.min(*p), b.max(*p))
            });
        let centre = if lo.x <= hi.x {
            0.5 * (lo + hi)
        } else {
            Vec3::ZERO
        };
        vec![Cube {
            centre,
            plane: None,
            faces: face_cameras(centre, size, exposure),
        }]
    }
}

impl RasterMethod for Cubemap {
    fn plan(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
    ) -> Result<Box<dyn PlannedFrame>, PlanError> {
        Ok(Box::new(PlannedCubes {
            cubes: cubes(scene, self.size, self.per_mirror),
            size: self.size,
            per_mirror: self.per_mirror,
            history: self.history,
            view: (width, height),
            carried: None,
        }))
    }
}

struct PlannedCubes {
    cubes: Vec<Cube>,
    size: u32,
    per_mirror: bool,
    history: u32,
    view: (u32, u32),
    carried: Option<Carried<CubeHistory>>,
}

/// One set of cube maps (six faces each).
type CubeSet = Vec<[RenderTarget; 6]>;

/// What a frame leaves for the next: its cube maps. They do not depend on the camera.
struct CubeHistory {
    cubes: Arc<CubeSet>,
    /// Face size and centre choice (another configuration starts afresh).
    config: (u32, bool),
}

impl PlannedFrame for PlannedCubes {
    /// Two sets (and a sequence's carried one) of six `--cube-size`² colour + depth faces
    /// per cube, the "no cube" 1×1 target, the scene buffers, and the uniform records: one
    /// per face pass, the main pass, one per cube and "no cube".
    fn memory(&self, scene: &Scene, color_bytes_per_texel: u64) -> crate::memory::MemoryEstimate {
        use crate::memory::{target_bytes, uniform_arena_bytes};
        let cubes = self.cubes.len() as u64;
        let sets = 2 + u64::from(self.carried.is_some());
        let face = target_bytes(self.size, self.size, color_bytes_per_texel);
        let mut e = SceneBuffers::memory_estimate(scene, &scene.geometry);
        e.gpu(
            "the cube maps",
            "--cube-size (or --cube-centre scene)",
            sets * 6 * cubes * face + target_bytes(1, 1, color_bytes_per_texel),
        );
        e.gpu(
            "the uniforms",
            "the scene's mirrors",
            uniform_arena_bytes(6 * cubes + 2 + cubes),
        );
        e
    }

    fn continue_from(&mut self, history: FrameHistory) {
        let config = (self.size, self.per_mirror);
        let cubes = self.cubes.len();
        self.carried = PingPong::carried_from(history, |h: &CubeHistory| {
            h.config == config && h.cubes.len() == cubes
        });
    }

    fn build(
        self: Box<Self>,
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
    ) -> Result<BuiltFrame, RasterError> {
        let frame = CubeFrame::new(gpu, scene, shadows, *self)?;
        Ok(BuiltFrame {
            stats: frame.stats,
            encoder: Box::new(frame),
            warnings: Vec::new(),
            bake_ms: None,
        })
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct PassUniform {
    clip_from_world: [[f32; 4]; 4],
    eye: [f32; 3],
    _pad0: f32,
    plane: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct CubeUniform {
    faces: [[[f32; 4]; 4]; 6],
    centre: [f32; 3],
    has_cube: u32,
    face_size: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

struct CubeFrame {
    scene_buffers: SceneBuffers,
    pipelines: TexturePipelines,
    pass_bind_group: wgpu::BindGroup,
    /// Per (source set, cube): the bind group of a mirror reading that cube; index 0 is "no
    /// cube" ([`CubeFrame::bind_group`]).
    bind_groups: Vec<wgpu::BindGroup>,
    own: [Arc<CubeSet>; 2],
    state: PingPong<CubeHistory>,
    /// Per cube and face, its pass uniform; then the main view's.
    face_offsets: Vec<[u32; 6]>,
    main_offset: u32,
    /// Per cube, the scene mirrors its passes draw (not those in its own plane).
    cube_mirrors: Vec<Vec<usize>>,
    /// The cube each scene mirror reads (per mirror: its own; scene: the one).
    reads: Vec<usize>,
    /// Per cube, its uniform's offset; and the "no cube" uniform's.
    cube_uniforms: Vec<u32>,
    no_cube_uniform: u32,
    all_mirrors: Vec<usize>,
    cube_count: usize,
    background: Vec3,
    config: (u32, bool),
    stats: FrameStats,
}

impl CubeFrame {
    fn new(
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
        planned: PlannedCubes,
    ) -> Result<Self, RasterError> {
        let PlannedCubes {
            cubes,
            size,
            per_mirror,
            history,
            view: (w, h),
            carried,
        } = planned;
        let state = PingPong::new(carried, history);
        let device = &gpu.device;
        let faces = 2 * 6 * cubes.len();
        check_mirror_textures(gpu, &vec![(size, size); faces])?;
        let scene_buffers = SceneBuffers::new(gpu, scene, shadows.binding());
        let own = cube_sets(gpu, cubes.len(), size);

        let (uniforms, face_offsets, main_offset, (cube_uniforms, no_cube_uniform)) =
            cube_records(gpu, scene, &cubes, size, (w, h));
        let cube_mirrors = cube_mirrors(scene, &cubes);
        let reads: Vec<usize> = (0..scene.mirrors.len())
            .map(|j| if per_mirror { j } else { 0 })
            .collect();

        let buffer = uniforms.buffer(device, "cubemap uniforms");
        let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let mut cube_entries = vec![dynamic_uniform_entry(0, stages)];
        cube_entries.extend((1..=6).map(texture_entry));
        let pipelines = TexturePipelines::with(
            gpu,
            &scene_buffers,
            [&SHADER, &CLIP_DISTANCE_SHADER],
            &cube_entries,
        );
        let pass_bind_group = pipelines.pass_bind_group::<PassUniform>(gpu, &buffer);
        let none = RenderTarget::new(gpu, "no cube", 1, 1, wgpu::TextureUsages::TEXTURE_BINDING);
        let bind_group = |faces: [&wgpu::TextureView; 6]| {
            let mut entries = vec![wgpu::BindGroupEntry {
                binding: 0,
                resource: record_binding::<CubeUniform>(&buffer),
            }];
            entries.extend(faces.iter().enumerate().map(|(k, v)| wgpu::BindGroupEntry {
                binding: k as u32 + 1,
                resource: wgpu::BindingResource::TextureView(v),
            }));
            pipelines.mirror_group(gpu, &entries)
        };
        // 0: no cube; then own set 0's cubes, own set 1's, the carried set's.
        let mut bind_groups = vec![bind_group([&none.color_view; 6])];
        for set in own.iter().chain(state.carried().map(|c| &c.cubes)) {
            for cube in set.iter() {
                bind_groups.push(bind_group(cube.each_ref().map(|t| &t.color_view)));
            }
        }

        let clipping = pipelines.clipping;

        // Six faces a cube, each drawing its cube's mirrors, then the main pass all of them.
        let stats = texture_frame_stats(
            (6 * cubes.len(), 1),
            6 * cube_mirrors.iter().map(Vec::len).sum::<usize>() + scene.mirrors.len(),
            scene_buffers.objects.len() / 3,
            (state.first_depth(), clipping),
        );
        Ok(CubeFrame {
            scene_buffers,
            pipelines,
            pass_bind_group,
            bind_groups,
            own,
            state,
            face_offsets,
            main_offset,
            cube_mirrors,
            reads,
            cube_uniforms,
            no_cube_uniform,
            all_mirrors: (0..scene.mirrors.len()).collect(),
            cube_count: cubes.len(),
            background: scene.background,
            config: (size, per_mirror),
            stats,
        })
    }

    /// The bind group and uniform offset of scene mirror `j` reading the cubes of `source`.
    fn mirror_binding(&self, source: Source, j: usize) -> (&wgpu::BindGroup, u32) {
        let cube = self.reads[j];
        let first = match source {
            Source::Nothing => return (&self.bind_groups[0], self.no_cube_uniform),
            Source::Own(i) => 1 + i * self.cube_count,
            Source::Carried => 1 + 2 * self.cube_count,
        };
        (&self.bind_groups[first + cube], self.cube_uniforms[cube])
    }

    /// One scene pass: the objects, then `mirrors` showing the cubes of `source`.
    fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        offset: u32,
        mirrors: &[usize],
        source: Source,
    ) {
        let mirrors = mirrors.iter().map(|&j| {
            let (group, offset) = self.mirror_binding(source, j);
            (j, group, offset)
        });
        self.pipelines.draw(
            pass,
            &self.scene_buffers,
            &self.pass_bind_group,
            offset,
            mirrors,
        );
    }
}

/// The uniform records of a frame: each cube face's pass, the main pass, one per cube (the
/// same for every set: the cubes do not move) and "no cube"; with their offsets.
#[allow(clippy::type_complexity)]
fn cube_records(
    gpu: &Gpu,
    scene: &Scene,
    cubes: &[Cube],
    size: u32,
    (w, h): (u32, u32),
) -> (UniformArena, Vec<[u32; 6]>, u32, (Vec<u32>, u32)) {
    let device = &gpu.device;
    let mut uniforms = UniformArena::new(device);
    let pass = |clip: Mat4, eye: Vec3, plane: Vec4| PassUniform {
        clip_from_world: clip.to_cols_array_2d(),
        eye: eye.to_array(),
        _pad0: 0.0,
        plane: plane.to_array(),
    };
    let face_offsets: Vec<[u32; 6]> = cubes
        .iter()
        .map(|c| {
            let plane = c.plane.map_or(Vec4::W, |p| p.coefficients());
            c.faces.map(|f| uniforms.push(&pass(f, c.centre, plane)))
        })
        .collect();
    let camera = scene.camera.with_size(w, h);
    let main_offset = uniforms.push(&pass(
        camera_projection(&camera, w, h) * camera.view(),
        camera.position,
        Vec4::W,
    ));
    // One uniform per cube (the same for every set: the cubes do not move), and "none".
    let cube_uniforms: Vec<u32> = cubes
        .iter()
        .map(|c| {
            uniforms.push(&CubeUniform {
                faces: c.faces.map(|f| f.to_cols_array_2d()),
                centre: c.centre.to_array(),
                has_cube: 1,
                face_size: size as f32,
                ..Zeroable::zeroed()
            })
        })
        .collect();
    let no_cube_uniform = uniforms.push(&CubeUniform {
        face_size: 1.0,
        ..Zeroable::zeroed()
    });
    (
        uniforms,
        face_offsets,
        main_offset,
        (cube_uniforms, no_cube_uniform),
    )
}

/// The two sets of this frame's cube maps, written in turn (`count` cubes of six `size`²
/// faces each).
fn cube_sets(gpu: &Gpu, count: usize, size: u32) -> [Arc<CubeSet>; 2] {
    [0, 1].map(|_| {
        Arc::new(
            (0..count)
                .map(|_| {
                    [0, 1, 2, 3, 4, 5].map(|_| {
                        RenderTarget::new(
                            gpu,
                            "cube face",
                            size,
                            size,
                            wgpu::TextureUsages::TEXTURE_BINDING,
                        )
                    })
                })
                .collect::<CubeSet>(),
        )
    })
}

/// Per cube, the scene mirrors its faces draw: all but those in its own mirror's plane.
fn cube_mirrors(scene: &Scene, cubes: &[Cube]) -> Vec<Vec<usize>> {
    cubes
        .iter()
        .map(|c| {
            (0..scene.mirrors.len())
                .filter(|&j| c.plane.is_none_or(|p| !scene.mirrors[j].lies_in(&p)))
                .collect()
        })
        .collect()
}

impl FrameEncoder for CubeFrame {
    /// Every cube's six faces into the set the frame writes (their mirrors reading the
    /// other set, or the carried one), then the main view reading the cubes just drawn.
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let (read, write) = self.state.begin_frame();
        let mut first_pass = first_pass;
        for (c, cube) in self.own[write].iter().enumerate() {
            for (k, face) in cube.iter().enumerate() {
                let mut pass = face.begin_pass_with_alpha(
                    encoder,
                    "cube face pass",
                    self.background,
                    1.0,
                    first_pass.take(),
                );
                self.draw(
                    &mut pass,
                    self.face_offsets[c][k],
                    &self.cube_mirrors[c],
                    read,
                );
            }
        }
        let mut pass = target.begin_pass_with_alpha(
            encoder,
            "main view pass",
            self.background,
            1.0,
            first_pass.take(),
        );
        self.draw(
            &mut pass,
            self.main_offset,
            &self.all_mirrors,
            Source::Own(write),
        );
    }

    crate::ping_pong_frame!();

    fn history(&self) -> Option<FrameHistory> {
        self.state.history(|i| {
            Arc::new(CubeHistory {
                cubes: self.own[i].clone(),
                config: self.config,
            })
        })
    }
}
