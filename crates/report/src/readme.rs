//! The figures the README, the book and the docs quote, generated from the committed reports.
//!
//! A region of `README.md`, `docs/methods.md` or a chapter of the book (`docs/book/src/*.md`)
//! between `<!-- generated: ID -->` and `<!-- end generated: ID -->` is written by [`fill`]
//! from the report its [`RegionSource`] names, with the same sentences and tables the report
//! itself prints — so the prose cannot drift from the numbers. This crate has the machinery
//! and the regions of no one experiment ([`REGIONS`]); each experiment's module declares its
//! own, and regions made by the caller outright (the command-line reference, rendered from the
//! CLI's argument parser) are passed in as text ([`fill_with`], [`stale_regions_with`]). `mirrorbox readme` rewrites the regions; `mirrorbox readme
//! --check` (run by the tests) fails when a region differs from what the reports give.
//! Everything outside the regions is left alone, byte for byte.

use crate::document::{Block, markdown};
use crate::folder::Sweep;
use std::path::Path;

const BEGIN: &str = "<!-- generated: ";
const END: &str = "<!-- end generated: ";
const CLOSE: &str = " -->";

pub use crate::error::ReadmeError;

/// One generated region: its ID and its Markdown.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    pub id: &'static str,
    pub text: String,
}

/// A region made from the committed reports: its ID, the report (under `reports/`) it
/// quotes, what it holds, and its generator, given the reports folder. The regions of no one
/// experiment are [`REGIONS`]; each experiment's module declares its own
/// (`mirrorbox-experiments`), and the caller passes them all ([`fill_with`]).
#[derive(Clone, Copy)]
pub struct RegionSource {
    pub id: &'static str,
    pub source: &'static str,
    pub about: &'static str,
    pub generate: fn(&Path) -> Result<String, ReadmeError>,
}

impl RegionSource {
    /// The region's text from the reports under `reports`, relative links replaced by their
    /// labels ([`without_relative_links`]).
    pub fn text(&self, reports: &Path) -> Result<String, ReadmeError> {
        (self.generate)(reports).map(|t| without_relative_links(&t))
    }
}

/// The regions of no one experiment: what the two commands cost.
pub const REGIONS: &[RegionSource] = &[
    RegionSource {
        id: "main-job",
        source: "main_job.json",
        about: "the main job's steps: time and peak memory",
        generate: |reports| main_job_region(&reports.join("main_job.json")),
    },
    RegionSource {
        id: "job-costs",
        source: "main_job.json",
        about: "what the two commands cost: the last recorded scripts/test.sh and scripts/run.sh",
        generate: job_costs_region,
    },
];

/// "Measured DATE on DEVICE: adapter …, `COMMAND`." The date is the latest run that measured
/// a record (the report's own date is when it was last written, perhaps by a resume).
pub fn measured_on(s: &Sweep) -> String {
    let info = &s.info;
    let date = s
        .records
        .iter()
        .filter_map(|r| r.run.as_deref())
        .max()
        .unwrap_or(&info.date);
    format!(
        "Measured {} on {}: {}, `{}`.",
        date.split('T').next().unwrap_or(date),
        info.cpu,
        info.adapter_description(),
        info.command
    )
}

/// The blocks a README quotes: text and tables, not headings, charts or image rows (the
/// README places those itself).
pub fn prose(blocks: Vec<Block>) -> Vec<Block> {
    blocks
        .into_iter()
        .filter(|b| {
            matches!(
                b,
                Block::Paragraph(_) | Block::Bullets(_) | Block::Table(..)
            )
        })
        .collect()
}

/// The tracer's median time per scene and k, with the light images and rays behind it.
/// A Markdown report written whole by a script: its text after the title line.
pub fn report_body_region(path: &Path) -> Result<String, ReadmeError> {
    let text = mirrorbox_files::read_bounded_text(path, 1 << 20, "a report")
        .map_err(|e| ReadmeError(e.to_string()))?;
    let body = text
        .lines()
        .skip_while(|l| l.starts_with("# ") || l.trim().is_empty())
        .collect::<Vec<_>>()
        .join("\n");
    Ok(format!("{}\n", body.trim_end()))
}

/// A report's body up to its first `## ` section: the summary before the details (the
/// tracer bench's table of CPUs, each CPU's table after it).
pub fn report_summary_region(path: &Path) -> Result<String, ReadmeError> {
    let body = report_body_region(path)?;
    let summary = body
        .lines()
        .take_while(|l| !l.starts_with("## "))
        .collect::<Vec<_>>()
        .join("\n");
    Ok(format!("{}\n", summary.trim_end()))
}

/// JSON-lines files of one-off runs are a few hundred KB; the bound keeps a wrong path from
/// being read whole.
const MAX_RUNS_BYTES: u64 = 16 << 20;

/// Reads every non-empty line of `path` as a `T`, naming the line that is not one.
pub fn read_lines<T: serde::de::DeserializeOwned>(path: &Path) -> Result<Vec<T>, ReadmeError> {
    let text = mirrorbox_files::read_bounded_text(path, MAX_RUNS_BYTES, "a JSON-lines file")
        .map_err(|e| ReadmeError(e.to_string()))?;
    let runs = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            serde_json::from_str(l)
                .map_err(|e| ReadmeError(format!("{}:{}: {e}", path.display(), i + 1)))
        })
        .collect::<Result<Vec<T>, _>>()?;
    if runs.is_empty() {
        return Err(ReadmeError(format!("{}: no runs to quote", path.display())));
    }
    Ok(runs)
}

/// One step of the main job, as `scripts/run.sh` records it in `reports/main_job.json`.
#[derive(serde::Deserialize)]
struct Step {
    name: String,
    seconds: u64,
    peak_kb: Option<u64>,
    /// A step `scripts/test.sh` runs in the background while the build compiles: its
    /// seconds overlap the build's, so they are not added to the rest.
    #[serde(default)]
    during_build: bool,
}

#[derive(serde::Deserialize)]
struct MainJob {
    date: String,
    cpu: String,
    /// `empty` when cargo had to download every crate (a fresh machine), `warm` when not;
    /// absent in older records.
    #[serde(default)]
    cargo_cache: Option<String>,
    seconds: u64,
    steps: Vec<Step>,
}

fn main_job_region(path: &Path) -> Result<String, ReadmeError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| ReadmeError(format!("{}: {e}", path.display())))?;
    let job: MainJob =
        serde_json::from_str(&text).map_err(|e| ReadmeError(format!("{}: {e}", path.display())))?;
    let mib = |kb: Option<u64>| kb.map_or("–".into(), |kb| format!("{:.0}", kb as f64 / 1024.0));
    let blocks = vec![
        Block::Paragraph(format!(
            "The last `scripts/run.sh` that wrote the committed reports ({}, {}) took {} s:",
            job.date.split('T').next().unwrap_or(&job.date),
            job.cpu,
            job.seconds
        )),
        Block::Table(
            ["step", "seconds", "peak memory, MiB (largest process)"]
                .map(String::from)
                .to_vec(),
            job.steps
                .iter()
                .map(|s| {
                    vec![
                        format!("`{}`", s.name),
                        s.seconds.to_string(),
                        mib(s.peak_kb),
                    ]
                })
                .collect(),
        ),
    ];
    Ok(markdown(&blocks))
}

/// `scripts/test.sh`'s own record (`target/test-timing.json`, committed as
/// `reports/tests/test_timing.json`): the same shape as the main job's, without memory.
const TEST_JOB: &str = "tests/test_timing.json";

/// The budgets of the two commands from a fresh clone on 2 cores with an empty cargo cache
/// (DEVELOPERS.md, docs/budgets.md): 10 minutes for the tests, 15 for the main job.
const TEST_BUDGET_S: u64 = 600;
const MAIN_JOB_BUDGET_S: u64 = 900;

/// A recorded run against its budget: within it (and by how much), or over it by how much.
/// The budget is for an empty cargo cache; a run with crates already downloaded is not
/// measured against it.
fn budget_verdict(seconds: u64, budget: u64, cargo_cache: Option<&str>) -> String {
    if cargo_cache != Some("empty") {
        format!("{budget} s: not comparable (cargo cache not empty)")
    } else if seconds <= budget {
        format!("{budget} s: within, {} s to spare", budget - seconds)
    } else {
        format!("{budget} s: **over by {} s**", seconds - budget)
    }
}

/// One line per command: its last recorded run's total, date and machine, its budget, and its two
/// longest steps (the rest summed), read from `main_job.json` and `tests/test_timing.json`.
fn job_costs_region(reports: &Path) -> Result<String, ReadmeError> {
    let read = |name: &str| -> Result<MainJob, ReadmeError> {
        let path = reports.join(name);
        let text = mirrorbox_files::read_bounded_text(&path, 1 << 20, "a job record")
            .map_err(|e| ReadmeError(e.to_string()))?;
        serde_json::from_str(&text).map_err(|e| ReadmeError(format!("{}: {e}", path.display())))
    };
    let row = |command: &str, what: &str, budget: u64, job: &MainJob| {
        let (overlapped, mut steps): (Vec<&Step>, Vec<&Step>) =
            job.steps.iter().partition(|s| s.during_build);
        steps.sort_by_key(|s| std::cmp::Reverse(s.seconds));
        let mut parts: Vec<String> = steps
            .iter()
            .take(2)
            .map(|s| format!("`{}` {} s", s.name, s.seconds))
            .collect();
        if steps.len() > 2 {
            let rest: u64 = steps[2..].iter().map(|s| s.seconds).sum();
            parts.push(format!("{} other steps {rest} s", steps.len() - 2));
        }
        if !overlapped.is_empty() {
            let during: u64 = overlapped.iter().map(|s| s.seconds).sum();
            parts.push(format!(
                "{} set-up steps {during} s during the build",
                overlapped.len()
            ));
        }
        vec![
            format!("`{command}`"),
            what.to_string(),
            format!(
                "{}, {}{}",
                job.date.split('T').next().unwrap_or(&job.date),
                job.cpu,
                match job.cargo_cache.as_deref() {
                    Some("empty") => ", empty cargo cache",
                    Some("warm") => ", crates already downloaded",
                    _ => "",
                }
            ),
            format!("**{}**", job.seconds),
            budget_verdict(job.seconds, budget, job.cargo_cache.as_deref()),
            parts.join("; "),
        ]
    };
    Ok(markdown(&[Block::Table(
        [
            "command",
            "what",
            "last recorded run",
            "seconds",
            "budget",
            "where the time went",
        ]
        .map(String::from)
        .to_vec(),
        vec![
            row(
                "scripts/test.sh",
                "the tests",
                TEST_BUDGET_S,
                &read(TEST_JOB)?,
            ),
            row(
                "scripts/run.sh",
                "the main job",
                MAIN_JOB_BUDGET_S,
                &read("main_job.json")?,
            ),
        ],
    )]))
}

/// Every region ID there is: `sources`' (the reports'), then the caller's `extra`, comma
/// separated.
pub fn known_regions(extra: &[Region], sources: &[RegionSource]) -> String {
    sources
        .iter()
        .map(|r| r.id)
        .chain(extra.iter().map(|r| r.id))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Generates the region `id` of `sources` from the reports under `reports`.
pub fn generate(id: &str, reports: &Path, sources: &[RegionSource]) -> Result<Region, ReadmeError> {
    let source = sources.iter().find(|r| r.id == id).ok_or_else(|| {
        ReadmeError(format!(
            "unknown generated region {id:?} (known: {})",
            known_regions(&[], sources)
        ))
    })?;
    Ok(Region {
        id: source.id,
        text: source.text(reports)?,
    })
}

/// `text` with every Markdown link to a relative target replaced by its label: a region is
/// quoted in files at different depths (the README, `docs/`, the book's chapters), where one
/// relative link cannot be right for all of them. Links with a scheme (`https://…`) stay.
fn without_relative_links(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(open) = rest.find('[') {
        out.push_str(&rest[..open]);
        let after = &rest[open + 1..];
        // `[label](target)` on one line, the label without brackets.
        let link = after.find("](").and_then(|close| {
            let label = &after[..close];
            let target_start = close + 2;
            let target_len = after[target_start..].find(')')?;
            let target = &after[target_start..target_start + target_len];
            let plain = |t: &str| !t.contains(['[', ']', '\n']);
            (plain(label) && plain(target) && !target.contains(' ')).then_some((
                label,
                target,
                target_start + target_len + 1,
            ))
        });
        match link {
            Some((label, target, len)) if !target.contains("://") => {
                out.push_str(label);
                rest = &after[len..];
            }
            _ => {
                out.push('[');
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// A region found in the README: its ID and the byte range of its content (between the
/// markers' lines).
struct Found {
    id: String,
    content: std::ops::Range<usize>,
}

fn find_regions(readme: &str) -> Result<Vec<Found>, ReadmeError> {
    let mut found = Vec::new();
    let mut at = 0;
    let line_of = |pos: usize| readme[..pos].lines().count() + 1;
    while let Some(start) = readme[at..].find(BEGIN).map(|p| p + at) {
        let id_end = readme[start..]
            .find(CLOSE)
            .map(|p| p + start)
            .ok_or_else(|| ReadmeError(format!("line {}: unclosed marker", line_of(start))))?;
        let id = readme[start + BEGIN.len()..id_end].trim().to_string();
        let content_start = readme[id_end..]
            .find('\n')
            .map(|p| p + id_end + 1)
            .unwrap_or(readme.len());
        let end_marker = format!("{END}{id}{CLOSE}");
        let end = readme[content_start..]
            .find(&end_marker)
            .map(|p| p + content_start)
            .ok_or_else(|| {
                ReadmeError(format!(
                    "line {}: region {id:?} has no `{end_marker}`",
                    line_of(start)
                ))
            })?;
        if let Some(nested) = readme[content_start..end].find(BEGIN) {
            return Err(ReadmeError(format!(
                "line {}: a region begins inside region {id:?}",
                line_of(content_start + nested)
            )));
        }
        if found.iter().any(|f: &Found| f.id == id) {
            return Err(ReadmeError(format!(
                "line {}: region {id:?} appears twice",
                line_of(start)
            )));
        }
        found.push(Found {
            id,
            content: content_start..end,
        });
        at = end + end_marker.len();
    }
    if let Some(stray) = readme[at..].find(END) {
        return Err(ReadmeError(format!(
            "line {}: an end marker without its beginning",
            line_of(at + stray)
        )));
    }
    Ok(found)
}

/// The text of region `id`: one of `extra` (regions made by the caller) if it has that ID,
/// else generated from the reports by its source.
fn region_text(
    id: &str,
    reports: &Path,
    extra: &[Region],
    sources: &[RegionSource],
) -> Result<String, ReadmeError> {
    match extra.iter().find(|r| r.id == id) {
        Some(r) => Ok(r.text.clone()),
        None => match sources.iter().find(|r| r.id == id) {
            Some(source) => source.text(reports),
            None => Err(ReadmeError(format!(
                "unknown generated region {id:?} (known: {})",
                known_regions(extra, sources)
            ))),
        },
    }
}

/// The README with every region of [`REGIONS`] replaced by its generated text.
pub fn fill(readme: &str, reports: &Path) -> Result<String, ReadmeError> {
    fill_with(readme, reports, &[], REGIONS)
}

/// [`fill`] with the regions of `sources` (the generic [`REGIONS`] and the experiments'),
/// and those of `extra` (made by the caller, e.g. from the CLI's argument parser) filled
/// from `extra`'s text.
pub fn fill_with(
    readme: &str,
    reports: &Path,
    extra: &[Region],
    sources: &[RegionSource],
) -> Result<String, ReadmeError> {
    let mut out = String::with_capacity(readme.len());
    let mut at = 0;
    for f in find_regions(readme)? {
        let text = region_text(&f.id, reports, extra, sources)?;
        out.push_str(&readme[at..f.content.start]);
        out.push_str(&text);
        at = f.content.end;
    }
    out.push_str(&readme[at..]);
    Ok(out)
}

/// The regions whose text differs from what the reports give, each with its first differing
/// line (README, then generated).
pub fn stale_regions(
    readme: &str,
    reports: &Path,
) -> Result<Vec<(String, String, String)>, ReadmeError> {
    stale_regions_with(readme, reports, &[], REGIONS)
}

/// [`stale_regions`], with the regions of `extra` compared against `extra`'s text.
pub fn stale_regions_with(
    readme: &str,
    reports: &Path,
    extra: &[Region],
    sources: &[RegionSource],
) -> Result<Vec<(String, String, String)>, ReadmeError> {
    let mut stale = Vec::new();
    for f in find_regions(readme)? {
        let generated = region_text(&f.id, reports, extra, sources)?;
        let current = &readme[f.content.clone()];
        if current != generated {
            let (have, want) = current
                .lines()
                .map(Some)
                .chain(std::iter::repeat(None))
                .zip(generated.lines().map(Some).chain(std::iter::repeat(None)))
                .take_while(|(a, b)| a.is_some() || b.is_some())
                .find(|(a, b)| a != b)
                .unwrap_or((None, None));
            stale.push((
                f.id.clone(),
                have.unwrap_or("(nothing)").to_string(),
                want.unwrap_or("(nothing)").to_string(),
            ));
        }
    }
    Ok(stale)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn main_job(dir: &Path, seconds: u64) {
        std::fs::write(
            dir.join("main_job.json"),
            format!(
                r#"{{"date":"2026-11-22T10:00:00Z","cpu":"a test CPU","seconds":{seconds},
                   "steps":[{{"name":"cargo build","seconds":{seconds},"peak_kb":2048}}]}}"#
            ),
        )
        .unwrap();
    }

    #[test]
    fn regions_are_filled_and_the_rest_is_kept() {
        let dir = tempfile::tempdir().unwrap();
        main_job(dir.path(), 300);
        let readme = "# Title\n\nBefore.\n<!-- generated: main-job -->\nstale text\n<!-- end generated: main-job -->\nAfter.\n";
        let filled = fill(readme, dir.path()).unwrap();
        assert!(filled.starts_with("# Title\n\nBefore.\n<!-- generated: main-job -->\n"));
        assert!(filled.ends_with("<!-- end generated: main-job -->\nAfter.\n"));
        assert!(filled.contains("took 300 s") && filled.contains("| `cargo build` | 300 | 2 |"));
        assert!(!filled.contains("stale text"));
        // Filled, it is up to date; a changed report makes it stale, naming the line.
        assert!(stale_regions(&filled, dir.path()).unwrap().is_empty());
        assert_eq!(fill(&filled, dir.path()).unwrap(), filled, "idempotent");
        main_job(dir.path(), 301);
        let stale = stale_regions(&filled, dir.path()).unwrap();
        assert_eq!(stale.len(), 1);
        assert_eq!(stale[0].0, "main-job");
        assert!(stale[0].1.contains("took 300 s") && stale[0].2.contains("took 301 s"));
    }

    #[test]
    fn malformed_regions_are_refused_with_their_line() {
        let dir = tempfile::tempdir().unwrap();
        main_job(dir.path(), 1);
        let err = |text: &str| fill(text, dir.path()).unwrap_err().0;
        assert!(
            err("a\n<!-- generated: main-job -->\nx\n")
                .contains("line 2: region \"main-job\" has no")
        );
        assert!(
            err("<!-- generated: nonsense -->\n<!-- end generated: nonsense -->\n")
                .contains("unknown generated region \"nonsense\"")
        );
        assert!(err("<!-- generated: main-job -->\n<!-- generated: job-costs -->\n<!-- end generated: main-job -->\n").contains("begins inside"));
        assert!(
            err("x\n<!-- end generated: main-job -->\n").contains("line 2: an end marker without")
        );
        let twice = "<!-- generated: main-job -->\n<!-- end generated: main-job -->\n";
        assert!(err(&twice.repeat(2)).contains("appears twice"));
        // A region whose report is missing names the file.
        assert!(
            err("<!-- generated: job-costs -->\n<!-- end generated: job-costs -->\n")
                .contains("tests/test_timing.json")
        );
    }

    #[test]
    fn relative_links_become_their_labels() {
        let text = "report: [`reports/m/report.md`](reports/m/report.md), \
                    [site](https://example.org/a) [x] [a](b c) [[n]](t) end\n";
        assert_eq!(
            without_relative_links(text),
            "report: `reports/m/report.md`, [site](https://example.org/a) [x] [a](b c) [[n]](t) end\n"
        );
    }

    #[test]
    fn regions_made_by_the_caller_are_filled_and_checked() {
        let dir = tempfile::tempdir().unwrap();
        main_job(dir.path(), 5);
        let extra = [Region {
            id: "cli",
            text: "usage\n".into(),
        }];
        let text = "<!-- generated: cli -->\nold\n<!-- end generated: cli -->\n\
                    <!-- generated: main-job -->\n<!-- end generated: main-job -->\n";
        let filled = fill_with(text, dir.path(), &extra, REGIONS).unwrap();
        assert!(
            filled.starts_with("<!-- generated: cli -->\nusage\n<!-- end generated: cli -->\n")
        );
        assert!(filled.contains("took 5 s"));
        assert!(
            stale_regions_with(&filled, dir.path(), &extra, REGIONS)
                .unwrap()
                .is_empty()
        );
        let stale = stale_regions_with(text, dir.path(), &extra, REGIONS).unwrap();
        assert_eq!(stale[0], ("cli".into(), "old".into(), "usage".into()));
        // Without the caller's region the ID is unknown; with it, the message lists it.
        assert!(
            fill(text, dir.path())
                .unwrap_err()
                .0
                .contains("unknown generated region \"cli\"")
        );
        let other = "<!-- generated: nonsense -->\n<!-- end generated: nonsense -->\n";
        assert!(
            fill_with(other, dir.path(), &extra, REGIONS)
                .unwrap_err()
                .0
                .contains(", cli)")
        );
    }

    /// The job-costs region of a reports folder holding a main job of 300 s and a test job
    /// of `seconds` with these `steps` (a JSON array).
    fn job_costs_of(seconds: u64, steps: &str) -> String {
        let dir = tempfile::tempdir().unwrap();
        main_job(dir.path(), 300);
        std::fs::create_dir(dir.path().join("tests")).unwrap();
        std::fs::write(
            dir.path().join(TEST_JOB),
            format!(
                r#"{{"date":"2026-11-23T10:00:00Z","cpu":"a test CPU","cargo_cache":"empty",
                    "seconds":{seconds},"steps":{steps}}}"#
            ),
        )
        .unwrap();
        generate("job-costs", dir.path(), REGIONS).unwrap().text
    }

    #[test]
    fn job_costs_name_both_commands_and_their_longest_steps() {
        let text = job_costs_of(
            60,
            r#"[{"name":"a","seconds":5},{"name":"build","seconds":40},
                {"name":"b","seconds":3},{"name":"tests","seconds":12}]"#,
        );
        assert!(text.contains(
            "| `scripts/test.sh` | the tests | 2026-11-23, a test CPU, empty cargo cache | **60** | 600 s: within, 540 s to spare | `build` 40 s; `tests` 12 s; 2 other steps 8 s |"
        ), "{text}");
        // A run without an empty cargo cache is not held to the budget.
        assert!(text.contains("| `scripts/run.sh` | the main job | 2026-11-22, a test CPU | **300** | 900 s: not comparable (cargo cache not empty) | `cargo build` 300 s |"), "{text}");
        // A run over its budget says by how much; one at it is within.
        assert!(job_costs_of(790, "[]").contains("| **790** | 600 s: **over by 190 s** |"));
        assert!(job_costs_of(600, "[]").contains("| **600** | 600 s: within, 0 s to spare |"));
    }

    /// Steps run during the build are named apart and never counted among the longest or
    /// added to the rest: their seconds overlap the build's.
    #[test]
    fn set_up_steps_during_the_build_are_summed_apart() {
        let text = job_costs_of(
            55,
            r#"[{"name":"a","seconds":1},{"name":"build","seconds":40},
                {"name":"npm","seconds":30,"during_build":true},
                {"name":"pip","seconds":9,"during_build":true},
                {"name":"b","seconds":2},{"name":"tests","seconds":12}]"#,
        );
        assert!(text.contains(
            "| **55** | 600 s: within, 545 s to spare | `build` 40 s; `tests` 12 s; 2 other steps 3 s; 2 set-up steps 39 s during the build |"
        ), "{text}");
    }
}
