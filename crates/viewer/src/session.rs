//! What the viewer shows, apart from the window: the method's frame (rebuilt when the view
//! or the settings change, redrawn every frame), the live truth, the error view, the frame
//! times, and the textures the panes are painted from.

use crate::error_view::{ErrorImage, ErrorMode, error_image};
use crate::fly_camera::FlyCamera;
use crate::live_truth::{LiveTruth, TruthDevice, TruthLevel, TruthRequest, level_count};
use mirrorbox_image::RgbImage;
use mirrorbox_raster::display_tone_map::{DisplayToneMap, ToneMapSource};
use mirrorbox_raster::{BuiltView, FrameStats, Gpu, Method, RasterError, RenderSettings};
use mirrorbox_scene::{Camera, Scene};
use std::collections::VecDeque;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Frame times kept for the graph.
pub const HISTORY: usize = 600;

/// The truth's or the error's pane on the GPU, as egui paints it: RGBA8 holding the
/// contract's sRGB bytes (egui's textures are not sRGB-aware; its shader writes them to a
/// non-sRGB target as they are, so a pane shown 1:1 holds the same bytes as the PNG `trace`
/// writes).
pub struct PaneTexture {
    pub texture: wgpu::Texture,
    pub id: Option<egui::TextureId>,
    pub size: (u32, u32),
    pub filter: wgpu::FilterMode,
}

impl PaneTexture {
    fn new(device: &wgpu::Device, label: &str, size: (u32, u32)) -> Self {
        let texture = mirrorbox_raster::targets::texture_2d(
            device,
            label,
            size.0,
            size.1,
            wgpu::TextureFormat::Rgba8Unorm,
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        );
        PaneTexture {
            texture,
            id: None,
            size,
            filter: wgpu::FilterMode::Nearest,
        }
    }

    /// Writes RGB 8-bit sRGB bytes of `size` into the texture (the truth's and the error's
    /// panes, images of the CPU), recreating it (and its egui registration) when the size
    /// changed.
    pub fn upload(
        slot: &mut Option<PaneTexture>,
        gpu: &Gpu,
        renderer: &mut egui_wgpu::Renderer,
        label: &str,
        size: (u32, u32),
        rgb: &[u8],
    ) {
        if slot.as_ref().map(|t| t.size) != Some(size) {
            if let Some(old) = slot.take().and_then(|t| t.id) {
                renderer.free_texture(&old);
            }
            let mut t = PaneTexture::new(&gpu.device, label, size);
            let view = t.texture.create_view(&Default::default());
            t.id = Some(renderer.register_native_texture(&gpu.device, &view, t.filter));
            *slot = Some(t);
        }
        let t = slot.as_ref().expect("texture just made");
        let rgba: Vec<u8> = rgb
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect();
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &t.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            &rgba,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * size.0),
                rows_per_image: Some(size.1),
            },
            wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: 1,
            },
        );
    }

    /// Samples nearest when shown 1:1 (the exact bytes), linearly when scaled.
    pub fn set_filter(
        &mut self,
        gpu: &Gpu,
        renderer: &mut egui_wgpu::Renderer,
        filter: wgpu::FilterMode,
    ) {
        if filter != self.filter
            && let Some(id) = self.id
        {
            self.filter = filter;
            let view = self.texture.create_view(&Default::default());
            renderer.update_egui_texture_from_wgpu_texture(&gpu.device, &view, filter, id);
        }
    }
}

/// The method's last frame.
pub struct MethodFrame {
    /// Its linear image, read back from the GPU when first asked for
    /// ([`Session::method_image`]: the error view, a screenshot); the pane is the frame
    /// tone-mapped on the GPU without it.
    image: std::cell::OnceCell<Arc<RgbImage>>,
    pub stats: FrameStats,
    /// GPU milliseconds of the frame (timestamps), or the CPU wall time of submit-to-done
    /// where the adapter has no timestamps.
    pub gpu_ms: f64,
    pub timing_source: String,
    pub warnings: Vec<String>,
    /// The camera it was drawn from.
    pub camera: Camera,
    /// Counts rebuilds: a new value means a new image.
    pub build: u64,
}

/// One entry of the frame-time history.
#[derive(Clone, Copy, Debug)]
pub struct FrameTime {
    /// Wall time since the previous frame (what the user sees as the frame rate).
    pub wall_ms: f64,
    /// The method's frame on the GPU.
    pub gpu_ms: f64,
    /// CPU time spent re-planning and building the method's frame (a moved camera).
    pub build_ms: f64,
    /// Of `build_ms`, planning on the CPU (paths, visibility, culling for the new view).
    pub plan_ms: f64,
}

/// Milliseconds of one update's parts (the log's `phases_ms`).
#[derive(Clone, Copy, Debug, Default)]
pub struct UpdatePhases {
    /// Planning and building the method's frame (0 while the view stays).
    pub build: f64,
    /// Of `build`, planning on the CPU.
    pub plan: f64,
    /// Drawing the frame on the GPU and waiting for it (its pane is tone-mapped from the
    /// GPU's image as the window paints).
    pub draw: f64,
    /// Tone mapping and uploading the truth's and the error's panes (images of the CPU,
    /// when they change), the method's image read back when the error view needs it.
    pub panes: f64,
}

/// A method frame built for one view and setting.
struct Built {
    view: BuiltView,
    key: String,
    camera: Camera,
}

pub struct Session {
    /// The scene, its camera replaced by each view's before planning (the live truth keeps
    /// its own copy: two in all).
    pub scene: Scene,
    pub camera: FlyCamera,
    pub method: Method,
    pub ssaa: u32,
    /// The view's size in pixels (the method's image and the truth's last level).
    pub size: (u32, u32),
    /// `--memory-budget`: a plan whose estimate exceeds it is refused like any other
    /// refused setting (its message in the method pane), before any GPU resource.
    pub memory_budget: u64,
    built: Option<Built>,
    builds: u64,
    /// Why the current settings were refused (shown in the panel and the method pane).
    pub method_error: Option<String>,
    refused_key: Option<String>,
    pub frame: Option<MethodFrame>,
    pub truth_enabled: bool,
    truth: LiveTruth,
    pub truth_shown: Option<TruthLevel>,
    pub error_mode: ErrorMode,
    pub error_gain: f32,
    pub error: Option<ErrorImage>,
    /// (method build, truth generation, mode, gain bits) of the error shown.
    error_key: Option<(u64, u64, ErrorMode, u32)>,
    pub history: VecDeque<FrameTime>,
    pub update_phases: UpdatePhases,
    last_frame: Option<Instant>,
    pub truth_texture: Option<PaneTexture>,
    pub error_texture: Option<PaneTexture>,
    /// The GPU tone map that paints the method's pane into the window (set by the window,
    /// which knows its format), and its binding of the current frame's image.
    pub display_tone_map: Option<Arc<DisplayToneMap>>,
    method_source: Option<Arc<ToneMapSource>>,
}

impl Session {
    pub fn new(
        scene: Scene,
        method: Method,
        ssaa: u32,
        size: (u32, u32),
        truth_device: TruthDevice,
    ) -> Self {
        let mut scene = scene;
        scene.stereo = None;
        scene.head = None;
        Session {
            camera: FlyCamera::new(scene.camera.clone()),
            truth: LiveTruth::start(Arc::new(scene.clone()), truth_device),
            scene,
            method,
            ssaa,
            size,
            memory_budget: mirrorbox_raster::DEFAULT_MEMORY_BUDGET,
            built: None,
            builds: 0,
            method_error: None,
            refused_key: None,
            frame: None,
            truth_enabled: true,
            truth_shown: None,
            error_mode: ErrorMode::Difference,
            error_gain: 4.0,
            error: None,
            error_key: None,
            history: VecDeque::with_capacity(HISTORY),
            update_phases: UpdatePhases::default(),
            last_frame: None,
            truth_texture: None,
            error_texture: None,
            display_tone_map: None,
            method_source: None,
        }
    }

    /// The scene camera of the current view.
    pub fn view_camera(&self) -> Camera {
        self.camera.camera(self.size.0, self.size.1)
    }

    fn settings(&self) -> RenderSettings {
        RenderSettings {
            method: self.method.clone(),
            ssaa: self.ssaa,
            frames: 1,
            warmup: 0,
        }
    }

    /// Draws the method's frame for the current view (planning and building it first when
    /// the view or the settings changed), asks the live truth for this view, takes its
    /// newest level and recomputes the error view when either changed. Uploads what changed.
    /// A refused setting (too many passes, …) is reported in `method_error`; a device failure
    /// is returned.
    pub fn update(
        &mut self,
        gpu: &Gpu,
        renderer: &mut egui_wgpu::Renderer,
    ) -> Result<(), RasterError> {
        let now = Instant::now();
        let wall_ms = self
            .last_frame
            .map(|t| now.duration_since(t).as_secs_f64() * 1e3)
            .unwrap_or(0.0);
        self.last_frame = Some(now);
        let camera = self.view_camera();
        let settings = self.settings();
        let key = format!(
            "{} ssaa={} {:?}",
            settings.method.key(),
            settings.ssaa,
            camera
        );
        let (mut build_ms, mut plan_ms) = (0.0, 0.0);
        let refused_again = self.method_error.is_some() && self.refused_key.as_ref() == Some(&key);
        if self.built.as_ref().map(|b| &b.key) != Some(&key) && !refused_again {
            let started = Instant::now();
            self.scene.camera = camera.clone();
            let scene = &self.scene;
            // A stateful method (`feedback`) continues from the frame drawn last, as in an
            // engine: a moved camera reads the textures of where it was.
            let history = self.built.as_ref().and_then(|b| b.view.history());
            // The frame being replaced: its targets serve the new one where sizes agree.
            let previous = self.built.take().map(|b| b.view);
            let budget = self.memory_budget;
            match mirrorbox_raster::plan_frame(scene, &settings)
                .and_then(|mut planned| {
                    if let Some(h) = history {
                        planned.continue_from(h);
                    }
                    planned.check_memory(scene, &settings, budget)?;
                    plan_ms = started.elapsed().as_secs_f64() * 1e3;
                    Ok(planned)
                })
                .map_err(RasterError::from)
                .and_then(|planned| {
                    mirrorbox_raster::build_planned_reusing(
                        gpu, scene, planned, &settings, previous,
                    )
                }) {
                Ok(view) => {
                    self.builds += 1;
                    self.built = Some(Built {
                        view,
                        key,
                        camera: camera.clone(),
                    });
                    self.method_error = None;
                }
                Err(e) if e.is_refusal() => {
                    // The pane says why instead of showing another setting's image.
                    self.built = None;
                    self.frame = None;
                    self.method_source = None;
                    self.method_error = Some(e.to_string());
                    // Not planned again until the view or the settings change.
                    self.refused_key = Some(key);
                }
                Err(e) => return Err(e),
            }
            build_ms = started.elapsed().as_secs_f64() * 1e3;
        }
        let mut draw_ms = 0.0;
        let panes_start;
        if let Some(built) = &self.built {
            let drawing = Instant::now();
            // The frame alone: its pane is tone-mapped from `output` as the window paints.
            let (gpu_ms, timing_source) = built.view.draw(gpu)?;
            let output = built.view.output();
            if let Some(tone_map) = &self.display_tone_map
                && !self.method_source.as_ref().is_some_and(|s| s.reads(output))
            {
                self.method_source = Some(Arc::new(tone_map.bind(gpu, output)));
            }
            let stats = built.view.drawn_stats();
            // Every drawn frame is committed: feedback's row grows by one per frame.
            built.view.advance();
            draw_ms = drawing.elapsed().as_secs_f64() * 1e3;
            panes_start = Instant::now();
            self.frame = Some(MethodFrame {
                image: Default::default(),
                stats,
                gpu_ms,
                timing_source: timing_source.name().to_string(),
                warnings: built.view.warnings.clone(),
                camera: built.camera.clone(),
                build: self.builds,
            });
            if self.history.len() == HISTORY {
                self.history.pop_front();
            }
            self.history.push_back(FrameTime {
                wall_ms,
                gpu_ms,
                build_ms,
                plan_ms,
            });
        } else {
            panes_start = Instant::now();
        }
        self.update_truth(gpu, renderer);
        self.update_error(gpu, renderer)?;
        self.update_phases = UpdatePhases {
            build: build_ms,
            plan: plan_ms,
            draw: draw_ms,
            panes: panes_start.elapsed().as_secs_f64() * 1e3,
        };
        Ok(())
    }

    fn update_truth(&mut self, gpu: &Gpu, renderer: &mut egui_wgpu::Renderer) {
        if !self.truth_enabled {
            return;
        }
        self.truth.request(TruthRequest {
            camera: self.view_camera(),
            grid_side: self.ssaa,
        });
        let newest = self.truth.latest();
        let shown = self.truth_shown.as_ref().map(|l| (l.generation, l.level));
        match newest {
            Some(level) if Some((level.generation, level.level)) != shown => {
                let rgb = level.image.to_srgb8(self.scene.camera.exposure);
                PaneTexture::upload(
                    &mut self.truth_texture,
                    gpu,
                    renderer,
                    "truth pane",
                    (level.image.width, level.image.height),
                    &rgb,
                );
                self.truth_shown = Some(level);
            }
            Some(_) => {}
            None => {
                // The view changed and nothing of it is traced yet: keep showing the last
                // image only while it is of the same view.
                if self
                    .truth_shown
                    .as_ref()
                    .is_some_and(|l| l.generation != self.truth.generation())
                {
                    self.truth_shown = None;
                }
            }
        }
    }

    /// The complete truth of the view the method's frame shows, if the tracer has it: traced
    /// for this camera on this grid, whether or not the truth is on now.
    pub fn complete_truth(&self) -> Option<&TruthLevel> {
        let level = self.view_truth()?;
        (self.frame.as_ref()?.camera == level.request.camera).then_some(level)
    }

    /// The complete truth of the current view and grid, if traced, whatever the method drew
    /// (a refused method draws nothing; a script's `wait-truth` still ends).
    pub fn view_truth(&self) -> Option<&TruthLevel> {
        let level = self.truth_shown.as_ref().filter(|l| l.complete)?;
        (level.request.camera == self.view_camera() && level.request.grid_side == self.ssaa)
            .then_some(level)
    }

    /// What paints the method's pane this frame (the tone map and its binding of the frame's
    /// image), when there is a frame.
    pub fn method_pane(&self) -> Option<(Arc<DisplayToneMap>, Arc<ToneMapSource>)> {
        self.frame.as_ref()?;
        Some((self.display_tone_map.clone()?, self.method_source.clone()?))
    }

    /// The linear image of the method's frame shown (the values `render` writes), read back
    /// from the GPU the first time it is asked for after each drawn frame.
    pub fn method_image(&self, gpu: &Gpu) -> Result<Option<Arc<RgbImage>>, RasterError> {
        let (Some(frame), Some(built)) = (&self.frame, &self.built) else {
            return Ok(None);
        };
        if let Some(image) = frame.image.get() {
            return Ok(Some(image.clone()));
        }
        let image = Arc::new(built.view.read_image(gpu)?);
        Ok(Some(frame.image.get_or_init(|| image).clone()))
    }

    fn update_error(
        &mut self,
        gpu: &Gpu,
        renderer: &mut egui_wgpu::Renderer,
    ) -> Result<(), RasterError> {
        let (Some(truth), Some(frame)) = (self.complete_truth(), self.frame.as_ref()) else {
            self.error = None;
            self.error_key = None;
            return Ok(());
        };
        let key = (
            frame.build,
            truth.generation,
            self.error_mode,
            self.error_gain.to_bits(),
        );
        if self.error_key == Some(key) {
            return Ok(());
        }
        let truth_image = truth.image.clone();
        let Some(image) = self.method_image(gpu)? else {
            return Ok(());
        };
        match error_image(
            &truth_image,
            &image,
            self.scene.camera.exposure,
            self.error_mode,
            self.error_gain,
        ) {
            Ok(e) => {
                PaneTexture::upload(
                    &mut self.error_texture,
                    gpu,
                    renderer,
                    "error pane",
                    (e.width, e.height),
                    &e.heat_rgb8,
                );
                self.error = Some(e);
            }
            Err(_) => self.error = None,
        }
        self.error_key = Some(key);
        Ok(())
    }

    /// Waits for the current view's complete truth (a script's `wait-truth`).
    pub fn wait_truth(&self, timeout: Duration) -> bool {
        self.truth.wait_complete(timeout).is_some()
    }

    /// Where the live truth is traced, in words (and why not on the GPU, where that failed).
    pub fn truth_device(&self) -> String {
        match self.truth.device() {
            (device, None) => device.name().into(),
            (device, Some(why)) => format!("{} (GPU truth unavailable: {why})", device.name()),
        }
    }

    /// Which level the truth pane shows, in words.
    pub fn truth_progress(&self) -> String {
        match &self.truth_shown {
            _ if !self.truth_enabled => "off".into(),
            Some(l) if l.complete => format!(
                "complete: {}×{}, {} spp, traced in {:.0} ms",
                l.image.width,
                l.image.height,
                l.request.grid_side * l.request.grid_side,
                l.trace_time.as_secs_f64() * 1e3
            ),
            Some(l) => format!(
                "level {}/{} ({}×{}, 1 spp), refining",
                l.level + 1,
                level_count(),
                l.image.width,
                l.image.height
            ),
            None => "tracing…".into(),
        }
    }
}
