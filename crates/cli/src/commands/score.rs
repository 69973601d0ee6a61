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
}

pub fn run(args: &Args) -> Result<(), Failure> {
    let command = std::env::args().collect::<Vec<_>>().join(" ");
    let done = mirrorbox_harness::score::score(&args.export, &args.run, &args.output, &command)
        .map_err(Failure::from)?;
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
