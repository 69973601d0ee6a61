//! The experiments' committed records read as they were written, whatever their age.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every `results.jsonl` under `dir`, recursively.
fn results_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            results_files(&path, out);
        } else if path.file_name().is_some_and(|n| n == "results.jsonl") {
            out.push(path);
        }
    }
}

/// Every committed `results.jsonl` (every experiment's, on every device, of every age) loads
/// in full: one record per distinct key of its lines — a line that failed to parse would be
/// skipped silently and its point measured again on a resume. The files written before
/// records had a colour format (Table 1's, the depth scaling's, the harness's test data) say
/// RGBA32F, the only format then.
#[test]
fn every_committed_record_loads_and_older_ones_as_rgba32float() {
    let mut files = Vec::new();
    results_files(&root().join("reports"), &mut files);
    files.push(root().join("crates/experiments/tests/data/table1_results_session2.jsonl"));
    assert!(files.len() >= 10, "{files:?}");
    for path in &files {
        let mut keys: Vec<String> = std::fs::read_to_string(path)
            .unwrap()
            .lines()
            .map(|l| {
                let v: serde_json::Value = serde_json::from_str(l).unwrap();
                v["key"].as_str().unwrap().to_string()
            })
            .collect();
        keys.sort();
        keys.dedup();
        let records = mirrorbox_report::read_records(path).unwrap();
        assert_eq!(records.len(), keys.len(), "{}", path.display());
    }
    for file in [
        "reports/table1/results.jsonl",
        "reports/depth_scaling/results.jsonl",
        "crates/experiments/tests/data/table1_results_session2.jsonl",
    ] {
        let records = mirrorbox_report::read_records(&root().join(file)).unwrap();
        assert!(
            records.iter().all(|r| r.color_format == "rgba32float"),
            "{file}"
        );
    }
}

/// Every committed report folder (a sweep's, on every device; a sequence sweep's) remade from
/// its records with the registry's sections gives its committed `report.md` byte for byte:
/// the report is a function of the records, and moving the experiments' sections here
/// (issue 52) changed no report.
#[test]
fn every_committed_report_is_rewritten_byte_for_byte() {
    let mut folders = Vec::new();
    let mut files = Vec::new();
    results_files(&root().join("reports"), &mut files);
    // An advice's rounds keep their records only; the advice is remade as a whole below.
    let (rounds, sweeps): (Vec<PathBuf>, Vec<PathBuf>) = files
        .iter()
        .map(|f| f.parent().unwrap().to_path_buf())
        .partition(|d| d.parent().is_some_and(|p| p.ends_with("search")));
    folders.extend(sweeps);
    folders.push(root().join("reports/motion"));
    let sections = mirrorbox_experiments::sections();
    // The figure check (issue 54): every chart of every committed report, as it is drawn.
    let mut problems: Vec<String> = Vec::new();
    // Every advice (issue 55): its advice.md and front.svg from its rounds' records.
    let mut advices: Vec<PathBuf> = rounds
        .iter()
        .filter_map(|r| r.parent()?.parent().map(Path::to_path_buf))
        .collect();
    advices.dedup();
    for advice in &advices {
        let dir = tempfile::tempdir().unwrap();
        std::fs::copy(advice.join("advice.json"), dir.path().join("advice.json")).unwrap();
        for round in rounds.iter().filter(|r| r.starts_with(advice)) {
            let to = dir.path().join("search").join(round.file_name().unwrap());
            std::fs::create_dir_all(&to).unwrap();
            for f in ["results.jsonl", "sweep.json"] {
                std::fs::copy(round.join(f), to.join(f)).unwrap();
            }
        }
        let (_, lint) = mirrorbox_report::plot::collect_lint(|| {
            mirrorbox_harness::advise::rewrite(dir.path()).unwrap()
        });
        problems.extend(
            lint.into_iter()
                .map(|m| format!("{}: {m}", advice.display())),
        );
        for f in ["advice.md", "front.svg"] {
            let want = std::fs::read_to_string(advice.join(f)).unwrap();
            let have = std::fs::read_to_string(dir.path().join(f)).unwrap();
            assert!(have == want, "{}: the remade {f} differs", advice.display());
        }
    }
    assert!(!advices.is_empty());
    for folder in &folders {
        let dir = tempfile::tempdir().unwrap();
        let mut copied = 0;
        for f in ["sweep.json", "results.jsonl", "motion.json", "frames.jsonl"] {
            if folder.join(f).is_file() {
                std::fs::copy(folder.join(f), dir.path().join(f)).unwrap();
                copied += 1;
            }
        }
        assert_eq!(copied, 2, "{}", folder.display());
        // The rows' images (their insets are made again from them).
        if let Ok(images) = std::fs::read_dir(folder.join("images")) {
            std::fs::create_dir(dir.path().join("images")).unwrap();
            for e in images.flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                if !name.ends_with("_inset.png") {
                    std::fs::copy(e.path(), dir.path().join("images").join(&name)).unwrap();
                }
            }
        }
        let (written, lint) = mirrorbox_report::plot::collect_lint(|| {
            mirrorbox_report::rewrite_report(dir.path(), "", &sections).unwrap()
        });
        assert!(written > 0);
        for m in lint {
            problems.push(format!("{}: {m}", folder.display()));
        }
        let want = std::fs::read_to_string(folder.join("report.md")).unwrap();
        let have = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
        assert!(
            have == want,
            "{}: the remade report.md differs from the committed one",
            folder.display()
        );
    }
    // And the overview's frontier charts.
    problems.extend(
        mirrorbox_report::overview::lint_frontiers(
            &root().join("reports"),
            &mirrorbox_experiments::frontier::SCENES,
        )
        .unwrap(),
    );
    assert!(
        problems.is_empty(),
        "{} figure problems:\n{}",
        problems.len(),
        problems.join("\n")
    );
}
