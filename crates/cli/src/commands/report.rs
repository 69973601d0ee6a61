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
    #[arg(required_unless_present = "index")]
    dirs: Vec<PathBuf>,
    /// Write the overview of every report under this folder (normally `reports`):
    /// `index.html`, `README.md` and the cross-method frontier charts `frontier_*.svg`.
    #[arg(long, value_name = "REPORTS")]
    index: Option<PathBuf>,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    if let Some(reports) = &args.index {
        let n = mirrorbox_report::overview::write_overview(reports, &records_commit, &about)
            .map_err(|e| Failure::BadInput(format!("{}: {e}", reports.display())))?;
        println!(
            "{}: index.html and README.md list {}",
            reports.display(),
            crate::count(n, "report")
        );
    }
    for dir in &args.dirs {
        let n = mirrorbox_report::rewrite_report(
            dir,
            &records_commit(dir),
            &mirrorbox_experiments::sections(),
        )
        .map_err(|e| Failure::BadInput(format!("{}: {e}", dir.display())))?;
        println!(
            "{}: report rewritten from {}",
            dir.display(),
            crate::count(n, "record")
        );
    }
    Ok(())
}

/// The commit that last committed `dir/results.jsonl` (for the figures' footers of a sweep
/// that did not record the commit that measured it); empty outside a git checkout.
fn records_commit(dir: &std::path::Path) -> String {
    if !dir.is_dir() {
        return String::new();
    }
    std::process::Command::new("git")
        .arg("-C")
        .arg(dir)
        .args(["log", "-1", "--format=%h", "--"])
        .arg(if dir.join("results.jsonl").is_file() {
            "results.jsonl"
        } else {
            "."
        })
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default()
}

/// What the registry's experiment writing the report folder `folder` (under `reports/`)
/// measures.
fn about(folder: &str) -> Option<String> {
    use mirrorbox_experiments::{EXPERIMENTS, Measure};
    EXPERIMENTS.iter().find_map(|e| {
        let folders: Vec<std::path::PathBuf> = match &e.measure {
            Measure::Sweeps(configs) => configs(&e.default_out())
                .into_iter()
                .map(|c| c.out)
                .collect(),
            _ => vec![e.default_out()],
        };
        folders
            .iter()
            .any(|f| {
                f.strip_prefix("reports")
                    .is_ok_and(|f| f == std::path::Path::new(folder))
            })
            .then(|| format!("{} (`{}`)", e.about, e.name))
    })
}
