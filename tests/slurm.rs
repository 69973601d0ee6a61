//! Issue 20, end to end on a real Slurm: a one-node Slurm on this machine
//! (`scripts/slurm-local.sh`: slurm-wlm and munge from Debian), a 4-shard job array of a small
//! sweep submitted with `deploy/slurm/submit.sh` (at most 2 tasks at once) and the merge as a
//! dependent job; the merged sweep must hold the unsharded sweep's points with the same
//! images bit for bit and the same errors. The daemons are stopped however the test ends.
//!
//! Needs root (to install and run the daemons): without root it fails, unless
//! `MIRRORBOX_TEST_SKIP` names `slurm` (`mirrorbox_testing`).

use crate::common::{SMALL_SWEEP, assert_same_points, mirrorbox, repo, sweep_records as records};
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

/// Stops the local Slurm when dropped (a failed assertion included).
struct LocalSlurm {
    state: PathBuf,
}

impl Drop for LocalSlurm {
    fn drop(&mut self) {
        let _ = Command::new(repo().join("scripts/slurm-local.sh"))
            .arg("stop")
            .arg(&self.state)
            .status();
    }
}

#[test]
fn a_sharded_sweep_through_slurm_merges_into_the_unsharded_one() {
    if !mirrorbox_testing::require(
        mirrorbox_testing::SLURM,
        is_root(),
        "the local Slurm needs root to install and run its daemons (scripts/slurm-local.sh)",
    ) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let state = d.join("slurm");
    let start = Command::new(repo().join("scripts/slurm-local.sh"))
        .arg("start")
        .arg(&state)
        .output()
        .unwrap();
    let slurm = LocalSlurm {
        state: state.clone(),
    };
    assert!(
        start.status.success(),
        "local Slurm did not start: {}{}",
        String::from_utf8_lossy(&start.stdout),
        String::from_utf8_lossy(&start.stderr)
    );
    let conf = state.join("slurm.conf");

    let full = d.join("full");
    let mut args = vec!["sweep", "--out", full.to_str().unwrap()];
    args.extend(SMALL_SWEEP);
    let run = mirrorbox(&args, &[]);
    assert_eq!(run.code, 0, "{}", run.stderr);

    let runs = d.join("runs");
    let submit = Command::new(repo().join("deploy/slurm/submit.sh"))
        .args(["4", "2", runs.to_str().unwrap()])
        .args(SMALL_SWEEP)
        .env("SLURM_CONF", &conf)
        .env("MIRRORBOX", env!("CARGO_BIN_EXE_mirrorbox"))
        .current_dir(repo())
        .output()
        .unwrap();
    assert!(
        submit.status.success(),
        "submit: {}{}",
        String::from_utf8_lossy(&submit.stdout),
        String::from_utf8_lossy(&submit.stderr)
    );
    // Wait for the queue to empty (the merge is the last job).
    let started = Instant::now();
    loop {
        let queue = Command::new("squeue")
            .args(["-h", "-o", "%i %T"])
            .env("SLURM_CONF", &conf)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&queue.stdout).to_string();
        if queue.status.success() && text.trim().is_empty() {
            break;
        }
        assert!(
            started.elapsed() < Duration::from_secs(900),
            "the jobs did not finish in 15 minutes: {text}"
        );
        std::thread::sleep(Duration::from_secs(2));
    }
    let logs = || -> String {
        std::fs::read_dir(&runs)
            .unwrap()
            .flatten()
            .filter(|e| e.path().extension().is_some_and(|x| x == "out"))
            .map(|e| std::fs::read_to_string(e.path()).unwrap_or_default())
            .collect::<Vec<_>>()
            .join("\n")
    };
    let merged = records(&runs.join("merged"));
    let unsharded = records(&full);
    assert_eq!(merged.len(), unsharded.len(), "job logs:\n{}", logs());
    let shards = (0..4)
        .filter(|i| !records(&runs.join(format!("shard-{i}"))).is_empty())
        .count();
    assert!(shards >= 2, "the points were spread over the shards");
    assert_same_points(&unsharded, &full, &merged, &runs.join("merged"));
    let report = std::fs::read_to_string(runs.join("merged/report.md")).unwrap();
    assert!(report.contains("Merged from 4 shards"), "{report}");
    drop(slurm);
}
