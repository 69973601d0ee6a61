//! `mirrorbox sweep SCENE --out DIR` and its preset `mirrorbox table1`: raster methods timed
//! and compared with cached ground truths, resumable, with reports.

use super::progress_bar;
use crate::Failure;
use mirrorbox_harness::{Event, HarnessError, MethodKind, SweepConfig, run_sweep};
use mirrorbox_trace::WhittedSettings;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Scene file (JSON).
    scene: PathBuf,
    /// Output folder (results.jsonl, results.csv, report.md, report.html, plots, images, cache).
    #[arg(long)]
    out: PathBuf,
    /// Methods, comma separated: naive, auxiliary, portal, unrolled.
    #[arg(long, default_value = "naive,auxiliary")]
    methods: String,
    /// Auxiliary mirror counts: a range `A..B` (inclusive) or a list `0,2,4`.
    #[arg(long, default_value = "0..4")]
    n: String,
    /// Reflection depths of the exact methods (portal, unrolled): a range `A..B` or a list
    /// `1,4,16,64`.
    #[arg(long, default_value = "1,2,4,8,16,32,64")]
    depth: String,
    /// Reflectances α, comma separated, each in [0, 1].
    #[arg(long, default_value = "0.5,0.7,0.9,1.0")]
    alpha: String,
    #[arg(long)]
    width: Option<u32>,
    #[arg(long)]
    height: Option<u32>,
    /// Supersampling s of the raster (the truth uses the same s×s sub-pixel grid).
    #[arg(long, default_value_t = 1)]
    ssaa: u32,
    /// Timed frames per point (after --warmup untimed ones).
    #[arg(long, default_value_t = 5)]
    frames: u32,
    #[arg(long, default_value_t = 2)]
    warmup: u32,
    #[arg(long, default_value_t = 5000)]
    max_passes: usize,
    /// Ground truth: most mirror reflections a path follows.
    #[arg(long, default_value_t = 10_000)]
    max_depth: u32,
    /// Ground truth: stop a path below this throughput.
    #[arg(long, default_value_t = 1e-4)]
    min_throughput: f32,
    /// Discard earlier results in --out and measure every point again (cached truths stay).
    #[arg(long)]
    fresh: bool,
}

/// The options of the preset sweeps (`table1`, `depth-scaling`).
#[derive(clap::Args)]
pub struct PresetArgs {
    /// Output folder of the committed report (default: the preset's folder in reports/).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Timed frames per point (default: 9 for table1, 5 for depth-scaling; lavapipe on 2
    /// shared cores is noisy).
    #[arg(long)]
    frames: Option<u32>,
    /// Discard earlier results and measure every point again (cached truths stay).
    #[arg(long)]
    fresh: bool,
}

fn bad(m: String) -> Failure {
    Failure::BadInput(m)
}

fn parse_ns(s: &str) -> Result<Vec<u32>, Failure> {
    let err = || {
        bad(format!(
            "--n {s:?}: expected a range like 0..4 or a list like 0,2,4 of counts 0..=16"
        ))
    };
    let v: Vec<u32> = if let Some((a, b)) = s.split_once("..") {
        let (a, b): (u32, u32) = (
            a.trim().parse().map_err(|_| err())?,
            b.trim().parse().map_err(|_| err())?,
        );
        if a > b {
            return Err(err());
        }
        (a..=b).collect()
    } else {
        s.split(',')
            .map(|x| x.trim().parse().map_err(|_| err()))
            .collect::<Result<_, _>>()?
    };
    if v.is_empty() || v.iter().any(|&n| n > 16) {
        return Err(err());
    }
    Ok(v)
}

fn parse_depths(s: &str) -> Result<Vec<u32>, Failure> {
    let err = || {
        bad(format!(
            "--depth {s:?}: expected a range like 1..8 or a list like 1,4,16,64 of depths 1..=4096"
        ))
    };
    let v: Vec<u32> = if let Some((a, b)) = s.split_once("..") {
        let (a, b): (u32, u32) = (
            a.trim().parse().map_err(|_| err())?,
            b.trim().parse().map_err(|_| err())?,
        );
        (a..=b).collect()
    } else {
        s.split(',')
            .map(|x| x.trim().parse().map_err(|_| err()))
            .collect::<Result<_, _>>()?
    };
    if v.is_empty() || v.iter().any(|&d| d == 0 || d > 4096) {
        return Err(err());
    }
    Ok(v)
}

fn parse_alphas(s: &str) -> Result<Vec<f32>, Failure> {
    s.split(',')
        .map(|x| match x.trim().parse::<f32>() {
            Ok(a) if (0.0..=1.0).contains(&a) => Ok(a),
            _ => Err(bad(format!(
                "--alpha {s:?}: each value must be a number in [0, 1], got {x:?}"
            ))),
        })
        .collect()
}

fn parse_methods(s: &str) -> Result<Vec<MethodKind>, Failure> {
    s.split(',')
        .map(|m| match m.trim() {
            "naive" => Ok(MethodKind::Naive),
            "auxiliary" => Ok(MethodKind::Auxiliary),
            "portal" => Ok(MethodKind::Portal),
            "unrolled" => Ok(MethodKind::Unrolled),
            other => Err(bad(format!(
                "--methods: unknown method {other:?} (known: naive, auxiliary, portal, unrolled)"
            ))),
        })
        .collect()
}

fn command_line() -> String {
    std::env::args().collect::<Vec<_>>().join(" ")
}

pub fn run(args: &Args) -> Result<(), Failure> {
    if !(1..=8).contains(&args.ssaa) {
        return Err(bad(format!("--ssaa must be in [1, 8], got {}", args.ssaa)));
    }
    if args.frames == 0 {
        return Err(bad("--frames must be at least 1".into()));
    }
    let config = SweepConfig {
        scene: args.scene.clone(),
        out: args.out.clone(),
        methods: parse_methods(&args.methods)?,
        ns: parse_ns(&args.n)?,
        depths: parse_depths(&args.depth)?,
        alphas: parse_alphas(&args.alpha)?,
        width: args.width,
        height: args.height,
        ssaa: args.ssaa,
        frames: args.frames,
        warmup: args.warmup,
        max_passes: args.max_passes,
        truth: WhittedSettings {
            max_depth: args.max_depth,
            min_throughput: args.min_throughput,
        },
        command: command_line(),
    };
    execute(&config, args.fresh)
}

/// Table 1 of the seed paper: the auxiliary method for n = 0…4 on mirror_box at α = 1 and
/// the paper's 0.7, with the exact methods at depth 64 beside it.
pub fn run_table1(args: &PresetArgs) -> Result<(), Failure> {
    let config = SweepConfig {
        scene: PathBuf::from("scenes/mirror_box.json"),
        out: args
            .out
            .clone()
            .unwrap_or_else(|| PathBuf::from("reports/table1")),
        methods: vec![
            MethodKind::Auxiliary,
            MethodKind::Portal,
            MethodKind::Unrolled,
        ],
        ns: (0..=4).collect(),
        depths: vec![64],
        alphas: vec![1.0, 0.7],
        width: None,
        height: None,
        ssaa: 1,
        frames: preset_frames(args, 9)?,
        warmup: 2,
        max_passes: 5000,
        truth: WhittedSettings::default(),
        command: command_line(),
    };
    execute(&config, args.fresh)
}

/// The exact methods' cost against depth, 1 to 1024, on mirror_box with perfect mirrors
/// (α = 1: no path ends by attenuation, only when its portal holds no pixel centre).
pub fn run_depth_scaling(args: &PresetArgs) -> Result<(), Failure> {
    let config = SweepConfig {
        scene: PathBuf::from("scenes/mirror_box.json"),
        out: args
            .out
            .clone()
            .unwrap_or_else(|| PathBuf::from("reports/depth_scaling")),
        methods: vec![MethodKind::Portal, MethodKind::Unrolled],
        ns: Vec::new(),
        depths: (0..=10).map(|k| 1 << k).collect(),
        alphas: vec![1.0],
        width: None,
        height: None,
        ssaa: 1,
        frames: preset_frames(args, 5)?,
        warmup: 2,
        max_passes: 5000,
        truth: WhittedSettings::default(),
        command: command_line(),
    };
    execute(&config, args.fresh)
}

fn preset_frames(args: &PresetArgs, default: u32) -> Result<u32, Failure> {
    match args.frames.unwrap_or(default) {
        0 => Err(bad("--frames must be at least 1".into())),
        f => Ok(f),
    }
}

fn execute(config: &SweepConfig, fresh: bool) -> Result<(), Failure> {
    let results = config.out.join("results.jsonl");
    if fresh && results.exists() {
        std::fs::remove_file(&results)
            .map_err(|e| Failure::Other(format!("{}: {e}", results.display())))?;
    }
    let started = std::time::Instant::now();
    let mut bar = None;
    let result = run_sweep(config, &mut |event| match event {
        Event::Planned { todo, reused } => {
            eprintln!(
                "sweep: {todo} points to compute, {reused} already in {}",
                config.out.join("results.jsonl").display()
            );
            bar = Some(progress_bar(todo as u64, "sweep"));
        }
        Event::Started { label } => {
            if let Some(b) = &bar {
                b.set_message(label.to_string());
            }
        }
        Event::Finished { record } => {
            let line = format!(
                "  {:<28} {:>9.2} ms/frame  {:>5} passes  FLIP {:.5}  relMSE {:.3e}",
                record.key.split('|').take(2).collect::<Vec<_>>().join(" "),
                record.ms_median,
                record.passes,
                record.metrics.flip_mean,
                record.metrics.relmse
            );
            match &bar {
                Some(b) if !b.is_hidden() => {
                    b.inc(1);
                    b.println(line);
                }
                _ => eprintln!("{line}"),
            }
        }
    });
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let summary = result.map_err(|e| match e {
        HarnessError::BadInput(m) => Failure::BadInput(m),
        HarnessError::Other(m) => Failure::Other(m),
    })?;
    println!(
        "sweep done in {:.1} s: {} points computed, {} reused; truths: {} traced, {} from cache; wrote {}",
        started.elapsed().as_secs_f64(),
        summary.computed,
        summary.reused,
        summary.truths_traced,
        summary.truths_cached,
        config.out.join("report.md").display()
    );
    Ok(())
}
