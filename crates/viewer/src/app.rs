//! The window: winit's event loop, the wgpu surface on the adapter `mirrorbox info` reports
//! (the same selection rule, among adapters that can present to the window), egui on top,
//! the keys and the mouse, the script, screenshots.

use crate::panel::{self, PanelActions};
use crate::screenshot;
use crate::script::{Action, Step};
use crate::session::Session;
use crate::{ViewError, ViewOptions};
use mirrorbox_raster::Gpu;
use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, OwnedDisplayHandle};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

/// Degrees turned per pixel of mouse movement while looking.
const LOOK_DEG_PER_PIXEL: f32 = 0.15;
/// The panel's width in points.
pub const PANEL_WIDTH: f32 = 300.0;

/// The height the panel's widgets need, logical pixels: a default window is never lower (a
/// 160×90 view's window had cut the panel off at 188 px).
const PANEL_MIN_HEIGHT: f64 = 640.0;

/// The default window for a `size` view at display `scale`, physical pixels: the panel beside
/// two panes across and two down, the panes at the view's size, at least the panel's height,
/// and no side above [`crate::script::MAX_WINDOW_SIDE`] (the panes scale down to fit; a 9000
/// pixel view had asked the surface for more than the device takes).
pub fn default_window((w, h): (u32, u32), scale: f64) -> (u32, u32) {
    let panel = ((f64::from(PANEL_WIDTH) + 20.0) * scale).ceil() as u64;
    let width = panel + 2 * u64::from(w);
    let height = (2 * u64::from(h) + 8).max((PANEL_MIN_HEIGHT * scale).ceil() as u64);
    let side = |v: u64| v.min(u64::from(crate::script::MAX_WINDOW_SIDE)) as u32;
    (side(width), side(height))
}

struct Running {
    window: Arc<Window>,
    instance: wgpu::Instance,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    gpu: Gpu,
    device_lost: Arc<AtomicBool>,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    renderer: egui_wgpu::Renderer,
    session: Session,
    ui: panel::UiState,
    held: HashSet<KeyCode>,
    looking: Option<(f64, f64)>,
    cursor: (f64, f64),
    last_step: Instant,
    frames_drawn: u64,
    /// The last number of a screenshot the keys took, and of a camera copy: each its own
    /// count (one shared count had skipped numbers of both).
    shots_saved: u32,
    cameras_saved: u32,
    pending_screenshot: Option<PathBuf>,
    /// egui textures to free after the next submitted frame.
    pending_free: Vec<egui::TextureId>,
}

pub struct App {
    options: ViewOptions,
    display: OwnedDisplayHandle,
    running: Option<Running>,
    script: Vec<Step>,
    next_step: usize,
    /// Frames left of a `frames N` step.
    frames_left: u32,
    /// Deadline of a `wait-truth` step.
    waiting_truth: Option<(Instant, usize)>,
    /// End of a `seconds` step.
    drawing_until: Option<Instant>,
    /// The frames' records for `--log`, the latest [`crate::MAX_LOG_FRAMES`]; kept only where
    /// a log was asked for (about 2 KB a frame).
    pub log: std::collections::VecDeque<serde_json::Value>,
    pub outcome: Result<(), ViewError>,
}

impl App {
    pub fn new(options: ViewOptions, event_loop: &EventLoop<()>) -> Self {
        let script = options.script.clone().unwrap_or_default();
        App {
            display: event_loop.owned_display_handle(),
            options,
            running: None,
            script,
            next_step: 0,
            frames_left: 0,
            waiting_truth: None,
            drawing_until: None,
            log: std::collections::VecDeque::new(),
            outcome: Ok(()),
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, error: ViewError) {
        if self.outcome.is_ok() {
            self.outcome = Err(error);
        }
        event_loop.exit();
    }

    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<Running, ViewError> {
        let o = &self.options;
        let (w, h) = o.size;
        let default = o.window.unwrap_or_else(|| default_window(o.size, 1.0));
        let attributes = Window::default_attributes()
            .with_title(format!("mirrorbox view — {}", o.scene_path.display()))
            .with_inner_size(PhysicalSize::new(default.0, default.1));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| ViewError::Failed(format!("cannot open a window: {e}")))?,
        );
        // The panel is laid out in logical pixels: on a HiDPI display it takes scale × its
        // width, and the default window grows by as much (the panes had shrunk to 20×11).
        let scale = window.scale_factor();
        if o.window.is_none() && scale != 1.0 {
            let (sw, sh) = default_window((w, h), scale);
            let _ = window.request_inner_size(PhysicalSize::new(sw, sh));
        }
        let display = self.display.clone();
        let for_surface = window.clone();
        let (selected, surface) = mirrorbox_raster::adapter::select_adapter_presenting(
            &mirrorbox_raster::adapter::PresentTarget {
                display: &|| Box::new(display.clone()),
                surface: &|instance: &wgpu::Instance| instance.create_surface(for_surface.clone()),
            },
        )
        .map_err(|e| ViewError::Failed(e.to_string()))?;
        let instance = selected.instance.clone();
        let adapter = selected.adapter.clone();
        let gpu = Gpu::open_adapter(selected, mirrorbox_raster::methods::wanted_features(), None)
            .map_err(|e| ViewError::Failed(e.to_string()))?;
        let device_lost = Arc::new(AtomicBool::new(false));
        let lost = device_lost.clone();
        gpu.device
            .set_device_lost_callback(move |_, _| lost.store(true, Ordering::SeqCst));
        let caps = surface.get_capabilities(&adapter);
        // egui writes its (gamma-encoded) colours as they are to a non-sRGB target: prefer
        // one, so a pane's pixels are the bytes of the image shown.
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| {
                !f.is_srgb()
                    && matches!(
                        f,
                        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm
                    )
            })
            .or_else(|| caps.formats.first().copied())
            .ok_or_else(|| ViewError::Failed("the window's surface offers no format".into()))?;
        if !mirrorbox_raster::display_tone_map::DisplayToneMap::exact_on(format) {
            eprintln!(
                "warning: the window's surface offers no 8-bit unorm RGBA or BGRA format, only \
                 {format:?}: the panes show the images, but not the exact bytes `render` writes"
            );
        }
        let size = window.inner_size();
        let usage = if caps.usages.contains(wgpu::TextureUsages::COPY_SRC) {
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC
        } else {
            wgpu::TextureUsages::RENDER_ATTACHMENT
        };
        let config = wgpu::SurfaceConfiguration {
            usage,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: present_mode(o.vsync),
            desired_maximum_frame_latency: 2,
            alpha_mode: caps
                .alpha_modes
                .first()
                .copied()
                .unwrap_or(wgpu::CompositeAlphaMode::Auto),
            color_space: wgpu::SurfaceColorSpace::Auto,
            view_formats: vec![],
        };
        surface.configure(&gpu.device, &config);
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(gpu.device.limits().max_texture_dimension_2d as usize),
        );
        let renderer = egui_wgpu::Renderer::new(
            &gpu.device,
            format,
            egui_wgpu::RendererOptions {
                dithering: false,
                ..Default::default()
            },
        );
        // Walking speed: a quarter of the scene's diagonal per second.
        let speed = o
            .scene
            .geometry
            .bounds()
            .map_or(1.0, |(lo, hi)| 0.25 * lo.distance(hi))
            .clamp(0.05, 20.0);
        let truth_device = o
            .truth_device
            .unwrap_or_else(|| crate::live_truth::TruthDevice::auto(&gpu.report, gpu.features));
        let mut session = Session::new(
            o.scene.clone(),
            o.method.clone(),
            o.ssaa,
            o.size,
            truth_device,
        );
        session.memory_budget = o.memory_budget;
        // The method's pane is tone-mapped into the window's own format as egui paints.
        session.display_tone_map = Some(Arc::new(
            mirrorbox_raster::display_tone_map::DisplayToneMap::new(&gpu, format),
        ));
        let mut ui = panel::UiState::new(o.vsync);
        ui.speed = speed;
        Ok(Running {
            window,
            instance,
            surface,
            config,
            gpu,
            device_lost,
            egui_ctx,
            egui_state,
            renderer,
            session,
            ui,
            held: HashSet::new(),
            looking: None,
            cursor: (0.0, 0.0),
            last_step: Instant::now(),
            frames_drawn: 0,
            shots_saved: 0,
            cameras_saved: 0,
            pending_screenshot: None,
            pending_free: Vec::new(),
        })
    }

    /// Runs script steps until one needs frames drawn; returns false when the viewer should
    /// close.
    fn advance_script(&mut self, event_loop: &ActiveEventLoop) -> bool {
        if self.options.script.is_none() {
            return true;
        }
        let Some(r) = self.running.as_mut() else {
            return true;
        };
        if self.frames_left > 0 {
            self.frames_left -= 1;
            if self.frames_left > 0 {
                return true;
            }
        }
        if let Some(until) = self.drawing_until {
            if Instant::now() < until {
                return true;
            }
            self.drawing_until = None;
        }
        if let Some((deadline, line)) = self.waiting_truth {
            if r.session.view_truth().is_some() {
                self.waiting_truth = None;
            } else if !r.session.truth_enabled {
                let file = self.options.script_name.clone();
                self.fail(
                    event_loop,
                    ViewError::Failed(format!(
                        "{file}:{line}: wait-truth: the truth is off (`truth on` before it)"
                    )),
                );
                return false;
            } else if Instant::now() > deadline {
                let file = self.options.script_name.clone();
                let device = r.session.truth_device();
                self.fail(
                    event_loop,
                    ViewError::Failed(format!(
                        "{file}:{line}: wait-truth: the truth of the view was not complete in time \
                         (traced by the {device})"
                    )),
                );
                return false;
            } else {
                // Let the tracer have the CPU instead of redrawing in a loop.
                r.session.wait_truth(Duration::from_millis(50));
                return true;
            }
        }
        while let Some(step) = self.script.get(self.next_step).cloned() {
            self.next_step += 1;
            let r = self.running.as_mut().expect("running");
            match step.action {
                Action::Frames(n) => {
                    self.frames_left = n;
                    return true;
                }
                Action::Seconds(seconds) => {
                    self.drawing_until = Some(Instant::now() + Duration::from_secs_f64(seconds));
                    return true;
                }
                Action::WaitTruth { seconds } => {
                    r.session.truth_enabled = true;
                    self.waiting_truth =
                        Some((Instant::now() + Duration::from_secs_f64(seconds), step.line));
                    return true;
                }
                Action::Method(m) => r.session.method = m,
                Action::Ssaa(s) => r.session.ssaa = s,
                Action::Error(mode) => r.session.error_mode = mode,
                Action::Truth(on) => r.session.truth_enabled = on,
                Action::Walk([f, rt, u]) => r.session.camera.walk(f, rt, u),
                Action::Turn { yaw, pitch } => r.session.camera.turn(yaw, pitch),
                Action::Look { position, at } => r
                    .session
                    .camera
                    .look(glam::Vec3::from(position), glam::Vec3::from(at)),
                Action::ResetCamera => r.session.camera.reset(),
                Action::Resize(w, h) => {
                    let _ = r.window.request_inner_size(PhysicalSize::new(w, h));
                    // Give the window system a few frames to apply it.
                    self.frames_left = 3;
                    return true;
                }
                Action::Screenshot(path) => {
                    r.pending_screenshot = Some(path);
                    // Taken after the next frame is drawn.
                    self.frames_left = 1;
                    return true;
                }
                Action::SaveCamera(path) => {
                    let camera = r.session.view_camera();
                    if let Err(e) =
                        crate::scene_copy::save_camera(&self.options.scene_path, &camera, &path)
                    {
                        self.fail(event_loop, ViewError::Failed(e));
                        return false;
                    }
                }
                Action::Exit => return false,
            }
        }
        self.frames_left > 0 || self.waiting_truth.is_some() || self.drawing_until.is_some()
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        let Some(r) = self.running.as_mut() else {
            return;
        };
        if r.device_lost.load(Ordering::SeqCst) {
            self.fail(
                event_loop,
                ViewError::Failed("the GPU device was lost".into()),
            );
            return;
        }
        let size = r.window.inner_size();
        if size.width == 0 || size.height == 0 {
            // Minimised: nothing to draw until the window comes back.
            return;
        }
        // Fly-camera movement from held keys, by wall time.
        let now = Instant::now();
        let dt = now.duration_since(r.last_step).as_secs_f32().min(0.25);
        r.last_step = now;
        if !r.egui_ctx.text_edit_focused() {
            move_camera(&mut r.session, &r.held, dt, r.ui.speed);
        }
        let phase_start = Instant::now();
        if let Err(e) = r.session.update(&r.gpu, &mut r.renderer) {
            self.fail(event_loop, ViewError::Failed(e.to_string()));
            return;
        }
        let updated = Instant::now();
        let mut raw_input = r.egui_state.take_egui_input(&r.window);
        // Tab is the layout key, not egui's focus step: a focused panel widget had made egui
        // claim every later key, and no key of the viewer's worked again.
        raw_input.events.retain(|e| {
            !matches!(
                e,
                egui::Event::Key {
                    key: egui::Key::Tab,
                    ..
                }
            )
        });
        let mut actions = PanelActions::default();
        let full_output = r.egui_ctx.run_ui(raw_input, |ui| {
            actions = panel::show(ui, &mut r.session, &mut r.ui, &r.gpu, &mut r.renderer);
        });
        r.egui_state
            .handle_platform_output(&r.window, full_output.platform_output);
        let ppp = full_output.pixels_per_point;
        let paint_jobs = r.egui_ctx.tessellate(full_output.shapes, ppp);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [r.config.width, r.config.height],
            pixels_per_point: ppp,
        };
        // egui's texture changes: uploads now; frees once this frame is submitted (or at
        // the next frame, when this one is skipped).
        let mut textures = full_output.textures_delta;
        for (id, deltas) in &textures.set {
            for delta in deltas {
                r.renderer
                    .update_texture(&r.gpu.device, &r.gpu.queue, *id, delta);
            }
        }
        r.pending_free.extend(textures.free.drain());
        textures.clear();
        let laid_out = Instant::now();
        let frame = match r.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated => {
                r.surface.configure(&r.gpu.device, &r.config);
                return;
            }
            wgpu::CurrentSurfaceTexture::Lost => {
                // Recreate the surface on the same adapter and device.
                match r.instance.create_surface(r.window.clone()) {
                    Ok(s) => {
                        r.surface = s;
                        r.surface.configure(&r.gpu.device, &r.config);
                    }
                    Err(e) => self.fail(
                        event_loop,
                        ViewError::Failed(format!("the window's surface was lost: {e}")),
                    ),
                }
                return;
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => return,
            other => {
                self.fail(
                    event_loop,
                    ViewError::Failed(format!("cannot draw to the window: {other:?}")),
                );
                return;
            }
        };
        let acquired = Instant::now();
        let view = frame.texture.create_view(&Default::default());
        let mut encoder = r.gpu.device.create_command_encoder(&Default::default());
        let commands = r.renderer.update_buffers(
            &r.gpu.device,
            &r.gpu.queue,
            &mut encoder,
            &paint_jobs,
            &screen,
        );
        paint(&r.renderer, &mut encoder, &view, &paint_jobs, &screen);
        // A screenshot is the frame as presented: the same paint jobs into a texture we
        // can read.
        let capture = r.pending_screenshot.take().map(|path| {
            let target = screenshot::Capture::new(
                &r.gpu,
                r.config.format,
                (r.config.width, r.config.height),
            );
            paint(
                &r.renderer,
                &mut encoder,
                &target.view,
                &paint_jobs,
                &screen,
            );
            target.copy(&mut encoder);
            (path, target)
        });
        r.gpu
            .queue
            .submit(commands.into_iter().chain([encoder.finish()]));
        r.window.pre_present_notify();
        r.gpu.queue.present(frame);
        let ms = |a: Instant, b: Instant| b.duration_since(a).as_secs_f64() * 1e3;
        let phases = screenshot::Phases {
            update: r.session.update_phases,
            ui: ms(updated, laid_out),
            acquire: ms(laid_out, acquired),
            paint_present: ms(acquired, Instant::now()),
            total: ms(phase_start, Instant::now()),
        };
        for id in r.pending_free.drain(..) {
            r.renderer.free_texture(&id);
        }
        r.frames_drawn += 1;
        let panes = r.ui.panes_px.clone();
        if self.options.log.is_some() {
            self.log.push_back(screenshot::frame_record(
                r.frames_drawn,
                &phases,
                &r.session,
                &panes,
                (r.config.width, r.config.height),
            ));
            if self.log.len() > crate::MAX_LOG_FRAMES {
                self.log.pop_front();
            }
        }
        if let Some((path, target)) = capture {
            // The method's linear image, read back at the screenshot's pace.
            let result = r
                .session
                .method_image(&r.gpu)
                .map_err(|e| e.to_string())
                .and_then(|image| {
                    let pixels = target.read(&r.gpu)?;
                    screenshot::save(
                        &path,
                        &pixels,
                        &r.session,
                        image.as_deref(),
                        &panes,
                        &self.options,
                    )
                });
            if let Err(e) = result {
                self.fail(event_loop, ViewError::Failed(e));
                return;
            }
        }
        if let Err(e) = r.gpu.check() {
            self.fail(event_loop, ViewError::Failed(e.to_string()));
            return;
        }
        self.apply(actions, event_loop);
        if !self.advance_script(event_loop) {
            event_loop.exit();
        }
    }

    /// What the panel's buttons and the keys asked for.
    fn apply(&mut self, actions: PanelActions, event_loop: &ActiveEventLoop) {
        let Some(r) = self.running.as_mut() else {
            return;
        };
        if let Some(vsync) = actions.vsync {
            r.config.present_mode = present_mode(vsync);
            r.surface.configure(&r.gpu.device, &r.config);
        }
        // Numbered files never replace one that exists ([`crate::screenshot::unused_number`]).
        if actions.screenshot && r.pending_screenshot.is_some() {
            // A script's screenshot waits for this frame: the key's would have replaced it.
            r.ui.status = "no screenshot: one is being taken".into();
        } else if actions.screenshot {
            let out_dir = &self.options.out_dir;
            let shot = |n: u32| out_dir.join(format!("mirrorbox-view-{n}.png"));
            match crate::screenshot::unused_number(r.shots_saved + 1, |n| {
                crate::screenshot::files(&shot(n))
            }) {
                Some(n) => {
                    r.shots_saved = n;
                    r.pending_screenshot = Some(shot(n));
                }
                None => {
                    r.ui.status = format!(
                        "no screenshot: mirrorbox-view-{}.png and the 9 999 after it exist in {}",
                        r.shots_saved + 1,
                        out_dir.display()
                    )
                }
            }
        }
        if actions.save_camera {
            let stem = self
                .options
                .scene_path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scene".into());
            let dir = mirrorbox_files::folder_of(&self.options.scene_path);
            let copy = |n: u32| dir.join(format!("{stem}.view-{n}.json"));
            r.ui.status = match crate::screenshot::unused_number(r.cameras_saved + 1, |n| [copy(n)])
            {
                Some(n) => {
                    r.cameras_saved = n;
                    let to = copy(n);
                    let camera = r.session.view_camera();
                    match crate::scene_copy::save_camera(&self.options.scene_path, &camera, &to) {
                        Ok(()) => format!("camera saved to {}", to.display()),
                        Err(e) => format!("cannot save the camera: {e}"),
                    }
                }
                None => format!(
                    "camera not saved: {stem}.view-{}.json and the 9 999 after it exist in {}",
                    r.cameras_saved + 1,
                    dir.display()
                ),
            };
        }
        if actions.quit {
            event_loop.exit();
        }
    }
}

fn present_mode(vsync: bool) -> wgpu::PresentMode {
    if vsync {
        wgpu::PresentMode::AutoVsync
    } else {
        wgpu::PresentMode::AutoNoVsync
    }
}

fn paint(
    renderer: &egui_wgpu::Renderer,
    encoder: &mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
    jobs: &[egui::ClippedPrimitive],
    screen: &egui_wgpu::ScreenDescriptor,
) {
    let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("egui"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            resolve_target: None,
            depth_slice: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color {
                    r: 0.05,
                    g: 0.05,
                    b: 0.05,
                    a: 1.0,
                }),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    renderer.render(&mut pass.forget_lifetime(), jobs, screen);
}

/// WASD (and the arrows) move along the view, Q/E down and up; Shift is four times faster.
fn move_camera(session: &mut Session, held: &HashSet<KeyCode>, dt: f32, speed: f32) {
    let axis = |plus: &[KeyCode], minus: &[KeyCode]| {
        let p = plus.iter().any(|k| held.contains(k)) as i32;
        let m = minus.iter().any(|k| held.contains(k)) as i32;
        (p - m) as f32
    };
    let forward = axis(
        &[KeyCode::KeyW, KeyCode::ArrowUp],
        &[KeyCode::KeyS, KeyCode::ArrowDown],
    );
    let right = axis(
        &[KeyCode::KeyD, KeyCode::ArrowRight],
        &[KeyCode::KeyA, KeyCode::ArrowLeft],
    );
    let up = axis(&[KeyCode::KeyE], &[KeyCode::KeyQ]);
    let fast = if held.contains(&KeyCode::ShiftLeft) || held.contains(&KeyCode::ShiftRight) {
        4.0
    } else {
        1.0
    };
    let step = speed * fast * dt;
    session.camera.walk(forward * step, right * step, up * step);
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_some() {
            return;
        }
        match self.start(event_loop) {
            Ok(r) => {
                r.window.request_redraw();
                self.running = Some(r);
                if !self.advance_script(event_loop) {
                    event_loop.exit();
                }
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(r) = self.running.as_mut() else {
            return;
        };
        let _ = r.egui_state.on_window_event(&r.window, &event);
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            // A zero size is a minimised window: nothing to configure until it comes back.
            WindowEvent::Resized(size) if size.width > 0 && size.height > 0 => {
                r.config.width = size.width;
                r.config.height = size.height;
                r.surface.configure(&r.gpu.device, &r.config);
                r.window.request_redraw();
            }
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            // The viewer's keys, unless a text field of the panel (a slider's typed value)
            // has them: egui reports every key as its own while any widget has focus.
            WindowEvent::KeyboardInput { event, .. } if !r.egui_ctx.text_edit_focused() => {
                let PhysicalKey::Code(code) = event.physical_key else {
                    return;
                };
                match event.state {
                    ElementState::Pressed => {
                        if !event.repeat {
                            let actions = panel::key_pressed(code, &mut r.session, &mut r.ui);
                            r.held.insert(code);
                            self.apply(actions, event_loop);
                        }
                    }
                    ElementState::Released => {
                        r.held.remove(&code);
                    }
                }
            }
            WindowEvent::Focused(false) => r.held.clear(),
            WindowEvent::MouseInput { state, button, .. } => {
                let (cx, cy) = r.cursor;
                let over_panes = !r.egui_ctx.egui_is_using_pointer()
                    && r.ui.panes_px.iter().any(|(_, [x, y, w, h])| {
                        cx >= f64::from(*x)
                            && cy >= f64::from(*y)
                            && cx < f64::from(x + w)
                            && cy < f64::from(y + h)
                    });
                match (state, button) {
                    (ElementState::Pressed, MouseButton::Right)
                    | (ElementState::Pressed, MouseButton::Left)
                        if over_panes || button == MouseButton::Right =>
                    {
                        r.looking = Some(r.cursor);
                    }
                    (ElementState::Released, MouseButton::Right | MouseButton::Left) => {
                        r.looking = None;
                    }
                    _ => {}
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                r.cursor = (position.x, position.y);
                if let Some((x0, y0)) = r.looking {
                    let (dx, dy) = (position.x - x0, position.y - y0);
                    r.session.camera.turn(
                        dx as f32 * LOOK_DEG_PER_PIXEL,
                        -dy as f32 * LOOK_DEG_PER_PIXEL,
                    );
                    r.looking = Some((position.x, position.y));
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if let Some(r) = &self.running {
            let size = r.window.inner_size();
            if size.width > 0 && size.height > 0 {
                // A real-time view: draw continuously.
                event_loop.set_control_flow(ControlFlow::Poll);
                r.window.request_redraw();
            } else {
                event_loop.set_control_flow(ControlFlow::Wait);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small view's window keeps the panel's height, a HiDPI display widens the panel's
    /// part by its scale, and a huge view's window stays within the largest side.
    #[test]
    fn the_default_window_fits_the_panel_and_the_device() {
        assert_eq!(default_window((640, 360), 1.0), (320 + 1280, 728));
        assert_eq!(default_window((160, 90), 1.0), (320 + 320, 640));
        assert_eq!(default_window((160, 90), 2.0), (640 + 320, 1280));
        let max = crate::script::MAX_WINDOW_SIDE;
        assert_eq!(default_window((9000, 64), 1.0), (max, 640));
    }
}
