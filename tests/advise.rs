//! `mirrorbox advise` end to end (issue 55): bad input refused before anything is written,
//! and the answer at budgets no machine's speed can change — one nothing fits, one everything
//! does.

use crate::common::{mirrorbox, repo};
use serde_json::Value;

/// A small search: the paper's method only (n = 0…4 on mirror_box at 32×18, 6 rounds).
fn advise(out: &std::path::Path, budget: &str) -> crate::common::Output {
    advise_with(out, budget, &[])
}

/// [`advise`] with more flags.
fn advise_with(out: &std::path::Path, budget: &str, flags: &[&str]) -> crate::common::Output {
    let mut args = vec![
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
    ];
    args.extend_from_slice(flags);
    mirrorbox(&args, &[])
}

#[test]
fn bad_advise_input_exits_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("advice");
    let out_s = out.to_str().unwrap();
    let bad_scene = dir.path().join("bad.json");
    std::fs::write(&bad_scene, "{").unwrap();
    let mut scene: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo().join("scenes/mirror_box.json")).unwrap(),
    )
    .unwrap();
    scene["mirrors"] = serde_json::json!([]);
    let no_mirrors = dir.path().join("no_mirrors.json");
    std::fs::write(&no_mirrors, scene.to_string()).unwrap();
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
            "--budget-ms: a frame time in ms from 0.000001 to 3600000, got 0",
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
            "--budget-ms: a frame time in ms from 0.000001 to 3600000, got -3",
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
                "scenes/mirror_box.json",
                "--budget-ms",
                "1e-300",
                "-o",
                out_s,
            ],
            "--budget-ms: a frame time in ms from 0.000001 to 3600000, got 1e-300",
        ),
        (
            vec![
                "advise",
                no_mirrors.to_str().unwrap(),
                "--budget-ms",
                "5",
                "-o",
                out_s,
            ],
            "the scene has no mirrors",
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
    // So is one whose advice.json is not an advice (it had been replaced whole).
    std::fs::write(out.join("advice.json"), "{}").unwrap();
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
    // The cheapest: n = 0 at full or at half texture resolution (the two are a few µs
    // apart at 32×18: which is cheaper is the machine's to say).
    let closest = v["closest"]["method"].as_str().unwrap_or_default();
    assert!(
        ["auxiliary n=0", "auxiliary n=0 texture-scale=0.5"].contains(&closest),
        "{v}"
    );
    assert_eq!(v["rounds"], 1, "{v}");
    // --exhaustive times every coarse candidate (n = 0…4 at both texture scales) in that one
    // round, whatever the budget.
    let out = dir.path().join("exhaustive");
    let r = advise_with(&out, "0.000001", &["--exhaustive"]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    let v: Value = serde_json::from_str(r.stdout.trim()).unwrap();
    assert_eq!(v["rounds"], 1, "{v}");
    assert_eq!(v["exhaustive"], true, "{v}");
    assert_eq!(v["measured"].as_array().unwrap().len(), 10, "{v}");
    // Everything renders within an hour: the ascent times n = 0…4 at both texture scales,
    // one n per round, and the pick is the cheapest of those within 2 % of the lowest error.
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
            "auxiliary n=0 texture-scale=0.5",
            "auxiliary n=1",
            "auxiliary n=1 texture-scale=0.5",
            "auxiliary n=2",
            "auxiliary n=2 texture-scale=0.5",
            "auxiliary n=3",
            "auxiliary n=3 texture-scale=0.5",
            "auxiliary n=4",
            "auxiliary n=4 texture-scale=0.5",
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
    // `auxiliary n=3 texture-scale=0.5` renders with `--n 3 --texture-scale 0.5`.
    let options = cheapest["method"]
        .as_str()
        .unwrap()
        .trim_start_matches("auxiliary ")
        .split(' ')
        .map(|w| w.replace('=', " "))
        .collect::<Vec<_>>()
        .join(" --");
    assert!(
        v["render"]
            .as_str()
            .unwrap()
            .contains(&format!("--method auxiliary --{options} ")),
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
    // The figure rings the pick and names it in its legend: one ring in the plot, one in
    // the legend (the ring's place on its point: the plot crate's own test).
    let svg = std::fs::read_to_string(out.join("front.svg")).unwrap();
    let pick = v["pick"]["method"].as_str().unwrap();
    assert!(svg.contains(&format!(">the pick: {pick}</text>")), "{svg}");
    let rings = svg.matches(r#"fill="none" stroke="black" stroke-width="2"/>"#);
    assert_eq!(rings.count(), 2, "{svg}");
    // Its footer names the code that measured (the first round's), as every figure's does.
    let round: Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("search/round-1/sweep.json")).unwrap(),
    )
    .unwrap();
    let commit = round["commit"].as_str().unwrap();
    assert!(
        !commit.is_empty() && svg.contains(commit.get(..10).unwrap_or(commit)),
        "{commit}: {svg}"
    );
    assert!(!dir.path().join("huge.partial").exists());
    let _ = repo();
}

/// A camera path of two views: every candidate is timed and scored from each (one sweep per
/// view per round, `round-K/<view>`), and the advice takes each candidate's worst view — its
/// largest median and error — and shows that view's images; `mirrorbox report` remakes the
/// same answer from the records. A view the scene cannot be seen from is refused first.
#[test]
fn advise_over_a_camera_path_takes_each_candidates_worst_view() {
    let dir = tempfile::tempdir().unwrap();
    let views = dir.path().join("views.json");
    std::fs::write(
        &views,
        r#"{"views": [
            {"name": "scene", "position": [0.8, 1.8, 1.7], "look_at": [-0.25, 1.15, -2.0]},
            {"name": "side", "position": [-0.6, 1.2, 1.5], "look_at": [0.4, 1.0, -2.0]}
        ]}"#,
    )
    .unwrap();
    let out = dir.path().join("path");
    let run = |views: &std::path::Path, over: &str| {
        mirrorbox(
            &[
                "advise",
                "scenes/mirror_box.json",
                "--budget-ms",
                "3600000",
                "--methods",
                "naive,auxiliary",
                "--width",
                "32",
                "--height",
                "18",
                "--frames",
                "6",
                "--views",
                views.to_str().unwrap(),
                "--over-views",
                over,
                "--json",
                "-o",
                out.to_str().unwrap(),
            ],
            &[],
        )
    };
    let r = run(&views, "worst");
    assert_eq!(r.code, 0, "{}", r.stderr);
    let v: Value = serde_json::from_str(r.stdout.trim()).unwrap();
    assert_eq!(v["views"], serde_json::json!(["scene", "side"]), "{v}");
    assert_eq!(v["over_views"], "worst");
    let per_view = |view: &str| -> Vec<Value> {
        let text =
            std::fs::read_to_string(out.join(format!("search/round-1/{view}/results.jsonl")))
                .unwrap();
        text.lines()
            .map(|l| serde_json::from_str::<Value>(l).unwrap())
            .filter(|r| r["kind"] != "floor")
            .collect()
    };
    let (a, b) = (per_view("scene"), per_view("side"));
    let flip = |r: &Value| {
        r["mirror_metrics"]["flip_mean"]
            .as_f64()
            .unwrap_or_else(|| r["metrics"]["flip_mean"].as_f64().unwrap())
    };
    let first = &v["measured"][0];
    let key = first["method"].as_str().unwrap();
    let find = |rs: &[Value]| {
        rs.iter()
            .find(|r| r["key"].as_str().unwrap().starts_with(&format!("{key}|")))
            .cloned()
            .unwrap()
    };
    let (ra, rb) = (find(&a), find(&b));
    let median = |r: &Value| r["ms_median"].as_f64().unwrap();
    assert_eq!(
        first["ms_median"].as_f64().unwrap(),
        median(&ra).max(median(&rb))
    );
    assert_eq!(first["error"].as_f64().unwrap(), flip(&ra).max(flip(&rb)));
    assert!(out.join("pick.png").is_file());
    // The answer remade from the records is the same answer.
    let before = std::fs::read_to_string(out.join("advice.json")).unwrap();
    let r = mirrorbox(&["report", out.to_str().unwrap()], &[]);
    assert_eq!(r.code, 0, "{}", r.stderr);
    assert_eq!(
        std::fs::read_to_string(out.join("advice.json")).unwrap(),
        before
    );
    // A view looking at its own position, and an unknown combination: exit 2, nothing
    // written.
    std::fs::remove_dir_all(&out).unwrap();
    let bad = dir.path().join("bad_views.json");
    std::fs::write(
        &bad,
        r#"{"views": [{"name": "blind", "position": [0, 1, 0], "look_at": [0, 1, 0]}]}"#,
    )
    .unwrap();
    let r = run(&bad, "worst");
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("bad_views.json") && r.stderr.contains("\"blind\""),
        "{}",
        r.stderr
    );
    let r = run(&views, "median");
    assert_eq!(r.code, 2, "{}", r.stderr);
    assert!(
        r.stderr.contains("--over-views: one of worst, mean"),
        "{}",
        r.stderr
    );
    assert!(!out.exists());
}
