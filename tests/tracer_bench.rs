//! The tracer bench's records (scripts/tracer-bench-record.py, scripts/tracer-bench-index.py):
//! made from their rounds alone, and a goal judged by the 95 % interval of the per-round
//! median, not by the median alone (issue 56: two runs of one build differ by ±10 %).

use crate::common::{repo, succeed};
use serde_json::{Value, json};
use std::path::Path;

/// Fifteen rounds of one CPU, mirrorbox on two threads: every scene and integrator with
/// Mitsuba ÷ mirrorbox `per_round(scene, integrator, k)` in round k.
fn rounds(dir: &Path, per_round: &dyn Fn(&str, &str, u32) -> f64) -> std::path::PathBuf {
    rounds_on(dir, 2, per_round)
}

/// [`rounds`] with mirrorbox on `threads` threads (the bench gives it every core).
fn rounds_on(
    dir: &Path,
    threads: u32,
    per_round: &dyn Fn(&str, &str, u32) -> f64,
) -> std::path::PathBuf {
    let mut lines = Vec::new();
    for round in 1..=15u32 {
        for scene in ["mirror_box", "mirror_room"] {
            for integrator in ["whitted", "path"] {
                let ratio = per_round(scene, integrator, round);
                lines.push(json!({"who": "mirrorbox", "scene": scene, "integrator": integrator,
                    "round": round, "seconds": 0.1, "first_seconds": 0.11, "rays": 1000, "threads": threads}));
                lines.push(json!({"who": "mitsuba", "scene": scene, "integrator": integrator,
                    "round": round, "seconds": 0.1 * ratio, "first_seconds": 0.5, "variant": "llvm_ad_rgb"}));
            }
        }
    }
    let path = dir.join("runs.jsonl");
    let text: Vec<String> = lines.iter().map(Value::to_string).collect();
    std::fs::write(&path, text.join("\n") + "\n").unwrap();
    path
}

/// A bench script (`scripts/NAME`) run from the repository with `args`, not yet run.
fn bench_script(name: &str, args: &[&str]) -> std::process::Command {
    let mut cmd = std::process::Command::new("python3");
    cmd.arg(repo().join("scripts").join(name))
        .args(args)
        .current_dir(repo())
        .env("MIRRORBOX_BENCH_DATE", "2026-11-28");
    cmd
}

/// The record script's command for the rounds `runs` into `out` (15 rounds, 16 spp).
fn record_script(runs: &Path, out: &Path) -> std::process::Command {
    let (runs, out) = (runs.to_str().unwrap(), out.to_str().unwrap());
    bench_script(
        "tracer-bench-record.py",
        &[runs, out, "15", "16", "3.9.1", "abc1234", "5"],
    )
}

/// The index of the records in `out` (bench.json) and its summary rows (bench.md).
fn index(out: &Path) -> (Vec<Value>, Vec<String>) {
    let name = "tracer-bench-index.py";
    succeed(&mut bench_script(name, &[out.to_str().unwrap()]), name);
    let index: Vec<Value> =
        serde_json::from_str(&std::fs::read_to_string(out.join("bench.json")).unwrap()).unwrap();
    let md = std::fs::read_to_string(out.join("bench.md")).unwrap();
    let rows = md
        .lines()
        .filter(|l| l.starts_with("| [") && l.contains("abc1234"))
        .map(str::to_string)
        .collect();
    (index, rows)
}

/// Runs the record and index scripts into `out`; the index's one record and summary row.
fn record(runs: &Path, out: &Path) -> (Value, String) {
    succeed(&mut record_script(runs, out), "tracer-bench-record.py");
    let (index, rows) = index(out);
    assert_eq!(index.len(), 1, "{index:?}");
    assert_eq!(rows.len(), 1, "{rows:?}");
    (index[0].clone(), rows[0].clone())
}

#[test]
fn a_goal_is_met_only_when_the_interval_of_the_median_clears_it() {
    let dir = tempfile::tempdir().unwrap();
    // Every row clearly above its goal: met, and the rounds kept beside the record.
    let above = |_: &str, integrator: &str, round: u32| {
        (if integrator == "whitted" { 3.5 } else { 2.5 }) + 0.01 * round as f64
    };
    let out = dir.path().join("above");
    std::fs::create_dir(&out).unwrap();
    let (b, row) = record(&rounds(dir.path(), &above), &out);
    assert!(row.ends_with("| met |"), "{row}");
    let box_whitted = &b["results"][0];
    let median = box_whitted["speedup_vs_mitsuba_paired"][0]
        .as_f64()
        .unwrap();
    assert!((median - 3.58).abs() < 1e-9, "{median}");
    let name = b["file"].as_str().unwrap().replace(".md", "-rounds.jsonl");
    assert!(
        out.join(name).is_file(),
        "the rounds are kept beside the record"
    );
    // `mirror_box` whitted's median above 3 but its rounds spread across it: undecided.
    let spread = |scene: &str, integrator: &str, round: u32| {
        if scene == "mirror_box" && integrator == "whitted" {
            [2.0, 4.0][round as usize % 2] + 0.01 * round as f64
        } else {
            above(scene, integrator, round)
        }
    };
    let out = dir.path().join("spread");
    std::fs::create_dir(&out).unwrap();
    let (b, row) = record(&rounds(dir.path(), &spread), &out);
    let median = b["results"][0]["speedup_vs_mitsuba_paired"][0]
        .as_f64()
        .unwrap();
    assert!(median >= 3.0, "{median}");
    assert!(row.ends_with("| undecided |"), "{row}");
    let md = std::fs::read_to_string(out.join(b["file"].as_str().unwrap())).unwrap();
    assert!(md.contains("≥ 3×: undecided"), "{md}");
    // One row clearly below: not met.
    let below = |scene: &str, integrator: &str, round: u32| {
        if scene == "mirror_room" && integrator == "path" {
            1.5 + 0.01 * round as f64
        } else {
            spread(scene, integrator, round)
        }
    };
    let out = dir.path().join("below");
    std::fs::create_dir(&out).unwrap();
    let (_, row) = record(&rounds(dir.path(), &below), &out);
    assert!(row.ends_with("| not met |"), "{row}");
}

/// A record is one CPU kind's at one core count, the rounds' own (mirrorbox's threads), not the
/// count of the machine that makes the record: a 7-core run made on this machine keeps its
/// count, and sits beside the same CPU kind's 12-core record instead of replacing it, listed
/// by the count as a number (7 before 12, where the file names sort 12 first).
#[test]
fn a_record_keeps_the_core_count_of_its_rounds() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    // Seven threads: no machine that runs this test has seven cores.
    let seven = dir.path().join("seven");
    let twelve = dir.path().join("twelve");
    std::fs::create_dir(&seven).unwrap();
    std::fs::create_dir(&twelve).unwrap();
    let (b, row) = record(&rounds_on(&seven, 7, &|_, _, _| 2.0), &out);
    assert_eq!(b["cores"], 7, "{b}");
    let file = b["file"].as_str().unwrap().to_string();
    assert!(file.ends_with("-7cores.md"), "{file}");
    assert!(row.contains(" | 7 | 2026-11-28 | "), "{row}");
    let md = std::fs::read_to_string(out.join(&file)).unwrap();
    assert!(
        md.starts_with("# ") && md.lines().next().unwrap().ends_with(", 7 cores)"),
        "{md}"
    );
    assert!(md.contains("), 7 cores"), "{md}");
    // The same CPU kind's 12-core rounds: a second record beside the first, listed after it.
    succeed(
        &mut record_script(&rounds_on(&twelve, 12, &|_, _, _| 2.0), &out),
        "tracer-bench-record.py",
    );
    let (all, rows) = index(&out);
    let cores: Vec<&Value> = all.iter().map(|b| &b["cores"]).collect();
    assert_eq!(cores, [7, 12], "{all:?}");
    assert_eq!(rows.len(), 2, "{rows:?}");
    assert!(out.join(&file).is_file() && out.join(file.replace("-7cores", "-12cores")).is_file());
}

/// Rounds of several thread counts are not one record: refused, naming the counts, and nothing
/// written.
#[test]
fn rounds_of_several_core_counts_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let runs = rounds_on(dir.path(), 2, &|_, _, _| 2.0);
    let text = std::fs::read_to_string(&runs).unwrap();
    let mixed = text.replacen("\"threads\":2", "\"threads\":16", 1);
    assert_ne!(mixed, text);
    std::fs::write(&runs, mixed).unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let result = record_script(&runs, &out).output().unwrap();
    assert!(!result.status.success());
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(
        stderr.contains("several thread counts [16, 2]")
            || stderr.contains("several thread counts [2, 16]"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        0,
        "nothing written"
    );
}
