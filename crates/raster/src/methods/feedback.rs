//! `feedback`: previous-frame feedback, the infinity-mirror trick real-time demos ship
//! (issue 22; docs/methods.md, "Previous-frame feedback").
//!
//! Each frame renders one texture per mirror, from that mirror's camera (seed 002: the view
//! that first sees the mirror composed with its reflection, [`crate::plan::feedback_cameras`]),
//! and the mirrors inside that view are textured with the *previous frame's* textures (two
//! sets, ping-pong); the main pass applies this frame's. A mirror looks a previous texture up
//! where the texture's own camera saw the fragment (projective texturing), so a texture
//! rendered for one viewpoint is reused from another: one scene pass per mirror, yet every
//! frame adds one reflection to the row, and for a still camera the row converges to the
//! full depth — with the parallax of the reused viewpoints in the deep reflections, and,
//! under motion, the lag of textures drawn for where the camera was.
//!
//! Frame 0 has no previous textures: the mirrors seen in a mirror show the depth cap (the
//! scene's `terminal`), like the exact methods at `--depth 1`. `--history K` draws K frames
//! from the same view first (a still camera), so the frame shown holds K + 1 reflections;
//! every timed frame redraws that frame from the same state. In a sequence
//! ([`crate::render_planned_after`]) and in `mirrorbox view` the state carries from frame to
//! frame, across camera moves, as in an engine.

use crate::gpu::{Gpu, RasterError};
use crate::method::{
    Advise, BuiltFrame, FrameStats, MethodEntry, OptionKind, OptionSpec, ParamValue, PlannedFrame,
    RasterMethod, SweepAxis,
};
use crate::methods::recursive_texture::{
    MirrorUniform, SHADERS, ScreenSpace, TexturePipelines, check_mirror_textures, gpu_structs,
    texture_frame_stats,
};
use crate::ping_pong::{Carried, PingPong, Source};
use crate::pipeline::UniformArena;
use crate::plan::{MirrorCamera, PlanError, Rect};
use crate::shading::SceneBuffers;
use crate::targets::RenderTarget;
use crate::timing::{FrameEncoder, FrameHistory};
use bytemuck::Zeroable;
use glam::{Mat4, Vec3, Vec4};
use mirrorbox_scene::Scene;
use std::sync::Arc;

/// Previous-frame feedback (issue 22): one texture per mirror per frame.
pub static FEEDBACK: MethodEntry = MethodEntry {
    name: "feedback",
    help: "Previous-frame feedback: one texture per mirror per frame from its mirror camera, the mirrors inside it textured with last frame's (one more reflection each frame).",
    exact: false,
    depth_limited: true,
    options: crate::method_options![&HISTORY],
    swept: Some(&HISTORY),
    optional_features: wgpu::Features::CLIP_DISTANCES,
    required_features: wgpu::Features::empty(),
    shaders: SHADERS,
    gpu_structs,
    configure: |p| {
        Box::new(Feedback {
            history: p.count(&HISTORY),
        })
    },
    advise: Advise::Fixed(&["history=16"]),
};

/// `--history K`: frames drawn from the same view before the one shown.
pub static HISTORY: OptionSpec = OptionSpec {
    name: "history",
    help: "feedback, cubemap: frames drawn from the same (still) view before the one shown; frame K shows K + 1 reflections.",
    kind: OptionKind::Count { min: 0, max: 1024 },
    default: ParamValue::Count(0),
    sweep: Some(SweepAxis {
        default: "0..8",
        range_example: "0..8",
        list_example: "0,1,4,16",
        noun: "frame counts",
    }),
    in_key: true,
};

struct Feedback {
    history: u32,
}

impl RasterMethod for Feedback {
    fn plan(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
    ) -> Result<Box<dyn PlannedFrame>, PlanError> {
        let (projection, cameras) = crate::plan::feedback_cameras(scene, width, height);
        Ok(Box::new(PlannedFeedback {
            screen: ScreenSpace {
                projection,
                width,
                height,
            },
            cameras,
            history: self.history,
            carried: None,
        }))
    }
}

struct PlannedFeedback {
    screen: ScreenSpace,
    cameras: Vec<MirrorCamera>,
    history: u32,
    carried: Option<Carried<FeedbackHistory>>,
}

/// One texture of a set: which mirror, the screen region it covers, and the camera it was
/// rendered from (world to the whole screen's clip space), which reads it back.
#[derive(Clone, Copy, Debug)]
struct TextureCamera {
    mirror: usize,
    region: Rect,
    screen_from_world: Mat4,
}

/// What a frame leaves for the next: the textures it rendered and their cameras.
struct FeedbackHistory {
    textures: Arc<Vec<RenderTarget>>,
    cameras: Arc<Vec<TextureCamera>>,
    /// The render size they were drawn at (another size starts afresh).
    size: (u32, u32),
}

impl PlannedFrame for PlannedFeedback {
    /// Two sets of one colour + depth target per mirror camera (its footprint), the carried
    /// set a sequence's previous frame left, the "no texture" 1×1 target, the scene buffers,
    /// and the uniform records: one per camera pass and the main pass, "no texture", and a
    /// mirror draw per (read source, camera pass, mirror) and per (set, mirror) in the main
    /// pass.
    fn memory(&self, scene: &Scene, color_bytes_per_texel: u64) -> crate::memory::MemoryEstimate {
        use crate::memory::{target_bytes, uniform_arena_bytes};
        let target = |w, h| target_bytes(w, h, color_bytes_per_texel);
        let set: u64 = self
            .cameras
            .iter()
            .map(|c| target(c.footprint.w, c.footprint.h))
            .sum();
        let carried: u64 = self.carried.as_ref().map_or(0, |c| {
            c.history
                .textures
                .iter()
                .map(|t| target(t.width, t.height))
                .sum()
        });
        let (cameras, mirrors) = (self.cameras.len() as u64, scene.mirrors.len() as u64);
        let records = cameras + 2 + 4 * cameras * mirrors + 2 * mirrors;
        let mut e = SceneBuffers::memory_estimate(scene, &scene.geometry);
        e.gpu(
            "the mirror textures",
            "the image size (--width/--height, --ssaa)",
            2 * set + carried + target(1, 1),
        );
        e.gpu(
            "the uniforms",
            "the scene's mirrors",
            uniform_arena_bytes(records),
        );
        e
    }

    fn continue_from(&mut self, history: FrameHistory) {
        let size = (self.screen.width, self.screen.height);
        self.carried = PingPong::carried_from(history, |h: &FeedbackHistory| h.size == size);
    }

    fn build(
        self: Box<Self>,
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
    ) -> Result<BuiltFrame, RasterError> {
        let frame = FeedbackFrame::new(gpu, scene, shadows, *self)?;
        Ok(BuiltFrame {
            stats: frame.stats,
            encoder: Box::new(frame),
            warnings: Vec::new(),
            bake_ms: None,
        })
    }
}

/// One mirror draw of a pass.
#[derive(Clone, Copy)]
struct Draw {
    mirror: usize,
    bind_group: usize,
    offset: u32,
}

struct FeedbackFrame {
    scene_buffers: SceneBuffers,
    pipelines: TexturePipelines,
    pass_bind_group: wgpu::BindGroup,
    bind_groups: Vec<wgpu::BindGroup>,
    /// This view's two texture sets (one per camera each).
    own: [Arc<Vec<RenderTarget>>; 2],
    cameras: Arc<Vec<TextureCamera>>,
    state: PingPong<FeedbackHistory>,
    /// Per read source ([`source_index`]), each camera pass's mirror draws.
    camera_draws: [Vec<Vec<Draw>>; 4],
    camera_offsets: Vec<u32>,
    /// The main pass's draws applying own set 0 or 1.
    main_draws: [Vec<Draw>; 2],
    main_offset: u32,
    background: Vec3,
    size: (u32, u32),
    stats: FrameStats,
}

impl FeedbackFrame {
    fn new(
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
        planned: PlannedFeedback,
    ) -> Result<Self, RasterError> {
        let PlannedFeedback {
            screen,
            cameras: mirror_cameras,
            history,
            carried,
        } = planned;
        let (w, h) = (screen.width, screen.height);
        let state = PingPong::new(carried, history);
        let device = &gpu.device;
        let scene_buffers = SceneBuffers::new(gpu, scene, shadows.binding());
        let cameras: Vec<TextureCamera> = mirror_cameras
            .iter()
            .map(|c| TextureCamera {
                mirror: c.mirror,
                region: c.footprint,
                screen_from_world: screen.projection * c.view.view,
            })
            .collect();
        let sizes: Vec<(u32, u32)> = cameras
            .iter()
            .flat_map(|c| [(c.region.w, c.region.h); 2])
            .collect();
        check_mirror_textures(gpu, &sizes)?;
        let own = texture_sets(gpu, &cameras);

        let mut uniforms = UniformArena::new(device);
        let camera_offsets: Vec<u32> = mirror_cameras
            .iter()
            .map(|c| {
                let size = (c.footprint.w, c.footprint.h);
                let u = screen.pass_uniform(
                    c.view.view,
                    c.view.eye(),
                    c.footprint,
                    size,
                    c.plane.coefficients(),
                );
                uniforms.push(&u)
            })
            .collect();
        let camera = scene.camera.with_size(w, h);
        let whole = Rect { x: 0, y: 0, w, h };
        let main_offset = uniforms.push(&screen.pass_uniform(
            camera.view(),
            camera.position,
            whole,
            (w, h),
            Vec4::W,
        ));

        // Bind groups: 0 "no texture", then own set 0, own set 1, carried (one per texture).
        let mut views: Vec<&wgpu::TextureView> = Vec::new();
        let none = RenderTarget::new(
            gpu,
            "no texture",
            1,
            1,
            wgpu::TextureUsages::TEXTURE_BINDING,
        );
        views.push(&none.color_view);
        let own_base = [1, 1 + cameras.len()];
        views.extend(own.iter().flat_map(|set| set.iter().map(|t| &t.color_view)));
        let carried_base = views.len();
        if let Some(c) = state.carried() {
            views.extend(c.textures.iter().map(|t| &t.color_view));
        }

        let carried_cameras = state.carried().map(|c| &c.cameras[..]);
        let (camera_draws, main_draws) = draw_lists(
            scene,
            &mirror_cameras,
            &cameras,
            carried_cameras,
            (own_base, carried_base),
            &mut uniforms,
        );

        let buffer = uniforms.buffer(device, "feedback uniforms");
        let pipelines = TexturePipelines::new(gpu, &scene_buffers);
        let pass_bind_group = pipelines
            .pass_bind_group::<crate::methods::recursive_texture::PassUniform>(gpu, &buffer);
        let bind_groups = views
            .iter()
            .map(|v| pipelines.mirror_bind_group(gpu, &buffer, v))
            .collect();

        let stats = texture_frame_stats(
            (cameras.len(), 1),
            mirror_draws(&camera_draws, &main_draws, state.carried().is_some()),
            scene_buffers.objects.len() / 3,
            (state.first_depth(), pipelines.clipping),
        );
        Ok(FeedbackFrame {
            scene_buffers,
            pipelines,
            pass_bind_group,
            bind_groups,
            own,
            cameras: Arc::new(cameras),
            state,
            camera_draws,
            camera_offsets,
            main_draws,
            main_offset,
            background: scene.background,
            size: (w, h),
            stats,
        })
    }

    fn draws<'a>(
        &'a self,
        draws: &'a [Draw],
    ) -> impl Iterator<Item = (usize, &'a wgpu::BindGroup, u32)> {
        draws
            .iter()
            .map(|d| (d.mirror, &self.bind_groups[d.bind_group], d.offset))
    }
}

impl FrameEncoder for FeedbackFrame {
    /// Every mirror's texture into the set the frame writes (reading the other, or the
    /// carried one), then the main view applying them.
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let (read, write) = self.state.begin_frame();
        let mut first_pass = first_pass;
        for (k, texture) in self.own[write].iter().enumerate() {
            let mut pass = texture.begin_pass_with_alpha(
                encoder,
                "feedback texture pass",
                self.background,
                1.0,
                first_pass.take(),
            );
            let draws = self.draws(&self.camera_draws[source_index(read)][k]);
            self.pipelines.draw(
                &mut pass,
                &self.scene_buffers,
                &self.pass_bind_group,
                self.camera_offsets[k],
                draws,
            );
        }
        let mut pass = target.begin_pass_with_alpha(
            encoder,
            "main view pass",
            self.background,
            1.0,
            first_pass.take(),
        );
        self.pipelines.draw(
            &mut pass,
            &self.scene_buffers,
            &self.pass_bind_group,
            self.main_offset,
            self.draws(&self.main_draws[write]),
        );
    }

    crate::ping_pong_frame!();

    fn history(&self) -> Option<FrameHistory> {
        self.state.history(|i| {
            Arc::new(FeedbackHistory {
                textures: self.own[i].clone(),
                cameras: self.cameras.clone(),
                size: self.size,
            })
        })
    }
}

/// The mirrors a frame draws: each mirror camera's pass, reading the carried textures where
/// there are some, then the main pass.
fn mirror_draws(
    camera_draws: &[Vec<Vec<Draw>>; 4],
    main_draws: &[Vec<Draw>; 2],
    carried: bool,
) -> usize {
    let read = if carried {
        Source::Carried
    } else {
        Source::Nothing
    };
    camera_draws[source_index(read)]
        .iter()
        .map(Vec::len)
        .sum::<usize>()
        + main_draws[0].len()
}

/// The two sets of this frame's textures, written in turn (one per mirror camera each).
fn texture_sets(gpu: &Gpu, cameras: &[TextureCamera]) -> [Arc<Vec<RenderTarget>>; 2] {
    [0, 1].map(|_| {
        Arc::new(
            cameras
                .iter()
                .map(|c| {
                    RenderTarget::new(
                        gpu,
                        "feedback texture",
                        c.region.w,
                        c.region.h,
                        wgpu::TextureUsages::TEXTURE_BINDING,
                    )
                })
                .collect::<Vec<_>>(),
        )
    })
}

/// Every pass's mirror draws: per source a mirror camera's pass reads (nothing, the carried
/// textures, either own set), each camera's draws; and the main pass's, reading either own
/// set. Their uniform records go into `uniforms`.
#[allow(clippy::type_complexity)]
fn draw_lists(
    scene: &Scene,
    mirror_cameras: &[MirrorCamera],
    cameras: &[TextureCamera],
    carried: Option<&[TextureCamera]>,
    (own_base, carried_base): ([usize; 2], usize),
    uniforms: &mut UniformArena,
) -> ([Vec<Vec<Draw>>; 4], [Vec<Draw>; 2]) {
    // A pass's draw of every scene mirror but those in its own plane: textured from the
    // set `source` holds for the mirror, if any, looked up through the texture's camera.
    let no_texture = uniforms.push(&MirrorUniform::zeroed());
    let mut draws_reading = |source: Source, plane: Option<&mirrorbox_scene::Plane>| {
        let set: Option<(&[TextureCamera], usize)> = match source {
            Source::Nothing => None,
            Source::Carried => carried.map(|c| (c, carried_base)),
            Source::Own(i) => Some((cameras, own_base[i])),
        };
        let mut draws = Vec::new();
        for (j, mirror) in scene.mirrors.iter().enumerate() {
            if plane.is_some_and(|p| mirror.lies_in(p)) {
                continue;
            }
            let texture = set.and_then(|(cams, base)| {
                let t = cams.iter().position(|c| c.mirror == j)?;
                Some((cams[t], base + t))
            });
            draws.push(match texture {
                Some((tc, bind_group)) => Draw {
                    mirror: j,
                    bind_group,
                    offset: uniforms.push(&MirrorUniform {
                        exact: 0,
                        projected: 1,
                        lookup_from_world: tc.screen_from_world.to_cols_array_2d(),
                        ..MirrorUniform::textured(tc.region)
                    }),
                },
                None => Draw {
                    mirror: j,
                    bind_group: 0,
                    offset: no_texture,
                },
            });
        }
        draws
    };
    let sources = [
        Source::Nothing,
        Source::Carried,
        Source::Own(0),
        Source::Own(1),
    ];
    let camera_draws = sources.map(|s| {
        mirror_cameras
            .iter()
            .map(|c| draws_reading(s, Some(&c.plane)))
            .collect::<Vec<_>>()
    });
    // The main pass applies this frame's textures of the mirrors it sees (their cameras
    // are its own mirror cameras: texel (x, y) is screen pixel region origin + (x, y)).
    let main_draws = [0, 1].map(|i| {
        scene
            .mirrors
            .iter()
            .enumerate()
            .map(|(j, _)| {
                let seen = mirror_cameras
                    .iter()
                    .position(|c| c.mirror == j && c.view.depth == 1);
                match seen {
                    Some(t) => Draw {
                        mirror: j,
                        bind_group: own_base[i] + t,
                        offset: uniforms.push(&MirrorUniform::textured(cameras[t].region)),
                    },
                    None => Draw {
                        mirror: j,
                        bind_group: 0,
                        offset: no_texture,
                    },
                }
            })
            .collect::<Vec<_>>()
    });
    (camera_draws, main_draws)
}

/// The index of a read source in [`FeedbackFrame::camera_draws`].
fn source_index(source: Source) -> usize {
    match source {
        Source::Nothing => 0,
        Source::Carried => 1,
        Source::Own(i) => 2 + i,
    }
}
