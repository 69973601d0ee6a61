//! `mirrorbox readme [--check]`: fills the README's generated regions (`<!-- generated: ID
//! -->` … `<!-- end generated: ID -->`) from the committed reports, so every figure its prose
//! quotes is the report's own (`mirrorbox_report::readme`).

use crate::Failure;
use mirrorbox_report::readme::{REGIONS, fill, stale_regions};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Do not write: exit 1 if a region differs from what the reports give, naming it.
    #[arg(long)]
    check: bool,
    /// The Markdown files to fill (their regions name the reports they quote).
    #[arg(default_values = ["README.md", "docs/methods.md"])]
    files: Vec<PathBuf>,
    /// The folder of the committed reports.
    #[arg(long, default_value = "reports")]
    reports: PathBuf,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    // Every file is tried; bad input (a malformed region, a missing report) decides exit 2
    // over a stale region's exit 1.
    let (mut messages, mut bad_input) = (Vec::new(), false);
    for file in &args.files {
        match one(file, args) {
            Ok(()) => {}
            Err(Failure::BadInput(m)) => {
                bad_input = true;
                messages.push(m);
            }
            Err(Failure::Other(m)) => messages.push(m),
        }
    }
    match (messages.is_empty(), bad_input) {
        (true, _) => Ok(()),
        (false, true) => Err(Failure::BadInput(messages.join("\n"))),
        (false, false) => Err(Failure::Other(messages.join("\n"))),
    }
}

/// Fills (or checks) one file; a malformed region or a missing report is bad input (exit 2).
fn one(file: &Path, args: &Args) -> Result<(), Failure> {
    let bad = |e: &dyn std::fmt::Display| Failure::BadInput(format!("{}: {e}", file.display()));
    let text = mirrorbox_files::read_bounded_text(file, MAX_README_BYTES, "a Markdown file")
        .map_err(|e| bad(&e))?;
    if args.check {
        let stale = stale_regions(&text, &args.reports).map_err(|e| bad(&e))?;
        if stale.is_empty() {
            println!(
                "{}: every generated region agrees with {}",
                file.display(),
                args.reports.display()
            );
            return Ok(());
        }
        let lines: Vec<String> = stale
            .iter()
            .map(|(id, have, want)| {
                format!("region {id:?}: the file has\n    {have}\n  the reports give\n    {want}")
            })
            .collect();
        return Err(Failure::Other(format!(
            "{} disagrees with the committed reports in {}:\n  {}\nrun `mirrorbox readme` to regenerate the regions",
            file.display(),
            crate::count(stale.len(), "region"),
            lines.join("\n  ")
        )));
    }
    let filled = fill(&text, &args.reports).map_err(|e| bad(&e))?;
    if filled != text {
        mirrorbox_files::write_atomically(file, filled.as_bytes())
            .map_err(|e| Failure::Other(e.to_string()))?;
    }
    println!(
        "{}: {} from {} (regions known: {})",
        file.display(),
        if filled != text {
            "generated regions filled"
        } else {
            "generated regions already up to date"
        },
        args.reports.display(),
        REGIONS.iter().map(|r| r.0).collect::<Vec<_>>().join(", ")
    );
    Ok(())
}

/// A README is text of a few hundred KB at most; the bound keeps a mistaken path from being
/// read whole.
const MAX_README_BYTES: u64 = 16 << 20;
