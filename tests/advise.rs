//! `mirrorbox advise` end to end (issue 55): bad input refused before anything is written,
//! and the answer at budgets no machine's speed can change — one nothing fits, one everything
//! does.

use crate::common::{mirrorbox, repo};
use serde_json::Value;

/// A small search: the paper's method only (n = 0…4 on mirror_box at 32×18, 6 rounds).
fn advise(out: &std::path::Path, budget: &str) -> crate::common::Output {
    mirrorbox(
        &[
            "advise",
            "scenes/mirror_box.json",
            "--budget-ms",
            budget,
            "--methods",
            "auxiliary",
            "--width",
            "32",
            "--height",
            "18",
            "--frames",
            "6",
            "--json",
            "-o",
            out.to_str().unwrap(),
        ],
        &[],
    )
}

#[test]
fn bad_advise_input_exits_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("advice");
    let out_s = out.to_str().unwrap();
    let bad_scene = dir.path().join("bad.json");
    std::fs::write(&bad_scene, "{").unwrap();
    for (args, says) in [
        (
            vec![
                "advise",
                "scenes/mirror_box.json",
                "--budget-ms",
                "0",
                "-o",
                out_s,
            ],
            "--budget-ms: a frame time in ms above 0, got 0",
        ),
        (
            vec![
                "advise",
                "scenes/mirror_box.json",
                "--budget-ms",
                "-3",
                "-o",
                out_s,
            ],
            "--budget-ms: a frame time in ms above 0, got -3",
        ),
        (
            vec![
                "advise",
                "scenes/mirror_box.json",
                "--budget-ms",
                "5",
                "--metric",
                "ssim",
                "-o",
                out_s,
            ],
            "--metric: one of flip, relmse, got \"ssim\"",
        ),
        (
            vec![
                "advise",
                "scenes/mirror_box.json",
                "--budget-ms",
                "5",
                "--methods",
                "symmetry",
                "-o",
                out_s,
            ],
            "--methods: \"symmetry\" is not a method advise offers",
        ),
        (
            vec![
                "advise",
                bad_scene.to_str().unwrap(),
                "--budget-ms",
                "5",
                "-o",
                out_s,
            ],
            "bad.json:1:1",
        ),
    ] {
        let r = mirrorbox(&args, &[]);
        assert_eq!(r.code, 2, "{args:?}: {}", r.stderr);
        assert!(r.stderr.contains(says), "{args:?}: {}", r.stderr);
        assert!(!out.exists(), "{args:?} wrote {out_s}");
    }
    // A folder holding something else is refused, not overwritten.
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("mine.txt"), "keep").unwrap();
    let r = advise(&out, "5");
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(r.stderr.contains("holds no earlier advice"), "{}", r.stderr);
    assert!(out.join("mine.txt").is_file());
}

#[test]
fn advise_names_the_closest_when_nothing_fits_and_the_best_when_everything_does() {
    let dir = tempfile::tempdir().unwrap();
    // Nothing renders in a nanosecond: no pick, the cheapest named; one round (each
    // knob's first value over budget: no ascent, no bisection).
    let out = dir.path().join("tiny");
    let r = advise(&out, "0.000001");
    assert_eq!(r.code, 0, "{}", r.stderr);
    let v: Value = serde_json::from_str(r.stdout.trim()).unwrap();
    assert!(v["pick"].is_null(), "{v}");
    assert_eq!(v["closest"]["method"], "auxiliary n=0", "{v}");
    assert_eq!(v["rounds"], 1, "{v}");
    // Everything renders within an hour: the ascent times n = 0…4, one per round, and the
    // pick is the cheapest of those within 2 % of the lowest error (n = 3 and 4 tie at 32×18).
    let out = dir.path().join("huge");
    let r = advise(&out, "3600000");
    assert_eq!(r.code, 0, "{}", r.stderr);
    let v: Value = serde_json::from_str(r.stdout.trim()).unwrap();
    let measured = v["measured"].as_array().unwrap();
    let methods: Vec<&str> = measured
        .iter()
        .map(|m| m["method"].as_str().unwrap())
        .collect();
    assert_eq!(
        methods,
        [
            "auxiliary n=0",
            "auxiliary n=1",
            "auxiliary n=2",
            "auxiliary n=3",
            "auxiliary n=4"
        ]
    );
    assert_eq!(v["rounds"], 5, "{v}");
    let f = |m: &Value| m["error"].as_f64().unwrap();
    let ms = |m: &Value| m["ms_median"].as_f64().unwrap();
    let lowest = measured.iter().map(f).fold(f64::INFINITY, f64::min);
    let tied: Vec<&Value> = measured.iter().filter(|m| f(m) <= lowest * 1.02).collect();
    let cheapest = tied.iter().min_by(|a, b| ms(a).total_cmp(&ms(b))).unwrap();
    assert_eq!(v["pick"]["method"], cheapest["method"], "{v}");
    assert_eq!(v["ties"].as_array().unwrap().len(), tied.len() - 1, "{v}");
    let n = cheapest["method"]
        .as_str()
        .unwrap()
        .trim_start_matches("auxiliary n=");
    assert!(
        v["render"]
            .as_str()
            .unwrap()
            .contains(&format!("--method auxiliary --n {n} ")),
        "{v}"
    );
    for f in [
        "advice.md",
        "advice.json",
        "front.svg",
        "pick.png",
        "truth.png",
        "pick_flip.png",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    assert!(!dir.path().join("huge.partial").exists());
    let _ = repo();
}
