//! A sweep's folder as the reports read it: `sweep.json` (the [`SweepInfo`] the sweep wrote)
//! and `results.jsonl` (its [`Record`]s). Shared by the README's generated regions and by
//! [`rewrite_report`], which remakes a folder's report from its records alone — no renderer,
//! no GPU: a report measured on another machine is regenerated here after a change to the
//! report's text.

use crate::error::ReadmeError;
use crate::{Record, SweepInfo, read_records, write_report};
use std::path::Path;

/// `sweep.json` is a few KB, or more where it lists every point's key (a sharded sweep's,
/// `mirrorbox merge`'s bound); the bound keeps a wrong path from being read whole.
pub const MAX_SWEEP_JSON_BYTES: u64 = 64 << 20;

/// A sweep folder's records and facts.
pub struct Sweep {
    pub info: SweepInfo,
    pub records: Vec<Record>,
}

/// Reads `dir/sweep.json` alone: what a folder's sweep (or score, or merge) says of itself,
/// whether or not it has records yet.
pub fn read_sweep_info(dir: &Path) -> Result<SweepInfo, ReadmeError> {
    let info_path = dir.join("sweep.json");
    let text =
        mirrorbox_files::read_bounded_text(&info_path, MAX_SWEEP_JSON_BYTES, "a sweep description")
            .map_err(|e| ReadmeError(e.to_string()))?;
    serde_json::from_str(&text).map_err(|e| {
        ReadmeError(format!(
            "{}: not a sweep description ({e}); regenerate the report with its sweep",
            info_path.display()
        ))
    })
}

/// Reads `dir/sweep.json` and `dir/results.jsonl`; a folder without records is an error.
pub fn load_sweep(dir: &Path) -> Result<Sweep, ReadmeError> {
    let info = read_sweep_info(dir)?;
    let results = dir.join("results.jsonl");
    let records = read_records(&results).map_err(|e| ReadmeError(e.to_string()))?;
    if records.is_empty() {
        return Err(ReadmeError(format!(
            "{}: no records to quote",
            results.display()
        )));
    }
    Ok(Sweep { info, records })
}

/// Rewrites `results.csv`, `report.md`, `report.html` and the plots of the sweep folder `dir`
/// from its `sweep.json` and `results.jsonl`; returns the number of records reported.
/// `records_commit`: the commit that committed the records, named in the figures' footers of
/// a sweep that did not record the commit that measured it (empty: unknown).
/// `sections`: the experiments' report sections (the registry's).
pub fn rewrite_report(
    dir: &Path,
    records_commit: &str,
    sections: &[crate::Section],
) -> Result<usize, ReadmeError> {
    // A sequence sweep's folder (`mirrorbox experiment motion`, `sweep --path`) has its own files.
    if dir.join("motion.json").is_file() && !dir.join("sweep.json").exists() {
        let (mut info, records) = crate::sequence::read_motion(dir).map_err(ReadmeError)?;
        info.records_commit = records_commit.to_string();
        crate::sequence::write_motion_figures(dir, &info, &records)
            .map_err(|e| ReadmeError(e.to_string()))?;
        return Ok(records.len());
    }
    let mut sweep = load_sweep(dir)?;
    sweep.info.records_commit = records_commit.to_string();
    write_report(dir, &sweep.info, &sweep.records, sections)
        .map_err(|e| ReadmeError(e.to_string()))?;
    Ok(sweep.records.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_without_a_sweep_description_is_named_in_the_error() {
        let dir = tempfile::tempdir().unwrap();
        let e = rewrite_report(dir.path(), "", &[]).err().unwrap();
        assert!(e.0.contains("sweep.json"), "{e}");
        std::fs::write(dir.path().join("sweep.json"), "[1, 2]").unwrap();
        let e = rewrite_report(dir.path(), "", &[]).err().unwrap();
        assert!(e.0.contains("not a sweep description"), "{e}");
    }
}
