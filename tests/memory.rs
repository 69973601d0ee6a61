//! Memory as a planned quantity (issue 37): every bundled scene × every registered method at
//! its defaults, rendered small in its own `mirrorbox render` process, stays under 2 GB of
//! peak resident memory (the process's own VmHWM, which `render --json` reports as
//! `peak_rss_bytes`), next to the plan's estimate (`memory_estimate`). A combination the CLI
//! refuses (exit 2: a symmetry method on a scene without planes, too many passes, …) is
//! recorded with its reason. The table is written to the test's temporary folder and
//! printed; `scripts/memory-peaks.sh` makes the committed `reports/memory/peaks.md` the same
//! way with the release binary.

use crate::common::repo;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The size every combination renders at: small enough for the whole sweep to take seconds.
const SIZE: (&str, &str) = ("32", "18");
/// The bound on every render's peak.
const PEAK_LIMIT: u64 = 2_000_000_000;

/// The registered methods, as `mirrorbox render --help` lists them.
fn methods() -> Vec<String> {
    mirrorbox_raster::METHODS
        .iter()
        .map(|e| e.name.to_string())
        .collect()
}

fn scenes() -> Vec<PathBuf> {
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(repo().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    scenes.sort();
    scenes
}

/// One combination's outcome: its peak and estimate in MB, or why it was refused.
enum Outcome {
    Rendered { peak: u64, estimate: u64 },
    Refused(String),
}

fn render(scene: &Path, method: &str, out: &Path) -> Outcome {
    let output = Command::new(env!("CARGO_BIN_EXE_mirrorbox"))
        .current_dir(repo())
        .env("NODEVICE_SELECT", "1")
        .args(["render"])
        .arg(scene)
        .args(["--method", method, "--width", SIZE.0, "--height", SIZE.1])
        .args(["--frames", "1", "--warmup", "0", "--json", "-o"])
        .arg(out)
        .output()
        .expect("run mirrorbox render");
    let stderr = String::from_utf8_lossy(&output.stderr);
    match output.status.code() {
        Some(0) => {
            let line = String::from_utf8_lossy(&output.stdout);
            let v: Value = serde_json::from_str(line.trim()).expect("render --json prints JSON");
            let estimate = &v["memory_estimate"];
            Outcome::Rendered {
                peak: v["peak_rss_bytes"].as_u64().expect("peak_rss_bytes"),
                estimate: estimate["gpu_bytes"].as_u64().unwrap()
                    + estimate["host_bytes"].as_u64().unwrap(),
            }
        }
        Some(2) => Outcome::Refused(
            stderr
                .lines()
                .find_map(|l| l.strip_prefix("error: "))
                .unwrap_or("(no message)")
                .to_string(),
        ),
        code => panic!(
            "{} --method {method}: exit {code:?}: {stderr}",
            scene.display()
        ),
    }
}

fn mb(bytes: u64) -> String {
    format!("{:.0}", bytes as f64 / 1e6)
}

#[test]
fn every_scene_and_method_peaks_under_two_gigabytes() {
    let dir = tempfile::tempdir().unwrap();
    let jobs: Vec<(PathBuf, String)> = scenes()
        .into_iter()
        .flat_map(|s| methods().into_iter().map(move |m| (s.clone(), m)))
        .collect();
    let results: Mutex<Vec<Option<Outcome>>> = Mutex::new(jobs.iter().map(|_| None).collect());
    let run = |i: usize| {
        let (scene, method) = &jobs[i];
        let outcome = render(scene, method, &dir.path().join(format!("{i}.png")));
        results.lock().unwrap()[i] = Some(outcome);
    };
    // Lavapipe's start-up waits as much as it computes: a few processes at a time. But with
    // Mesa's shader cache empty (a fresh machine), processes started together each compiled
    // the pipelines they share: the first scene's renders go one at a time (each method's
    // pipelines compiled once), and each later scene's first render alone (that scene's
    // own), before the rest four at a time. Cold: 118-121 -> 81 s of CPU (docs/budgets.md).
    let per_scene = methods().len();
    for (nth, scene) in (0..jobs.len()).step_by(per_scene).enumerate() {
        let end = (scene + per_scene).min(jobs.len());
        let alone = if nth == 0 { end } else { scene + 1 };
        (scene..alone).for_each(run);
        let next = AtomicUsize::new(alone);
        std::thread::scope(|scope| {
            for _ in 0..4 {
                scope.spawn(|| {
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        if i >= end {
                            break;
                        }
                        run(i);
                    }
                });
            }
        });
    }
    let mut table = format!(
        "Every bundled scene × every method at its defaults, {}×{}, one `render` each.\n\n\
         | scene | method | peak RSS (MB) | estimate (MB) |\n|---|---|---:|---:|\n",
        SIZE.0, SIZE.1
    );
    let mut over = Vec::new();
    for ((scene, method), outcome) in jobs.iter().zip(results.into_inner().unwrap()) {
        let name = scene.file_stem().unwrap().to_string_lossy();
        match outcome.expect("every job ran") {
            Outcome::Rendered { peak, estimate } => {
                table.push_str(&format!(
                    "| {name} | {method} | {} | {} |\n",
                    mb(peak),
                    mb(estimate)
                ));
                if peak > PEAK_LIMIT {
                    over.push(format!("{name} {method}: {} MB", mb(peak)));
                }
            }
            Outcome::Refused(reason) => {
                table.push_str(&format!("| {name} | {method} | refused: {reason} | |\n"));
            }
        }
    }
    let path = dir.path().join("peaks.md");
    std::fs::write(&path, &table).unwrap();
    println!("{table}(written to {})", path.display());
    assert!(over.is_empty(), "peaks above 2 GB: {over:?}");
}
