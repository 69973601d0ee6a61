//! `mirrorbox view`: the seed paper's real-time demo, with the truth and the error live
//! beside it (docs/viewer.md).
//!
//! - [`fly_camera`]: the free camera, which stays the scene's camera bit for bit until moved;
//! - [`live_truth`]: the CPU tracer rendering the current view in the background, coarse
//!   to fine, restarted when the view changes;
//! - [`error_view`]: the heat map and metrics of the method against a complete truth;
//! - [`script`]: `--script` actions that drive the viewer for tests and demos;
//! - [`scene_copy`]: the current camera written into a copy of the scene file;
//! - the window (winit, a wgpu surface, egui), the panel and screenshots.
//!
//! Data flows one way here too: scene → method frame and truth → error → panes; the viewer
//! uses the same `mirrorbox-raster` frames `render` times and the same tracer `trace` runs,
//! so a pane shows what the batch commands write.

mod app;
pub mod error_view;
pub mod fly_camera;
pub mod live_truth;
mod method_pane;
mod panel;
pub mod scene_copy;
mod screenshot;
pub mod script;
mod session;

use mirrorbox_raster::Method;
use mirrorbox_scene::Scene;
use std::path::PathBuf;

/// Most frames kept in the `--log` (the newest).
pub const MAX_LOG_FRAMES: usize = 100_000;

/// What `mirrorbox view` was asked to show.
pub struct ViewOptions {
    pub scene_path: PathBuf,
    pub scene: Scene,
    pub method: Method,
    pub ssaa: u32,
    /// `--memory-budget` in bytes: a method or option whose plan's memory estimate exceeds
    /// it is refused (the method pane says why) instead of built.
    pub memory_budget: u64,
    /// The view's size in pixels (the scene camera's unless `--size` says otherwise).
    pub size: (u32, u32),
    /// The window's inner size; by default the panel and four panes of `size`.
    pub window: Option<(u32, u32)>,
    pub script: Option<Vec<script::Step>>,
    /// The script's file name, for messages.
    pub script_name: String,
    /// A JSON-lines record of every frame, written when the viewer closes.
    pub log: Option<PathBuf>,
    pub vsync: bool,
    /// Where the screenshot key writes.
    pub out_dir: PathBuf,
    /// Where the live truth is traced; `None`: [`live_truth::TruthDevice::auto`].
    pub truth_device: Option<live_truth::TruthDevice>,
}

#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// Bad input (exit 2).
    #[error("{0}")]
    Refused(String),
    /// The window, the device or a file failed (exit 1).
    #[error("{0}")]
    Failed(String),
}

/// Opens the window and runs until it is closed, the script ends, or something fails.
pub fn run(options: ViewOptions) -> Result<(), ViewError> {
    let event_loop = winit::event_loop::EventLoop::new().map_err(|e| {
        ViewError::Failed(format!(
            "cannot open a window: {e} (a desktop session is needed: DISPLAY or \
             WAYLAND_DISPLAY; on a headless machine run it under Xvfb, e.g. `xvfb-run -a \
             mirrorbox view …`)"
        ))
    })?;
    let log_path = options.log.clone();
    let mut app = app::App::new(options, &event_loop);
    event_loop
        .run_app(&mut app)
        .map_err(|e| ViewError::Failed(format!("the window's event loop failed: {e}")))?;
    if let Some(path) = log_path {
        let mut text = String::new();
        for record in &app.log {
            text.push_str(&record.to_string());
            text.push('\n');
        }
        mirrorbox_files::write_atomically(&path, text.as_bytes())
            .map_err(|e| ViewError::Failed(e.to_string()))?;
    }
    app.outcome
}
