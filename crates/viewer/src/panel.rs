//! The egui side: the panel (method and every registry option, SSAA, camera, truth, error,
//! frame times), the image panes, the help overlay, and the keys.

use crate::error_view::ErrorMode;
use crate::method_pane::MethodPanePaint;
use crate::session::Session;
use egui::{Color32, Pos2, Rect, Vec2};
use mirrorbox_raster::display_tone_map::ToneMapUniform;
use mirrorbox_raster::method::OptionKind;
use mirrorbox_raster::{Gpu, METHODS, Method, ParamValue};
use winit::keyboard::KeyCode;

/// How the panes fill the window.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Method | truth on top, error below.
    Grid,
    Method,
    Truth,
    Error,
}

impl Layout {
    const ALL: [Layout; 4] = [Layout::Grid, Layout::Method, Layout::Truth, Layout::Error];

    fn name(self) -> &'static str {
        match self {
            Layout::Grid => "method | truth / error",
            Layout::Method => "method",
            Layout::Truth => "truth",
            Layout::Error => "error",
        }
    }

    fn next(self) -> Layout {
        let i = Layout::ALL.iter().position(|&l| l == self).unwrap_or(0);
        Layout::ALL[(i + 1) % Layout::ALL.len()]
    }
}

/// The panel's own state.
pub struct UiState {
    pub layout: Layout,
    pub help: bool,
    pub vsync: bool,
    /// Camera speed in scene units per second.
    pub speed: f32,
    /// A message for the user (a saved file, …).
    pub status: String,
    /// Each pane's rectangle in physical pixels of the window, `[x, y, w, h]`, as last laid
    /// out (screenshots and the log record them).
    pub panes_px: Vec<(&'static str, [u32; 4])>,
}

impl UiState {
    pub fn new(vsync: bool) -> Self {
        UiState {
            layout: Layout::Grid,
            help: false,
            vsync,
            speed: 1.0,
            status: String::new(),
            panes_px: Vec::new(),
        }
    }
}

/// What the user asked for this frame that the window carries out.
#[derive(Default)]
pub struct PanelActions {
    pub screenshot: bool,
    pub save_camera: bool,
    pub vsync: Option<bool>,
    pub quit: bool,
}

const HELP: &[(&str, &str)] = &[
    ("W A S D / arrows", "move along the view"),
    ("Q / E", "down / up"),
    ("Shift", "move four times faster"),
    ("drag (left on the images, or right)", "look around"),
    ("R", "reset to the scene's camera"),
    ("1 … 9, 0", "method by its place in the list (0: the tenth)"),
    ("M", "next method, through every one in the list"),
    ("Tab", "layout: grid, method, truth, error"),
    ("T", "live truth on / off"),
    ("F", "error map: difference / FLIP"),
    ("V", "vsync on / off"),
    (
        "P or F12",
        "screenshot (PNG of the window; EXR of method and truth; error PNG)",
    ),
    ("C", "save the camera into a copy of the scene file"),
    ("H or F1", "this help"),
    ("Esc", "quit"),
];

/// The method after `current` in the registry's list, the first after the last: `M` reaches
/// every method however many the list holds (the number keys reach ten).
fn next_method(current: &Method) -> &'static mirrorbox_raster::MethodEntry {
    let i = METHODS
        .iter()
        .position(|e| e.name == current.entry().name)
        .map_or(0, |i| (i + 1) % METHODS.len());
    METHODS[i]
}

/// A key press not taken by egui.
pub fn key_pressed(code: KeyCode, session: &mut Session, ui: &mut UiState) -> PanelActions {
    let mut actions = PanelActions::default();
    match code {
        KeyCode::KeyR => session.camera.reset(),
        KeyCode::Tab => ui.layout = ui.layout.next(),
        KeyCode::KeyT => session.truth_enabled = !session.truth_enabled,
        KeyCode::KeyF => {
            session.error_mode = match session.error_mode {
                ErrorMode::Difference => ErrorMode::Flip,
                ErrorMode::Flip => ErrorMode::Difference,
            }
        }
        KeyCode::KeyV => {
            ui.vsync = !ui.vsync;
            actions.vsync = Some(ui.vsync);
        }
        KeyCode::KeyP | KeyCode::F12 => actions.screenshot = true,
        KeyCode::KeyC => actions.save_camera = true,
        KeyCode::KeyH | KeyCode::F1 => ui.help = !ui.help,
        KeyCode::Escape => actions.quit = true,
        KeyCode::KeyM => session.method = Method::defaults(next_method(&session.method)),
        _ => {
            let digits = [
                KeyCode::Digit1,
                KeyCode::Digit2,
                KeyCode::Digit3,
                KeyCode::Digit4,
                KeyCode::Digit5,
                KeyCode::Digit6,
                KeyCode::Digit7,
                KeyCode::Digit8,
                KeyCode::Digit9,
                KeyCode::Digit0,
            ];
            if let Some(i) = digits.iter().position(|&d| d == code)
                && let Some(entry) = METHODS.get(i)
            {
                session.method = Method::defaults(entry);
            }
        }
    }
    actions
}

/// The whole window's egui frame.
pub fn show(
    root: &mut egui::Ui,
    session: &mut Session,
    ui_state: &mut UiState,
    gpu: &Gpu,
    renderer: &mut egui_wgpu::Renderer,
) -> PanelActions {
    let mut actions = PanelActions::default();
    egui::Panel::left("controls")
        .resizable(false)
        .exact_size(crate::app::PANEL_WIDTH)
        .show(root, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                controls(ui, session, ui_state, gpu, &mut actions);
            });
        });
    egui::CentralPanel::default()
        .frame(egui::Frame::NONE.fill(Color32::from_gray(13)))
        .show(root, |ui| panes(ui, session, ui_state, gpu, renderer));
    if ui_state.help {
        egui::Window::new("Keys")
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::RIGHT_TOP, [-8.0, 8.0])
            .show(root.ctx(), |ui| {
                egui::Grid::new("keys").striped(true).show(ui, |ui| {
                    for (k, what) in HELP {
                        ui.monospace(*k);
                        ui.label(*what);
                        ui.end_row();
                    }
                });
            });
    }
    actions
}

fn controls(
    ui: &mut egui::Ui,
    session: &mut Session,
    state: &mut UiState,
    gpu: &Gpu,
    actions: &mut PanelActions,
) {
    ui.heading("mirrorbox view");
    ui.small(format!("{} ({})", gpu.report.name, gpu.report.backend));
    ui.separator();

    // The method and its options, all from the registry's table.
    let mut method = session.method.clone();
    egui::ComboBox::from_label("method")
        .selected_text(method.name())
        .show_ui(ui, |ui| {
            for entry in METHODS {
                let selected = method.name() == entry.name;
                if ui
                    .selectable_label(selected, entry.name)
                    .on_hover_text(entry.help)
                    .clicked()
                    && !selected
                {
                    method = Method::defaults(entry);
                }
            }
        });
    for option in method.entry().options {
        let current = method.params().get(option).unwrap_or(option.default);
        let changed = option_widget(ui, option, current);
        if let Some(value) = changed {
            match method.clone().with(option, value) {
                Ok(m) => method = m,
                Err(e) => state.status = e.to_string(),
            }
        }
    }
    session.method = method;
    // Edits clamp, the shown value does not: egui's default wrote a script's `ssaa 8` back
    // to the slider's end every frame.
    ui.add(
        egui::Slider::new(&mut session.ssaa, 1..=mirrorbox_raster::MAX_SSAA)
            .clamping(egui::SliderClamping::Edits)
            .text("SSAA"),
    );
    if let Some(e) = &session.method_error {
        ui.colored_label(Color32::from_rgb(255, 110, 90), e);
    }
    ui.separator();

    // Frame times.
    if let Some(frame) = &session.frame {
        let s = &frame.stats;
        ui.label(format!(
            "{:.2} ms/frame ({})",
            frame.gpu_ms, frame.timing_source
        ));
        let wall = session.history.back().map(|t| t.wall_ms).unwrap_or(0.0);
        if wall > 0.0 {
            ui.label(format!(
                "{:.1} fps shown ({:.1} ms between frames)",
                1e3 / wall,
                wall
            ));
        }
        ui.label(format!(
            "{} passes, {} draws, {} triangles, {} reflections deep",
            s.passes, s.draws, s.triangles, s.depth
        ));
        if let Some(p) = s.paths {
            ui.label(format!("{} reflection paths", p.kept));
        }
        for w in &frame.warnings {
            ui.small(w);
        }
    }
    frame_graph(ui, session);
    ui.separator();

    // Truth and error.
    ui.checkbox(&mut session.truth_enabled, "live truth");
    ui.small(session.truth_device());
    ui.small(session.truth_progress());
    ui.horizontal(|ui| {
        ui.label("error map");
        for mode in ErrorMode::ALL {
            ui.selectable_value(&mut session.error_mode, mode, mode.name());
        }
    });
    if session.error_mode == ErrorMode::Difference {
        ui.add(
            egui::Slider::new(&mut session.error_gain, 1.0..=64.0)
                .logarithmic(true)
                .text("gain"),
        );
    }
    match &session.error {
        Some(e) => {
            let m = &e.metrics;
            ui.label(format!(
                "FLIP mean {:.3e} (p95 {:.3e})",
                m.flip_mean, m.flip_p95
            ));
            ui.label(format!(
                "relMSE {:.3e}, PSNR {:.1} dB, SSIM {:.4}",
                m.relmse, m.psnr, m.ssim
            ));
        }
        None => {
            ui.small("metrics: when the truth of this view is complete");
        }
    }
    ui.separator();

    // Camera.
    let p = session.camera.position();
    ui.label(format!("camera at ({:.2}, {:.2}, {:.2})", p.x, p.y, p.z));
    ui.add(
        egui::Slider::new(&mut state.speed, 0.05..=20.0)
            .logarithmic(true)
            .text("speed /s"),
    );
    let mut fov = session.camera.fov_y_deg();
    if ui
        .add(
            egui::Slider::new(&mut fov, 10.0..=120.0)
                .clamping(egui::SliderClamping::Edits)
                .text("fov °"),
        )
        .changed()
    {
        session.camera.set_fov(fov);
    }
    ui.horizontal(|ui| {
        if ui.button("reset (R)").clicked() {
            session.camera.reset();
        }
        if ui.button("save camera (C)").clicked() {
            actions.save_camera = true;
        }
    });
    ui.separator();
    ui.horizontal(|ui| {
        if ui.button("screenshot (P)").clicked() {
            actions.screenshot = true;
        }
        if ui.checkbox(&mut state.vsync, "vsync").changed() {
            actions.vsync = Some(state.vsync);
        }
    });
    egui::ComboBox::from_label("layout (Tab)")
        .selected_text(state.layout.name())
        .show_ui(ui, |ui| {
            for l in Layout::ALL {
                ui.selectable_value(&mut state.layout, l, l.name());
            }
        });
    if ui.button("keys (H)").clicked() {
        state.help = !state.help;
    }
    if !state.status.is_empty() {
        ui.small(&state.status);
    }
}

/// Seconds of frame times the graph spans.
const GRAPH_SECONDS: f64 = 10.0;

/// One registry option's widget; the new value where the user changed it this frame. A
/// count's range is the option's own (`max-passes` goes to 1 000 000): a narrower one would
/// clamp a value the command line accepts (the panel showed `max-passes 4096` for its
/// default 5000).
fn option_widget(
    ui: &mut egui::Ui,
    option: &'static mirrorbox_raster::OptionSpec,
    current: ParamValue,
) -> Option<ParamValue> {
    match (option.kind, current) {
        (OptionKind::Count { min, max }, ParamValue::Count(mut v)) => ui
            .add(
                egui::DragValue::new(&mut v)
                    .range(min..=max)
                    .prefix(format!("{} ", option.name)),
            )
            .on_hover_text(option.help)
            .changed()
            .then_some(ParamValue::Count(v)),
        (OptionKind::Real { min, max, .. }, ParamValue::Real(mut v)) => ui
            .add(
                egui::DragValue::new(&mut v)
                    .range(min..=max.unwrap_or(1e6))
                    .speed(0.01)
                    .prefix(format!("{} ", option.name)),
            )
            .on_hover_text(option.help)
            .changed()
            .then_some(ParamValue::Real(v)),
        (OptionKind::Switch, ParamValue::Switch(mut v)) => ui
            .checkbox(&mut v, option.name)
            .on_hover_text(option.help)
            .changed()
            .then_some(ParamValue::Switch(v)),
        (OptionKind::Choice { values }, ParamValue::Choice(v)) => {
            let mut chosen = None;
            egui::ComboBox::from_label(option.name)
                .selected_text(v)
                .show_ui(ui, |ui| {
                    for &value in values {
                        if ui.selectable_label(value == v, value).clicked() {
                            chosen = Some(ParamValue::Choice(value));
                        }
                    }
                })
                .response
                .on_hover_text(option.help);
            chosen
        }
        _ => None,
    }
}

/// The last seconds of frame times, newest on the right: the method's GPU time and the wall
/// time between shown frames (which adds planning for a moved camera, the truth's share of
/// the CPU and the window's own work).
fn frame_graph(ui: &mut egui::Ui, session: &Session) {
    let (rect, _) =
        ui.allocate_exact_size(Vec2::new(ui.available_width(), 70.0), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, Color32::from_gray(25));
    // Newest first, each with its age in ms at its end.
    let mut age = 0.0;
    let recent: Vec<(f64, &crate::session::FrameTime)> = session
        .history
        .iter()
        .rev()
        .map(|t| {
            let at = age;
            age += t.wall_ms;
            (at, t)
        })
        .take_while(|(at, _)| *at <= GRAPH_SECONDS * 1e3)
        .collect();
    if recent.len() < 2 {
        return;
    }
    let top = recent
        .iter()
        .map(|(_, t)| t.wall_ms.max(t.gpu_ms))
        .fold(1.0, f64::max)
        * 1.1;
    let point = |at: f64, v: f64| {
        Pos2::new(
            rect.right() - rect.width() * (at / (GRAPH_SECONDS * 1e3)) as f32,
            rect.bottom() - rect.height() * (v / top) as f32,
        )
    };
    let line = |f: &dyn Fn(&crate::session::FrameTime) -> f64, colour: Color32| {
        let points: Vec<Pos2> = recent.iter().map(|(at, t)| point(*at, f(t))).collect();
        painter.add(egui::Shape::line(points, egui::Stroke::new(1.0, colour)));
    };
    line(&|t| t.wall_ms, Color32::from_gray(150));
    line(&|t| t.gpu_ms, Color32::from_rgb(90, 200, 120));
    painter.text(
        rect.left_top() + Vec2::new(4.0, 2.0),
        egui::Align2::LEFT_TOP,
        format!("last {GRAPH_SECONDS:.0} s, top {top:.0} ms — green: GPU, grey: between frames"),
        egui::FontId::proportional(10.0),
        Color32::from_gray(200),
    );
}

/// The image panes: drawn 1:1 where they fit (pixel-aligned, nearest sampling, so a pane
/// holds the image's bytes), scaled down to fit otherwise.
fn panes(
    ui: &mut egui::Ui,
    session: &mut Session,
    state: &mut UiState,
    gpu: &Gpu,
    renderer: &mut egui_wgpu::Renderer,
) {
    let ppp = ui.ctx().pixels_per_point();
    let area = ui.max_rect();
    let (w, h) = session.size;
    let (cols, rows) = match state.layout {
        Layout::Grid => (2, 2),
        _ => (1, 1),
    };
    // Scale in pixels per image pixel: 1 where the panes fit, smaller where they do not.
    let avail = (area.width() * ppp, area.height() * ppp);
    let scale = (avail.0 / (cols * w) as f32)
        .min(avail.1 / (rows * h) as f32)
        .min(1.0);
    let (pw, ph) = ((w as f32 * scale).floor(), (h as f32 * scale).floor());
    let origin = ((area.left() * ppp).ceil(), (area.top() * ppp).ceil());
    let filter = if scale == 1.0 {
        wgpu::FilterMode::Nearest
    } else {
        wgpu::FilterMode::Linear
    };
    let slots: Vec<(&'static str, (u32, u32))> = match state.layout {
        Layout::Grid => vec![("method", (0, 0)), ("truth", (1, 0)), ("error", (0, 1))],
        Layout::Method => vec![("method", (0, 0))],
        Layout::Truth => vec![("truth", (0, 0))],
        Layout::Error => vec![("error", (0, 0))],
    };
    state.panes_px.clear();
    let painter = ui.painter();
    for (name, (cx, cy)) in slots {
        let px = [origin.0 + cx as f32 * pw, origin.1 + cy as f32 * ph];
        let rect = Rect::from_min_size(
            Pos2::new(px[0] / ppp, px[1] / ppp),
            Vec2::new(pw / ppp, ph / ppp),
        );
        state
            .panes_px
            .push((name, [px[0] as u32, px[1] as u32, pw as u32, ph as u32]));
        let method_pane = match name {
            "method" => session.method_pane(),
            _ => None,
        };
        // The truth's and the error's panes are images of the CPU, uploaded when they change.
        let texture = match name {
            "truth" => session.truth_texture.as_mut(),
            "error" => session.error_texture.as_mut(),
            _ => None,
        };
        let shown = match name {
            "truth" => session.truth_shown.is_some(),
            "error" => session.error.is_some(),
            _ => false,
        };
        match (method_pane, texture) {
            (Some((tone_map, source)), _) => {
                // Tone-mapped from the frame's linear image as the window is painted.
                let uniform = ToneMapUniform {
                    origin: px,
                    step: if scale == 1.0 {
                        [1.0, 1.0]
                    } else {
                        [w as f32 / pw, h as f32 / ph]
                    },
                    exposure: session.scene.camera.exposure,
                    pad: 0.0,
                };
                painter.add(egui_wgpu::Callback::new_paint_callback(
                    rect,
                    MethodPanePaint {
                        tone_map,
                        source,
                        uniform,
                    },
                ));
            }
            (None, Some(t)) if shown => {
                // A coarse truth level is smaller than the pane: scaled up, blocky.
                t.set_filter(gpu, renderer, filter);
                if let Some(id) = t.id {
                    painter.image(
                        id,
                        rect,
                        Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0)),
                        Color32::WHITE,
                    );
                }
            }
            _ => {
                painter.rect_filled(rect, 0.0, Color32::from_gray(30));
                let why = match name {
                    "method" => session
                        .method_error
                        .clone()
                        .unwrap_or_else(|| "rendering…".into()),
                    "truth" => session.truth_progress(),
                    _ => "error: waiting for the complete truth of this view".into(),
                };
                painter.text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    why,
                    egui::FontId::proportional(13.0),
                    Color32::from_gray(180),
                );
            }
        }
    }
    if state.layout == Layout::Grid {
        // The fourth quarter says what the three others are.
        let rect = Rect::from_min_size(
            Pos2::new((origin.0 + pw) / ppp, (origin.1 + ph) / ppp),
            Vec2::new(pw / ppp, ph / ppp),
        );
        let text = format!(
            "top left: {}\ntop right: the traced truth ({})\nbottom left: error, {}\n\nH: keys",
            session.method.key(),
            session.truth_progress(),
            session.error_mode.name()
        );
        painter.text(
            rect.left_top() + Vec2::new(12.0, 12.0),
            egui::Align2::LEFT_TOP,
            text,
            egui::FontId::proportional(13.0),
            Color32::from_gray(190),
        );
    }
    // Mouse drags on the panes turn the camera (handled by the window); egui only needs to
    // know the area is not its own.
    let _ = ui.allocate_rect(area, egui::Sense::hover());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_m_key_reaches_every_method() {
        let mut m = Method::defaults(METHODS[0]);
        let mut seen = vec![m.entry().name];
        for _ in 1..METHODS.len() {
            m = Method::defaults(next_method(&m));
            seen.push(m.entry().name);
        }
        let mut all: Vec<&str> = METHODS.iter().map(|e| e.name).collect();
        seen.sort_unstable();
        all.sort_unstable();
        assert_eq!(seen, all);
        assert_eq!(
            next_method(&m).name,
            METHODS[0].name,
            "after the last, the first"
        );
    }

    /// Every option of every method at its default, its least and its largest value, drawn
    /// for a few frames of a headless egui context: the widget never changes a value by
    /// itself (a range narrower than the option's clamped `max-passes` 5000 to 4096).
    #[test]
    fn an_option_widget_keeps_every_value_the_option_allows() {
        let ctx = egui::Context::default();
        for entry in METHODS {
            for option in entry.options {
                let values = match option.kind {
                    OptionKind::Count { min, max } => {
                        vec![
                            option.default,
                            ParamValue::Count(min),
                            ParamValue::Count(max),
                        ]
                    }
                    _ => vec![option.default],
                };
                for value in values {
                    for _ in 0..3 {
                        let mut output = ctx.run_ui(egui::RawInput::default(), |ui| {
                            let changed = option_widget(ui, option, value);
                            assert_eq!(changed, None, "{} {}: {value:?}", entry.name, option.name);
                        });
                        output.textures_delta.clear();
                    }
                }
            }
        }
    }
}
