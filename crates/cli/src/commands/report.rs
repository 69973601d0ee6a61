//! `mirrorbox report DIR...`: remakes each sweep folder's `results.csv`, `report.md`,
//! `report.html` and plots from its `sweep.json` and `results.jsonl` (a sequence sweep's
//! `report.md` and plots from its `motion.json` and `frames.jsonl`), without rendering — for
//! a report measured elsewhere (a GPU machine, a cluster) after the report's text changed.

use crate::Failure;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Sweep folders (each with the `sweep.json` and `results.jsonl` a sweep wrote, or a
    /// sequence sweep's `motion.json` and `frames.jsonl`).
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    for dir in &args.dirs {
        let n = mirrorbox_report::rewrite_report(dir)
            .map_err(|e| Failure::BadInput(format!("{}: {e}", dir.display())))?;
        println!(
            "{}: report rewritten from {}",
            dir.display(),
            crate::count(n, "record")
        );
    }
    Ok(())
}
