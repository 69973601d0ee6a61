//! Error over time (issue 22): each method rendered frame by frame along a camera path (or a
//! still camera) against the truth of every frame — `feedback`'s convergence for a still
//! camera, its lag under motion, beside the stateless methods. The records come from a
//! sequence sweep (`mirrorbox_harness::sequence`); this module only reads and writes them.

use crate::plot::{Chart, Series, styles_for};
use crate::stats::median;
use mirrorbox_files::{FileError, write_atomically_with};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;

/// One frame of one method in one scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameRecord {
    pub scenario: String,
    /// The method's key (`feedback history=16`, `auxiliary n=2`).
    pub method: String,
    /// Whether the method claims to match the truth (registry `exact`).
    pub exact: bool,
    pub frame: u32,
    /// Seconds along the camera path.
    pub time: f64,
    pub flip_mean: f64,
    pub flip_p95: f64,
    pub relmse: f64,
    pub psnr: f64,
    /// GPU milliseconds of the frame (median of its timed redraws).
    pub ms: f64,
    pub passes: usize,
    /// Reflections the frame shows (`feedback`'s grow frame by frame).
    pub reflections: usize,
}

/// A scenario as the report describes it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScenarioInfo {
    pub name: String,
    pub description: String,
    pub scene: String,
    pub frames: u32,
    pub fps: f64,
    /// Median distance the camera moves per frame, scene units (0 for a still camera).
    pub step: f64,
    /// Filmstrips of the stateful methods' worst frames: (method, image, frames shown).
    pub filmstrips: Vec<(String, String, Vec<u32>)>,
}

/// What every frame of a motion sweep shares.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MotionInfo {
    pub command: String,
    pub date: String,
    pub device: String,
    pub cpu: String,
    pub width: u32,
    pub height: u32,
    pub truth: String,
    pub scenarios: Vec<ScenarioInfo>,
    /// The commit that measured it (`git describe`, as [`crate::SweepInfo::commit`]); empty
    /// in older reports, whose figures name the commit that committed their frames instead.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub commit: String,
    /// For a report without [`MotionInfo::commit`]: the commit that last committed it.
    #[serde(skip)]
    pub records_commit: String,
    /// Each frame's untimed and timed draws (`--warmup`, `--frames`); absent in reports made
    /// before they were recorded (the motion experiment's: one and one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub draws: Option<[u32; 2]>,
}

/// The frames of `method` in `scenario`, in frame order.
fn frames<'a>(records: &'a [FrameRecord], scenario: &str, method: &str) -> Vec<&'a FrameRecord> {
    let mut v: Vec<&FrameRecord> = records
        .iter()
        .filter(|r| r.scenario == scenario && r.method == method)
        .collect();
    v.sort_by_key(|r| r.frame);
    v
}

/// The methods of a scenario, in first-seen order.
fn methods<'a>(records: &'a [FrameRecord], scenario: &str) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for r in records.iter().filter(|r| r.scenario == scenario) {
        if !out.contains(&r.method.as_str()) {
            out.push(&r.method);
        }
    }
    out
}

fn sci(v: f64) -> String {
    format!("{v:.3e}")
}

/// The first frame from which `flips` stays within `tolerance` (relative) of its last value:
/// where a converging method has settled.
pub fn settled_after(flips: &[f64], tolerance: f64) -> Option<usize> {
    let last = *flips.last()?;
    let within = |v: f64| (v - last).abs() <= tolerance * last.abs().max(1e-12);
    (0..flips.len()).find(|&k| flips[k..].iter().all(|&v| within(v)))
}

/// The report's markdown.
pub fn document(info: &MotionInfo, records: &[FrameRecord]) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Error over time: moving cameras, previous-frame feedback and cube maps\n"
    );
    // The draws per frame as recorded (a report before they were: the motion experiment's
    // one untimed and one timed draw).
    let [untimed, timed] = info.draws.unwrap_or([1, 1]);
    let draw = |n: u32, what: &str| match n {
        1 => format!("one {what} draw"),
        n => format!("{n} {what} draws"),
    };
    let _ = writeln!(
        md,
        "Every method and the truth rendered frame by frame along the same camera path \
         (issue 22; docs/methods.md, \"Previous-frame feedback\" and \"Cube-map \
         reflections\"); each frame compared with the truth of that frame. The stateful \
         methods (`feedback`, `cubemap`) carry their textures from frame to frame as an \
         engine would (`history=H`, as each one's name says: it starts from H frames drawn at \
         the first view); the other methods have no state. Times: {} per frame after {} \
         (the frame's time is their median); the table gives the median over the frames.\n",
        draw(timed, "GPU-timestamped"),
        draw(untimed, "untimed")
    );
    let _ = writeln!(
        md,
        "- Device: {} (CPU: {})\n- Size: {}×{}\n- Truth: {}\n- Date: {}\n- Command: `{}`\n",
        info.device, info.cpu, info.width, info.height, info.truth, info.date, info.command
    );
    for s in &info.scenarios {
        let _ = writeln!(md, "## {}\n", s.name);
        let _ = writeln!(
            md,
            "{} `{}`, {} frames at {} frames per second of path time; the camera moves {:.4} \
             scene units per frame (median).\n",
            s.description, s.scene, s.frames, s.fps, s.step
        );
        let _ = writeln!(
            md,
            "| method | FLIP frame 0 | FLIP last frame | FLIP mean over frames | worst frame (FLIP) | reflections, last frame | ms/frame (median) |\n|---|---|---|---|---|---|---|"
        );
        for m in methods(records, &s.name) {
            let f = frames(records, &s.name, m);
            let flips: Vec<f64> = f.iter().map(|r| r.flip_mean).collect();
            let worst = f
                .iter()
                .max_by(|a, b| a.flip_mean.total_cmp(&b.flip_mean))
                .map(|r| format!("{} ({})", r.frame, sci(r.flip_mean)))
                .unwrap_or_default();
            let ms: Vec<f64> = f.iter().map(|r| r.ms).collect();
            let _ = writeln!(
                md,
                "| {m}{} | {} | {} | {} | {} | {} | {:.1} |",
                if f.first().is_some_and(|r| r.exact) {
                    " (exact)"
                } else {
                    ""
                },
                flips.first().map_or(String::new(), |v| sci(*v)),
                flips.last().map_or(String::new(), |v| sci(*v)),
                sci(flips.iter().sum::<f64>() / flips.len().max(1) as f64),
                worst,
                f.last().map_or(0, |r| r.reflections),
                median(&ms),
            );
        }
        let _ = writeln!(md);
        for line in findings(records, &s.name, s.step == 0.0) {
            let _ = writeln!(md, "- {line}");
        }
        let _ = writeln!(md, "\n![FLIP against frame, {0}](plot_{0}.svg)\n", s.name);
        for (method, strip, worst) in &s.filmstrips {
            let _ = writeln!(
                md,
                "`{method}`, its worst frames {worst:?} (truth | {method} | FLIP error, brighter is worse):\n\n![{strip}]({strip})\n"
            );
        }
    }
    md
}

/// What a scenario shows about `feedback`: when it settles, against the exact methods and
/// each `auxiliary` n, in words with the measured numbers.
fn findings(records: &[FrameRecord], scenario: &str, still: bool) -> Vec<String> {
    let mut out = Vec::new();
    let ms = methods(records, scenario);
    let Some(fb) = ms.iter().find(|m| m.starts_with("feedback")) else {
        return out;
    };
    let fb_flips: Vec<f64> = frames(records, scenario, fb)
        .iter()
        .map(|r| r.flip_mean)
        .collect();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    if !still {
        out.push(format!(
            "`{fb}` over the walk: mean FLIP {}, last frame {}.",
            sci(mean(&fb_flips)),
            sci(*fb_flips.last().unwrap_or(&0.0))
        ));
    } else if let Some(k) = settled_after(&fb_flips, 0.05) {
        out.push(format!(
            "`{fb}` settles (FLIP within 5 % of its last frame's, {}) from frame {k} on; its mean over the frames is {}.",
            sci(*fb_flips.last().unwrap_or(&0.0)),
            sci(mean(&fb_flips))
        ));
    }
    for m in &ms {
        if m == fb {
            continue;
        }
        let other: Vec<f64> = frames(records, scenario, m)
            .iter()
            .map(|r| r.flip_mean)
            .collect();
        let first_below = (0..fb_flips.len().min(other.len())).find(|&k| fb_flips[k] <= other[k]);
        let exact = frames(records, scenario, m)
            .first()
            .is_some_and(|r| r.exact);
        let verdict = match first_below {
            Some(k) => format!("at or below it from frame {k}"),
            None => "above it in every frame".to_string(),
        };
        out.push(format!(
            "against `{m}`{} (mean FLIP {}): `{fb}` is {verdict}; mean ratio {:.2}×.",
            if exact { ", exact" } else { "" },
            sci(mean(&other)),
            mean(&fb_flips) / mean(&other).max(1e-12)
        ));
    }
    out
}

/// FLIP against frame, one series per method (log y).
pub fn chart(records: &[FrameRecord], scenario: &str) -> Chart {
    let methods = methods(records, scenario);
    let styles = styles_for(&methods);
    Chart {
        y_log: true,
        x_whole: true,
        series: methods
            .iter()
            .zip(styles)
            .map(|(m, style)| {
                Series::new(
                    m.to_string(),
                    style,
                    frames(records, scenario, m)
                        .iter()
                        .map(|r| (f64::from(r.frame), r.flip_mean.max(1e-6)))
                        .collect(),
                )
            })
            .collect(),
        ..Chart::new(
            format!("FLIP over the image per frame: {scenario}"),
            "frame",
            "FLIP mean over the image (log)",
        )
    }
}

fn write_text(path: &Path, text: &str) -> Result<(), FileError> {
    write_atomically_with(path, |tmp| {
        std::fs::write(tmp, text).map_err(|e| e.to_string())
    })
}

/// Writes `frames.jsonl` (the records), `motion.json` (the info), `report.md` and one
/// `plot_<scenario>.svg` per scenario into `dir`, each atomically.
pub fn write_motion_report(
    dir: &Path,
    info: &MotionInfo,
    records: &[FrameRecord],
) -> Result<(), FileError> {
    // Before the records are rewritten: a figure's or the report's place taken by a folder
    // had left new records beside the old report.
    check_motion_outputs(dir, info)?;
    let mut lines = String::new();
    for r in records {
        let _ = writeln!(
            lines,
            "{}",
            serde_json::to_string(r).expect("a frame record encodes")
        );
    }
    write_text(&dir.join("frames.jsonl"), &lines)?;
    write_text(
        &dir.join("motion.json"),
        &serde_json::to_string_pretty(info).expect("the motion info encodes"),
    )?;
    write_figures(dir, info, records)
}

/// Refuses, before any is written, a folder in the place of a motion report's file: its
/// records, info, report and figures.
fn check_motion_outputs(dir: &Path, info: &MotionInfo) -> Result<(), FileError> {
    let mut outputs: Vec<(&str, std::path::PathBuf)> = info
        .scenarios
        .iter()
        .map(|s| ("report", dir.join(format!("plot_{}.svg", s.name))))
        .collect();
    for f in ["report.md", "frames.jsonl", "motion.json"] {
        outputs.push(("report", dir.join(f)));
    }
    mirrorbox_files::check_outputs(&outputs)
}

/// Writes `report.md` and the `plot_<scenario>.svg`s of a sequence sweep from its records,
/// leaving the records and the info as they are: what remaking a committed report rewrites
/// (re-encoding the records would change their text, not their values).
pub fn write_motion_figures(
    dir: &Path,
    info: &MotionInfo,
    records: &[FrameRecord],
) -> Result<(), FileError> {
    check_motion_outputs(dir, info)?;
    write_figures(dir, info, records)
}

/// [`write_motion_figures`] once its outputs are checked.
fn write_figures(dir: &Path, info: &MotionInfo, records: &[FrameRecord]) -> Result<(), FileError> {
    for s in &info.scenarios {
        write_text(
            &dir.join(format!("plot_{}.svg", s.name)),
            &Chart {
                footer: format!(
                    "{} · {}x{} · {} on {} · {} · {}",
                    s.scene,
                    info.width,
                    info.height,
                    info.device,
                    info.cpu,
                    info.date.get(..10).unwrap_or(&info.date),
                    if !info.commit.is_empty() {
                        format!("commit {}", info.commit)
                    } else if !info.records_commit.is_empty() {
                        format!("records committed in {}", info.records_commit)
                    } else {
                        "commit not recorded".to_string()
                    }
                ),
                ..chart(records, &s.name)
            }
            .to_svg(),
        )?;
    }
    write_text(&dir.join("report.md"), &document(info, records))
}

/// Reads a motion report's records and info (bounded: a report folder is the user's).
pub fn read_motion(dir: &Path) -> Result<(MotionInfo, Vec<FrameRecord>), String> {
    let text = |name: &str, what: &str| {
        mirrorbox_files::read_bounded_text(&dir.join(name), 64 << 20, what)
            .map_err(|e| e.to_string())
    };
    let info: MotionInfo = serde_json::from_str(&text("motion.json", "a motion report's info")?)
        .map_err(|e| format!("{}: {e}", dir.join("motion.json").display()))?;
    let records = text("frames.jsonl", "a motion report's frames")?
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            serde_json::from_str(l)
                .map_err(|e| format!("{}:{}: {e}", dir.join("frames.jsonl").display(), i + 1))
        })
        .collect::<Result<Vec<FrameRecord>, _>>()?;
    check_motion(dir, &info, &records)?;
    Ok((info, records))
}

/// Most frames of one scenario a motion report holds: a bound of reading, far above what
/// `sweep --path` renders (`mirrorbox_harness::sequence::MAX_SEQUENCE_FRAMES`, 1000).
const MAX_SEQUENCE_FRAMES: u32 = 1 << 16;

/// Refuses a motion report whose records cannot be of a sweep: a scenario name that is not a
/// file name's part (it names `plot_<scenario>.svg`: `/../../x` had written outside the
/// folder), a frame of no scenario or twice, a metric or time that is no measurement, or no
/// frame at all. The error names the file and the record.
fn check_motion(dir: &Path, info: &MotionInfo, records: &[FrameRecord]) -> Result<(), String> {
    let info_file = dir.join("motion.json");
    let frames_file = dir.join("frames.jsonl");
    for (i, s) in info.scenarios.iter().enumerate() {
        if info.scenarios[..i].iter().any(|o| o.name == s.name) {
            return Err(format!(
                "{}: scenarios[{i}].name {:?} a second time",
                info_file.display(),
                s.name
            ));
        }
        let ok = (1..=64).contains(&s.name.len())
            && s.name
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_');
        if !ok {
            return Err(format!(
                "{}: scenarios[{i}].name {:?}: 1 to 64 letters, digits, '-' or '_'",
                info_file.display(),
                s.name
            ));
        }
    }
    if records.is_empty() {
        return Err(format!("{}: no frame records", frames_file.display()));
    }
    let mut seen = std::collections::BTreeSet::new();
    for (i, r) in records.iter().enumerate() {
        let at = |what: String| format!("{}: record {}: {what}", frames_file.display(), i + 1);
        if !info.scenarios.iter().any(|s| s.name == r.scenario) {
            return Err(at(format!(
                "scenario {:?} is none of motion.json's",
                r.scenario
            )));
        }
        if r.frame >= MAX_SEQUENCE_FRAMES {
            return Err(at(format!(
                "frame {} (frames 0..{MAX_SEQUENCE_FRAMES} are read)",
                r.frame
            )));
        }
        if !seen.insert((r.scenario.as_str(), r.method.as_str(), r.frame)) {
            return Err(at(format!(
                "frame {} of {:?} in {:?} a second time",
                r.frame, r.method, r.scenario
            )));
        }
        let measures = [
            ("flip_mean", r.flip_mean),
            ("flip_p95", r.flip_p95),
            ("relmse", r.relmse),
        ];
        if let Some((name, v)) = measures.iter().find(|(_, v)| !(v.is_finite() && *v >= 0.0)) {
            return Err(at(format!("{name} {v} (finite and ≥ 0)")));
        }
        if !(r.ms.is_finite() && r.ms > 0.0 && r.time.is_finite()) {
            return Err(at(format!(
                "ms {} and time {} (ms finite and > 0, time finite)",
                r.ms, r.time
            )));
        }
    }
    Ok(())
}

/// A README's summary of a sequence sweep measured by `command`, its report at `report`:
/// per scenario, each method's mean and last-frame FLIP and its median time, and a stateful
/// method's settling frame on the still camera.
pub fn summary(info: &MotionInfo, records: &[FrameRecord], command: &str, report: &str) -> String {
    let mut md = format!(
        "Measured by `{command}` ({}, {}×{}, {}; report: [`{report}`]({report})). FLIP mean against each frame's truth:\n\n",
        info.device, info.width, info.height, info.date
    );
    let mut head = String::from("| method |");
    let mut rule = String::from("|---|");
    for s in &info.scenarios {
        let _ = write!(head, " {} ({:.3}/frame): mean, last |", s.name, s.step);
        rule.push_str("---|");
    }
    head.push_str(" ms/frame (median, still) |");
    rule.push_str("---|");
    let _ = writeln!(md, "{head}\n{rule}");
    let Some(first) = info.scenarios.first() else {
        return md;
    };
    // Rows by method family (stateful methods' history differs between scenarios).
    let family = |m: &str| match m.split_once(" history=") {
        Some((base, _)) => base.to_string(),
        None => m.to_string(),
    };
    let mut rows: Vec<String> = Vec::new();
    for r in records {
        let f = family(&r.method);
        if !rows.contains(&f) {
            rows.push(f);
        }
    }
    for row in rows {
        let _ = write!(md, "| {row} |");
        for s in &info.scenarios {
            let f: Vec<&FrameRecord> = methods(records, &s.name)
                .into_iter()
                .filter(|m| family(m) == row)
                .flat_map(|m| frames(records, &s.name, m))
                .collect();
            let flips: Vec<f64> = f.iter().map(|r| r.flip_mean).collect();
            if flips.is_empty() {
                md.push_str(" – |");
            } else {
                let _ = write!(
                    md,
                    " {}, {} |",
                    sci(flips.iter().sum::<f64>() / flips.len() as f64),
                    sci(*flips.last().unwrap_or(&0.0))
                );
            }
        }
        let ms: Vec<f64> = methods(records, &first.name)
            .into_iter()
            .filter(|m| family(m) == row)
            .flat_map(|m| frames(records, &first.name, m))
            .map(|r| r.ms)
            .collect();
        let _ = writeln!(md, " {:.1} |", median(&ms));
    }
    md.push('\n');
    for s in info.scenarios.iter().filter(|s| s.step == 0.0) {
        for m in methods(records, &s.name) {
            if !m.contains("history=") {
                continue;
            }
            let flips: Vec<f64> = frames(records, &s.name, m)
                .iter()
                .map(|r| r.flip_mean)
                .collect();
            if let Some(k) = settled_after(&flips, 0.05) {
                let _ = writeln!(
                    md,
                    "- {}: `{m}` settles from frame {k} (FLIP within 5 % of its last frame's, {}).",
                    s.name,
                    sci(*flips.last().unwrap_or(&0.0))
                );
            }
        }
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(scenario: &str, method: &str, frame: u32, flip: f64) -> FrameRecord {
        FrameRecord {
            scenario: scenario.into(),
            method: method.into(),
            exact: method.starts_with("unrolled"),
            frame,
            time: 0.0,
            flip_mean: flip,
            flip_p95: flip,
            relmse: flip,
            psnr: 30.0,
            ms: 1.0,
            passes: 3,
            reflections: frame as usize + 1,
        }
    }

    fn info(name: &str) -> MotionInfo {
        MotionInfo {
            commit: String::new(),
            records_commit: String::new(),
            draws: None,
            command: "mirrorbox sweep --path".into(),
            date: "today".into(),
            device: "test".into(),
            cpu: "test".into(),
            width: 8,
            height: 8,
            truth: "whitted".into(),
            scenarios: vec![ScenarioInfo {
                name: name.into(),
                description: "A still camera:".into(),
                scene: "scenes/mirror_box.json".into(),
                frames: 2,
                fps: 30.0,
                step: 0.0,
                filmstrips: Vec::new(),
            }],
        }
    }

    /// A motion report is read back only if its records can be a sweep's: a scenario name
    /// that would put its figure outside the folder, and records that are no measurement,
    /// are refused naming the file and record.
    #[test]
    fn a_motion_report_that_no_sweep_wrote_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let good = vec![
            record("still", "naive", 0, 0.1),
            record("still", "naive", 1, 0.1),
        ];
        write_motion_report(dir.path(), &info("still"), &good).unwrap();
        assert!(read_motion(dir.path()).is_ok());
        let cases: Vec<(MotionInfo, Vec<FrameRecord>, &str)> = vec![
            (
                MotionInfo {
                    scenarios: [info("still").scenarios, info("still").scenarios].concat(),
                    ..info("still")
                },
                good.clone(),
                "scenarios[1].name \"still\" a second time",
            ),
            (
                info("/../../x"),
                good.clone(),
                "scenarios[0].name \"/../../x\"",
            ),
            (info("still"), Vec::new(), "no frame records"),
            (
                info("still"),
                vec![record("walk", "naive", 0, 0.1)],
                "scenario \"walk\" is none of motion.json's",
            ),
            (
                info("still"),
                vec![good[0].clone(), good[0].clone()],
                "record 2: frame 0 of \"naive\" in \"still\" a second time",
            ),
            (
                info("still"),
                vec![record("still", "naive", 0, -1.0)],
                "record 1: flip_mean -1",
            ),
            (
                info("still"),
                vec![FrameRecord {
                    ms: -3.0,
                    ..good[0].clone()
                }],
                "ms -3",
            ),
            (
                info("still"),
                vec![record("still", "naive", 4_000_000_000, 0.1)],
                "frame 4000000000",
            ),
        ];
        for (info, records, says) in cases {
            // Written as a hand would edit them (the writer itself writes no such report).
            std::fs::write(
                dir.path().join("motion.json"),
                serde_json::to_string(&info).unwrap(),
            )
            .unwrap();
            let lines: Vec<String> = records
                .iter()
                .map(|r| serde_json::to_string(r).unwrap())
                .collect();
            std::fs::write(dir.path().join("frames.jsonl"), lines.join("\n")).unwrap();
            let e = read_motion(dir.path()).unwrap_err();
            assert!(e.contains(says), "{says}: {e}");
        }
    }

    #[test]
    fn settling_is_the_first_frame_that_stays_near_the_last() {
        assert_eq!(settled_after(&[0.5, 0.2, 0.11, 0.1, 0.1], 0.05), Some(3));
        assert_eq!(settled_after(&[0.1, 0.5, 0.1], 0.05), Some(2));
        assert_eq!(settled_after(&[0.3], 0.05), Some(0));
        assert_eq!(settled_after(&[], 0.05), None);
    }

    #[test]
    fn findings_compare_feedback_frame_by_frame() {
        let mut r = Vec::new();
        for (k, f) in [0.4, 0.2, 0.05, 0.05].into_iter().enumerate() {
            r.push(record("still", "feedback history=0", k as u32, f));
            r.push(record("still", "auxiliary n=0", k as u32, 0.1));
            r.push(record("still", "unrolled depth=64", k as u32, 0.01));
        }
        let f = findings(&r, "still", true);
        assert!(f[0].contains("from frame 2"), "{f:?}");
        assert!(
            f[1].contains("auxiliary n=0") && f[1].contains("from frame 2"),
            "{f:?}"
        );
        assert!(
            f[2].contains("exact") && f[2].contains("above it in every frame"),
            "{f:?}"
        );
        let md = document(
            &MotionInfo {
                draws: Some([2, 5]),
                command: "mirrorbox motion".into(),
                scenarios: vec![ScenarioInfo {
                    frames: 4,
                    ..info("still").scenarios.remove(0)
                }],
                ..info("still")
            },
            &r,
        );
        assert!(
            md.contains("| feedback history=0 | 4.000e-1 | 5.000e-2 |"),
            "{md}"
        );
        assert!(md.contains("unrolled depth=64 (exact)"), "{md}");
        // The draws as recorded, not the motion experiment's one and one.
        assert!(
            md.contains("Times: 5 GPU-timestamped draws per frame after 2 untimed draws"),
            "{md}"
        );
        assert!(!md.contains("history=16"), "{md}");
    }
}
