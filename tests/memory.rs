//! Memory as a planned quantity (issue 37): every bundled scene × every registered method at
//! its defaults, rendered small, stays under 2 GB of peak resident memory, next to the plan's
//! estimate (`memory_estimate`). A combination the plan refuses (a symmetry method on a scene
//! without planes, too many passes, …) is recorded with its reason. The table is written to
//! the test's temporary folder and printed; `scripts/memory-peaks.sh` makes the committed
//! `reports/memory/peaks.md` with the release binary, one `render` process a combination.
//!
//! Here the combinations render one after another in one child process of the test, on one
//! adapter, each peak read as a sweep reads it (`mirrorbox_harness::reset_peak_memory`
//! before the scene is loaded, then `peak_memory_bytes`): the resident memory of the
//! process while that render ran, the adapter and everything the renders before it left
//! resident included (the first row is the adapter's opening). Not quite a bound on the
//! same render in a process of its own: a pipeline's first compilation, with Mesa's shader
//! cache empty, falls in the first scene's rows only. But the later rows show what 168
//! renders in one process keep (about 480 MB at 32×18 on lavapipe, against the 115-255 MB
//! of a process each in the committed table), far more than those transients.
//!
//! One process, not 168: 168 `render` processes of the debug binary took 61 s of wall time
//! and 89 s of CPU with Mesa's shader cache empty (a fresh machine), 23 s and 40 s with it
//! warm; one process 45 s and 48 s, 10 s and 13 s. An adapter per render, as each process
//! opens one, cost 80 ms each and the pipelines' creation again (23 s warm); one per scene,
//! 17 s (docs/budgets.md).

use crate::common::repo;
use mirrorbox_raster::{DEFAULT_MEMORY_BUDGET, Gpu, Method, RenderSettings, plan_frame};
use std::path::PathBuf;
use std::process::Command;

/// The size every combination renders at: `render --width 32 --height 18`.
const SIZE: (u32, u32) = (32, 18);
/// The bound on every render's peak.
const PEAK_LIMIT: u64 = 2_000_000_000;

fn scenes() -> Vec<PathBuf> {
    let mut scenes: Vec<PathBuf> = std::fs::read_dir(repo().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    scenes.sort();
    scenes
}

/// One combination's outcome: its peak and estimate in bytes, or why it was refused.
enum Outcome {
    Rendered { peak: u64, estimate: u64 },
    Refused(String),
}

/// What `render SCENE --method METHOD --width 32 --height 18 --frames 1 --warmup 0` does
/// once its adapter is open: load, resize, plan, check the plan against the default
/// `--memory-budget`, render. The peak is reset first when `resets` (the kernel takes it).
fn render(gpu: &Gpu, scene: &std::path::Path, method: Method, resets: bool) -> Outcome {
    if resets {
        assert!(
            mirrorbox_harness::reset_peak_memory(),
            "/proc/self/clear_refs took a reset before and refuses one now"
        );
    }
    let mut s = mirrorbox_scene::load_scene(scene).expect("a bundled scene loads");
    s.resize(Some(SIZE.0), Some(SIZE.1))
        .expect("every bundled scene renders at 32×18");
    let settings = RenderSettings {
        frames: 1,
        warmup: 0,
        ..RenderSettings::new(method)
    };
    let planned = match plan_frame(&s, &settings) {
        Ok(p) => p,
        Err(e) => return Outcome::Refused(e.to_string()),
    };
    let estimate = match planned.check_memory(&s, &settings, DEFAULT_MEMORY_BUDGET) {
        Ok(e) => e,
        Err(e) => return Outcome::Refused(e.to_string()),
    };
    match mirrorbox_raster::render_planned(gpu, &s, planned, &settings) {
        Ok(_) => {}
        Err(e) if e.is_refusal() => return Outcome::Refused(e.to_string()),
        Err(e) => panic!("{} --method {}: {e}", scene.display(), settings.method),
    }
    Outcome::Rendered {
        peak: mirrorbox_harness::peak_memory_bytes().expect("Linux's VmHWM"),
        estimate: estimate.gpu_bytes + estimate.host_bytes,
    }
}

fn mb(bytes: u64) -> String {
    format!("{:.0}", bytes as f64 / 1e6)
}

/// Set in the child process that renders (this test binary again, running this test
/// alone).
const CHILD: &str = "MIRRORBOX_MEMORY_PEAKS_CHILD";

/// Runs [`peaks`] in a child process of this test binary, this test alone: its resident
/// memory is then the renders' only, under cargo's own runner too (which runs a binary's
/// tests as threads of one process; nextest gives each its own).
#[test]
fn every_scene_and_method_peaks_under_two_gigabytes() {
    if std::env::var_os(CHILD).is_some() {
        return peaks();
    }
    let this_test = "memory::every_scene_and_method_peaks_under_two_gigabytes";
    let out = Command::new(std::env::current_exe().unwrap())
        .args(["--exact", this_test, "--nocapture", "--test-threads", "1"])
        .env(CHILD, "1")
        .output()
        .expect("run the memory peaks in a child process");
    let stdout = String::from_utf8_lossy(&out.stdout);
    print!("{stdout}");
    assert!(
        out.status.success(),
        "{}\n{stdout}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The child ran the test, not nothing (a filter that matched no test exits 0).
    assert!(stdout.contains("| scene | method |"), "{stdout}");
}

fn peaks() {
    // Each row the peak of that render alone, where the kernel resets it; elsewhere every
    // row is the largest so far, still a bound, and the table says so.
    let resets = mirrorbox_harness::reset_peak_memory();
    let dir = tempfile::tempdir().unwrap();
    let mut table = format!(
        "Every bundled scene × every method at its defaults, {}×{}, one after another in one \
         process; {}.\n\n| scene | method | peak RSS (MB) | estimate (MB) |\n|---|---|---:|---:|\n",
        SIZE.0,
        SIZE.1,
        if resets {
            "each row's peak since the render began"
        } else {
            "this kernel does not reset VmHWM: each row is the process's peak so far"
        }
    );
    let mut over = Vec::new();
    let mut rendered = 0;
    let gpu = Gpu::new().expect("a wgpu adapter (scripts/install-system-deps.sh)");
    // Opening the adapter, as every `render` process does first.
    let opened = mirrorbox_harness::peak_memory_bytes().expect("Linux's VmHWM");
    table.push_str(&format!("| (opening the adapter) | | {} | |\n", mb(opened)));
    if opened > PEAK_LIMIT {
        over.push(format!("opening the adapter: {} MB", mb(opened)));
    }
    let scenes = scenes();
    for scene in &scenes {
        let name = scene.file_stem().unwrap().to_string_lossy().to_string();
        for entry in mirrorbox_raster::METHODS {
            match render(&gpu, scene, Method::defaults(entry), resets) {
                Outcome::Rendered { peak, estimate } => {
                    rendered += 1;
                    table.push_str(&format!(
                        "| {name} | {} | {} | {} |\n",
                        entry.name,
                        mb(peak),
                        mb(estimate)
                    ));
                    if peak > PEAK_LIMIT {
                        over.push(format!("{name} {}: {} MB", entry.name, mb(peak)));
                    }
                }
                Outcome::Refused(reason) => {
                    table.push_str(&format!(
                        "| {name} | {} | refused: {reason} | |\n",
                        entry.name
                    ));
                }
            }
        }
    }
    let path = dir.path().join("peaks.md");
    std::fs::write(&path, &table).unwrap();
    println!("{table}(written to {})", path.display());
    // Most combinations render: a plan that refused everything would pass hollow.
    assert!(
        rendered * 10 >= scenes.len() * mirrorbox_raster::METHODS.len() * 9,
        "{table}"
    );
    assert!(over.is_empty(), "peaks above 2 GB: {over:?}");
}
