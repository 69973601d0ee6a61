//! The seed paper's methods (`naive`, `auxiliary`): recursive render-to-texture mirrors,
//! executing a [`Plan`] of `MIRRORTEXTURE` calls. Entry points: `shaders/recursive_texture.wgsl`.
//!
//! Each call renders the scene from its mirror camera (seed 002: the view composed with the
//! mirror's reflection, so the image is not flipped but the winding is — culling is off and
//! shading is two-sided), keeping what lies in front of the mirror's plane (a hardware clip
//! distance where the adapter has them, else a per-fragment test: the plane is not made the
//! near plane, which would tilt the depth range — every pass uses the camera's infinite
//! reversed Z, [`crate::projection`]), into a texture covering the mirror's footprint on
//! screen. Because every camera shares the
//! screen's projection, texel (x, y) of a texture is screen pixel footprint-origin + (x, y):
//! the mirror looks its texture up by screen position, with no resampling at the default
//! `texture_scale` of 1. Textures are rendered depth first (children before the pass that
//! applies them) and recycled by exact size once applied.

use crate::gpu::{Gpu, RasterError};
use crate::method::{
    Advise, BuiltFrame, Clipping, FrameStats, MethodEntry, OptionKind, OptionSpec, ParamValue,
    Params, PlannedFrame, RasterMethod, SweepAxis,
};
use crate::pipeline::{
    ScenePipeline, UniformArena, depth_state, dynamic_uniform_entry, pipeline_layout,
    record_binding,
};
use crate::plan::{Plan, PlanError, Queue, Rect, TextureNode};
use crate::projection::NEARER_OR_EQUAL;
use crate::shading::{SceneBuffers, VERTEX_LAYOUT};
use crate::targets::{DEPTH_FORMAT, RenderTarget, texture_entry};
use crate::timing::FrameEncoder;
use crate::uneven::BumpSettings;
use crate::wgsl::HostLayout;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3, Vec4};
use mirrorbox_scene::{Plane, Scene};
use std::collections::HashMap;

/// The seed paper's Algorithm 1 as printed: the queue is the scene's mirrors (two
/// reflections on `mirror_box`, its Figure 2).
pub static NAIVE: MethodEntry = MethodEntry {
    name: "naive",
    help: "The paper's Algorithm 1: recursive mirror textures, each mirror hidden in its own recursion.",
    exact: false,
    depth_limited: true,
    options: crate::method_options![&TEXTURE_SCALE, &MAX_PASSES; mirror_textures],
    swept: None,
    optional_features: wgpu::Features::CLIP_DISTANCES,
    required_features: wgpu::Features::empty(),
    shaders: SHADERS,
    gpu_structs,
    configure: |p| Box::new(RecursiveTextureMethod::new(Queue::SceneMirrors, p)),
    // Mirror textures at full and at half the mirror's footprint: cost against blur.
    advise: Advise::Fixed(&["", "texture-scale=0.5"]),
};

/// The paper's §3.1–3.2: n auxiliary mirrors coincide with the two real ones (n + 2 in the
/// queue), the k-th reflection attenuated by α^k; with more mirrors, n per mirror and the
/// mirror opposite it (`plan::partner`, docs/methods.md).
pub static AUXILIARY: MethodEntry = MethodEntry {
    name: "auxiliary",
    help: "The paper's §3.1–3.2: n auxiliary mirrors per facing pair (n + 2 in the queue for two mirrors), attenuation α^k.",
    exact: false,
    depth_limited: true,
    options: crate::method_options![
        &AUXILIARY_MIRRORS, &TEXTURE_SCALE, &MAX_PASSES; mirror_textures
    ],
    swept: Some(&AUXILIARY_MIRRORS),
    optional_features: wgpu::Features::CLIP_DISTANCES,
    required_features: wgpu::Features::empty(),
    shaders: SHADERS,
    gpu_structs,
    configure: |p| {
        Box::new(RecursiveTextureMethod::new(
            Queue::Auxiliary {
                n: p.count(&AUXILIARY_MIRRORS),
            },
            p,
        ))
    },
    advise: Advise::Knob {
        option: &AUXILIARY_MIRRORS,
        coarse: &[0, 1, 2, 3, 4],
        variants: &["", "texture-scale=0.5"],
    },
};

/// Exact to `--depth`: the paper's mirror textures, one per reflection path — a colour and
/// distance target per path in screen space, so the uneven-mirror tricks (`--bump`) work at
/// every depth of an exact method (issue 16). Cost: one scene pass per kept path, like
/// `portal`, each into a texture no larger than its parent's.
pub static PATH_TEXTURES: MethodEntry = MethodEntry {
    name: "path-textures",
    help: "Exact to --depth: one mirror texture per reflection path (a colour + distance target each), so uneven-mirror tricks apply at every depth.",
    exact: true,
    depth_limited: true,
    options: crate::method_options![
        &crate::exact_options::DEPTH,
        &crate::exact_options::MIN_ATTENUATION,
        &MAX_PASSES;
        mirror_textures
    ],
    swept: Some(&crate::exact_options::DEPTH),
    optional_features: wgpu::Features::CLIP_DISTANCES,
    required_features: wgpu::Features::empty(),
    shaders: SHADERS,
    gpu_structs,
    configure: |p| {
        Box::new(RecursiveTextureMethod {
            queue: TextureQueue::Paths(crate::plan::PathTextureLimits {
                depth: p.count(&crate::exact_options::DEPTH),
                min_attenuation: p.real(&crate::exact_options::MIN_ATTENUATION),
            }),
            texture_scale: 1.0,
            max_passes: p.count(&MAX_PASSES) as usize,
            bump: BumpSettings::from_params(p),
            shared_mirrors: shared_mirrors(p),
        })
    },
    advise: Advise::Knob {
        option: &crate::exact_options::DEPTH,
        coarse: &[1, 2, 4, 8, 16, 32, 64],
        variants: &[""],
    },
};

const ENTRY_POINTS: &str = include_str!("../../../../shaders/recursive_texture.wgsl");

crate::mirror_plane_shaders!("recursive texture", ENTRY_POINTS, crate::wgsl::PASS_VIEW);

/// The shader variants of every texture method (this file's and `feedback`'s).
pub(crate) static SHADERS: &[&crate::wgsl::WgslSource] = &[&SHADER, &CLIP_DISTANCE_SHADER];

pub(crate) fn gpu_structs() -> Vec<HostLayout> {
    vec![
        crate::host_layout!(PassUniform as "Pass" {
            clip_from_world, eye, _pad0, origin, pixels_per_texel, plane, screen_from_world,
            screen_size, bump_mode, march_steps, bump_strength, proxy_distance,
            march_distance, projected_lookup, lookup_from_world, lookup_eye, _pad1
        }),
        crate::host_layout!(MirrorUniform as "MirrorDraw" {
            origin, size, texels_per_pixel, exact, has_texture, lookup_from_world, projected,
            _pad0, _pad1, _pad2
        }),
    ]
}

/// `--n`: auxiliary mirrors (per mirror pair beyond two mirrors). Bounded by 16: at n = 7 the
/// plan already needs 11 146 passes on `mirror_box`, at n = 3 120 199 in `mirror_room`.
pub static AUXILIARY_MIRRORS: OptionSpec = OptionSpec {
    name: "n",
    help: "Auxiliary mirrors (the paper's n), per pair of opposite mirrors.",
    kind: OptionKind::Count { min: 0, max: 16 },
    default: ParamValue::Count(0),
    sweep: Some(SweepAxis {
        default: "0..4",
        range_example: "0..4",
        list_example: "0,2,4",
        noun: "counts",
    }),
    in_key: true,
};

/// `--texture-scale`: mirror texture resolution relative to the mirror's footprint.
pub static TEXTURE_SCALE: OptionSpec = OptionSpec {
    name: "texture-scale",
    help: "Mirror texture resolution relative to the mirror's footprint on screen (1 = exact).",
    kind: OptionKind::Real {
        min: 0.0,
        min_open: true,
        max: Some(4.0),
    },
    default: ParamValue::Real(1.0),
    sweep: None,
    in_key: true,
};

/// `--max-passes`: refuse, before any work, a plan needing more scene passes per frame.
pub static MAX_PASSES: OptionSpec = OptionSpec {
    name: "max-passes",
    help: "Refuse, before any work, a configuration needing more scene passes per frame.",
    kind: OptionKind::Count {
        min: 1,
        max: 1_000_000,
    },
    default: ParamValue::Count(5000),
    sweep: None,
    in_key: false,
};

/// What the textures recurse over: the paper's queue, or every reflection path.
#[derive(Clone, Copy)]
enum TextureQueue {
    Paper(Queue),
    Paths(crate::plan::PathTextureLimits),
}

/// The typed settings of `naive`, `auxiliary` and `path-textures`.
struct RecursiveTextureMethod {
    queue: TextureQueue,
    texture_scale: f32,
    max_passes: usize,
    bump: BumpSettings,
    /// `--stereo-mirrors shared`: the textures of an eye's frame come from the head.
    shared_mirrors: bool,
}

fn shared_mirrors(p: &Params) -> bool {
    p.choice(&crate::stereo_mirrors::STEREO_MIRRORS) == "shared"
}

impl RecursiveTextureMethod {
    fn new(queue: Queue, p: &Params) -> Self {
        RecursiveTextureMethod {
            queue: TextureQueue::Paper(queue),
            texture_scale: p.real(&TEXTURE_SCALE),
            max_passes: p.count(&MAX_PASSES) as usize,
            bump: BumpSettings::from_params(p),
            shared_mirrors: shared_mirrors(p),
        }
    }
}

impl RecursiveTextureMethod {
    /// The textures seen from `scene`'s camera.
    fn plan_textures(&self, scene: &Scene, width: u32, height: u32) -> Result<Plan, PlanError> {
        match self.queue {
            TextureQueue::Paper(q) => crate::plan::plan(scene, q, width, height, self.max_passes),
            TextureQueue::Paths(limits) => {
                crate::plan::plan_path_textures(scene, limits, width, height, self.max_passes)
            }
        }
    }
}

impl RasterMethod for RecursiveTextureMethod {
    fn plan(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
    ) -> Result<Box<dyn PlannedFrame>, PlanError> {
        // Shared mirrors in one eye's frame: the textures are the head's (an eye at the head,
        // IPD 0, is the head: its own textures, bit for bit the mono frame).
        let head = scene
            .head
            .as_ref()
            .filter(|h| self.shared_mirrors && **h != scene.camera);
        let head_scene;
        let planned_scene = match head {
            Some(h) => {
                head_scene = Scene {
                    camera: h.clone(),
                    ..scene.clone()
                };
                &head_scene
            }
            None => scene,
        };
        let plan = self.plan_textures(planned_scene, width, height)?;
        let views = vec![MainView {
            camera: scene.camera.clone(),
            lookup: head.cloned(),
        }];
        Ok(Box::new(PlannedTextures {
            plan,
            texture_scale: self.texture_scale,
            bump: self.bump,
            views,
        }))
    }

    /// With `--stereo-mirrors shared` and a real IPD, one set of textures from the head for
    /// both eyes, then each eye's main pass: the shortcut's saving is in the pair's time.
    fn plan_pair(
        &self,
        eyes: [&Scene; 2],
        width: u32,
        height: u32,
    ) -> Result<crate::stereo_pair::PlannedPair, PlanError> {
        let head = eyes[0].head.as_ref().filter(|h| {
            self.shared_mirrors
                && eyes[1].head.as_ref() == Some(*h)
                && eyes.iter().all(|e| e.camera != **h)
        });
        let Some(head) = head else {
            return crate::stereo_pair::plan_each_eye(self, eyes, width, height);
        };
        let head_scene = Scene {
            camera: head.clone(),
            ..eyes[0].clone()
        };
        let plan = self.plan_textures(&head_scene, width, height)?;
        let views = eyes
            .iter()
            .map(|e| MainView {
                camera: e.camera.clone(),
                lookup: Some(head.clone()),
            })
            .collect();
        Ok(crate::stereo_pair::PlannedPair::Joint(Box::new(
            PlannedTextures {
                plan,
                texture_scale: self.texture_scale,
                bump: self.bump,
                views,
            },
        )))
    }
}

/// One main pass of a frame: the camera that draws it, and where its mirror textures are
/// looked up from when they are not its own (`--stereo-mirrors shared`: the head's).
#[derive(Clone)]
pub struct MainView {
    pub camera: mirrorbox_scene::Camera,
    pub lookup: Option<mirrorbox_scene::Camera>,
}

impl crate::stereo_pair::PlannedJointPair for PlannedTextures {
    fn memory(
        &self,
        eyes: [&Scene; 2],
        color_bytes_per_texel: u64,
    ) -> crate::memory::MemoryEstimate {
        texture_memory(eyes[0], self, color_bytes_per_texel)
    }

    fn build(
        self: Box<Self>,
        gpu: &Gpu,
        eyes: [&Scene; 2],
        shadows: &crate::shadow_maps::ShadowMaps,
    ) -> Result<crate::stereo_pair::BuiltPair, RasterError> {
        let m = RecursiveTexture::new(
            gpu,
            eyes[0],
            shadows,
            &self.plan,
            self.texture_scale,
            self.bump,
            &self.views,
        )?;
        Ok(crate::stereo_pair::BuiltPair {
            stats: m.stats,
            encoder: Box::new(m),
        })
    }
}

struct PlannedTextures {
    plan: Plan,
    texture_scale: f32,
    bump: BumpSettings,
    /// The main passes: one, or a stereo pair's two sharing the head's textures.
    views: Vec<MainView>,
}

impl PlannedFrame for PlannedTextures {
    fn memory(&self, scene: &Scene, color_bytes_per_texel: u64) -> crate::memory::MemoryEstimate {
        texture_memory(scene, self, color_bytes_per_texel)
    }

    fn build(
        self: Box<Self>,
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
    ) -> Result<BuiltFrame, RasterError> {
        let m = RecursiveTexture::new(
            gpu,
            scene,
            shadows,
            &self.plan,
            self.texture_scale,
            self.bump,
            &self.views,
        )?;
        Ok(BuiltFrame {
            stats: m.stats,
            encoder: Box::new(m),
            warnings: Vec::new(),
            bake_ms: None,
        })
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct PassUniform {
    clip_from_world: [[f32; 4]; 4],
    eye: [f32; 3],
    _pad0: f32,
    origin: [f32; 2],
    pixels_per_texel: [f32; 2],
    /// The pass's mirror plane in scene space, front positive; `(0, 0, 0, 1)` for the
    /// camera's pass.
    plane: [f32; 4],
    /// The pass's camera without the crop: world to the whole screen's clip space (where
    /// the uneven-mirror tricks project their points).
    screen_from_world: [[f32; 4]; 4],
    screen_size: [f32; 2],
    /// [`BumpSettings`]: the trick and its parameters; the march's longest reach (the
    /// scene's diagonal).
    bump_mode: u32,
    march_steps: u32,
    bump_strength: f32,
    proxy_distance: f32,
    march_distance: f32,
    /// 1 in the main pass of an eye sharing the head's textures: mirror lookups project the
    /// fragment's world position with `lookup_from_world` (the head's camera) instead of
    /// reading its own screen position; distances compare against `lookup_eye`.
    projected_lookup: u32,
    /// Where the applied textures' screen space comes from (= `screen_from_world` but in
    /// that pass).
    lookup_from_world: [[f32; 4]; 4],
    lookup_eye: [f32; 3],
    _pad1: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(crate) struct MirrorUniform {
    pub origin: [f32; 2],
    pub size: [f32; 2],
    pub texels_per_pixel: [f32; 2],
    pub exact: u32,
    pub has_texture: u32,
    /// With `projected`: the camera the applied texture was rendered from (world to the
    /// whole screen's clip space); the mirror looks a fragment up where that camera saw it
    /// (`feedback`, whose textures come from other cameras than the pass's).
    pub lookup_from_world: [[f32; 4]; 4],
    pub projected: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

impl MirrorUniform {
    /// A mirror drawn with texture region `region` applied at one texel per pixel.
    pub(crate) fn textured(region: Rect) -> Self {
        MirrorUniform {
            origin: [region.x as f32, region.y as f32],
            size: [region.w as f32, region.h as f32],
            texels_per_pixel: [1.0, 1.0],
            exact: 1,
            has_texture: 1,
            ..Zeroable::zeroed()
        }
    }
}

enum Target {
    Slot(usize),
    /// The frame's k-th main view (one, or a stereo pair's two).
    View(usize),
}

struct MirrorDraw {
    mirror: usize,
    /// Its bind group: while scheduling, its index in `mirror_bindings`; once built, in
    /// `mirror_bind_groups` (one per texture).
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
    pipelines: TexturePipelines,
    pass_bind_group: wgpu::BindGroup,
    mirror_bind_groups: Vec<wgpu::BindGroup>,
    slots: Vec<RenderTarget>,
    passes: Vec<PassSpec>,
    background: Vec3,
    /// What a texture's alpha holds where nothing was drawn: with `--bump march` the
    /// distance "nothing", else 1.
    clear_alpha: f32,
    pub stats: FrameStats,
}

/// The distance a marched texture stores where it shows the background (within half-float
/// range, beyond any bundled scene).
const NO_SURFACE_DISTANCE: f32 = 60_000.0;

/// Builds the uniform records and pass list from the plan.
struct Builder<'a> {
    scene: &'a Scene,
    plan: &'a Plan,
    texture_scale: f32,
    bump: BumpSettings,
    march_distance: f32,
    uniforms: UniformArena,
    /// Free slots by exact texture size.
    free: HashMap<(u32, u32), Vec<usize>>,
    slot_sizes: Vec<(u32, u32)>,
    passes: Vec<PassSpec>,
    /// (uniform offset, slot or None for the "no texture" binding) per mirror bind group.
    mirror_bindings: Vec<(u32, Option<usize>)>,
    /// Mirror draws scheduled. With a counting-only arena (a memory estimate) the draws
    /// and their bindings are counted, not kept: a frame of N mirrors seen in each other's
    /// textures has ~N² of them, which the estimate must refuse before they are allocated
    /// (issue 51: 4 000 facets held 774 MB of draw lists before the refusal).
    mirror_draw_count: u64,
}

impl Builder<'_> {
    /// A node's texture region: its footprint grown by `--texture-margin` within the screen.
    fn region(&self, r: Rect) -> Rect {
        let m = self.bump.margin;
        let x = r.x.saturating_sub(m);
        let y = r.y.saturating_sub(m);
        let right = (r.x + r.w).saturating_add(m).min(self.plan.width);
        let bottom = (r.y + r.h).saturating_add(m).min(self.plan.height);
        Rect {
            x,
            y,
            w: right - x,
            h: bottom - y,
        }
    }

    /// The pass uniform of a camera `view` (projection `plan.projection`) drawing into
    /// `region` of the screen at `size` texels, keeping what lies in front of `plane`.
    fn pass_uniform(
        &self,
        view: Mat4,
        eye: Vec3,
        region: Rect,
        size: (u32, u32),
        plane: Vec4,
    ) -> PassUniform {
        let screen = ScreenSpace {
            projection: self.plan.projection,
            width: self.plan.width,
            height: self.plan.height,
        };
        PassUniform {
            bump_mode: self.bump.mode,
            march_steps: self.bump.march_steps,
            bump_strength: self.bump.strength,
            proxy_distance: self.bump.proxy_distance,
            march_distance: self.march_distance,
            ..screen.pass_uniform(view, eye, region, size, plane)
        }
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
        let region = self.region(node.footprint);
        let size = self.texture_size(region);
        let slot = self.alloc(size);
        let uniform = self.pass_uniform(
            node.view.view,
            node.view.eye(),
            region,
            size,
            node.plane.coefficients(),
        );
        let offset = self.uniforms.push(&uniform);
        let draws = self.mirror_draws(&node.hidden, Some(&node.plane), &children);
        self.passes.push(PassSpec {
            target: Target::Slot(slot),
            offset,
            draws,
        });
        for (c, s) in children {
            let size = self.texture_size(self.region(c.footprint));
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
            if plane.is_some_and(|p| mirror.lies_in(p)) {
                continue;
            }
            let binding = match children.iter().find(|(c, _)| c.instance == i) {
                Some((child, slot)) => {
                    let f = self.region(child.footprint);
                    let (tw, th) = self.texture_size(f);
                    let texels_per_pixel = [tw as f32 / f.w as f32, th as f32 / f.h as f32];
                    let exact = texels_per_pixel == [1.0, 1.0];
                    let offset = self.uniforms.push(&MirrorUniform {
                        texels_per_pixel,
                        exact: exact as u32,
                        ..MirrorUniform::textured(f)
                    });
                    (offset, Some(*slot))
                }
                None => (self.uniforms.push(&MirrorUniform::zeroed()), None),
            };
            self.mirror_draw_count += 1;
            if !self.uniforms.keeps_records() {
                continue;
            }
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

/// The screen every texture of a frame shares: the camera's projection at render size.
#[derive(Clone, Copy)]
pub(crate) struct ScreenSpace {
    pub projection: Mat4,
    pub width: u32,
    pub height: u32,
}

impl ScreenSpace {
    /// The pass uniform of a camera `view` drawing into `region` of the screen at `size`
    /// texels, keeping what lies in front of `plane` (flat mirrors: no uneven-mirror trick).
    pub(crate) fn pass_uniform(
        &self,
        view: Mat4,
        eye: Vec3,
        region: Rect,
        size: (u32, u32),
        plane: Vec4,
    ) -> PassUniform {
        let screen = self.projection * view;
        PassUniform {
            clip_from_world: (crop(region, self.width, self.height) * screen).to_cols_array_2d(),
            eye: eye.to_array(),
            _pad0: 0.0,
            origin: [region.x as f32, region.y as f32],
            pixels_per_texel: [
                region.w as f32 / size.0 as f32,
                region.h as f32 / size.1 as f32,
            ],
            plane: plane.to_array(),
            screen_from_world: screen.to_cols_array_2d(),
            screen_size: [self.width as f32, self.height as f32],
            bump_mode: 0,
            march_steps: 0,
            bump_strength: 0.0,
            proxy_distance: 0.0,
            march_distance: 1.0,
            projected_lookup: 0,
            lookup_from_world: screen.to_cols_array_2d(),
            lookup_eye: eye.to_array(),
            _pad1: 0.0,
        }
    }
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

/// Most bytes the mirror textures of one frame may take (colour and depth), so that
/// `--texture-scale` on a large image is refused with the numbers instead of failing in the
/// driver or aborting for memory.
pub const MAX_MIRROR_TEXTURE_BYTES: u64 = 2_000_000_000;

/// Refuses mirror textures larger than the device's largest texture, or more of them in
/// bytes than [`MAX_MIRROR_TEXTURE_BYTES`], before any is created.
pub(crate) fn check_mirror_textures(gpu: &Gpu, sizes: &[(u32, u32)]) -> Result<(), RasterError> {
    for &(w, h) in sizes {
        gpu.check_target(w, h, "; lower --texture-scale or --texture-margin")?;
    }
    // RGBA32F colour (at most 16 bytes) and 32-bit depth per texel.
    let bytes: u64 = sizes
        .iter()
        .map(|&(w, h)| u64::from(w) * u64::from(h) * 20)
        .sum();
    if bytes > MAX_MIRROR_TEXTURE_BYTES {
        return Err(RasterError::ExceedsDevice {
            what: format!("{} mirror textures", sizes.len()),
            needed: mirrorbox_files::human_bytes(bytes),
            limit: format!(
                "at most {}",
                mirrorbox_files::human_bytes(MAX_MIRROR_TEXTURE_BYTES)
            ),
            adapter: "mirrorbox".into(),
            advice: "; lower --texture-scale, --n or the image size",
        });
    }
    Ok(())
}

impl RecursiveTexture {
    pub fn new(
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
        plan: &Plan,
        texture_scale: f32,
        bump: BumpSettings,
        views: &[MainView],
    ) -> Result<Self, RasterError> {
        let device = &gpu.device;
        let scene_buffers = SceneBuffers::new(gpu, scene, shadows.binding());
        let mut b = schedule(
            scene,
            plan,
            texture_scale,
            bump,
            views,
            UniformArena::new(device),
        );
        let uniforms = b.uniforms.buffer(device, "recursive texture uniforms");
        let pipelines = TexturePipelines::new(gpu, &scene_buffers);
        let pass_bind_group = pipelines.pass_bind_group::<PassUniform>(gpu, &uniforms);
        check_mirror_textures(gpu, &b.slot_sizes)?;
        let slots: Vec<RenderTarget> = b
            .slot_sizes
            .iter()
            .map(|&(w, h)| {
                RenderTarget::new(
                    gpu,
                    "mirror texture",
                    w,
                    h,
                    wgpu::TextureUsages::TEXTURE_BINDING,
                )
            })
            .collect();
        let none = RenderTarget::new(
            gpu,
            "no texture",
            1,
            1,
            wgpu::TextureUsages::TEXTURE_BINDING,
        );
        // One bind group per texture a mirror draw applies (its uniform is bound at the
        // draw's dynamic offset), not one per draw: a frame of N mirrors each seen in the
        // other mirrors' textures draws ~N² mirrors, and a bind group each crashed lavapipe's
        // descriptor allocation at 400 mirrors (issue 51).
        let mut mirror_bind_groups = Vec::new();
        let mut group_of_slot: std::collections::HashMap<Option<usize>, usize> = Default::default();
        let group_of_binding: Vec<usize> = b
            .mirror_bindings
            .iter()
            .map(|&(_, slot)| {
                *group_of_slot.entry(slot).or_insert_with(|| {
                    let view = slot.map_or(&none.color_view, |s| &slots[s].color_view);
                    mirror_bind_groups.push(pipelines.mirror_bind_group(gpu, &uniforms, view));
                    mirror_bind_groups.len() - 1
                })
            })
            .collect();
        for d in b.passes.iter_mut().flat_map(|p| p.draws.iter_mut()) {
            d.bind_group = group_of_binding[d.bind_group];
        }
        let stats = texture_frame_stats(
            (plan.passes - 1, views.len()),
            b.passes.iter().map(|p| p.draws.len()).sum(),
            scene_buffers.objects.len() / 3,
            (plan.depth, pipelines.clipping),
        );
        Ok(RecursiveTexture {
            scene_buffers,
            pipelines,
            pass_bind_group,
            mirror_bind_groups,
            slots,
            passes: b.passes,
            background: scene.background,
            clear_alpha: if bump.needs_distances() {
                NO_SURFACE_DISTANCE
            } else {
                1.0
            },
            stats,
        })
    }
}

/// The stats of a frame of `texture_renders` texture passes and `main_passes` main passes
/// (the paper's methods, `feedback`, `cubemap`), each drawing the scene's objects, with
/// `mirror_draws` mirrors drawn in all: a draw per pass and per mirror, and the resolve.
pub(crate) fn texture_frame_stats(
    (texture_renders, main_passes): (usize, usize),
    mirror_draws: usize,
    object_triangles: usize,
    (depth, clipping): (usize, crate::method::Clipping),
) -> FrameStats {
    let passes = texture_renders + main_passes;
    FrameStats {
        passes,
        texture_renders,
        draws: passes + mirror_draws + 1,
        depth,
        triangles: passes * object_triangles + 2 * mirror_draws,
        paths: None,
        clipping,
        depth_format: DEPTH_FORMAT,
        copies: None,
    }
}

/// Lays out a frame's passes, texture slots and uniform records from `plan`, on the CPU:
/// what [`RecursiveTexture::new`] creates, and what [`PlannedFrame::memory`] counts.
fn schedule<'a>(
    scene: &'a Scene,
    plan: &'a Plan,
    texture_scale: f32,
    bump: BumpSettings,
    views: &[MainView],
    uniforms: UniformArena,
) -> Builder<'a> {
    let (lo, hi) = scene
        .geometry
        .triangles
        .iter()
        .flatten()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| {
            (a.min(*p), b.max(*p))
        });
    let mut b = Builder {
        scene,
        plan,
        texture_scale,
        bump,
        march_distance: if lo.x <= hi.x {
            (hi - lo).length()
        } else {
            1.0
        },
        uniforms,
        free: HashMap::new(),
        slot_sizes: Vec::new(),
        passes: Vec::new(),
        mirror_bindings: Vec::new(),
        mirror_draw_count: 0,
    };
    let roots: Vec<(&TextureNode, usize)> = plan.roots.iter().map(|n| (n, b.emit(n))).collect();
    let screen = Rect {
        x: 0,
        y: 0,
        w: plan.width,
        h: plan.height,
    };
    for (k, view) in views.iter().enumerate() {
        let camera = view.camera.with_size(plan.width, plan.height);
        let mut main_uniform = b.pass_uniform(
            camera.view(),
            camera.position,
            screen,
            (plan.width, plan.height),
            Vec4::W,
        );
        if let Some(head) = &view.lookup {
            // The eye's own projection (its lens shift) draws the frame; the textures are
            // looked up where the head sees each mirror point.
            let eye_clip = crate::projection::camera_projection(&camera, plan.width, plan.height)
                * camera.view();
            main_uniform.clip_from_world = eye_clip.to_cols_array_2d();
            main_uniform.screen_from_world = eye_clip.to_cols_array_2d();
            main_uniform.projected_lookup = 1;
            main_uniform.lookup_from_world = (plan.projection
                * head.with_size(plan.width, plan.height).view())
            .to_cols_array_2d();
            main_uniform.lookup_eye = head.position.to_array();
        }
        let main_offset = b.uniforms.push(&main_uniform);
        let main_draws = b.mirror_draws(&[], None, &roots);
        b.passes.push(PassSpec {
            target: Target::View(k),
            offset: main_offset,
            draws: main_draws,
        });
    }

    b
}

/// The GPU and host bytes of a planned texture frame: its scene buffers, one colour +
/// depth target per texture slot (slots are recycled by size, as built) and the "no
/// texture" 1×1 one, the uniform records at the largest alignment, and the plan's nodes.
fn texture_memory(
    scene: &Scene,
    planned: &PlannedTextures,
    color_bytes_per_texel: u64,
) -> crate::memory::MemoryEstimate {
    use crate::memory::{MAX_UNIFORM_ALIGNMENT, buffer_bytes, target_bytes};
    let b = schedule(
        scene,
        &planned.plan,
        planned.texture_scale,
        planned.bump,
        &planned.views,
        UniformArena::with_alignment(MAX_UNIFORM_ALIGNMENT as usize),
    );
    let textures: u64 = b
        .slot_sizes
        .iter()
        .map(|&(w, h)| target_bytes(w, h, color_bytes_per_texel))
        .sum::<u64>()
        + target_bytes(1, 1, color_bytes_per_texel);
    let mut e = SceneBuffers::memory_estimate(scene, &scene.geometry);
    e.gpu(
        "the mirror textures",
        "--texture-scale, --n, --depth or the image size (--width/--height, --ssaa)",
        textures,
    );
    let uniforms = buffer_bytes(b.uniforms.buffer_size());
    e.gpu("the uniforms", "--max-passes, --n or --depth", uniforms);
    // The records are built on the host and reach the buffer through wgpu's staging copy:
    // twice the buffer on the host at its peak (measured: 2 000 mirrors' 1.0 GB of uniforms
    // peaked at 3.4 GB of resident memory on lavapipe, whose buffers are host memory too).
    e.host(
        "the uniforms' records and staging copy",
        "--max-passes, --n or --depth",
        2 * uniforms,
    );
    e.host(
        "the plan",
        "--max-passes, --n or --depth",
        planned.plan.passes as u64 * PLAN_BYTES_PER_PASS,
    );
    e.host(
        "the mirror draw lists",
        "--max-passes, --n or --depth",
        b.mirror_draw_count * MIRROR_DRAW_HOST_BYTES,
    );
    e
}

/// Host bytes one scheduled mirror draw holds while a frame is built: its [`MirrorDraw`],
/// its binding record and the bind-group index it is mapped to.
const MIRROR_DRAW_HOST_BYTES: u64 = (std::mem::size_of::<MirrorDraw>()
    + std::mem::size_of::<(u32, Option<usize>)>()
    + std::mem::size_of::<usize>()) as u64;

/// Host bytes a plan keeps per texture render (its node, camera, hidden list and pass).
const PLAN_BYTES_PER_PASS: u64 = 1024;

impl FrameEncoder for RecursiveTexture {
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        main: &RenderTarget,
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        self.encode_views(encoder, &[main], first_pass);
    }
}

impl crate::stereo_pair::PairEncoder for RecursiveTexture {
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: [&RenderTarget; 2],
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        self.encode_views(encoder, &targets, first_pass);
    }
}

impl RecursiveTexture {
    /// Every texture pass, then each main view into its target.
    fn encode_views(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        views: &[&RenderTarget],
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let mut first_pass = first_pass;
        for spec in &self.passes {
            let (target, label) = match spec.target {
                Target::Slot(s) => (&self.slots[s], "mirror texture pass"),
                Target::View(k) => (views[k], "main view pass"),
            };
            let mut pass = target.begin_pass_with_alpha(
                encoder,
                label,
                self.background,
                self.clear_alpha,
                first_pass.take(),
            );
            let draws = spec
                .draws
                .iter()
                .map(|d| (d.mirror, &self.mirror_bind_groups[d.bind_group], d.offset));
            self.pipelines.draw(
                &mut pass,
                &self.scene_buffers,
                &self.pass_bind_group,
                spec.offset,
                draws,
            );
        }
    }
}

/// The two pipelines of a texture method's scene pass (objects, then mirrors with their
/// applied textures) and their bind-group layouts: pass uniform at group 1, mirror uniform
/// and texture at group 2.
pub(crate) struct TexturePipelines {
    objects: wgpu::RenderPipeline,
    mirrors: wgpu::RenderPipeline,
    pass_layout: wgpu::BindGroupLayout,
    mirror_layout: wgpu::BindGroupLayout,
    /// Hardware clip distances where the adapter has them, else per-fragment discard.
    pub clipping: Clipping,
}

impl TexturePipelines {
    /// The pipelines of this file's shaders: a mirror's group holds its uniform and one
    /// texture.
    pub(crate) fn new(gpu: &Gpu, scene_buffers: &SceneBuffers) -> Self {
        let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
        Self::with(
            gpu,
            scene_buffers,
            [&SHADER, &CLIP_DISTANCE_SHADER],
            &[dynamic_uniform_entry(0, stages), texture_entry(1)],
        )
    }

    /// The pipelines of a method whose shaders follow `mirror_plane_shaders!` (`shaders`:
    /// its plain and clip-distance variants), the mirror group laid out as `mirror_entries`.
    pub(crate) fn with(
        gpu: &Gpu,
        scene_buffers: &SceneBuffers,
        shaders: [&'static crate::wgsl::WgslSource; 2],
        mirror_entries: &[wgpu::BindGroupLayoutEntry],
    ) -> Self {
        let stages = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let pass_layout = gpu.bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pass"),
            entries: &[dynamic_uniform_entry(0, stages)],
        });
        let mirror_layout = gpu.bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("mirror"),
            entries: mirror_entries,
        });
        let clipping = Clipping::for_features(gpu.features);
        let (shader, vertex, fs_object, fs_mirror) = match clipping {
            Clipping::ClipDistances => (
                gpu.shader_module(shaders[1], scene_buffers.textured),
                "vs_clip_distances",
                "fs_object",
                "fs_mirror",
            ),
            Clipping::FragmentDiscard | Clipping::None => (
                gpu.shader_module(shaders[0], scene_buffers.textured),
                "vs_main",
                "fs_object_discard",
                "fs_mirror_discard",
            ),
        };
        let sl = &scene_buffers.layout;
        let pipeline = |label: &str, layout: &wgpu::PipelineLayout, fragment: &str| {
            ScenePipeline {
                label,
                layout,
                module: &shader,
                vertex,
                fragment,
                buffers: &[Some(VERTEX_LAYOUT)],
                // Of coincident mirror instances the last drawn wins, deterministically.
                depth_stencil: depth_state(DEPTH_FORMAT, true, NEARER_OR_EQUAL, Default::default()),
                color_writes: wgpu::ColorWrites::ALL,
            }
            .build(gpu)
        };
        let objects = pipeline(
            "texture pass objects",
            &pipeline_layout(gpu, "texture pass objects", &[sl, &pass_layout]),
            fs_object,
        );
        let mirrors = pipeline(
            "texture pass mirrors",
            &pipeline_layout(
                gpu,
                "texture pass mirrors",
                &[sl, &pass_layout, &mirror_layout],
            ),
            fs_mirror,
        );
        TexturePipelines {
            objects,
            mirrors,
            pass_layout,
            mirror_layout,
            clipping,
        }
    }

    /// The pass uniforms' bind group over the frame's uniform arena (records of `P`).
    pub(crate) fn pass_bind_group<P>(&self, gpu: &Gpu, uniforms: &wgpu::Buffer) -> wgpu::BindGroup {
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pass"),
            layout: &self.pass_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: record_binding::<P>(uniforms),
            }],
        })
    }

    /// A mirror draw's bind group of `entries` (its uniform and textures), in the layout
    /// [`TexturePipelines::with`] was given.
    pub(crate) fn mirror_group(
        &self,
        gpu: &Gpu,
        entries: &[wgpu::BindGroupEntry<'_>],
    ) -> wgpu::BindGroup {
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("mirror"),
            layout: &self.mirror_layout,
            entries,
        })
    }

    /// A mirror draw's bind group: its uniform (at a dynamic offset) and applied texture.
    pub(crate) fn mirror_bind_group(
        &self,
        gpu: &Gpu,
        uniforms: &wgpu::Buffer,
        texture: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        self.mirror_group(
            gpu,
            &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: record_binding::<MirrorUniform>(uniforms),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(texture),
                },
            ],
        )
    }

    /// One scene pass: the objects with the pass uniform at `offset`, then each mirror
    /// `(scene mirror, bind group, uniform offset)`.
    pub(crate) fn draw<'a>(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        scene_buffers: &SceneBuffers,
        pass_bind_group: &wgpu::BindGroup,
        offset: u32,
        mirrors: impl Iterator<Item = (usize, &'a wgpu::BindGroup, u32)>,
    ) {
        pass.set_vertex_buffer(0, scene_buffers.vertices.slice(..));
        pass.set_bind_group(0, &scene_buffers.bind_group, &[]);
        pass.set_bind_group(1, pass_bind_group, &[offset]);
        pass.set_pipeline(&self.objects);
        pass.draw(scene_buffers.objects.clone(), 0..1);
        let mut mirrors = mirrors.peekable();
        if mirrors.peek().is_some() {
            pass.set_pipeline(&self.mirrors);
            for (mirror, bind_group, offset) in mirrors {
                pass.set_bind_group(2, bind_group, &[offset]);
                pass.draw(scene_buffers.mirrors[mirror].clone(), 0..1);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::Queue;

    /// A wall of `side`² small mirrors facing the camera, each slightly tilted (as
    /// `scripts/make_mirror_mosaic.py` writes one), in front of a floor.
    fn mosaic(side: usize) -> Scene {
        let mirrors: Vec<String> = (0..side * side)
            .map(|i| {
                let (x, y) = ((i % side) as f32, (i / side) as f32);
                let tilt = 0.02 * ((i * 7 % 5) as f32 - 2.0);
                format!(
                    r#"{{ "center": [{}, {}, -2], "normal": [{tilt}, 0, 1], "up": [0, 1, 0],
                    "width": 0.3, "height": 0.3 }}"#,
                    0.35 * (x - side as f32 / 2.0),
                    0.5 + 0.35 * y
                )
            })
            .collect();
        let text = format!(
            r#"{{ "camera": {{ "position": [0, 1.5, 3], "look_at": [0, 1.2, -2],
                "fov_y_deg": 60, "width": 64, "height": 36 }},
              "mirrors": [ {} ],
              "objects": [ {{ "type": "quad", "size": [6, 6], "albedo": [0.5, 0.5, 0.5],
                "transform": {{ "rotate_deg": [-90, 0, 0] }} }} ],
              "lights": [ {{ "position": [0, 3, 1], "intensity": [10, 10, 10] }} ] }}"#,
            mirrors.join(",")
        );
        mirrorbox_scene::load::parse_scene(&text, std::path::Path::new("mosaic.json")).unwrap()
    }

    /// A memory estimate schedules a frame's ~N² mirror draws (N mirrors, each drawn in the
    /// others' textures) by counting them, keeping no draw list and no binding (issue 51: the
    /// estimate of 4 000 facets held 774 MB of them before refusing the frame), and counts
    /// their host bytes in the estimate.
    #[test]
    fn the_estimate_counts_mirror_draws_without_keeping_them() {
        let side = 6;
        let n = side * side;
        let scene = mosaic(side);
        let plan = crate::plan::plan(&scene, Queue::SceneMirrors, 64, 36, 5000).unwrap();
        assert!(
            plan.passes > n / 2,
            "most facets get a texture: {}",
            plan.passes
        );
        let bump = BumpSettings {
            mode: 0,
            strength: 0.0,
            proxy_distance: 0.0,
            march_steps: 0,
            margin: 0,
        };
        let views = [MainView {
            camera: scene.camera.clone(),
            lookup: None,
        }];
        let b = schedule(
            &scene,
            &plan,
            1.0,
            bump,
            &views,
            UniformArena::with_alignment(256),
        );
        assert!(b.passes.iter().all(|p| p.draws.is_empty()));
        assert!(b.mirror_bindings.is_empty());
        // Every pass draws every mirror but those in its own portal's plane (a fifth of the
        // facets share the untilted plane): more than (passes)·N/2.
        let at_least = (plan.passes * n / 2) as u64;
        let count = b.mirror_draw_count;
        assert!(count >= at_least, "{count} draws, at least {at_least}");
        drop(b);
        let planned = PlannedTextures {
            plan,
            texture_scale: 1.0,
            bump,
            views: views.to_vec(),
        };
        let estimate = texture_memory(&scene, &planned, 8);
        let lists = estimate
            .parts
            .iter()
            .find(|p| p.what == "the mirror draw lists")
            .expect("the estimate names the draw lists");
        assert_eq!(lists.host_bytes, count * MIRROR_DRAW_HOST_BYTES);
    }
}
