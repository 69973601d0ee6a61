//! The wgpu rasterizer of mirrorbox.
//!
//! Three floors, each importing only the ones below it (`tests::floors`):
//! - [`plan`]: what every method plans from, on the CPU (the seed paper's recursion, the
//!   exact methods' reflection paths, culling, symmetry cells, shadow plans, the memory
//!   estimate, the projection);
//! - [`gpu`]: the wgpu layer (adapter, device, targets, pipelines, caches, resolve, timing,
//!   readback, WGSL composition);
//! - the methods, [`methods`] (one file each, one row each in [`METHODS`]: see
//!   `CONTRIBUTING.md`), and what they share at this crate's root: [`method`] (the
//!   interface — [`MethodEntry`], the [`RasterMethod`] trait, options, parameters, frame
//!   stats), [`registry`] (the table looked up, configured [`Method`]s and their keys),
//!   [`exact_options`] (the exact methods' options), [`ping_pong`] (the frame-to-frame state
//!   of `feedback` and `cubemap`), [`shading`] (the scene buffers the contract's WGSL reads),
//!   [`shadow_maps`], [`lighting`], [`uneven`], [`stereo_pair`] and [`stereo_mirrors`].

pub mod exact_options;
pub mod gpu;
pub mod lighting;
pub mod method;
mod method_options;
pub mod methods;
pub mod ping_pong;
pub mod plan;
pub mod registry;
pub mod shading;
pub mod shadow_maps;
pub mod stereo_mirrors;
pub mod stereo_pair;
pub mod uneven;

// The floors' modules at the crate's root too, where the crates above (and the methods)
// have always named them: `mirrorbox_raster::targets` is `gpu::targets`.
pub use gpu::{
    adapter, camera_rays, color_format, display_tone_map, pipeline, readback, resolve, state_cache,
    targets, timing, wgsl,
};
pub use plan::{culling, exact_paths, memory, projection, shadow_plan, symmetry_cells};

pub use adapter::{
    AdapterError, AdapterReport, MIN_MESA, SelectedAdapter, mesa_shader_cache_disabled,
    mesa_version, select_adapter,
};
pub use color_format::ColorFormat;
pub use gpu::{Gpu, GpuOptions, RasterError};
pub use memory::{DEFAULT_MEMORY_BUDGET, MemoryEstimate, OverMemoryBudget, parse_memory_size};
pub use method::{
    Advise, Clipping, CopyCounts, FrameStats, MethodEntry, OptionSpec, ParamError, ParamValue,
    PathCounts, RasterMethod,
};
pub use plan::PlanError;
pub use registry::{METHODS, Method};
pub use timing::{FrameHistory, FrameTiming, TimingSource};

use mirrorbox_image::RgbImage;
use mirrorbox_scene::Scene;
use mirrorbox_scene::limits::SettingError;

/// Largest supersampling factor.
pub const MAX_SSAA: u32 = 8;
/// Most timed frames per render (each keeps two GPU timestamps and one duration).
pub const MAX_FRAMES: u32 = 10_000;
/// Most untimed warm-up frames.
pub const MAX_WARMUP: u32 = 1_000;
/// Largest render-target side (camera × SSAA); the device's `max_texture_dimension_2d` may
/// be lower (checked when the frame is built).
pub const MAX_RENDER_SIDE: u32 = mirrorbox_scene::limits::MAX_IMAGE_SIDE;

/// How to render: the method and what every method shares.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub method: Method,
    /// Supersampling factor s (the s×s sub-pixel grid of the tracer's `--spp s²`).
    pub ssaa: u32,
    /// Timed frames, after `warmup` untimed ones.
    pub frames: u32,
    pub warmup: u32,
}

impl RenderSettings {
    /// One timed frame after two warm-up frames, no supersampling.
    pub fn new(method: Method) -> Self {
        RenderSettings {
            method,
            ssaa: 1,
            frames: 1,
            warmup: 2,
        }
    }

    /// The one check of the settings every method shares (`render` and `sweep` alike):
    /// SSAA in `[1, MAX_SSAA]`, `frames` in `[1, MAX_FRAMES]`, `warmup` at most
    /// `MAX_WARMUP`, and a render size (camera × SSAA) of at most `MAX_RENDER_SIDE` per side
    /// and [`MAX_PIXELS`](mirrorbox_scene::limits::MAX_PIXELS) in all (an RGBA32F target of
    /// that size is 1.1 GB).
    pub fn check(&self, scene: &Scene) -> Result<(), SettingError> {
        if !(1..=MAX_SSAA).contains(&self.ssaa) {
            return Err(SettingError::new(
                "--ssaa",
                format!("in [1, {MAX_SSAA}]"),
                self.ssaa,
            ));
        }
        if !(1..=MAX_FRAMES).contains(&self.frames) {
            return Err(SettingError::new(
                "--frames",
                format!("in [1, {MAX_FRAMES}]"),
                self.frames,
            ));
        }
        if self.warmup > MAX_WARMUP {
            return Err(SettingError::new(
                "--warmup",
                format!("in [0, {MAX_WARMUP}]"),
                self.warmup,
            ));
        }
        let (w, h) = (
            u64::from(scene.camera.width) * u64::from(self.ssaa),
            u64::from(scene.camera.height) * u64::from(self.ssaa),
        );
        let max_pixels = mirrorbox_scene::limits::MAX_PIXELS;
        if w.max(h) > u64::from(MAX_RENDER_SIDE) || w * h > max_pixels {
            return Err(SettingError::new(
                "--ssaa",
                format!(
                    "such that the render (image × SSAA) is at most {MAX_RENDER_SIDE} pixels per side and {max_pixels} in all"
                ),
                format!("{} (a {w}×{h} render)", self.ssaa),
            ));
        }
        Ok(())
    }

    /// Render resolution: the scene camera's size × SSAA.
    pub fn render_size(&self, scene: &Scene) -> (u32, u32) {
        (
            scene.camera.width * self.ssaa,
            scene.camera.height * self.ssaa,
        )
    }
}

pub struct RenderOutput {
    /// The view; in a stereo pair's frame ([`stereo_pair::render_pair`]) the left eye.
    pub image: RgbImage,
    /// A stereo pair's right eye.
    pub right_eye: Option<RgbImage>,
    pub timing: FrameTiming,
    pub stats: FrameStats,
    /// The format of every colour target and mirror texture it was rendered into (RGBA16F
    /// adds its rounding, `ColorFormat::relative_store_error`, each time a value is stored).
    pub color_format: ColorFormat,
    /// Conditions under which the image may not be what the method promises.
    pub warnings: Vec<String>,
    /// GPU memory the device held while the frame's resources were alive.
    pub gpu_memory: GpuMemory,
    /// CPU milliseconds of baking geometry while planning (`symmetry-baked`), apart from the
    /// frame time ([`method::BuiltFrame::bake_ms`]).
    pub bake_ms: Option<f64>,
    /// What a stateful method (`feedback`) leaves for the next frame of a sequence
    /// ([`render_planned_after`]); `None` for the others.
    pub history: Option<FrameHistory>,
}

/// Bytes of GPU memory held by the device's buffers and textures (wgpu's internal counters:
/// the allocation sizes its backend made, alignment included), read while a frame's
/// resources are alive. Device-wide: in a render worker, which renders one point, that is
/// the point's footprint plus the resolve target and readback buffers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuMemory {
    pub buffer_bytes: u64,
    pub texture_bytes: u64,
}

impl GpuMemory {
    pub fn read(gpu: &Gpu) -> GpuMemory {
        let hal = gpu.device.get_internal_counters().hal;
        let bytes = |c: isize| u64::try_from(c).unwrap_or(0);
        GpuMemory {
            buffer_bytes: bytes(hal.buffer_memory.read()),
            texture_bytes: bytes(hal.texture_memory.read()),
        }
    }
}

/// A frame planned on the CPU: a refused configuration (too many passes, paths, …) fails
/// here, before any GPU resource exists.
pub struct Planned {
    frame: Box<dyn method::PlannedFrame>,
    /// Its shadow-map layers (`--shadows map` on a scene with shadows).
    shadows: Option<shadow_plan::ShadowPlan>,
    /// What it was planned for: the method's key and the render size.
    key: String,
    size: (u32, u32),
}

impl Planned {
    /// Makes a stateful method (`feedback`) continue from the previous frame's `history`
    /// instead of starting afresh (and drawing its `--history` pre-roll).
    pub fn continue_from(&mut self, history: FrameHistory) {
        self.frame.continue_from(history);
    }

    /// The memory this frame will need when built and rendered for `scene` with `settings`
    /// (those it was planned with), computed from the plan before any GPU resource exists
    /// ([`memory`] gives the formula):
    ///
    /// `gpu = target(W·s, H·s) + resolve(W, H) + readback(W, H) + shadow maps + wgpu's own +
    /// method` and `host = driver + 48·W·H + method`, where `target` is colour (16 bytes a
    /// texel, RGBA32F) + depth (4), the shadow maps `layers × size² × 4` + one depth layer +
    /// a vertex buffer of every triangle, and `method` is
    /// [`PlannedFrame::memory`](method::PlannedFrame::memory) (its scene buffers, mirror
    /// textures, uniforms, instance buffers, …).
    pub fn memory_estimate(&self, scene: &Scene, settings: &RenderSettings) -> MemoryEstimate {
        let scene = &*lighting::lit_scene(scene, settings.method.params());
        let color = u64::from(ColorFormat::Rgba32Float.texel_bytes());
        let mut estimate = frame_memory(scene, settings, self.shadows.as_ref(), 1);
        estimate.merge(self.frame.memory(scene, color));
        estimate
    }

    /// [`Planned::memory_estimate`], refused above `budget` bytes
    /// ([`PlanError::OverMemoryBudget`], exit 2: the estimate, the budget and what to lower).
    /// What `render`, `view` and a sweep's points call after planning and before building.
    pub fn check_memory(
        &self,
        scene: &Scene,
        settings: &RenderSettings,
        budget: u64,
    ) -> Result<MemoryEstimate, PlanError> {
        let estimate = self.memory_estimate(scene, settings);
        estimate.check(budget)?;
        Ok(estimate)
    }
}

/// The memory every frame has whatever its method, for `views` views (a stereo pair: 2):
/// the render targets at the SSAA size, the resolves' outputs and readback buffers at the
/// image size, the shadow maps (or their 1×1 placeholder), wgpu's own buffers, the driver,
/// and the images' copies on the CPU.
pub(crate) fn frame_memory(
    scene: &Scene,
    settings: &RenderSettings,
    shadows: Option<&shadow_plan::ShadowPlan>,
    views: u64,
) -> MemoryEstimate {
    use memory::{buffer_bytes, target_bytes, texture_bytes, uniform_arena_bytes};
    let color = u64::from(ColorFormat::Rgba32Float.texel_bytes());
    let (w, h) = settings.render_size(scene);
    let (ow, oh) = (scene.camera.width, scene.camera.height);
    let image = "the image size (--width/--height)";
    let mut e = MemoryEstimate::new();
    e.gpu(
        "the render target",
        "the image size (--width/--height) or --ssaa",
        views * target_bytes(w, h, color),
    );
    let readback_row = (u64::from(ow) * color).next_multiple_of(256);
    e.gpu(
        "the resolve and readback",
        image,
        views
            * (texture_bytes(ow, oh, color)
                + buffer_bytes(16)
                + buffer_bytes(readback_row * u64::from(oh))),
    );
    let shadow_bytes = match shadows {
        None => texture_bytes(1, 1, 4),
        Some(plan) => {
            let size = plan.settings.size;
            // R32F layers (RGBA16F, 8 bytes, on a device whose colours are RGBA16F).
            let layer = texture_bytes(size, size, if color >= 16 { 4 } else { 8 });
            let layers = (plan.views.len() as u64).max(1);
            let triangles = scene.geometry.triangles.len() as u64;
            layers * layer
                + texture_bytes(size, size, memory::DEPTH_BYTES)
                + uniform_arena_bytes(plan.views.len() as u64)
                + buffer_bytes(3 * triangles.max(1) * std::mem::size_of::<shading::Vertex>() as u64)
        }
    };
    e.gpu(
        "the shadow maps",
        "--shadow-map-size or lighting.mirrored_lights (--mirrored-lights)",
        shadow_bytes,
    );
    e.gpu("wgpu's own buffers", "", memory::WGPU_DEVICE_BYTES);
    e.host("the driver", "", memory::DRIVER_HOST_BYTES);
    e.host(
        "the image's copies",
        image,
        views * u64::from(ow) * u64::from(oh) * memory::HOST_BYTES_PER_PIXEL,
    );
    e
}

/// Plans `settings.method` for `scene` at render resolution, without a GPU.
pub fn plan_frame(scene: &Scene, settings: &RenderSettings) -> Result<Planned, PlanError> {
    let scene = &*lighting::lit_scene(scene, settings.method.params());
    settings.check(scene)?;
    let (w, h) = settings.render_size(scene);
    let shadows = lighting::shadow_settings(scene, settings.method.params())
        .map(|s| shadow_plan::ShadowPlan::new(scene, s))
        .transpose()?;
    let frame = settings.method.configure().plan(scene, w, h)?;
    Ok(Planned {
        frame,
        shadows,
        key: settings.method.key(),
        size: (w, h),
    })
}

/// The checks every planned frame passes before it is built: the method's required
/// features, the plan made for these settings (key and size), the render target and the
/// scene buffers within the device's limits. Returns the render size.
pub(crate) fn check_planned_frame(
    gpu: &Gpu,
    scene: &Scene,
    settings: &RenderSettings,
    planned_key: &str,
    planned_size: (u32, u32),
) -> Result<(u32, u32), RasterError> {
    settings.method.entry().check_features(gpu)?;
    let (w, h) = settings.render_size(scene);
    assert!(
        planned_key == settings.method.key() && planned_size == (w, h),
        "a frame planned for {} at {:?} rendered as {} at {:?}",
        planned_key,
        planned_size,
        settings.method.key(),
        (w, h)
    );
    gpu.check_target(w, h, "; lower --ssaa or the image size")?;
    shading::SceneBuffers::check_fits(gpu, scene)?;
    Ok((w, h))
}

/// Counts a frame's shadow-map layers as scene passes, and warns when `--shadows map` has
/// nothing to draw.
pub(crate) fn add_shadow_maps(
    stats: &mut FrameStats,
    warnings: &mut Vec<String>,
    shadows: &shadow_maps::ShadowMaps,
    scene: &Scene,
    settings: &RenderSettings,
) {
    if lighting::wants_shadow_maps(settings.method.params()) && !scene.lighting.shadows {
        warnings.push(
            "--shadows map: the scene has no shadows (lighting.shadows is false), so no shadow \
             map is drawn"
                .into(),
        );
    }
    stats.passes += shadows.layers();
    stats.draws += shadows.layers();
    stats.triangles += shadows.triangles();
}

/// A frame built on the device, ready to be drawn any number of times: what `render` times
/// once, and what `mirrorbox view` draws every frame while the view stays the same (a
/// method's uniforms hold the camera: a moved camera builds a frame again, with
/// [`build_planned_reusing`], from the device's cached pipelines and the previous frame's
/// targets).
pub struct BuiltView {
    target: targets::RenderTarget,
    resolve: resolve::Resolve,
    encoder: Box<dyn timing::FrameEncoder>,
    /// [`BuiltView::draw`]'s timestamp queries, made at its first call (`render` times
    /// with [`BuiltView::run`]'s own).
    queries: std::sync::OnceLock<Option<timing::FrameQueries>>,
    pub stats: FrameStats,
    pub warnings: Vec<String>,
    pub bake_ms: Option<f64>,
}

impl BuiltView {
    /// Draws `warmup + frames` frames, times the last `frames` and reads the last back.
    pub fn run(
        &self,
        gpu: &Gpu,
        warmup: u32,
        frames: u32,
    ) -> Result<(RgbImage, FrameTiming), RasterError> {
        timing::run_frames(
            gpu,
            self.encoder.as_ref(),
            &self.target,
            &self.resolve,
            warmup,
            frames,
        )
    }

    /// Draws one frame and waits for it, without reading the image back (the viewer
    /// tone-maps [`BuiltView::output`] into its window as it paints). Returns the frame's
    /// milliseconds and how they were measured.
    pub fn draw(&self, gpu: &Gpu) -> Result<(f64, TimingSource), RasterError> {
        let encode =
            |encoder: &mut wgpu::CommandEncoder,
             first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>| {
                self.encoder.encode(encoder, &self.target, first_pass)
            };
        let queries = self
            .queries
            .get_or_init(|| timing::FrameQueries::new(gpu))
            .as_ref();
        let (ms, _) = timing::submit_frame(gpu, queries, &encode, &[&self.resolve])?;
        let source = if queries.is_some() {
            TimingSource::GpuTimestamps
        } else {
            TimingSource::WallClock
        };
        Ok((ms, source))
    }

    /// The linear image of the frame last drawn (the values `render` writes), read back.
    pub fn read_image(&self, gpu: &Gpu) -> Result<RgbImage, RasterError> {
        readback::read_texture(gpu, &self.resolve.output)
    }

    /// The texture the frame's image is resolved into (the image's size, the device's colour
    /// format), readable by a shader.
    pub fn output(&self) -> &wgpu::Texture {
        &self.resolve.output
    }

    /// Commits the frame last drawn as the state of a stateful method (`feedback`): the next
    /// [`BuiltView::run`] or [`BuiltView::draw`] draws the frame after it. What `mirrorbox view` does every frame.
    pub fn advance(&self) {
        self.encoder.advance();
    }

    /// The counts of the frame last drawn (a stateful method's reflections change as its
    /// frames advance).
    pub fn drawn_stats(&self) -> FrameStats {
        FrameStats {
            depth: self.encoder.drawn_depth().unwrap_or(self.stats.depth),
            ..self.stats
        }
    }

    /// The state a frame of the next view continues from ([`Planned::continue_from`]).
    pub fn history(&self) -> Option<FrameHistory> {
        self.encoder.history()
    }
}

/// Builds a planned frame's GPU resources (its shadow maps included) at the scene camera's
/// size.
pub fn build_planned(
    gpu: &Gpu,
    scene: &Scene,
    planned: Planned,
    settings: &RenderSettings,
) -> Result<BuiltView, RasterError> {
    build_planned_reusing(gpu, scene, planned, settings, None)
}

/// [`build_planned`] in place of `previous` (the viewer's frame before the camera moved or
/// a setting changed): its render target, resolve and timestamp queries are kept where the
/// render size and SSAA factor are the same, so only what the plan changes is made again
/// (the pipelines come from the device's cache, [`state_cache`]).
pub fn build_planned_reusing(
    gpu: &Gpu,
    scene: &Scene,
    planned: Planned,
    settings: &RenderSettings,
    previous: Option<BuiltView>,
) -> Result<BuiltView, RasterError> {
    let scene = &*lighting::lit_scene(scene, settings.method.params());
    let (w, h) = check_planned_frame(gpu, scene, settings, &planned.key, planned.size)?;
    let kept = previous.and_then(|p| {
        (p.target.width == w && p.target.height == h && p.resolve.factor == settings.ssaa)
            .then_some((p.target, p.resolve, p.queries))
    });
    let (target, resolve, queries) = match kept {
        Some(kept) => kept,
        None => {
            let target =
                targets::RenderTarget::new(gpu, "view", w, h, wgpu::TextureUsages::TEXTURE_BINDING);
            let resolve = resolve::Resolve::new(gpu, &target, settings.ssaa);
            (target, resolve, Default::default())
        }
    };
    let shadows = shadow_maps::ShadowMaps::new(gpu, scene, planned.shadows)?;
    let mut built = planned.frame.build(gpu, scene, &shadows)?;
    add_shadow_maps(
        &mut built.stats,
        &mut built.warnings,
        &shadows,
        scene,
        settings,
    );
    if shadows.layers() > 0 {
        built.encoder = Box::new(shadow_maps::WithShadowMaps {
            shadows,
            method: built.encoder,
        });
    }
    gpu.check()?;
    timing::preroll(gpu, built.encoder.as_ref(), &target)?;
    Ok(BuiltView {
        target,
        resolve,
        encoder: built.encoder,
        queries,
        stats: built.stats,
        warnings: built.warnings,
        bake_ms: built.bake_ms,
    })
}

/// Renders a planned frame at the scene camera's size.
pub fn render_planned(
    gpu: &Gpu,
    scene: &Scene,
    planned: Planned,
    settings: &RenderSettings,
) -> Result<RenderOutput, RasterError> {
    render_planned_after(gpu, scene, planned, settings, None)
}

/// [`render_planned`] for a frame of a sequence: a stateful method (`feedback`) continues
/// from the previous frame's `history` (one more frame of its recursion, from this frame's
/// camera), and the output's `history` is what the next frame continues from. Every timed
/// frame draws this same frame from the same state; the frame is committed once, after.
pub fn render_planned_after(
    gpu: &Gpu,
    scene: &Scene,
    mut planned: Planned,
    settings: &RenderSettings,
    history: Option<FrameHistory>,
) -> Result<RenderOutput, RasterError> {
    if let Some(h) = history {
        planned.continue_from(h);
    }
    let built = build_planned(gpu, scene, planned, settings)?;
    let (image, timing) = built.run(gpu, settings.warmup, settings.frames)?;
    built.advance();
    let history = built.history();
    let gpu_memory = GpuMemory::read(gpu);
    Ok(RenderOutput {
        image,
        right_eye: None,
        timing,
        stats: built.stats,
        color_format: gpu.color_format,
        warnings: built.warnings,
        gpu_memory,
        bake_ms: built.bake_ms,
        history,
    })
}

/// Plans, then renders `scene` at its camera's size with `settings`.
pub fn render(
    gpu: &Gpu,
    scene: &Scene,
    settings: &RenderSettings,
) -> Result<RenderOutput, RasterError> {
    let planned = plan_frame(scene, settings)?;
    render_planned(gpu, scene, planned, settings)
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;
    use std::path::{Path, PathBuf};

    /// The `.rs` files of `dir` (one level).
    fn files(dir: &Path) -> Vec<PathBuf> {
        let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "rs"))
            .collect();
        out.sort();
        out
    }

    /// The crate paths a file's code names (`crate::NAME`, `use crate::{A, B::…}`, macros
    /// `crate::NAME!`): the first segment after `crate::`. Comments and the `tests` module at
    /// the file's end are not code that ships.
    fn names(path: &Path) -> BTreeSet<String> {
        let text = std::fs::read_to_string(path).unwrap();
        let code = text.split("\n#[cfg(test)]\nmod tests").next().unwrap();
        let mut out = BTreeSet::new();
        for line in code.lines().filter(|l| !l.trim_start().starts_with("//")) {
            for (i, _) in line.match_indices("crate::") {
                let rest = &line[i + "crate::".len()..];
                if let Some(list) = rest.strip_prefix('{') {
                    // `use crate::{a, b::c};` on one line (rustfmt breaks long ones).
                    for item in list.split([',', '}']) {
                        let first = item.trim().split("::").next().unwrap_or("");
                        if !first.is_empty() {
                            out.insert(first.to_string());
                        }
                    }
                } else {
                    let name: String = rest
                        .chars()
                        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                        .collect();
                    out.insert(name);
                }
            }
        }
        out
    }

    /// The module names of a floor: its folder's files and the floor itself.
    fn floor(dir: &Path) -> BTreeSet<String> {
        let mut out: BTreeSet<String> = files(dir)
            .iter()
            .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
            .filter(|n| n != "mod")
            .collect();
        out.insert(dir.file_name().unwrap().to_string_lossy().into_owned());
        out
    }

    /// The rasterizer's floors (issue 52): `plan/` imports nothing of the crate above itself,
    /// `gpu/` nothing above `plan/` and itself — the methods and what they share import both,
    /// never the other way round. (The floors' modules are re-exported at the crate's root,
    /// so a name is judged by the module it names, whatever path the code takes to it.)
    #[test]
    fn floors() {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let plan = floor(&src.join("plan"));
        let mut gpu = floor(&src.join("gpu"));
        // The macros `gpu::wgsl` exports at the crate's root.
        gpu.extend(["host_layout", "mirror_plane_shaders"].map(String::from));
        let mut wrong = Vec::new();
        for (dir, allowed) in [
            ("plan", plan.clone()),
            ("gpu", plan.union(&gpu).cloned().collect()),
        ] {
            for file in files(&src.join(dir)) {
                for name in names(&file) {
                    if !allowed.contains(&name) {
                        wrong.push(format!(
                            "src/{dir}/{} names crate::{name}, above its floor",
                            file.file_name().unwrap().to_string_lossy()
                        ));
                    }
                }
            }
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
        assert!(plan.len() >= 7 && gpu.len() >= 12, "{plan:?} {gpu:?}");
    }
}
