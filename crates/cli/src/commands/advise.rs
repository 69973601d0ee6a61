//! `mirrorbox advise SCENE --budget-ms B`: the method and setting to ship for a scene and a
//! frame budget on this device, found by a search that measures few candidates (issue 55,
//! `mirrorbox_harness::advise`).

use super::unit_interval;
use crate::Failure;
use mirrorbox_harness::advise::{AdviseConfig, Metric, OverViews, advise_into, sentences, to_json};
use mirrorbox_harness::{Event, SweepConfig};
use mirrorbox_raster::{Advise, METHODS};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Scene file (JSON); `mirrorbox check` must accept it.
    scene: PathBuf,
    /// The frame budget in ms: a candidate fits only if the upper end of its ms/frame 95 %
    /// interval is at most this. Above 0.
    #[arg(long = "budget-ms", allow_negative_numbers = true)]
    budget_ms: f64,
    #[command(flatten)]
    size: super::TruthSizeArgs,
    /// Supersampling s of the raster (the truth uses the same s×s sub-pixel grid), 1..8.
    #[arg(long, default_value_t = 1)]
    ssaa: u32,
    /// α: every mirror's reflectance, in [0, 1], as in a sweep. `--reflectance` is the same
    /// flag.
    #[arg(
        long,
        visible_alias = "reflectance",
        default_value_t = 1.0,
        allow_negative_numbers = true
    )]
    alpha: f32,
    /// The error to minimise: flip (FLIP mean over the mirror pixels) or relmse (over the
    /// image).
    #[arg(long, default_value = "flip")]
    metric: String,
    /// Only these methods (comma-separated registry names); default: every method the
    /// registry offers for mirrors.
    #[arg(long, value_delimiter = ',')]
    methods: Vec<String>,
    /// Timed rounds per candidate (6 or more give each median a 95 % interval), 6..100.
    #[arg(long, default_value_t = 9)]
    frames: u32,
    /// A camera path: a view list as `export-views` reads it (`{"views": [{"name",
    /// "position", "look_at", "up"?, "fov_y_deg"?}]}`, 1 to 64 views). Every candidate is
    /// timed and scored from each view; default: the scene's camera.
    #[arg(long)]
    views: Option<PathBuf>,
    /// How the views make one candidate's time and error: worst (every view must fit) or
    /// mean.
    #[arg(long = "over-views", default_value = "worst", requires = "views")]
    over_views: String,
    /// Output folder (its parent must exist): advice.md, advice.json, front.svg, the pick's
    /// images, and the search's rounds. An earlier advice there is replaced.
    #[arg(short, long, default_value = "advice")]
    output: PathBuf,
    /// Time every coarse candidate of the registry's rows in one round, without ascent or
    /// bisection: the search's whole first stage, to judge the search against (its cost is
    /// stated beside the search's).
    #[arg(long)]
    exhaustive: bool,
    /// Also print the answer as JSON on stdout.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    memory: super::MemoryBudgetArgs,
}

/// The methods `advise` can offer, for messages.
fn offered() -> Vec<&'static str> {
    METHODS
        .iter()
        .filter(|e| !matches!(e.advise, Advise::Skip))
        .map(|e| e.name)
        .collect()
}

/// The budgets `advise` takes: from a nanosecond (in which nothing renders: the way to ask
/// for the cheapest; 1e-300 had printed a 300-digit ratio) to an hour (everything fits).
const MIN_BUDGET_MS: f64 = 1e-6;
const MAX_BUDGET_MS: f64 = 3_600_000.0;

pub fn run(args: &Args) -> Result<(), Failure> {
    if !(MIN_BUDGET_MS..=MAX_BUDGET_MS).contains(&args.budget_ms) {
        return Err(Failure::BadInput(format!(
            "--budget-ms: a frame time in ms from {MIN_BUDGET_MS} to {MAX_BUDGET_MS}, got {}",
            // 1e-300 in full is 300 digits.
            if args.budget_ms != 0.0 && !(1e-3..1e9).contains(&args.budget_ms.abs()) {
                format!("{:e}", args.budget_ms)
            } else {
                args.budget_ms.to_string()
            }
        )));
    }
    let metric = Metric::parse(&args.metric).ok_or_else(|| {
        Failure::BadInput(format!(
            "--metric: one of flip, relmse, got {:?}",
            args.metric
        ))
    })?;
    if let Some(m) = args
        .methods
        .iter()
        .find(|m| !offered().contains(&m.as_str()))
    {
        return Err(Failure::BadInput(format!(
            "--methods: {m:?} is not a method advise offers (one of {})",
            offered().join(", ")
        )));
    }
    if !(6..=100).contains(&args.frames) {
        return Err(Failure::BadInput(format!(
            "--frames: 6..100 timed rounds (a 95 % interval needs 6), got {}",
            args.frames
        )));
    }
    super::ssaa(args.ssaa)?;
    unit_interval("--alpha", Some(args.alpha))?;
    let over_views = OverViews::parse(&args.over_views).ok_or_else(|| {
        Failure::BadInput(format!(
            "--over-views: one of worst, mean, got {:?}",
            args.over_views
        ))
    })?;
    // The scene as `check` reads it, and every view of it: a clear error (exit 2) before any
    // search.
    let scene = super::load(&args.scene)?;
    if scene.mirrors.is_empty() {
        // Every method draws it alike: a search would rank timing noise.
        return Err(Failure::BadInput(format!(
            "{}: the scene has no mirrors; advise chooses how to draw mirrors",
            args.scene.display()
        )));
    }
    let views = match &args.views {
        Some(path) => {
            let views = mirrorbox_harness::exchange::read_view_list(path)
                .map_err(|e| Failure::BadInput(e.to_string()))?;
            mirrorbox_harness::exchange::check_views(path, &views, &scene)
                .map_err(|e| Failure::BadInput(e.to_string()))?;
            views
        }
        None => Vec::new(),
    };
    let sweep = SweepConfig {
        width: args.size.width,
        height: args.size.height,
        ssaa: args.ssaa,
        frames: args.frames,
        memory_budget: args.memory.memory_budget,
        command: std::env::args().collect::<Vec<_>>().join(" "),
        sections: Vec::new(),
        ..SweepConfig::new(
            args.scene.clone(),
            PathBuf::new(),
            Vec::new(),
            vec![args.alpha],
        )
    };
    let config = AdviseConfig {
        sweep,
        budget_ms: args.budget_ms,
        metric,
        methods: args.methods.clone(),
        views,
        over_views,
        shadows: scene.lighting.shadows,
        exhaustive: args.exhaustive,
    };
    let started = std::time::Instant::now();
    let advice = advise_into(&config, &args.output, &mut |e| {
        if let Event::Finished { record } = e
            && record.kind != "floor"
        {
            // The verdict is on the interval's upper end (a fit must hold with 95 %
            // confidence): said with it, or a median under the budget read "over budget".
            let upper = record
                .ms_interval
                .map_or(String::new(), |[_, hi]| format!(" (95 % up to {hi:.3})"));
            eprintln!(
                "  {:<34} {:>9.3} ms/frame{upper}  {}",
                record.method_key(),
                record.ms_median,
                if mirrorbox_harness::advise::within(record, args.budget_ms) {
                    "within budget"
                } else {
                    "over budget"
                }
            );
        }
    })
    .map_err(Failure::from)?;
    if args.json {
        println!("{}", to_json(&advice, metric, &args.scene));
    } else {
        for s in sentences(&advice, metric, &args.scene) {
            println!("{s}");
        }
        println!(
            "{}: advice.md, advice.json, front.svg ({:.1} s)",
            args.output.display(),
            started.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
