//! `mirrorbox sweep SCENE --out DIR` and `mirrorbox experiment NAME`: raster methods timed
//! and compared with cached ground truths, resumable, with reports.

use super::method_flags::SweepOptions;
use super::progress_bar;
use crate::Failure;
use mirrorbox_harness::sequence::{Scenario, SequenceConfig};
use mirrorbox_harness::{AxisValues, Event, Shard, SweepConfig, run_sweep};
use mirrorbox_raster::registry::{find, names};
use mirrorbox_trace::WhittedSettings;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Scene file (JSON).
    scene: PathBuf,
    /// Output folder (results.jsonl, results.csv, report.md, report.html, plots, images, cache).
    #[arg(long)]
    out: PathBuf,
    /// Methods, comma separated (the registry's: see `render --help`).
    #[arg(long, default_value = "naive,auxiliary")]
    methods: String,
    /// Each method is swept over its swept option's axis (`--n` for auxiliary, `--depth` for
    /// the exact methods); its other options take one value, for the methods that have them.
    #[command(flatten)]
    options: SweepOptions,
    /// α: mirror reflectances, comma separated, each in [0, 1]. `--reflectance` is the same
    /// flag.
    #[arg(
        long,
        visible_alias = "reflectance",
        default_value = "0.5,0.7,0.9,1.0",
        allow_hyphen_values = true
    )]
    alpha: String,
    #[command(flatten)]
    size: super::TruthSizeArgs,
    /// Supersampling s of the raster (the truth uses the same s×s sub-pixel grid), 1..8.
    #[arg(long, default_value_t = 1)]
    ssaa: u32,
    /// Timed frames per point, 1..10000, one per interleaved round (after --warmup untimed
    /// ones each, and an untimed settling round of every point first); 6 or more give each
    /// median a 95 % interval.
    #[arg(long, default_value_t = 5)]
    frames: u32,
    /// Untimed frames rendered first (driver caches, pipeline compilation), 0..1000.
    #[arg(long, default_value_t = 2)]
    warmup: u32,
    /// Ground truth: most mirror reflections a path follows.
    #[arg(long, default_value_t = 10_000)]
    max_depth: u32,
    /// Ground truth: stop a path below this throughput, in [0, 1).
    #[arg(long, default_value_t = 1e-4, allow_negative_numbers = true)]
    min_throughput: f32,
    /// Discard earlier results in --out and measure every point again (cached truths stay).
    #[arg(long)]
    fresh: bool,
    /// Symmetry planes p, comma separated or a range `a..=b` or `a..b` (both ends
    /// included): every point is measured on the scene keeping its first p
    /// `symmetry_planes` (seed 001), for each p; each 0..=16 and at most the scene's planes.
    #[arg(long)]
    symmetry_planes: Option<String>,
    /// Mirrored-light depths k, comma separated or a range `a..=b` or `a..b` (both ends
    /// included): every point is measured on the scene lighting its surfaces through chains
    /// of up to k mirrors (`lighting.mirrored_lights`, docs/shading.md), for each k; each
    /// 0..=64.
    #[arg(long)]
    mirrored_lights: Option<String>,
    /// Uneven-mirror tilts in degrees, comma separated: every point is measured on the scene
    /// with its uneven mirrors' steepest tilt set to each (ripple amplitude; normal-map
    /// strength, docs/shading.md); each in [0, 90).
    #[arg(long)]
    bump_amplitude: Option<String>,
    /// Stereo pairs: interpupillary distances in scene units, comma separated, each in [0, 1],
    /// or `mono`: every point renders both eyes of the camera's `stereo` rig (or an off-axis
    /// rig converging at look_at) as one frame, each eye against its own truth, at each IPD;
    /// `mono` is the plain frame.
    #[arg(long)]
    ipd: Option<String>,
    /// Camera turns in degrees, comma separated, each in [-180, 180]: every point is measured
    /// with the camera turned about the scene's up axis through its position (positive to the
    /// left) — how much of what the mirrors reflect is on screen (`ssr`'s question).
    #[arg(long, allow_negative_numbers = true)]
    camera_yaw: Option<String>,
    /// With --ipd: the name of a diffuse object whose first reflection is located in each eye
    /// (raster and truth), for the report's disparity check.
    #[arg(long, requires = "ipd")]
    marker: Option<String>,
    /// A sequence sweep (issue 22): render every method and the truth along the scene's
    /// camera path for N frames (frame k at --time + k / --fps), each method's frames in
    /// order in one process (so `feedback` carries its state), each frame against its own
    /// truth; writes frames.jsonl, report.md, a plot of FLIP against frame and a filmstrip
    /// of each stateful setting's worst frames. Not resumed: an earlier sequence sweep in
    /// --out needs --fresh. 1..1000.
    #[arg(
        long,
        value_name = "N",
        conflicts_with_all = ["symmetry_planes", "mirrored_lights", "bump_amplitude", "ipd", "camera_yaw", "alpha", "shard", "truth_cache", "isolate_renders", "memory_budget"]
    )]
    path: Option<u32>,
    /// Frames per second of path time for --path, in (0, 1000].
    #[arg(long, default_value_t = 30.0, requires = "path")]
    fps: f64,
    /// Path time of --path's first frame, seconds.
    #[arg(
        long,
        default_value_t = 0.0,
        requires = "path",
        allow_negative_numbers = true
    )]
    time: f64,
    #[command(flatten)]
    shard: ShardArgs,
    /// Render every timed frame in its own child process (`mirrorbox render-worker`), as the
    /// sweeps did for Mesa 22.3's lavapipe, which kept the memory of every executed pass; by
    /// default the sweep renders in its own process on one device (docs/budgets.md).
    #[arg(long)]
    isolate_renders: bool,
    #[command(flatten)]
    memory: super::MemoryBudgetArgs,
}

/// `--shard` and `--truth-cache`, for `sweep` and `experiment` (issue 20).
#[derive(clap::Args, Clone, Debug, Default)]
pub struct ShardArgs {
    /// Run one shard of the sweep: `I/N` (I from 0), or `auto/N` / `auto`, taking I from
    /// SLURM_ARRAY_TASK_ID (less SLURM_ARRAY_TASK_MIN) or JOB_COMPLETION_INDEX (Kubernetes
    /// Indexed Jobs) and N, with `auto`, from SLURM_ARRAY_TASK_COUNT. The points are split by a
    /// hash of their keys; `mirrorbox merge` joins the shards' folders.
    #[arg(long)]
    shard: Option<String>,
    /// Folder of the traced truths (default OUT/cache); shards may share one.
    #[arg(long)]
    truth_cache: Option<PathBuf>,
}

impl ShardArgs {
    fn apply(&self, config: &mut SweepConfig) -> Result<(), Failure> {
        config.shard = self.shard.as_deref().map(parse_shard).transpose()?;
        config.truth_cache = self.truth_cache.clone();
        Ok(())
    }
}

/// `--shard I/N`, `auto/N` or `auto` (see [`ShardArgs`]); the ranges are checked with the
/// other settings.
fn parse_shard(text: &str) -> Result<Shard, Failure> {
    let bad = |why: String| bad(format!("--shard {text:?}: {why}"));
    let number = |s: &str, what: &str| -> Result<u32, Failure> {
        s.trim()
            .parse::<u32>()
            .map_err(|_| bad(format!("{what} must be a whole number, got {s:?}")))
    };
    let env = |name: &str| std::env::var(name).ok().filter(|v| !v.trim().is_empty());
    let (index, count) = text.split_once('/').unwrap_or((text, ""));
    let count = match (count, env("SLURM_ARRAY_TASK_COUNT")) {
        ("", Some(c)) if index == "auto" => number(&c, "SLURM_ARRAY_TASK_COUNT")?,
        ("", _) => {
            return Err(bad(
                "expected I/N, auto/N, or auto inside a Slurm job array".into(),
            ));
        }
        (n, _) => number(n, "N")?,
    };
    let index = if index == "auto" {
        match (env("SLURM_ARRAY_TASK_ID"), env("JOB_COMPLETION_INDEX")) {
            (Some(id), _) => {
                let min = env("SLURM_ARRAY_TASK_MIN")
                    .map(|m| number(&m, "SLURM_ARRAY_TASK_MIN"))
                    .transpose()?
                    .unwrap_or(0);
                number(&id, "SLURM_ARRAY_TASK_ID")?
                    .checked_sub(min)
                    .ok_or_else(
                        || bad("SLURM_ARRAY_TASK_ID is below SLURM_ARRAY_TASK_MIN".into()),
                    )?
            }
            (None, Some(i)) => number(&i, "JOB_COMPLETION_INDEX")?,
            (None, None) => {
                return Err(bad(
                    "auto needs SLURM_ARRAY_TASK_ID (a Slurm job array) or JOB_COMPLETION_INDEX \
                     (a Kubernetes Indexed Job)"
                        .into(),
                ));
            }
        }
    } else {
        number(index, "I")?
    };
    Ok(Shard { index, count })
}

/// The options of `experiment NAME` (the preset subcommands `table1`, `depth-scaling` … that
/// once took them are gone).
#[derive(clap::Args, Default)]
pub struct PresetArgs {
    /// Output folder of the report (default: the experiment's folder in reports/; a script
    /// experiment writes where its script does and refuses --out).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Timed frames per point, one per interleaved round after an untimed settling round
    /// (default: the experiment's: 9, 15 for Table 1; 6 or more give each median a 95 %
    /// interval); a sequence experiment (motion): frames per scenario.
    #[arg(long)]
    frames: Option<u32>,
    /// Discard earlier results and measure every point again (cached truths stay).
    #[arg(long)]
    fresh: bool,
    #[command(flatten)]
    shard: ShardArgs,
    /// Render every timed frame in its own child process (`mirrorbox render-worker`), as the
    /// sweeps did for Mesa 22.3's lavapipe, which kept the memory of every executed pass; by
    /// default the sweep renders in its own process on one device (docs/budgets.md).
    #[arg(long)]
    isolate_renders: bool,
    #[command(flatten)]
    memory: super::MemoryBudgetArgs,
}

fn bad(m: String) -> Failure {
    Failure::BadInput(m)
}

/// The numbers of `--alpha`; their range is checked with every other sweep setting
/// (`SweepConfig::validate`, the check `trace` and `render` use).
fn parse_alphas(s: &str) -> Result<Vec<f32>, Failure> {
    s.split(',')
        .map(|x| {
            x.trim().parse::<f32>().map_err(|_| {
                bad(format!(
                    "--alpha {s:?}: each value must be a number in [0, 1], got {x:?}"
                ))
            })
        })
        .collect()
}

/// The configured methods of `--methods` with their axes and options. An option that none
/// of the chosen methods has is an error, as on `render`.
fn parse_methods(
    s: &str,
    options: &SweepOptions,
) -> Result<Vec<mirrorbox_raster::Method>, Failure> {
    let mut entries = Vec::new();
    for m in s.split(',') {
        let entry = find(m.trim()).ok_or_else(|| {
            bad(format!(
                "--methods: unknown method {:?} (known: {})",
                m.trim(),
                names()
            ))
        })?;
        entries.push(entry);
    }
    if let Some(unused) = options.unused_by(&entries) {
        return Err(bad(unused));
    }
    let mut methods = Vec::new();
    for e in entries {
        methods.extend(options.methods_of(e)?);
    }
    Ok(methods)
}

/// This executable, run as `render-worker` for every timed render of a sweep with
/// `--isolate-renders` (see `mirrorbox_harness::worker`), and for the sequences of `motion`.
/// On Linux `/proc/self/exe`, which stays this very binary even if the file is rebuilt
/// during the sweep.
fn render_worker() -> Option<PathBuf> {
    let this = PathBuf::from("/proc/self/exe");
    if this.exists() {
        Some(this)
    } else {
        std::env::current_exe().ok()
    }
}

fn command_line() -> String {
    std::env::args().collect::<Vec<_>>().join(" ")
}

pub fn run(args: &Args) -> Result<(), Failure> {
    if let Some(frames) = args.path {
        let methods = parse_methods(&args.methods, &args.options)?;
        let config = SequenceConfig {
            out: args.out.clone(),
            scenarios: vec![Scenario {
                name: "path".into(),
                description: "The camera follows the path of".into(),
                scene: args.scene.clone(),
                start: args.time,
                fps: args.fps,
                frames,
                methods,
            }],
            width: args.size.width,
            height: args.size.height,
            ssaa: args.ssaa,
            truth: WhittedSettings {
                max_depth: args.max_depth,
                min_throughput: args.min_throughput,
            },
            warmup: args.warmup,
            timed: args.frames,
            exe: render_worker()
                .ok_or_else(|| Failure::Other("cannot find this executable".into()))?,
            command: command_line(),
            replace: args.fresh,
        };
        return run_sequences(&config);
    }
    let mut config = SweepConfig {
        scene: args.scene.clone(),
        out: args.out.clone(),
        methods: parse_methods(&args.methods, &args.options)?,
        alphas: parse_alphas(&args.alpha)?,
        width: args.size.width,
        height: args.size.height,
        ssaa: args.ssaa,
        frames: args.frames,
        warmup: args.warmup,
        truth: WhittedSettings {
            max_depth: args.max_depth,
            min_throughput: args.min_throughput,
        },
        command: command_line(),
        worker: args.isolate_renders.then(render_worker).flatten(),
        memory_budget: args.memory.memory_budget,
        axes: scene_axes(args)?,
        sections: mirrorbox_experiments::sections(),
        marker: args.marker.clone(),
        shard: None,
        truth_cache: None,
        camera: None,
        drop_refused: false,
    };
    args.shard.apply(&mut config)?;
    execute(&config, args.fresh)
}

/// The scene axes given on the command line, each parsed and bounded by its
/// [`mirrorbox_harness::AxisSpec`].
fn scene_axes(args: &Args) -> Result<Vec<AxisValues>, Failure> {
    use mirrorbox_harness::axes;
    [
        (&axes::SYMMETRY_PLANES, &args.symmetry_planes),
        (&axes::MIRRORED_LIGHTS, &args.mirrored_lights),
        (&axes::BUMP_AMPLITUDE, &args.bump_amplitude),
        (&axes::STEREO_IPD, &args.ipd),
        (&axes::CAMERA_YAW, &args.camera_yaw),
    ]
    .into_iter()
    .filter_map(|(axis, text)| text.as_deref().map(|t| (axis, t)))
    .map(|(axis, text)| {
        axis.parse(text)
            .map(|values| AxisValues { axis, values })
            .map_err(|e| Failure::BadInput(e.to_string()))
    })
    .collect()
}

/// `mirrorbox experiment NAME`: an experiment of the registry (`mirrorbox-experiments`).
#[derive(clap::Args)]
pub struct ExperimentArgs {
    /// The experiment: one of the registry's (crates/experiments/src/lib.rs, `EXPERIMENTS`).
    #[arg(value_parser = experiment_names(), required_unless_present_any = ["list", "main_job"])]
    name: Option<String>,
    /// List every experiment with what it measures, and exit.
    #[arg(long)]
    list: bool,
    /// Print the names of the experiments the main job runs, one per line, in its order
    /// (`scripts/run.sh` reads them), and exit.
    #[arg(long, conflicts_with = "list")]
    main_job: bool,
    #[command(flatten)]
    preset: PresetArgs,
}

/// The registry's names, each with what it measures (clap lists them in the help).
fn experiment_names() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(
        mirrorbox_experiments::EXPERIMENTS
            .iter()
            .map(|e| clap::builder::PossibleValue::new(e.name).help(e.about)),
    )
}

pub fn run_experiment_command(args: &ExperimentArgs) -> Result<(), Failure> {
    use mirrorbox_experiments::EXPERIMENTS;
    if args.list || args.main_job {
        for e in EXPERIMENTS.iter().filter(|e| args.list || e.main_job) {
            if args.list {
                println!("{:<20} {}", e.name, e.about);
            } else {
                println!("{}", e.name);
            }
        }
        return Ok(());
    }
    let name = args.name.as_deref().unwrap_or_default();
    run_experiment(name, &args.preset)
}

/// Runs the registry's experiment `name` with the preset options (`mirrorbox experiment
/// NAME`; the older preset subcommands, `mirrorbox table1` and the like, are gone: one way in).
fn run_experiment(name: &str, args: &PresetArgs) -> Result<(), Failure> {
    use mirrorbox_experiments::Measure;
    let e = mirrorbox_experiments::find(name)
        .ok_or_else(|| bad(format!("no experiment named {name:?} in the registry")))?;
    let unapplied = unapplied_options(args, &e.measure);
    if !unapplied.is_empty() {
        return Err(bad(format!(
            "experiment {name} does not apply {}: {}",
            unapplied.join(", "),
            match e.measure {
                Measure::Script(script, _) => {
                    format!("it runs {script}, which writes its own report folder")
                }
                _ => "its sequences are rendered whole, in one process, into --out".into(),
            }
        )));
    }
    if args.frames == Some(0) {
        return Err(bad("--frames must be 1 or more, got 0".into()));
    }
    let out = args.out.clone().unwrap_or_else(|| e.default_out());
    match &e.measure {
        Measure::Sweeps(configs) => {
            for config in configs(&out) {
                run_preset(config, args)?;
            }
            Ok(())
        }
        Measure::Sequences(sequences) => {
            let exe = render_worker()
                .ok_or_else(|| Failure::Other("cannot find this executable".into()))?;
            let mut config = sequences(&out, exe, command_line());
            config.replace = args.fresh;
            if let Some(n) = args.frames {
                for s in &mut config.scenarios {
                    s.frames = n;
                }
            }
            run_sequences(&config)
        }
        Measure::Script(script, script_args) => {
            if !std::path::Path::new(script).is_file() {
                return Err(bad(format!(
                    "experiment {name}: {script} not found; run it from the repository root"
                )));
            }
            let exe = std::env::current_exe()
                .map_err(|e| Failure::Other(format!("cannot find this executable: {e}")))?;
            let status = std::process::Command::new("bash")
                .arg(script)
                .args(*script_args)
                .env("MIRRORBOX", exe)
                .status()
                .map_err(|e| Failure::Other(format!("cannot run {script}: {e}")))?;
            if status.success() {
                Ok(())
            } else {
                Err(Failure::Other(format!("{script} failed ({status})")))
            }
        }
    }
}

/// The options given to `experiment` that its kind of measure would ignore (a script takes
/// none of them; sequences take `--out` and `--frames`): refused rather than ignored unsaid,
/// but for `--fresh` and `--truth-cache`, which mean nothing more to them than what they do.
fn unapplied_options(
    args: &PresetArgs,
    measure: &mirrorbox_experiments::Measure,
) -> Vec<&'static str> {
    use mirrorbox_experiments::Measure;
    let script = matches!(measure, Measure::Script(..));
    let sweeps = matches!(measure, Measure::Sweeps(_));
    let given = [
        ("--out", script && args.out.is_some()),
        ("--frames", script && args.frames.is_some()),
        // `--fresh` and `--truth-cache` are the main job's for every experiment
        // (scripts/run.sh): a script measures afresh and traces its own truths anyway, and a
        // sequence needs `--fresh` to replace its earlier report, so they are accepted
        // everywhere.
        ("--shard", !sweeps && args.shard.shard.is_some()),
        ("--isolate-renders", !sweeps && args.isolate_renders),
        (
            "--memory-budget",
            !sweeps
                && args.memory.memory_budget != super::MemoryBudgetArgs::default().memory_budget,
        ),
    ];
    given
        .into_iter()
        .filter_map(|(flag, on)| on.then_some(flag))
        .collect()
}

fn run_sequences(config: &SequenceConfig) -> Result<(), Failure> {
    let started = std::time::Instant::now();
    let records = mirrorbox_harness::sequence::run_sequences(config, &mut |line| {
        eprintln!("sequence: {line}");
    })?;
    eprintln!(
        "sequence sweep: {} frames compared in {:.0} s; report in {}",
        records.len(),
        started.elapsed().as_secs_f64(),
        config.out.join("report.md").display()
    );
    Ok(())
}

fn run_preset(mut config: SweepConfig, args: &PresetArgs) -> Result<(), Failure> {
    config.sections = mirrorbox_experiments::sections();
    if let Some(frames) = args.frames {
        config.frames = frames;
    }
    config.command = command_line();
    config.worker = args.isolate_renders.then(render_worker).flatten();
    config.memory_budget = args.memory.memory_budget;
    args.shard.apply(&mut config)?;
    execute(&config, args.fresh)
}

fn execute(config: &SweepConfig, fresh: bool) -> Result<(), Failure> {
    let started = std::time::Instant::now();
    let mut bar = None;
    let result = run_sweep(config, fresh, &mut |event| match event {
        Event::Planned { todo, reused } => {
            eprintln!(
                "sweep: {todo} points to compute, {reused} already in {}",
                config.out.join("results.jsonl").display()
            );
            // One step per render (points × rounds, the settling round included).
            bar = Some(progress_bar(
                todo as u64 * u64::from(config.frames + mirrorbox_harness::SETTLING_ROUNDS),
                "sweep",
            ));
        }
        Event::Started { label } => {
            if let Some(b) = &bar {
                b.set_message(format!("truth: {label}"));
            }
        }
        Event::Settling { label } => {
            if let Some(b) = &bar {
                b.set_message(format!("settling round: {label}"));
                b.inc(1);
            }
        }
        Event::Timing {
            label,
            round,
            rounds,
        } => {
            if let Some(b) = &bar {
                b.set_message(format!("round {round}/{rounds}: {label}"));
                b.inc(1);
            }
        }
        Event::Unsupported { label, reason } | Event::Refused { label, reason, .. } => {
            eprintln!("  {label:<28} left out: {reason}");
        }
        Event::Finished { record } => {
            // FLIP over the mirror pixels first, as the reports headline it, then over the
            // image (named: the two differ by up to an order of magnitude).
            let mirrors = record.mirror_metrics.as_ref().map_or(String::new(), |m| {
                format!("FLIP mirrors {:.3e}  ", m.flip_mean)
            });
            let line = format!(
                "  {:<28} {:>9.2} ms/frame  {:>5} passes  {mirrors}FLIP image {:.3e}  relMSE {:.3e}",
                record.key.split('|').take(2).collect::<Vec<_>>().join(" "),
                record.ms_median,
                record.passes,
                record.metrics.flip_mean,
                record.metrics.relmse
            );
            match &bar {
                Some(b) if !b.is_hidden() => b.println(line),
                _ => eprintln!("{line}"),
            }
        }
    });
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let summary = result?;
    println!(
        "sweep done in {:.1} s (peak memory {}): {} computed, {} reused{}; truths: {} traced, {} from the cache (traced before, in this run or an earlier one); wrote {}",
        started.elapsed().as_secs_f64(),
        super::peak_memory().unwrap_or_else(|| "unknown".into()),
        crate::count(summary.computed, "point"),
        summary.reused,
        match summary.unsupported {
            0 => String::new(),
            n => format!(", {n} left out (the adapter lacks a feature their method needs)"),
        },
        summary.truths_traced,
        summary.truths_cached,
        config.out.join("report.md").display()
    );
    Ok(())
}
