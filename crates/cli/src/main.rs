//! `mirrorbox`: the command-line harness. A thin layer: it parses arguments, calls the
//! crates (scene → renderers → images → metrics → reports) and maps failures to exit codes:
//! 0 success, 2 bad input (unreadable or invalid scene, bad arguments), 1 anything else.
//!
//! One module per subcommand under `commands/`; a new subcommand is one more module and one
//! more variant of the command enum.

mod commands;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "mirrorbox",
    version,
    about = "Rasterized infinity mirrors measured against ray-traced truth"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate scene files and print one summary line per scene.
    Check(commands::check::Args),
    /// Print the wgpu adapter mirrorbox would render and time on.
    Info(commands::info::Args),
    /// Render the ray-traced ground truth (obvhs, all CPU cores).
    Trace(commands::trace::Args),
    /// Render with a raster method (wgpu), timed.
    Render(commands::render::Args),
    /// Compare an image with a reference: linear and perceptual metrics.
    Compare(commands::compare::Args),
    /// Sweep methods, n and α: time, compare with cached truths, write reports (resumable).
    Sweep(commands::sweep::Args),
    /// Run an experiment of the registry (crates/experiments): its sweeps, sequences or script, into its report folder (`--list` lists them).
    Experiment(commands::sweep::ExperimentArgs),
    /// The method and setting to ship for a scene and a frame budget on this device: a search that times few candidates, with the pick, its ties, the next better choice and the front (issue 55).
    Advise(commands::advise::Args),
    /// A window: the method live (free camera, every option switchable), the traced truth
    /// refining beside it, and their error (docs/viewer.md).
    View(commands::view::Args),
    /// Export a scene as Mitsuba 3 XML (tools/mitsuba renders and compares it).
    ExportMitsuba(commands::export_mitsuba::Args),
    /// Export a scene for any renderer: glTF, its views in every camera convention, and their truths with and without mirrors (docs/exchange.md).
    ExportViews(commands::export_views::Args),
    /// Score any renderer's images and timings against an export's truths, into a sweep folder (docs/exchange.md).
    Score(commands::score::Args),
    /// Place a glTF 2.0 asset in a mirror box sized to its bounds and write the scene file (docs/gltf.md).
    Import(commands::import::Args),
    /// Fill the generated regions of README.md, docs/methods.md and the book (docs/book/src/*.md) from the committed reports and the CLI's own help (--check: only compare).
    Readme(commands::readme::Args),
    /// Rewrite a sweep folder's report (Markdown, HTML, CSV, plots) from its results.jsonl, without rendering.
    Report(commands::report::Args),
    /// Join the shards of a sweep (`sweep --shard I/N`, each in its own folder) into one sweep folder and write its reports.
    Merge(commands::merge::Args),
    /// Internal: one timed render of a sweep, a job as JSON on stdin (see
    /// `mirrorbox_harness::worker`).
    #[command(hide = true)]
    RenderWorker,
}

/// Mesa's Vulkan device-select layer prints "error: XDG_RUNTIME_DIR is invalid" on headless
/// machines, which reads like one of our own errors. wgpu enumerates every device itself, so
/// the layer adds nothing here; disable it unless the user set `NODEVICE_SELECT` themselves.
fn quiet_mesa_device_select() {
    if std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: called first thing in `main`, before any other thread exists.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}

/// Mesa keeps compiled shaders on disk (`~/.cache/mesa_shader_cache*`), and lavapipe runs the
/// shaders it loads from there slower than those it compiles: on Mesa 25.0.7, `portal` depth
/// 64 took 1.7× and `unrolled` 1.4× as long while the paper's method and the floor did not
/// change (`reports/shader_cache`, issue 54). Whether a run found the cache warm (a second run
/// on a machine, not a fresh one) then decided a speed verdict, so the commands that time
/// frames (`advise` among them) compile every shader afresh, unless the user set `MESA_SHADER_CACHE_DISABLE`
/// themselves; each sweep records which (`sweep.json`, `shader_cache`), and `info` says what
/// they will have.
fn compile_shaders_afresh_when_timing(command: &Command) {
    let timing = matches!(
        command,
        Command::Info(_)
            | Command::Render(_)
            | Command::Sweep(_)
            | Command::Experiment(_)
            | Command::Advise(_)
            | Command::View(_)
            | Command::RenderWorker
    );
    if timing && std::env::var_os("MESA_SHADER_CACHE_DISABLE").is_none() {
        // SAFETY: called in `main` before any other thread exists (argument parsing starts
        // none).
        unsafe { std::env::set_var("MESA_SHADER_CACHE_DISABLE", "true") };
    }
}

/// Printing into a closed pipe (`mirrorbox check … | head`) ends the process quietly, as Unix
/// tools do, instead of Rust's "failed printing to stdout: Broken pipe" panic: restore the
/// default action of SIGPIPE, which Rust's runtime sets to ignore.
fn die_quietly_on_closed_pipe() {
    #[cfg(unix)]
    {
        const SIGPIPE: std::ffi::c_int = 13;
        const SIG_DFL: usize = 0;
        unsafe extern "C" {
            fn signal(signum: std::ffi::c_int, handler: usize) -> usize;
        }
        // SAFETY: called first thing in `main`, before any other thread exists.
        unsafe {
            signal(SIGPIPE, SIG_DFL);
        }
    }
}

/// `n thing` or `n things` (`n passes` for a word ending in s, x, ch or sh).
pub fn count(n: usize, thing: &str) -> String {
    if n == 1 {
        format!("1 {thing}")
    } else if ["s", "x", "ch", "sh"].iter().any(|e| thing.ends_with(e)) {
        format!("{n} {thing}es")
    } else {
        format!("{n} {thing}s")
    }
}

/// Why a command failed; decides the exit code.
#[derive(Debug)]
pub enum Failure {
    /// The user's input is wrong (exit 2). The message names the file and field.
    BadInput(String),
    /// Anything else (exit 1).
    Other(String),
}

/// A refused input exits 2, a failing device or driver 1 (`RasterError::is_refusal`).
impl From<mirrorbox_raster::RasterError> for Failure {
    fn from(e: mirrorbox_raster::RasterError) -> Self {
        if e.is_refusal() {
            Failure::BadInput(e.to_string())
        } else {
            Failure::Other(e.to_string())
        }
    }
}

impl From<mirrorbox_raster::PlanError> for Failure {
    fn from(e: mirrorbox_raster::PlanError) -> Self {
        Failure::BadInput(e.to_string())
    }
}

impl From<mirrorbox_raster::ParamError> for Failure {
    fn from(e: mirrorbox_raster::ParamError) -> Self {
        Failure::BadInput(e.to_string())
    }
}

impl From<mirrorbox_harness::HarnessError> for Failure {
    fn from(e: mirrorbox_harness::HarnessError) -> Self {
        if e.is_refusal() {
            Failure::BadInput(e.to_string())
        } else {
            Failure::Other(e.to_string())
        }
    }
}

impl Failure {
    fn exit_code(&self) -> u8 {
        match self {
            Failure::BadInput(_) => 2,
            Failure::Other(_) => 1,
        }
    }
    pub fn message(&self) -> &str {
        match self {
            Failure::BadInput(m) | Failure::Other(m) => m,
        }
    }
}

fn main() -> ExitCode {
    quiet_mesa_device_select();
    die_quietly_on_closed_pipe();
    // A repeated flag: the last one wins, as in most command lines (scripts append overrides).
    let command = Cli::command().mut_subcommands(|s| s.args_override_self(true));
    // clap exits with 2 on bad arguments, matching our convention.
    let cli = Cli::from_arg_matches(&command.get_matches()).unwrap_or_else(|e| e.exit());
    compile_shaders_afresh_when_timing(&cli.command);
    let result = match cli.command {
        Command::Check(args) => commands::check::run(&args),
        Command::Import(args) => commands::import::run(&args),
        Command::Info(args) => commands::info::run(&args),
        Command::Trace(args) => commands::trace::run(&args),
        Command::Render(args) => commands::render::run(&args),
        Command::Compare(args) => commands::compare::run(&args),
        Command::Sweep(args) => commands::sweep::run(&args),
        Command::Experiment(args) => commands::sweep::run_experiment_command(&args),
        Command::Advise(args) => commands::advise::run(&args),
        Command::View(args) => commands::view::run(&args),
        Command::ExportMitsuba(args) => commands::export_mitsuba::run(&args),
        Command::ExportViews(args) => commands::export_views::run(&args),
        Command::Score(args) => commands::score::run(&args),
        Command::Readme(args) => commands::readme::run(&args),
        Command::Report(args) => commands::report::run(&args),
        Command::Merge(args) => commands::merge::run(&args),
        Command::RenderWorker => {
            mirrorbox_harness::serve(std::io::stdin().lock(), std::io::stdout().lock())
                .map_err(Failure::from)
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => {
            eprintln!("error: {}", failure.message());
            ExitCode::from(failure.exit_code())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The image crate reads what the scene's limits allow to be written, no more, no less.
    #[test]
    fn image_and_scene_limits_agree() {
        use mirrorbox_scene::limits;
        assert_eq!(mirrorbox_image::MAX_PIXELS, limits::MAX_PIXELS);
        assert_eq!(mirrorbox_image::MAX_IMAGE_SIDE, limits::MAX_IMAGE_SIDE);
    }

    /// Issue #13: every flag and argument of every subcommand says what it is.
    #[test]
    fn every_flag_has_help() {
        let command = Cli::command();
        let mut missing = Vec::new();
        for sub in command.get_subcommands() {
            for arg in sub.get_arguments() {
                if arg.get_help().is_none() && arg.get_long_help().is_none() {
                    missing.push(format!("{} --{}", sub.get_name(), arg.get_id()));
                }
            }
        }
        assert!(missing.is_empty(), "no help: {missing:?}");
    }
}
