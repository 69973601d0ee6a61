//! The advisor on four scenes at three budgets each (issue 55): what `mirrorbox advise`
//! picked, what its search cost, whether a repeat picks the same, and — on the two scenes
//! whose every coarse candidate was also timed in one round (`advise --exhaustive`) — whether
//! the pick is as good as the best of those within the same budget, at what share of their
//! frames.

use crate::{Experiment, Measure};
use mirrorbox_harness::advise::TIE;
use mirrorbox_report::document::{Block, markdown, ms, sci};
use mirrorbox_report::overview::OtherReport;
use mirrorbox_report::readme::{ReadmeError, RegionSource};
use serde_json::Value;
use std::path::Path;

/// How many candidates the registry's advise rows offer at their coarse values on a scene
/// without shadows: what `advise --exhaustive` times.
pub fn coarse_space() -> usize {
    use mirrorbox_raster::{Advise, METHODS};
    METHODS
        .iter()
        .map(|e| match e.advise {
            Advise::Skip => 0,
            Advise::Fixed(v) => v.len(),
            Advise::Knob {
                coarse, variants, ..
            } => coarse.len() * variants.len(),
        })
        .sum()
}

/// Largest advice.json read (a few KB as written).
const MAX_ADVICE_BYTES: u64 = 16 << 20;

/// A field's name and the test of its type.
type FieldCheck = (&'static str, fn(&Value) -> bool);

/// The fields the section quotes, of the types `advise` writes them with (the field that is
/// not, if one is not): a broken file was quoted as "null×null" and "α = ?".
fn check_advice(v: &Value) -> Result<(), &'static str> {
    let checks: [FieldCheck; 10] = [
        ("scene", Value::is_string),
        ("device", Value::is_string),
        ("budget_ms", Value::is_number),
        ("alpha", Value::is_number),
        ("width", Value::is_u64),
        ("height", Value::is_u64),
        ("renders", Value::is_u64),
        ("rounds", Value::is_u64),
        ("seconds", Value::is_number),
        ("measured", Value::is_array),
    ];
    for (field, is) in checks {
        if !is(&v[field]) {
            return Err(field);
        }
    }
    if !(v["pick"].is_object() || v["pick"].is_null()) {
        return Err("pick");
    }
    Ok(())
}

/// Every advice under `reports/<folder>/`, by folder name.
fn advices(reports: &Path, folder: &str) -> Result<Vec<(String, Value)>, ReadmeError> {
    let dir = reports.join(folder);
    let mut out = Vec::new();
    let entries =
        std::fs::read_dir(&dir).map_err(|e| ReadmeError(format!("{}: {e}", dir.display())))?;
    for e in entries.flatten() {
        let path = e.path().join("advice.json");
        // A folder without one is no advice; one that is there is read, or refused.
        if std::fs::symlink_metadata(&path).is_err() {
            continue;
        }
        let text = mirrorbox_files::read_bounded_text(&path, MAX_ADVICE_BYTES, "an advice file")
            .map_err(|e| ReadmeError(e.to_string()))?;
        let v: Value = serde_json::from_str(&text)
            .map_err(|e| ReadmeError(format!("{}: {e}", path.display())))?;
        check_advice(&v).map_err(|field| {
            ReadmeError(format!(
                "{}: {field}: not what `mirrorbox advise` writes",
                path.display()
            ))
        })?;
        out.push((e.file_name().to_string_lossy().into_owned(), v));
    }
    // Scene, then budget, then the repeat after its first run, then the folder's name (two
    // advices of one scene and budget, e.g. a `_cold` one and its rerun, in an order that
    // does not depend on the file system's).
    out.sort_by(|a, b| {
        let key = |v: &Value, f: &str| {
            (
                v["scene"].as_str().unwrap_or_default().to_string(),
                v["budget_ms"].as_f64().unwrap_or(0.0),
                f.ends_with("_repeat"),
                f.to_string(),
            )
        };
        key(&a.1, &a.0)
            .partial_cmp(&key(&b.1, &b.0))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    if out.is_empty() {
        return Err(ReadmeError(format!("{}: no advice.json", dir.display())));
    }
    Ok(out)
}

/// A JSON point's ms/frame median and, where it has one, its 95 % interval.
fn timing(p: &Value) -> (f64, Option<(f64, f64)>) {
    let interval = p["ms_interval"]
        .as_array()
        .and_then(|i| Some((i.first()?.as_f64()?, i.get(1)?.as_f64()?)));
    (p["ms_median"].as_f64().unwrap_or(f64::NAN), interval)
}

/// The method of a JSON point, or "–".
fn method(v: &Value) -> String {
    v["method"]
        .as_str()
        .map_or("–".into(), |m| format!("`{m}`"))
}

/// Whether a JSON point fits `budget`: the upper end of its interval (its median without
/// one) at most the budget (`advise::within`).
fn fits(p: &Value, budget: f64) -> bool {
    let (median, interval) = timing(p);
    interval.map_or(median, |(_, hi)| hi) <= budget
}

/// Why the advisor's pick is worse than the exhaustive run's best within budget, `x`:
/// either the advisor measured `x` and found it over budget (the two runs' timings disagree:
/// a tie at the budget where its interval holds the budget), or it never measured it.
fn timing_verdict(advice: &Value, x: &Value, budget: f64) -> String {
    let key = x["method"].as_str().unwrap_or_default();
    let theirs = advice["measured"]
        .as_array()
        .into_iter()
        .flatten()
        .find(|m| m["method"].as_str() == Some(key));
    let exhaustive_ms = ms(timing(x).0, 3);
    let error = x["error"].as_f64().map_or("–".into(), sci);
    match theirs {
        Some(m) => {
            let (median, interval) = timing(m);
            let (lo, hi) = interval.unwrap_or((median, median));
            let at = if lo <= budget && budget <= hi {
                "a tie at the budget"
            } else {
                "the runs' timings disagree"
            };
            format!(
                "{at}: `{key}` ({error}) fits the exhaustive run ({exhaustive_ms} ms) but not \
                 the advisor's ({} [{}–{}] ms)",
                ms(median, 3),
                ms(lo, 3),
                ms(hi, 3)
            )
        }
        None => format!(
            "NO: the advisor never measured `{key}` ({error}, {exhaustive_ms} ms in the \
             exhaustive run)"
        ),
    }
}

/// The suffix of an advice folder whose timings are known not to be an answer: the first
/// work of a freshly started GPU, timed before its clocks settled (docs/gpu.md).
const COLD: &str = "_cold";

/// The region: one row per advice under `reports/<folder>/`, then the repeat's verdict.
fn advise_region_of(reports: &Path, folder: &str) -> Result<String, ReadmeError> {
    let all = advices(reports, folder)?;
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    let mut exhaustive_runs = Vec::new();
    for (folder, v) in &all {
        if v["exhaustive"].as_bool() == Some(true) {
            exhaustive_runs.push(format!(
                "`{folder}` ({} candidates, {} frames, {:.0} s)",
                v["measured"].as_array().map_or(0, Vec::len),
                v["renders"],
                v["seconds"].as_f64().unwrap_or(0.0)
            ));
            continue;
        }
        let scene = v["scene"].as_str().unwrap_or_default();
        let budget = v["budget_ms"].as_f64().unwrap_or(0.0);
        let pick = &v["pick"];
        let error = |p: &Value| p["error"].as_f64();
        let (pick_text, pick_ms, pick_error) = if pick.is_null() {
            (
                format!("none fits; cheapest {}", method(&v["closest"])),
                match timing(&v["closest"]) {
                    (median, _) if median.is_nan() => "–".into(),
                    (median, Some((lo, hi))) => {
                        format!("{} [{}–{}]", ms(median, 3), ms(lo, 3), ms(hi, 3))
                    }
                    (median, None) => ms(median, 3),
                },
                v["closest"]["error"].as_f64().map_or("–".into(), sci),
            )
        } else {
            let ties = v["ties"].as_array().map_or(0, Vec::len);
            (
                if ties > 0 {
                    format!("{} (+{ties} tied)", method(pick))
                } else {
                    method(pick)
                },
                match timing(pick) {
                    (median, Some((lo, hi))) => {
                        format!("{} [{}–{}]", ms(median, 3), ms(lo, 3), ms(hi, 3))
                    }
                    (median, None) => ms(median, 3),
                },
                error(pick).map_or("–".into(), sci),
            )
        };
        // Against the exhaustive run of the same scene (the folder's advices share one size
        // and α: the paragraph above says which, or that they differ).
        let exhaustive = all.iter().find(|(_, x)| {
            x["exhaustive"].as_bool() == Some(true) && x["scene"].as_str() == Some(scene)
        });
        let renders = v["renders"].as_u64().unwrap_or(0);
        let (share, verdict) = match exhaustive {
            Some((f, x)) => {
                let best = x["measured"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .filter(|p| fits(p, budget) && p["error"].as_f64().is_some())
                    .min_by(|a, b| {
                        let e = |p: &&Value| p["error"].as_f64().unwrap_or(f64::INFINITY);
                        e(a).total_cmp(&e(b))
                    });
                // The exhaustive run's own timing of the pick: a pick better than its best
                // within budget was, in that run, over the budget.
                let pick_there = x["measured"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .find(|m| m["method"] == pick["method"]);
                let verdict = match (error(pick), best) {
                    (_, None) => "the exhaustive run has nothing within budget".into(),
                    (Some(e), Some(b)) if e <= error(b).unwrap_or(0.0) * (1.0 + TIE) => {
                        // Its verdict word and clause, where that run timed the pick over.
                        let over_there = pick_there.filter(|m| !fits(m, budget)).map(|m| {
                            let (median, interval) = timing(m);
                            let (lo, hi) = interval.unwrap_or((median, median));
                            let at = lo <= budget;
                            (
                                if at {
                                    "at the budget"
                                } else {
                                    "over the budget there"
                                },
                                format!(
                                    "; but the exhaustive run timed {} {}, {} [{}–{}] ms: {}",
                                    method(pick),
                                    if at {
                                        "with an interval holding the budget"
                                    } else {
                                        "wholly over the budget"
                                    },
                                    ms(median, 3),
                                    ms(lo, 3),
                                    ms(hi, 3),
                                    if at {
                                        "the two runs differ at the budget"
                                    } else {
                                        "the two runs' timings disagree"
                                    }
                                ),
                            )
                        });
                        let (word, clause) = over_there.unwrap_or(("yes", String::new()));
                        format!(
                            "{word}: {} against the exhaustive best within budget {} ({}){clause}",
                            sci(e),
                            error(b).map_or("–".into(), sci),
                            method(b),
                        )
                    }
                    (_, Some(b)) => timing_verdict(v, b, budget),
                };
                let theirs = x["renders"].as_u64().unwrap_or(0);
                (
                    format!(
                        "{:.0} % of `{f}`'s {theirs}",
                        100.0 * renders as f64 / theirs.max(1) as f64
                    ),
                    verdict,
                )
            }
            None => ("–".into(), "no exhaustive run of this scene".into()),
        };
        rows.push(vec![
            format!("`{folder}`"),
            ms(budget, 3),
            pick_text,
            pick_ms,
            pick_error,
            format!(
                "{} in {} {}, {} frames, {:.0} s",
                v["measured"].as_array().map_or(0, Vec::len),
                v["rounds"],
                if v["rounds"] == 1 { "round" } else { "rounds" },
                v["renders"],
                v["seconds"].as_f64().unwrap_or(0.0)
            ),
            share,
            verdict,
        ]);
        if folder.ends_with(COLD) {
            notes.push(format!(
                "`{folder}` timed a GPU that had just started (every candidate slower, with \
                 wide intervals, than the same candidates in the later advices): not an \
                 answer (docs/gpu.md)."
            ));
        }
        if let Some(first) = folder.strip_suffix("_repeat")
            && let Some((_, a)) = all.iter().find(|(f, _)| f == first)
        {
            let name = |p: &Value| p["method"].as_str().unwrap_or("none").to_string();
            let set = |v: &Value| -> Vec<String> {
                std::iter::once(name(&v["pick"]))
                    .chain(v["ties"].as_array().into_iter().flatten().map(name))
                    .collect()
            };
            let (p1, p2) = (name(&a["pick"]), name(&v["pick"]));
            // A pick of one run that the other run measured with an interval holding the
            // budget: the runs differ by the noise at the budget, a tie.
            let at_budget = |run: &Value, key: &str| {
                run["measured"].as_array().into_iter().flatten().any(|m| {
                    m["method"].as_str() == Some(key)
                        && timing(m)
                            .1
                            .is_some_and(|(lo, hi)| lo <= budget && budget <= hi)
                })
            };
            notes.push(if p1 == p2 {
                format!("`{folder}` picks what `{first}` picked: `{p1}`.")
            } else if set(a).contains(&p2) || set(v).contains(&p1) {
                format!(
                    "`{folder}` picks `{p2}`, tied with `{first}`'s `{p1}` (errors within {:.0} %).",
                    100.0 * TIE
                )
            } else if at_budget(v, &p1) || at_budget(a, &p2) {
                let e = |run: &Value| run["pick"]["error"].as_f64().map_or("–".into(), sci);
                format!(
                    "`{folder}` picks `{p2}` (error {}) where `{first}` picked `{p1}` ({}): the \
                     runs differ at the budget (one run's 95 % interval for the other's pick \
                     holds it), so which of the two fits is the machine's spread to decide.",
                    e(v),
                    e(a)
                )
            } else {
                format!("`{folder}` picks `{p2}` where `{first}` picked `{p1}`: they DIFFER.")
            });
        }
    }
    // What every advice of the folder shares: the device, the size, α (one value each, or
    // each value found, in order).
    let distinct = |f: &dyn Fn(&Value) -> String| {
        let mut seen: Vec<String> = Vec::new();
        for (_, v) in &all {
            let x = f(v);
            if !seen.contains(&x) {
                seen.push(x);
            }
        }
        seen.join(", ")
    };
    let device = distinct(&|v| {
        v["device"]
            .as_str()
            .unwrap_or("an unrecorded device")
            .to_string()
    });
    let size = distinct(&|v| format!("{}×{}", v["width"], v["height"]));
    let alpha = distinct(&|v| v["alpha"].as_f64().map_or("?".into(), |a| format!("{a}")));
    let exhaustive = if exhaustive_runs.is_empty() {
        "No exhaustive run of these scenes on this device: the picks are not judged against one."
            .to_string()
    } else {
        format!(
            "The exhaustive runs time every one of them in one round — {} — and each pick is \
             judged against the best of those within its budget.",
            exhaustive_runs.join(", ")
        )
    };
    let mut blocks = vec![Block::Paragraph(format!(
        "Measured on {device}, {size}, α = {alpha}, error = FLIP mean over the mirror \
             pixels; a pick fits only if its ms/frame interval's upper end is within the \
             budget. The registry's rows offer {} coarse candidates per scene (before \
             bisection; fewer are measured where a plan's limits — passes, paths, triangles — \
             or the adapter refuse some). {exhaustive}",
        coarse_space(),
    ))];
    let mut header = [
        "advice",
        "budget ms",
        "pick",
        "ms/frame [95 % CI]",
        "error",
        "search: candidates, rounds, frames, time",
        "frames against the exhaustive run's",
        "as good as the exhaustive run's best within budget",
    ]
    .map(String::from)
    .to_vec();
    if exhaustive_runs.is_empty() {
        // Nothing to judge against: the last two columns would say so on every row.
        header.truncate(6);
        rows.iter_mut().for_each(|r| r.truncate(6));
    }
    blocks.push(Block::Table(header, rows));
    if !notes.is_empty() {
        blocks.push(Block::Bullets(notes));
    }
    Ok(markdown(&blocks))
}

pub const ADVISE: Experiment = Experiment {
    name: "advise",
    about: "mirrorbox advise on four scenes at three budgets each: its picks, their search cost, a repeat, and every coarse candidate's best beside them",
    folder: "advise",
    measure: Measure::Script("scripts/measure-advise.sh", &[]),
    section: None,
    regions: &[
        RegionSource {
            id: "advise",
            source: "advise",
            about: "what the advisor picked per scene and budget, its search cost, and the exhaustive run's best beside it",
            generate: |reports| advise_region_of(reports, "advise"),
        },
        RegionSource {
            id: "advise-gpu",
            source: "gpu/advise_h200",
            about: "what the advisor picked on an NVIDIA H200 (scripts/gpu-measure.sh advise)",
            generate: |reports| advise_region_of(reports, "gpu/advise_h200"),
        },
    ],
    chapter: "advise.md",
    main_job: false,
    // The answers are no sweep folders: the overview lists their README, whose table
    // `mirrorbox readme` fills (the "advise" region above). Its records' commit is that of
    // one answer's `advice.json` (scripts/measure-advise.sh remakes them all in one run),
    // not the folder's, which the README's own edits would move.
    overview: Some(OtherReport {
        report: "advise/README.md",
        data: "advise/mirror_box_8ms/advice.json",
        scene: "scenes/mirror_box.json, scenes/mirror_room.json, scenes/tilted_pair.json, scenes/imported/engine_box.json",
    }),
};

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn write_advice(reports: &Path, folder: &str, advice: &Value) {
        let dir = reports.join(folder);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("advice.json"), advice.to_string()).unwrap();
    }

    fn advice(budget: f64, exhaustive: bool) -> Value {
        let pick = json!({"method": "unrolled depth=4", "ms_median": 0.9,
                          "ms_interval": [0.89, 0.91], "error": 0.01});
        json!({"scene": "scenes/mirror_box.json", "budget_ms": budget, "device": "NVIDIA H200",
               "width": 960, "height": 540, "alpha": 1.0, "exhaustive": exhaustive,
               "pick": pick, "ties": [], "measured": [pick], "rounds": 2, "renders": 40,
               "seconds": 3.0})
    }

    /// A folder of advices without an exhaustive run gets a table without the two columns
    /// that judge against one; a `_cold` advice is said not to be an answer; the paragraph
    /// names the device, size and α the advices record.
    #[test]
    fn the_region_names_what_it_cannot_judge_and_what_is_not_an_answer() {
        let reports = tempfile::tempdir().unwrap();
        write_advice(reports.path(), "gpu/a/box_1ms", &advice(1.0, false));
        write_advice(reports.path(), "gpu/a/box_2ms_cold", &advice(2.0, false));
        write_advice(reports.path(), "gpu/a/box_2ms", &advice(2.0, false));
        let region = advise_region_of(reports.path(), "gpu/a").unwrap();
        // One scene and budget twice: by folder name, whatever order the folder lists them in.
        let at = |f: &str| region.find(&format!("| `{f}` |")).unwrap();
        assert!(
            at("box_1ms") < at("box_2ms") && at("box_2ms") < at("box_2ms_cold"),
            "{region}"
        );
        assert!(
            region.contains("Measured on NVIDIA H200, 960×540, α = 1,"),
            "{region}"
        );
        assert!(region.contains("No exhaustive run"), "{region}");
        assert!(!region.contains("exhaustive run's best"), "{region}");
        assert!(
            region.contains("`box_2ms_cold` timed a GPU that had just started"),
            "{region}"
        );
        assert!(!region.contains("`box_1ms` timed"), "{region}");
        // With an exhaustive run of the scene, every row is judged against it.
        write_advice(
            reports.path(),
            "gpu/a/box_8ms_exhaustive",
            &advice(8.0, true),
        );
        let region = advise_region_of(reports.path(), "gpu/a").unwrap();
        assert!(
            region.contains("as good as the exhaustive run's best"),
            "{region}"
        );
        assert!(region.contains("| yes: 1.000e-2 against"), "{region}");
    }

    /// An advice.json that `advise` could not have written is refused naming the file and
    /// the field, and one that is no file is refused too (they were quoted as "null×null,
    /// α = ?", or passed over).
    #[test]
    fn a_broken_advice_is_refused_naming_its_field() {
        let reports = tempfile::tempdir().unwrap();
        write_advice(reports.path(), "a/box_1ms", &advice(1.0, false));
        assert!(advise_region_of(reports.path(), "a").is_ok());
        let mut broken = advice(2.0, false);
        broken["width"] = json!(null);
        write_advice(reports.path(), "a/box_2ms", &broken);
        let e = advise_region_of(reports.path(), "a").unwrap_err().0;
        assert!(e.contains("box_2ms/advice.json: width:"), "{e}");
        std::fs::remove_dir_all(reports.path().join("a/box_2ms")).unwrap();
        std::fs::create_dir_all(reports.path().join("a/box_3ms/advice.json")).unwrap();
        let e = advise_region_of(reports.path(), "a").unwrap_err().0;
        assert!(e.contains("box_3ms/advice.json"), "{e}");
    }
}
