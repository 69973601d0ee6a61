//! The measuring scripts' shared shell: a committed report folder is replaced whole or not at
//! all (scripts/lib/reports-aside.sh, sourced by measure-advise.sh and measure-table1-runs.sh).

use crate::common::repo;
use std::path::Path;
use std::process::Command;

/// Runs `body` in bash in `dir` after sourcing the library; the exit code.
fn run_with_library(dir: &Path, body: &str) -> (i32, String) {
    let lib = repo().join("scripts/lib/reports-aside.sh");
    let script = format!("set -euo pipefail\n. '{}'\n{body}\n", lib.display());
    let out = Command::new("bash")
        .arg("-c")
        .arg(script)
        .current_dir(dir)
        .output()
        .expect("run bash");
    let code = out.status.code().unwrap_or(-1);
    (code, String::from_utf8_lossy(&out.stderr).into_owned())
}

/// A folder `out` of committed reports holding `old.txt`.
fn committed(dir: &Path) {
    std::fs::create_dir_all(dir.join("out")).unwrap();
    std::fs::write(dir.join("out/old.txt"), "committed").unwrap();
}

#[test]
fn a_run_that_fails_or_is_killed_leaves_the_committed_reports_as_they_were() {
    for end in [
        "false",
        "kill -TERM $$; sleep 5",
        "kill -INT $$; sleep 5",
        "exit 3",
    ] {
        let dir = tempfile::tempdir().unwrap();
        committed(dir.path());
        let body = format!(
            "set_reports_aside out\non_exit 'touch cleaned'\necho new > out/new.txt\n{end}\nkeep_new_reports"
        );
        let (code, stderr) = run_with_library(dir.path(), &body);
        assert_ne!(code, 0, "{end}: {stderr}");
        assert!(dir.path().join("out/old.txt").exists(), "{end}: {stderr}");
        assert!(
            !dir.path().join("out/new.txt").exists(),
            "{end}: half-made output kept"
        );
        assert!(!dir.path().join("out.previous").exists(), "{end}");
        assert!(
            dir.path().join("cleaned").exists(),
            "{end}: on_exit not run"
        );
        assert!(stderr.contains("the earlier reports are back"), "{stderr}");
    }
}

#[test]
fn a_run_that_finishes_replaces_the_reports_whole() {
    let dir = tempfile::tempdir().unwrap();
    committed(dir.path());
    let body =
        "set_reports_aside out\non_exit 'touch cleaned'\necho new > out/new.txt\nkeep_new_reports";
    let (code, stderr) = run_with_library(dir.path(), body);
    assert_eq!(code, 0, "{stderr}");
    assert!(dir.path().join("out/new.txt").exists());
    assert!(!dir.path().join("out/old.txt").exists(), "an old file kept");
    assert!(!dir.path().join("out.previous").exists());
    assert!(dir.path().join("cleaned").exists(), "on_exit not run");
}

/// A run killed outright (no trap) leaves `out.previous` (the committed reports) and its half
/// in `out`: the next run puts the committed ones back before anything else, and they are
/// what its own failure leaves.
#[test]
fn a_run_after_one_killed_outright_keeps_the_committed_reports() {
    let dir = tempfile::tempdir().unwrap();
    committed(dir.path());
    std::fs::rename(dir.path().join("out"), dir.path().join("out.previous")).unwrap();
    std::fs::create_dir(dir.path().join("out")).unwrap();
    std::fs::write(dir.path().join("out/half.txt"), "half").unwrap();
    let (code, stderr) = run_with_library(
        dir.path(),
        "set_reports_aside out\necho new > out/new.txt\nfalse",
    );
    assert_ne!(code, 0);
    assert!(
        stderr.contains("its committed reports are back"),
        "{stderr}"
    );
    assert!(dir.path().join("out/old.txt").exists(), "{stderr}");
    assert!(!dir.path().join("out/half.txt").exists());
    assert!(!dir.path().join("out/new.txt").exists());
    assert!(!dir.path().join("out.previous").exists());
}

/// The other states a run killed outright leaves: a first run's half (marked `out.none`) is
/// removed, not kept as reports; the replaced reports a finished run was deleting
/// (`out.discard`) are deleted, the new ones kept.
#[test]
fn a_killed_first_run_or_a_killed_clean_up_is_settled_by_the_next_run() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("out")).unwrap();
    std::fs::write(dir.path().join("out/half.txt"), "half").unwrap();
    std::fs::write(dir.path().join("out.none"), "").unwrap();
    let (code, stderr) = run_with_library(dir.path(), "set_reports_aside out\nfalse");
    assert_ne!(code, 0);
    assert!(stderr.contains("its half is removed"), "{stderr}");
    assert!(!dir.path().join("out").exists() && !dir.path().join("out.none").exists());

    committed(dir.path());
    std::fs::create_dir(dir.path().join("out.discard")).unwrap();
    let (code, stderr) = run_with_library(
        dir.path(),
        "set_reports_aside out\necho new > out/new.txt\nkeep_new_reports",
    );
    assert_eq!(code, 0, "{stderr}");
    assert!(dir.path().join("out/new.txt").exists());
    for leftover in ["out.discard", "out.previous", "out.none"] {
        assert!(!dir.path().join(leftover).exists(), "{leftover}");
    }
}

/// A second run while one measures into the folder is refused before it touches anything
/// (both had written into one folder, and a failure lost the committed reports).
#[test]
fn a_second_run_at_once_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    committed(dir.path());
    let (code, stderr) = run_with_library(
        dir.path(),
        "exec 8>out.lock\nflock 8\nif ( set_reports_aside out ); then exit 3; fi",
    );
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("another run is measuring into it"),
        "{stderr}"
    );
    assert!(dir.path().join("out/old.txt").exists());
    assert!(!dir.path().join("out.previous").exists());
}

#[test]
fn a_first_run_that_fails_leaves_nothing_half_made() {
    let dir = tempfile::tempdir().unwrap();
    let (code, stderr) = run_with_library(
        dir.path(),
        "set_reports_aside out\necho new > out/new.txt\nfalse",
    );
    assert_ne!(code, 0);
    assert!(!dir.path().join("out").exists(), "{stderr}");
    assert!(stderr.contains("partial output is removed"), "{stderr}");
}

/// Entries the script does not make (runs made by hand) carry over into the new reports; the
/// rest is replaced, and an entry the new run made is not overwritten.
#[test]
fn named_entries_carry_over_into_the_new_reports() {
    let dir = tempfile::tempdir().unwrap();
    committed(dir.path());
    for (name, text) in [("fresh_a", "by hand"), ("fresh_b", "by hand")] {
        std::fs::create_dir_all(dir.path().join("out").join(name)).unwrap();
        std::fs::write(dir.path().join("out").join(name).join("r.txt"), text).unwrap();
    }
    let body = "set_reports_aside out\nmkdir out/fresh_b\necho new > out/fresh_b/r.txt\n\
                carry_over_reports 'fresh_*' 'none_*'\nkeep_new_reports";
    let (code, stderr) = run_with_library(dir.path(), body);
    assert_eq!(code, 0, "{stderr}");
    let read = |p: &str| std::fs::read_to_string(dir.path().join("out").join(p)).ok();
    assert_eq!(read("fresh_a/r.txt").as_deref(), Some("by hand"));
    assert_eq!(read("fresh_b/r.txt").as_deref(), Some("new\n"));
    assert_eq!(read("old.txt"), None, "an entry not named was carried over");
    assert!(!dir.path().join("out.previous").exists());
}

#[test]
fn the_measuring_scripts_use_it() {
    for script in ["measure-advise.sh", "measure-table1-runs.sh"] {
        let text = std::fs::read_to_string(repo().join("scripts").join(script)).unwrap();
        let aside = text.find("set_reports_aside \"$out\"");
        let kept = text.rfind("keep_new_reports");
        assert!(
            matches!((aside, kept), (Some(a), Some(k)) if a < k),
            "{script}: its reports are not set aside, then kept at its end"
        );
        assert!(!text.contains("rm -rf \"$out\"\n"), "{script}");
    }
}
