pub mod advise;
pub mod check;
pub mod compare;
pub mod export_mitsuba;
pub mod export_views;
pub mod import;
pub mod info;
pub mod merge;
pub mod method_flags;
pub mod readme;
pub mod render;
pub mod report;
pub mod score;
pub mod stereo;
pub mod sweep;
pub mod trace;
pub mod view;

use crate::Failure;
use mirrorbox_scene::{Scene, load_scene};
use std::path::{Path, PathBuf};

/// Loads a scene; any problem with it is the user's input (exit 2).
pub fn load(path: &Path) -> Result<Scene, Failure> {
    load_scene(path).map_err(|e| Failure::BadInput(e.to_string()))
}

/// The s of `--spp s²` ([`mirrorbox_scene::limits::spp_grid_side`]).
pub fn grid_side(spp: u32) -> Result<u32, Failure> {
    mirrorbox_scene::limits::spp_grid_side(spp).map_err(setting)
}

/// A reflectance override (`--reflectance`, `--alpha`), in [0, 1].
pub fn unit_interval(flag: &str, value: Option<f32>) -> Result<Option<f32>, Failure> {
    value
        .map(|v| mirrorbox_scene::limits::unit_interval(flag, v))
        .transpose()
        .map_err(setting)
}

/// `--ssaa s`: the raster's supersampling (the truth's s×s sub-pixel grid), checked before
/// anything is done with it: `s * s` of a large s overflowed.
pub fn ssaa(value: u32) -> Result<u32, Failure> {
    let max = mirrorbox_raster::MAX_SSAA;
    if !(1..=max).contains(&value) {
        return Err(setting(mirrorbox_scene::limits::SettingError::new(
            "--ssaa",
            format!("in [1, {max}]"),
            value,
        )));
    }
    Ok(value)
}

/// `--width` / `--height` of the commands that compare an image with its truth (`sweep`,
/// `advise`, `export-views`): SSIM's window sets the smallest side.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct TruthSizeArgs {
    /// Image width in pixels, 11..16384 (SSIM's window needs 11; default: the scene
    /// camera's; the vertical field of view is kept).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels, 11..16384 (default: the scene camera's).
    #[arg(long)]
    pub height: Option<u32>,
}

/// `--width` / `--height`: the image size, where it differs from the scene camera's (every
/// command that renders or exports a view without comparing it).
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct SizeArgs {
    /// Image width in pixels, 1..16384 (default: the scene camera's; the vertical field of
    /// view is kept).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels, 1..16384 (default: the scene camera's).
    #[arg(long)]
    pub height: Option<u32>,
}

impl SizeArgs {
    /// Applies the overrides ([`Scene::resize`]); a size out of range is exit 2.
    pub fn apply(&self, scene: &mut Scene) -> Result<(), Failure> {
        scene.resize(self.width, self.height).map_err(setting)
    }
}

/// `--memory-budget SIZE`: a plan whose estimated GPU + host memory
/// (`mirrorbox_raster::Planned::memory_estimate`) is above it is refused before any GPU work
/// (exit 2, naming the estimate and what to lower).
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct MemoryBudgetArgs {
    /// Refuse a frame whose estimated GPU + host memory exceeds SIZE (before any GPU work):
    /// 2G, 512M, 1.5GB or plain bytes (K, M, G, T are powers of 1024), 1M..1T.
    #[arg(
        long = "memory-budget",
        value_name = "SIZE",
        default_value = "2G",
        value_parser = parse_memory_budget
    )]
    pub memory_budget: u64,
}

impl Default for MemoryBudgetArgs {
    fn default() -> Self {
        MemoryBudgetArgs {
            memory_budget: mirrorbox_raster::DEFAULT_MEMORY_BUDGET,
        }
    }
}

/// The one parser of `--memory-budget` values (clap reports its error with exit 2).
pub fn parse_memory_budget(text: &str) -> Result<u64, String> {
    mirrorbox_raster::parse_memory_size("--memory-budget", text)
}

/// Most frames of a `--sequence`.
pub const MAX_SEQUENCE: u32 = 10_000;

/// `--time T`: the scene's camera placed by its `camera.path` at T seconds; `--sequence N
/// --fps F`: N frames along it.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct TimeArgs {
    /// Seconds along the scene's camera path (`camera.path`, docs/scene-format.md): the
    /// camera where the path puts it then (held before the first key and after the last).
    /// Without a path the scene is still and every time is the same view.
    #[arg(long, allow_negative_numbers = true)]
    pub time: Option<f64>,
    /// Render N frames along the camera path, frame k at --time (default 0) + k / --fps, into
    /// OUT_0000, OUT_0001, … (1..10000).
    #[arg(long)]
    pub sequence: Option<u32>,
    /// Frames per second of a --sequence, in (0, 1000].
    #[arg(long, default_value_t = 30.0, requires = "sequence")]
    pub fps: f64,
}

impl TimeArgs {
    /// The frames of a `--sequence`: each frame's time and output suffix; `None` without
    /// the flag. Bad values are exit 2.
    pub fn sequence(&self) -> Result<Option<Vec<(f64, String)>>, Failure> {
        let Some(n) = self.sequence else {
            return Ok(None);
        };
        if !(1..=MAX_SEQUENCE).contains(&n) {
            return Err(Failure::BadInput(format!(
                "--sequence must be in [1, {MAX_SEQUENCE}] frames, got {n}"
            )));
        }
        if !(self.fps.is_finite() && self.fps > 0.0 && self.fps <= 1000.0) {
            return Err(Failure::BadInput(format!(
                "--fps must be in (0, 1000], got {}",
                self.fps
            )));
        }
        let start = self.time.unwrap_or(0.0);
        let frames: Vec<(f64, String)> = (0..n)
            .map(|k| (start + f64::from(k) / self.fps, format!("{k:04}")))
            .collect();
        for (k, (time, suffix)) in frames.iter().enumerate() {
            // The frame's time comes from three flags: say which made it.
            check_time(*time).map_err(|e| match e {
                Failure::BadInput(m) => Failure::BadInput(format!(
                    "frame {suffix}, at --time {start} + {k} / --fps {}: {m}",
                    self.fps
                )),
                other => other,
            })?;
        }
        Ok(Some(frames))
    }

    /// Runs `run_frame` once, or with `--sequence` once per frame: `with_frame(args, time,
    /// suffix)` gives that frame's arguments (its `--time`, its output `OUT_suffix`). Each
    /// frame is written whole before the next starts; `check_frame` (the frame's time and
    /// outputs) passes for every frame before the first runs, so a refused frame leaves no
    /// earlier frames on disk.
    pub fn run<A>(
        &self,
        args: &A,
        with_frame: impl Fn(&A, TimeArgs, &str) -> A,
        check_frame: impl Fn(&A) -> Result<(), Failure>,
        run_frame: impl Fn(&A) -> Result<(), Failure>,
    ) -> Result<(), Failure> {
        let Some(frames) = self.sequence()? else {
            return run_frame(args);
        };
        let frames: Vec<A> = frames
            .into_iter()
            .map(|(time, suffix)| {
                let frame = TimeArgs {
                    time: Some(time),
                    sequence: None,
                    ..*self
                };
                with_frame(args, frame, &suffix)
            })
            .collect();
        for frame in &frames {
            check_frame(frame)?;
        }
        for frame in &frames {
            run_frame(frame)?;
        }
        Ok(())
    }

    /// The scene at `--time` (itself without the flag); a bad time is exit 2.
    pub fn apply(&self, scene: Scene) -> Result<Scene, Failure> {
        let Some(time) = self.time else {
            return Ok(scene);
        };
        check_time(time)?;
        scene.at_time(time).map_err(|e| path_error(&scene, e))
    }

    /// What [`TimeArgs::apply`] would refuse, without making the scene at that time.
    pub fn check(&self, scene: &Scene) -> Result<(), Failure> {
        let Some(time) = self.time else {
            return Ok(());
        };
        check_time(time)?;
        scene
            .camera_at_time(time)
            .map(drop)
            .map_err(|e| path_error(scene, e))
    }

    /// The provenance attribute of an output, when a time was given.
    pub fn attribute(&self) -> Option<(&'static str, String)> {
        self.time.map(|t| ("mirrorbox.time", t.to_string()))
    }
}

/// Checks a sequence frame's `--time` against the scene (its camera path may give no view
/// then), before any frame runs; `loaded` holds the scene, read once for all frames.
pub fn check_frame_time(
    time: TimeArgs,
    path: &Path,
    loaded: &std::cell::OnceCell<Scene>,
) -> Result<(), Failure> {
    if loaded.get().is_none() {
        let _ = loaded.set(load(path)?);
    }
    let scene = loaded.get().expect("the scene was loaded just above");
    time.check(scene)
}

/// A camera path that gives no view at a time (exit 2), naming the scene file.
fn path_error(scene: &Scene, e: mirrorbox_scene::camera_path::DegenerateView) -> Failure {
    Failure::BadInput(format!("{}: camera.path: {e}", scene.source.display()))
}

/// A `--time` (or a sequence frame's) out of range is exit 2.
fn check_time(time: f64) -> Result<(), Failure> {
    if !time.is_finite() || time.abs() > 1e9 {
        return Err(Failure::BadInput(format!(
            "--time must be a finite number of seconds within ±1e9, got {time}"
        )));
    }
    Ok(())
}

/// A setting out of its range is the user's input (exit 2).
/// A flag (`--alpha`, `--reflectance`, `--min-throughput`) that makes `scene`'s light images
/// exceed their budget (exit 2).
pub fn light_budget(
    scene: &Scene,
    flag: &str,
    e: mirrorbox_scene::light_images::TooManyLightImages,
) -> Failure {
    Failure::BadInput(format!("{}: {flag}: {e}", scene.source.display()))
}

pub fn setting(e: mirrorbox_scene::limits::SettingError) -> Failure {
    Failure::BadInput(e.to_string())
}

/// Checks that `path` has extension `ext` and that its folder exists, before any work. The
/// rule of every command: an output's folder must exist — a mistyped folder is refused, not
/// created; commands create only folders of their own inside it (`sweep`'s `--out` and its
/// `images/` and `cache/`, `export-mitsuba`'s `meshes/`).
pub fn output_path(flag: &str, path: &Path, ext: &str) -> Result<PathBuf, Failure> {
    let has_ext = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case(ext));
    if !has_ext {
        return Err(Failure::BadInput(format!(
            "{flag} {}: must name a .{ext} file",
            path.display()
        )));
    }
    if path.is_dir() {
        return Err(Failure::BadInput(format!(
            "{flag} {}: is a folder; name a .{ext} file",
            path.display()
        )));
    }
    let parent = mirrorbox_files::folder_of(path);
    if !parent.is_dir() {
        let what = if parent.exists() {
            "is a file, not a folder"
        } else {
            "does not exist"
        };
        return Err(Failure::BadInput(format!(
            "{flag} {}: folder {} {what}",
            path.display(),
            parent.display()
        )));
    }
    // A folder that takes no new file (read-only, `/proc`) is found now, not after the work
    // (a trace had run to its end and then failed, exit 1): a probe file made and removed.
    let probe = parent.join(format!(".mirrorbox-probe-{}", std::process::id()));
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
        }
        Err(e) if e.kind() != std::io::ErrorKind::AlreadyExists => {
            return Err(Failure::BadInput(format!(
                "{flag} {}: folder {} takes no new file: {e}",
                path.display(),
                parent.display()
            )));
        }
        Err(_) => {}
    }
    Ok(path.to_path_buf())
}

/// This process's peak resident memory so far, for the summary lines of long commands;
/// `None` where `/proc` does not say.
pub fn peak_memory() -> Option<String> {
    mirrorbox_harness::peak_memory_bytes().map(mirrorbox_files::human_bytes)
}

/// The files one command writes: none a folder, no two the same file — checked before any
/// work (write them with `StagedFiles`, so they appear together or not at all).
pub fn check_outputs(outputs: &[(&str, PathBuf)]) -> Result<(), Failure> {
    mirrorbox_files::check_outputs(outputs).map_err(|e| Failure::BadInput(e.to_string()))
}

/// A progress bar on stderr (drawn only when stderr is a terminal).
pub fn progress_bar(len: u64, what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} {per_sec} ETA {eta}")
            .expect("static template")
            .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}
