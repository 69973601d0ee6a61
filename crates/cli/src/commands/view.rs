//! `mirrorbox view SCENE`: a window with the method live, the traced truth refining beside
//! it and their error (docs/viewer.md). `--script` drives it; `--frames N --screenshot
//! OUT.png` takes one picture and closes.
//!
//! Built without the `viewer` feature (`cargo build --no-default-features`, as
//! `scripts/run.sh` builds it: the main job draws no window, and the window's crates are about
//! a third of a cold release build), the command takes the same arguments — its `--help`, and
//! the CLI reference generated from it, are the same — and says how to build the viewer.

use super::method_flags::{RenderOptions, method_value_parser};
use crate::Failure;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Scene file (JSON).
    scene: PathBuf,
    /// The raster method to start with (switchable in the window: the panel, keys 1…9 and 0, or M for the next).
    #[arg(long, default_value = "auxiliary", value_parser = method_value_parser())]
    method: String,
    #[command(flatten)]
    options: RenderOptions,
    /// α: sets every mirror's reflectance, in [0, 1] (default: the scene's).
    #[arg(long, visible_alias = "reflectance", allow_negative_numbers = true)]
    alpha: Option<f32>,
    #[command(flatten)]
    size: super::TruthSizeArgs,
    /// Start at the camera the scene's `camera.path` gives at this many seconds.
    #[arg(long, allow_negative_numbers = true)]
    time: Option<f64>,
    /// Supersampling factor s of the method, 1..8; the live truth uses the same s×s grid.
    #[arg(long, default_value_t = 1)]
    ssaa: u32,
    /// Window size WIDTHxHEIGHT in pixels (default: the panel and four panes of the view).
    #[arg(long, value_parser = parse_size)]
    window: Option<(u32, u32)>,
    /// Timed actions that drive the viewer, one per line (see docs/viewer.md).
    #[arg(long, conflicts_with_all = ["frames", "screenshot"])]
    script: Option<PathBuf>,
    /// Draw N frames, then close (with --screenshot: one more frame, whose window is saved:
    /// N + 1 frames in all, which `feedback` and `cubemap` show as one more reflection).
    #[arg(long)]
    frames: Option<u32>,
    /// Save the window (PNG) with the method and truth EXRs beside it, after --frames.
    #[arg(long, requires = "frames")]
    screenshot: Option<PathBuf>,
    /// Write one JSON line per frame (method, passes, draws, GPU ms, truth level, panes) here
    /// when the viewer closes.
    #[arg(long)]
    log: Option<PathBuf>,
    /// Present without waiting for the display's refresh (default: vsync on).
    #[arg(long)]
    no_vsync: bool,
    /// Folder the screenshot key (P) writes into (default: the current folder); the camera key
    /// (C) writes beside the scene, whose relative paths its copy keeps.
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// Where the live truth is traced: cpu (the tracer), gpu (ray queries on the adapter,
    /// `trace --device gpu`), or auto: the GPU where the adapter has ray queries and is not a
    /// CPU (on lavapipe the GPU truth runs on the same cores and is slower than the tracer).
    #[arg(long, value_enum, default_value_t = TruthDeviceArg::Auto)]
    truth: TruthDeviceArg,
    #[command(flatten)]
    memory: super::MemoryBudgetArgs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TruthDeviceArg {
    Auto,
    Cpu,
    Gpu,
}

/// The largest window side (the viewer's; without it, nothing is opened).
#[cfg(feature = "viewer")]
const MAX_WINDOW_SIDE: u32 = mirrorbox_viewer::script::MAX_WINDOW_SIDE;
#[cfg(not(feature = "viewer"))]
const MAX_WINDOW_SIDE: u32 = u32::MAX;
/// The smallest window side.
#[cfg(feature = "viewer")]
const MIN_WINDOW_SIDE: u32 = mirrorbox_viewer::script::MIN_WINDOW_SIDE;
#[cfg(not(feature = "viewer"))]
const MIN_WINDOW_SIDE: u32 = 64;

fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let (w, h) = text
        .split_once('x')
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got {text:?}"))?;
    let side = |s: &str| {
        s.parse::<u32>()
            .ok()
            .filter(|v| (MIN_WINDOW_SIDE..=MAX_WINDOW_SIDE).contains(v))
            .ok_or_else(|| {
                format!("each side must be in [{MIN_WINDOW_SIDE}, {MAX_WINDOW_SIDE}], got {s:?}")
            })
    };
    Ok((side(w)?, side(h)?))
}

/// Without the viewer: says how to build it (exit 2), whatever the arguments.
#[cfg(not(feature = "viewer"))]
pub fn run(_: &Args) -> Result<(), Failure> {
    Err(Failure::BadInput(
        "this mirrorbox was built without the viewer (`--no-default-features`: scripts/run.sh \
         builds it so, to keep the main job within its time budget); build it with the viewer \
         with `cargo build --release -p mirrorbox`"
            .into(),
    ))
}

#[cfg(feature = "viewer")]
pub fn run(args: &Args) -> Result<(), Failure> {
    use super::{load, output_path, unit_interval};
    use mirrorbox_raster::RenderSettings;
    use mirrorbox_viewer::script::{self, Action, Step};
    use mirrorbox_viewer::{ViewError, ViewOptions};
    let bad = Failure::BadInput;
    let entry = mirrorbox_raster::registry::find(&args.method)
        .ok_or_else(|| bad(format!("unknown method {:?}", args.method)))?;
    let method = args.options.0.configure(entry)?;
    let alpha = unit_interval("--alpha", args.alpha)?;
    // The limit of every command, the script's `ssaa` and the panel's slider.
    super::ssaa(args.ssaa)?;
    let at = super::TimeArgs {
        time: args.time,
        ..Default::default()
    };
    let mut scene = at.apply(load(&args.scene)?)?;
    super::SizeArgs {
        width: args.size.width,
        height: args.size.height,
    }
    .apply(&mut scene)?;
    // The error pane's metrics need SSIM's window: a smaller view had waited for them forever.
    let min = mirrorbox_image::metrics::MIN_SIDE;
    let (w, h) = (scene.camera.width, scene.camera.height);
    if w < min || h < min {
        return Err(bad(format!(
            "the view is {w}×{h} pixels; the viewer compares it with its truth, which needs at \
             least {min} on each side (SSIM's window): give --width and --height of {min} or more"
        )));
    }
    if let Some(alpha) = alpha {
        scene
            .set_reflectance(glam::Vec3::splat(alpha))
            .map_err(|e| super::light_budget(&scene, "--alpha", e))?;
    }
    let settings = RenderSettings {
        method: method.clone(),
        ssaa: args.ssaa,
        frames: 1,
        warmup: 0,
    };
    settings.check(&scene).map_err(super::setting)?;
    // The starting method over --memory-budget is refused before the window opens (a method
    // chosen in the window is refused in its pane, as is a starting plan refused otherwise).
    if let Ok(planned) = mirrorbox_raster::plan_frame(&scene, &settings) {
        planned.check_memory(&scene, &settings, args.memory.memory_budget)?;
    }
    if !args.out.is_dir() {
        return Err(bad(format!(
            "--out {}: folder does not exist",
            args.out.display()
        )));
    }
    let mut inputs = vec![(script::SCENE_INPUT, args.scene.as_path())];
    if let Some(path) = &args.script {
        inputs.push(("the script", path.as_path()));
    }
    let (steps, script_name) = match (&args.script, args.frames) {
        (Some(path), _) => {
            let steps = script::read_script(path).map_err(|e| bad(e.to_string()))?;
            let name = path.display().to_string();
            script::check_script_writes(&steps, &name, &inputs).map_err(|e| bad(e.to_string()))?;
            (Some(steps), name)
        }
        (None, Some(frames)) => {
            if !(1..=script::MAX_FRAMES).contains(&frames) {
                return Err(bad(format!(
                    "--frames must be in [1, {}], got {frames}",
                    script::MAX_FRAMES
                )));
            }
            let mut steps = vec![Step {
                line: 0,
                action: Action::Frames(frames),
            }];
            if let Some(png) = &args.screenshot {
                let png = output_path("--screenshot", png, "png")?;
                let action = Action::Screenshot(png.clone());
                script::check_writes(&action, &inputs)
                    .map_err(|e| bad(format!("--screenshot {}: {e}", png.display())))?;
                steps.push(Step { line: 0, action });
            }
            (Some(steps), "--frames".to_string())
        }
        (None, None) => (None, String::new()),
    };
    if let Some(log) = &args.log {
        // Written when the window closes: refused now if it would replace an input.
        let log = output_path("--log", log, "jsonl")?;
        script::check_files(&[log], &inputs).map_err(|e| bad(format!("--log {e}")))?;
    }
    let size = (scene.camera.width, scene.camera.height);
    let options = ViewOptions {
        scene_path: args.scene.clone(),
        scene,
        method,
        ssaa: args.ssaa,
        memory_budget: args.memory.memory_budget,
        size,
        window: args.window,
        script: steps,
        script_name,
        log: args.log.clone(),
        vsync: !args.no_vsync,
        out_dir: args.out.clone(),
        truth_device: match args.truth {
            TruthDeviceArg::Auto => None,
            TruthDeviceArg::Cpu => Some(mirrorbox_viewer::live_truth::TruthDevice::Cpu),
            TruthDeviceArg::Gpu => Some(mirrorbox_viewer::live_truth::TruthDevice::Gpu),
        },
    };
    mirrorbox_viewer::run(options).map_err(|e| match e {
        ViewError::Refused(m) => Failure::BadInput(m),
        ViewError::Failed(m) => Failure::Other(m),
    })
}
