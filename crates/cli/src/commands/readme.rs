//! `mirrorbox readme [--check]`: fills the README's generated regions (`<!-- generated: ID
//! -->` … `<!-- end generated: ID -->`) from the committed reports, so every figure its prose
//! quotes is the report's own (`mirrorbox_report::readme`).

use crate::Failure;
use mirrorbox_report::readme::{REGIONS, fill, stale_regions};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Do not write: exit 1 if a region differs from what the reports give, naming it.
    #[arg(long)]
    check: bool,
    /// The README to fill.
    #[arg(long, default_value = "README.md")]
    readme: PathBuf,
    /// The folder of the committed reports.
    #[arg(long, default_value = "reports")]
    reports: PathBuf,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    let text = mirrorbox_files::read_bounded_text(&args.readme, MAX_README_BYTES, "a README")
        .map_err(|e| Failure::BadInput(e.to_string()))?;
    let bad = |e: mirrorbox_report::readme::ReadmeError| {
        Failure::BadInput(format!("{}: {e}", args.readme.display()))
    };
    if args.check {
        let stale = stale_regions(&text, &args.reports).map_err(bad)?;
        if stale.is_empty() {
            println!(
                "{}: every generated region agrees with {}",
                args.readme.display(),
                args.reports.display()
            );
            return Ok(());
        }
        let lines: Vec<String> = stale
            .iter()
            .map(|(id, have, want)| {
                format!("region {id:?}: the README has\n    {have}\n  the reports give\n    {want}")
            })
            .collect();
        return Err(Failure::Other(format!(
            "{} disagrees with the committed reports in {}:\n  {}\nrun `mirrorbox readme` to regenerate the regions",
            args.readme.display(),
            crate::count(stale.len(), "region"),
            lines.join("\n  ")
        )));
    }
    let filled = fill(&text, &args.reports).map_err(bad)?;
    if filled != text {
        mirrorbox_files::write_atomically(&args.readme, filled.as_bytes())
            .map_err(|e| Failure::Other(e.to_string()))?;
    }
    println!(
        "{}: {} generated regions filled from {} (known: {})",
        args.readme.display(),
        if filled != text {
            "its"
        } else {
            "no change; its"
        },
        args.reports.display(),
        REGIONS.iter().map(|r| r.0).collect::<Vec<_>>().join(", ")
    );
    Ok(())
}

/// A README is text of a few hundred KB at most; the bound keeps a mistaken path from being
/// read whole.
const MAX_README_BYTES: u64 = 16 << 20;
