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
    /// With --index: write nothing, and fail (exit 1) where the overview on disk differs from
    /// the one the records give (a record committed without `report --index` after it).
    #[arg(long, requires = "index")]
    check: bool,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    if let Some(reports) = &args.index {
        if !reports.is_dir() {
            return Err(Failure::BadInput(format!(
                "--index {}: not a folder; it takes the folder of report folders (reports/)",
                reports.display()
            )));
        }
        // What was found leads the overview, each finding with its figure, its links relative
        // to `reports/` as written. The findings are the project's, computed from its
        // experiments' records, the first of them Table 1's: a folder without
        // `table1/sweep.json` (one's own sweeps, whatever their folders are called) gets the
        // overview without them (before, it was refused for lacking it).
        let experiments = reports.join("table1/sweep.json").is_file();
        let lead = if experiments {
            let findings = mirrorbox_experiments::findings::findings_with_figures(reports)
                .map_err(|e| {
                    Failure::BadInput(format!("{}: the findings: {e}", reports.display()))
                })?;
            mirrorbox_experiments::findings::rebased(&findings, "", "../")
        } else {
            println!(
                "{}: no table1/ records (`mirrorbox experiment table1`): the overview lists the \
                 reports without the project's findings",
                reports.display()
            );
            String::new()
        };
        let overview = mirrorbox_report::overview::overview(
            reports,
            &records_commit,
            &about,
            &mirrorbox_experiments::other_reports(),
            &mirrorbox_experiments::frontier::SCENES,
            mirrorbox_report::overview::Lead(&lead),
        )
        .map_err(|e| Failure::BadInput(format!("{}: {e}", reports.display())))?;
        if args.check {
            let differences = overview.differences();
            if !differences.is_empty() {
                return Err(Failure::Other(format!(
                    "{}\nthe overview is not the records': run `mirrorbox report --index {}`",
                    differences.join("\n"),
                    reports.display()
                )));
            }
            println!(
                "{}: the overview agrees with the records ({})",
                reports.display(),
                crate::count(overview.listed, "report")
            );
            return Ok(());
        }
        overview
            .write()
            .map_err(|e| Failure::BadInput(format!("{}: {e}", reports.display())))?;
        println!(
            "{}: index.html and README.md list {}",
            reports.display(),
            crate::count(overview.listed, "report")
        );
    }
    for dir in &args.dirs {
        if !dir.is_dir() {
            return Err(Failure::BadInput(format!(
                "{}: not a folder; `report` takes a sweep's, score's, advice's or motion \
                 report's folder",
                dir.display()
            )));
        }
        // An advice (`mirrorbox advise`): its answer and files from its rounds' records.
        if dir.join("advice.json").is_file() {
            let advice = mirrorbox_harness::advise::rewrite(dir).map_err(Failure::from)?;
            println!(
                "{}: advice rewritten from {}",
                dir.display(),
                crate::count(advice.measured.len(), "record")
            );
            continue;
        }
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

/// The commit that last committed `path` — a measurement's file, or a sweep folder's
/// `results.jsonl` — for the figures and the overview of reports that did not record the
/// commit that measured them; empty outside a git checkout.
fn records_commit(path: &std::path::Path) -> String {
    // A measurement's file, or a sweep folder's records.
    let (dir, file) = if path.is_file() {
        match (path.parent(), path.file_name()) {
            (Some(d), Some(f)) => (d.to_path_buf(), f.to_string_lossy().into_owned()),
            _ => return String::new(),
        }
    } else if path.join("results.jsonl").is_file() {
        (path.to_path_buf(), "results.jsonl".into())
    } else if path.is_dir() {
        (path.to_path_buf(), ".".into())
    } else {
        return String::new();
    };
    let dir = if dir.as_os_str().is_empty() {
        std::path::PathBuf::from(".")
    } else {
        dir
    };
    // The first seven hex digits of the full hash, as every committed report has: git's own
    // `%h` (and `--abbrev=7`, a least length) grows with the repository's object count (eight
    // past 16 384 objects) and where seven are ambiguous, which would change report footers
    // with no record changed.
    mirrorbox_harness::git_output(&dir, &["log", "-1", "--format=%H", "--", &file])
        .map(|full| full.chars().take(7).collect())
        .unwrap_or_default()
}

/// What the registry's experiment writing the report folder `folder` (under `reports/`)
/// measures.
fn about(folder: &str) -> Option<String> {
    // One of an experiment's runs in a folder of its own (`table1_runs/a_table1`).
    let run_of = || {
        let (parent, run) = folder.rsplit_once('/')?;
        about_folder(parent).map(|a| format!("{a}: run `{run}`"))
    };
    let on_a_gpu = || {
        // A lent GPU's run of an experiment: `gpu/<its folder>`, perhaps with the GPU, a run
        // number or a size after it (`gpu/table1_h200_run2`, `gpu/table1_1080p`).
        let mut name = folder.strip_prefix("gpu/")?;
        loop {
            if let Some(a) = about_folder(name) {
                return Some(format!("{a}, on a lent GPU"));
            }
            name = ["_run2", "_1080p", "_h100", "_h200", "_gpu"]
                .iter()
                .find_map(|s| name.strip_suffix(s))?;
        }
    };
    // Another sweep of an experiment whose script names its folders after its own
    // (`web_engines_room`: `web_engines` with `_room`), the longest such prefix.
    let named_after = || {
        let mut name = folder;
        loop {
            let (prefix, _) = name.rsplit_once('_')?;
            if let Some(a) = about_folder(prefix) {
                let rest = &folder[prefix.len() + 1..];
                return Some(format!("{a}: its `{rest}` sweep"));
            }
            name = prefix;
        }
    };
    about_folder(folder)
        .or_else(on_a_gpu)
        .or_else(run_of)
        .or_else(named_after)
}

/// [`about`] of a folder the registry's rows name as they are.
fn about_folder(folder: &str) -> Option<String> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The overview names what a folder holds by the registry's row: as it is, a lent GPU's
    /// run of it, or one of its runs.
    #[test]
    fn a_folder_is_named_by_its_experiment() {
        let table1 = about("table1").unwrap();
        assert!(table1.ends_with("(`table1`)"), "{table1}");
        assert_eq!(
            about("gpu/table1_h200_run2").unwrap(),
            format!("{table1}, on a lent GPU")
        );
        assert_eq!(
            about("gpu/table1").unwrap(),
            format!("{table1}, on a lent GPU")
        );
        let run = about("table1_runs/a_table1").unwrap();
        assert!(run.contains("(`table1-runs`): run `a_table1`"), "{run}");
        // Another file of the GPU's folder: one of the `gpu` experiment's.
        let other = about("gpu/not_an_experiment").unwrap();
        assert!(
            other.ends_with("(`gpu`): run `not_an_experiment`"),
            "{other}"
        );
        assert_eq!(about("mine/sweep"), None);
        // A sweep named after an experiment's folder: that experiment's.
        let web = about("web_engines").unwrap();
        assert_eq!(
            about("web_engines_room").unwrap(),
            format!("{web}: its `room` sweep")
        );
        assert_eq!(about("nothing_like_it"), None);
    }

    /// A report's footer names its records' commit by the first seven hex digits of its hash,
    /// whatever git's own abbreviation: a repository of its own whose `core.abbrev` is 12
    /// (git's grows past seven with the object count; this repository's gives eight).
    #[test]
    fn the_records_commit_has_seven_hex_digits() {
        let dir = tempfile::tempdir().unwrap();
        let git = |args: &[&str]| {
            let out = std::process::Command::new("git")
                .args([
                    "-c",
                    "user.name=t",
                    "-c",
                    "user.email=t@t",
                    "-c",
                    "core.abbrev=12",
                ])
                .args(args)
                .current_dir(dir.path())
                .output()
                .expect("git runs");
            assert!(out.status.success(), "git {args:?}: {out:?}");
            String::from_utf8(out.stdout).unwrap().trim().to_string()
        };
        git(&["init", "-q"]);
        git(&["config", "core.abbrev", "12"]);
        std::fs::write(dir.path().join("results.jsonl"), "{}\n").unwrap();
        git(&["add", "results.jsonl"]);
        git(&["commit", "-q", "-m", "records"]);
        assert_eq!(git(&["log", "-1", "--format=%h"]).len(), 12);
        let full = git(&["rev-parse", "HEAD"]);
        let commit = records_commit(&dir.path().join("results.jsonl"));
        assert_eq!(commit, full[..7], "{commit:?}");
    }
}
