//! `mirrorbox score EXPORT RUN -o OUT`: the exchange's way in (issue 53,
//! `docs/exchange.md`): any renderer's images and timings, scored against the export's truths
//! as a sweep scores our methods, into a sweep folder (records, report).

use crate::Failure;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The folder `mirrorbox export-views` wrote (views.json, truth/).
    export: PathBuf,
    /// The run: RUN/<client>/<variant>/<view>.exr (or .png, 8-bit sRGB) and timing.json;
    /// a variant named `floor` drew the scene without mirrors.
    run: PathBuf,
    /// Output folder (its parent must exist): results.jsonl, sweep.json, the report. An
    /// earlier score there is replaced.
    #[arg(short, long)]
    output: PathBuf,
    /// A sweep folder of our own methods set beside the run's variants in the report
    /// (repeatable): e.g. the equivalents measured on the same device. It must be of the
    /// scene exported, at its α, at the size and ssaa of its view at the scene's own camera,
    /// with no scene axis swept (docs/exchange.md).
    #[arg(long)]
    with: Vec<PathBuf>,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    let settings = mirrorbox_harness::score::ScoreSettings {
        command: std::env::args().collect::<Vec<_>>().join(" "),
        with: args.with.clone(),
        sections: mirrorbox_experiments::sections(),
    };
    let done = mirrorbox_harness::score::score(&args.export, &args.run, &args.output, &settings)
        .map_err(Failure::from)?;
    for hint in &done.hints {
        eprintln!("warning: {hint}");
    }
    println!(
        "scored {} variant(s) of {} against {}: {} records; wrote {}",
        done.variants,
        args.run.display(),
        args.export.display(),
        done.records,
        args.output.join("report.md").display()
    );
    Ok(())
}
