//! The figures the README, the book and the docs quote, generated from the committed reports.
//!
//! A region of `README.md`, `docs/methods.md` or a chapter of the book (`docs/book/src/*.md`)
//! between `<!-- generated: ID -->` and `<!-- end generated: ID -->` is written by [`fill`]
//! from the report folder its ID names (its `results.jsonl` and `sweep.json`), with the same
//! sentences and tables the report itself prints — so the prose cannot drift from the
//! numbers. Regions made elsewhere (the command-line reference, which the CLI crate renders
//! from its argument parser) are passed in by the caller ([`fill_with`],
//! [`stale_regions_with`]). `mirrorbox readme` rewrites the regions; `mirrorbox readme
//! --check` (run by the tests) fails when a region differs from what the reports give.
//! Everything outside the regions is left alone, byte for byte.

use crate::document::{Block, markdown, ms_cell};
use crate::folder::{Sweep, load_sweep};
use crate::write::{depth_scaling, floor_paragraph, row_cell, symmetry_section, table1_section};
use crate::{stats, table1};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

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

/// Every region ID the generator knows, with the report folder (under `reports/`) it is made
/// from and what it holds.
pub const REGIONS: &[(&str, &str, &str)] = &[
    (
        "table1",
        "table1",
        "the reproduction of Table 1, the exact methods beside it, the floor",
    ),
    (
        "table1-summary",
        "table1",
        "Table 1's methods at one glance: ms/frame, passes, reflections and error of each point",
    ),
    (
        "table1-repeat",
        "table1_repeat",
        "Table 1's rows from two consecutive runs side by side",
    ),
    (
        "depth-scaling",
        "depth_scaling",
        "the exact methods' cost per bounce",
    ),
    (
        "depth-scaling-table",
        "depth_scaling",
        "the exact methods' cost against depth, every point, and per bounce",
    ),
    (
        "symmetry-scaling",
        "symmetry_scaling",
        "the symmetry methods against p: every point, the crossover, the pruning",
    ),
    (
        "lighting",
        "lighting",
        "shadows and mirrored lights on the lit mirror box: each lighting variant's error and cost",
    ),
    (
        "lighting-room",
        "lighting_room",
        "the same on the lit mirror room",
    ),
    (
        "uneven-mirrors",
        "uneven_mirrors",
        "uneven mirrors on the rippled box: every trick's error against the tilt, and its cost",
    ),
    (
        "uneven-mirrors-single",
        "uneven_mirrors_single",
        "the same on the hammered single mirror",
    ),
    (
        "stereo",
        "stereo",
        "stereo mirrors: the pair's cost against mono, per-eye against shared, and the disparity check",
    ),
    (
        "viewer-frame-rates",
        "viewer/frame_rates.md",
        "`mirrorbox view`'s frame rates per method, still and walking (scripts/viewer-frame-rates.sh)",
    ),
    (
        "tracer-bench",
        "tracer/bench.md",
        "the tracer against Mitsuba 3 side by side (scripts/bench-tracer.sh)",
    ),
    (
        "tracer-bench-summary",
        "tracer/bench.md",
        "the tracer against Mitsuba 3: one row per CPU kind measured, with the goals",
    ),
    (
        "motion",
        "motion",
        "error over time: feedback, cubemap, auxiliary and an exact method, still and walking (mirrorbox motion)",
    ),
    (
        "lighting-trace-cost",
        "lighting/trace_cost.jsonl",
        "the tracer's time against the mirrored-light depth k on both lit scenes",
    ),
    (
        "gpu-table1",
        "gpu/table1",
        "Table 1 and the exact methods beside it, measured on a GPU",
    ),
    (
        "gpu-column",
        "gpu/table1",
        "Table 1's points on lavapipe (reports/table1) and on a GPU side by side",
    ),
    (
        "gpu-depth-scaling",
        "gpu/depth_scaling",
        "the exact methods' cost per bounce, measured on a GPU",
    ),
    (
        "gpu-room",
        "gpu/room_1080p.jsonl",
        "the mirror room at 1920×1080 against depth on a GPU: where real time ends",
    ),
    (
        "gpu-trace-threads",
        "gpu/trace_threads.jsonl",
        "the tracer against its thread count on the GPU machine's CPU",
    ),
    (
        "main-job",
        "main_job.json",
        "the main job's steps: time and peak memory",
    ),
    (
        "job-costs",
        "main_job.json",
        "what the two commands cost: the last recorded scripts/test.sh and scripts/run.sh",
    ),
];

/// "Measured DATE on DEVICE: adapter …, `COMMAND`." The date is the latest run that measured
/// a record (the report's own date is when it was last written, perhaps by a resume).
fn measured_on(s: &Sweep) -> String {
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
fn prose(blocks: Vec<Block>) -> Vec<Block> {
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

fn table1_region(s: &Sweep) -> Result<String, ReadmeError> {
    let mut blocks = vec![Block::Paragraph(measured_on(s))];
    let section = prose(table1_section(&s.info, &s.records));
    if section.is_empty() {
        return Err(ReadmeError(format!(
            "{}: not the paper's experiment (every n of Table 1 on {}), nothing to quote",
            s.info.scene,
            table1::PAPER_SCENE
        )));
    }
    blocks.extend(section);
    if let Some(fl) = s.records.iter().find(|r| r.kind == "floor") {
        blocks.push(floor_paragraph(fl));
    }
    Ok(markdown(&blocks))
}

/// The short form of [`table1_region`]: the device, the table of every method's point (the
/// paper's auxiliary n = 0…4 and the exact methods) and the floor.
fn table1_summary_region(s: &Sweep) -> Result<String, ReadmeError> {
    let table = prose(table1_section(&s.info, &s.records))
        .into_iter()
        .rfind(|b| matches!(b, Block::Table(..)))
        .ok_or_else(|| {
            ReadmeError(format!(
                "{}: not the paper's experiment (every n of Table 1 on {}), nothing to quote",
                s.info.scene,
                table1::PAPER_SCENE
            ))
        })?;
    let mut blocks = vec![Block::Paragraph(measured_on(s)), table];
    if let Some(fl) = s.records.iter().find(|r| r.kind == "floor") {
        blocks.push(floor_paragraph(fl));
    }
    Ok(markdown(&blocks))
}

/// The depth-scaling section's cost per bounce (and with `table`, every point).
fn depth_scaling_region(s: &Sweep, table: bool) -> Result<String, ReadmeError> {
    let floor = s.records.iter().find(|r| r.kind == "floor");
    let section = prose(depth_scaling(&s.info, &s.records, floor));
    let bullets: Vec<Block> = section
        .into_iter()
        .filter(|b| table || matches!(b, Block::Bullets(_)))
        .collect();
    if bullets.is_empty() {
        return Err(ReadmeError(format!(
            "{}: no exact method swept over depth, nothing to quote",
            s.info.scene
        )));
    }
    let mut blocks = vec![Block::Paragraph(measured_on(s))];
    blocks.extend(bullets);
    Ok(markdown(&blocks))
}

fn symmetry_region(s: &Sweep) -> Result<String, ReadmeError> {
    let section = prose(symmetry_section(&s.records));
    if section.is_empty() {
        return Err(ReadmeError(format!(
            "{}: no symmetry-planes sweep, nothing to quote",
            s.info.scene
        )));
    }
    let mut blocks = vec![Block::Paragraph(measured_on(s))];
    blocks.extend(section);
    Ok(markdown(&blocks))
}

fn lighting_region(s: &Sweep) -> Result<String, ReadmeError> {
    let sentences = crate::lighting::sentences(&s.records);
    if sentences.is_empty() {
        return Err(ReadmeError(format!(
            "{}: no mirrored-lights sweep, nothing to quote",
            s.info.scene
        )));
    }
    Ok(markdown(&[
        Block::Paragraph(measured_on(s)),
        Block::Bullets(sentences),
    ]))
}

fn uneven_region(s: &Sweep) -> Result<String, ReadmeError> {
    let sentences = crate::uneven::sentences(&s.records, &s.info.bump_methods);
    if sentences.is_empty() {
        return Err(ReadmeError(format!(
            "{}: no bump-amplitude sweep, nothing to quote",
            s.info.scene
        )));
    }
    Ok(markdown(&[
        Block::Paragraph(measured_on(s)),
        crate::uneven::table(&s.records, &s.info.bump_methods, false),
        Block::Bullets(sentences),
    ]))
}

fn stereo_region(s: &Sweep) -> Result<String, ReadmeError> {
    let sentences = crate::stereo::sentences(&s.records);
    if sentences.is_empty() {
        return Err(ReadmeError(format!(
            "{}: no stereo sweep measuring per-eye and shared, nothing to quote",
            s.info.scene
        )));
    }
    Ok(markdown(&[
        Block::Paragraph(measured_on(s)),
        crate::stereo::cost_table(&s.records),
        crate::stereo::error_table(&s.records),
        crate::stereo::disparity_table(&s.records),
        Block::Bullets(sentences),
    ]))
}

/// One `trace --json` run of `scripts/lighting-trace-cost.sh`.
#[derive(serde::Deserialize)]
struct TraceRun {
    scene: String,
    mirrored_lights: u32,
    render_seconds: f64,
    rays: u64,
    threads: usize,
    lighting: TraceLighting,
}

#[derive(serde::Deserialize)]
struct TraceLighting {
    light_images: usize,
}

/// The tracer's median time per scene and k, with the light images and rays behind it.
/// A Markdown report written whole by a script: its text after the title line.
fn report_body_region(path: &Path) -> Result<String, ReadmeError> {
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
fn report_summary_region(path: &Path) -> Result<String, ReadmeError> {
    let body = report_body_region(path)?;
    let summary = body
        .lines()
        .take_while(|l| !l.starts_with("## "))
        .collect::<Vec<_>>()
        .join("\n");
    Ok(format!("{}\n", summary.trim_end()))
}

fn trace_cost_region(path: &Path) -> Result<String, ReadmeError> {
    let runs: Vec<TraceRun> = crate::runs::read_lines(path)?;
    let mut groups: Vec<(String, u32)> = Vec::new();
    for r in &runs {
        let g = (r.scene.clone(), r.mirrored_lights);
        if !groups.contains(&g) {
            groups.push(g);
        }
    }
    groups.sort();
    let rows = groups
        .iter()
        .map(|(scene, k)| {
            let of: Vec<&TraceRun> = runs
                .iter()
                .filter(|r| &r.scene == scene && r.mirrored_lights == *k)
                .collect();
            let mut secs: Vec<f64> = of.iter().map(|r| r.render_seconds).collect();
            secs.sort_by(f64::total_cmp);
            let (lo, hi) = (secs[0], secs[secs.len() - 1]);
            vec![
                format!("`{scene}`"),
                k.to_string(),
                of[0].lighting.light_images.to_string(),
                format!("{:.2} [{lo:.2}–{hi:.2}]", stats::median(&secs)),
                format!("{:.1}", of[0].rays as f64 / 1e6),
                of.len().to_string(),
            ]
        })
        .collect();
    let threads = runs.first().map_or(0, |r| r.threads);
    Ok(markdown(&[
        Block::Paragraph(format!(
            "`scripts/lighting-trace-cost.sh`: `mirrorbox trace --mirrored-lights k --spp 1` at \
             640×360 with shadows, {threads} threads, runs interleaved."
        )),
        Block::Table(
            [
                "scene",
                "k",
                "light images",
                "trace s, median [min–max]",
                "Mrays (shadow legs included)",
                "runs",
            ]
            .map(String::from)
            .to_vec(),
            rows,
        ),
    ]))
}

/// The points two sweeps of one configuration share, measured on two devices, side by side:
/// each one's ms/frame and FLIP, and how many times faster the second device is. Times compare
/// only as ratios of medians here (the devices ran at different times); errors should agree up
/// to each device's floor, which the last row shows.
fn device_column_region(first: &Sweep, second: &Sweep) -> Result<String, ReadmeError> {
    let device = |s: &Sweep| s.info.adapter.clone();
    let mut rows = Vec::new();
    for a in &first.records {
        let Some(b) = second
            .records
            .iter()
            .find(|b| b.key == a.key && b.kind == a.kind)
        else {
            continue;
        };
        let name = if a.kind == "floor" {
            "floor (no mirrors)".to_string()
        } else {
            crate::document::label(a)
        };
        rows.push(vec![
            name,
            format!("{}", a.alpha),
            ms_cell(a, 1),
            ms_cell(b, 1),
            format!("{:.0}×", a.ms_median / b.ms_median),
            crate::document::sci(a.metrics.flip_mean),
            crate::document::sci(b.metrics.flip_mean),
        ]);
    }
    if rows.is_empty() {
        return Err(ReadmeError(format!(
            "{} and {}: no point in common",
            first.info.command, second.info.command
        )));
    }
    Ok(markdown(&[
        Block::Paragraph(format!(
            "First: {} Second: {}",
            measured_on(first),
            measured_on(second)
        )),
        Block::Table(
            vec![
                "point".into(),
                "α".into(),
                format!("{} ms/frame [95 % CI]", device(first)),
                format!("{} ms/frame [95 % CI]", device(second)),
                "ratio of medians".into(),
                format!("FLIP {}", device(first)),
                format!("FLIP {}", device(second)),
            ],
            rows,
        ),
    ]))
}

/// Table 1's rows of two runs side by side: whether each row's intervals overlap, and whether
/// each run's times keep the order of the pass counts.
fn repeat_region(first: &Sweep, second: &Sweep) -> Result<String, ReadmeError> {
    let (alpha_a, a) = table1::rows(&first.records);
    let (alpha_b, b) = table1::rows(&second.records);
    if a.len() != table1::PAPER_MS.len() || b.len() != a.len() || alpha_a != alpha_b {
        return Err(ReadmeError(
            "reports/table1 and reports/table1_repeat do not both hold Table 1's rows at one α"
                .into(),
        ));
    }
    let interval = |r: &table1::Row| stats::median_interval(&r.frames_ms);
    let mut rows = Vec::new();
    let mut overlapping = 0;
    for (ra, rb) in a.iter().zip(&b) {
        let overlap = match (interval(ra), interval(rb)) {
            (Some(x), Some(y)) if x.overlaps(&y) => {
                overlapping += 1;
                "yes"
            }
            (Some(_), Some(_)) => "no",
            _ => "–",
        };
        rows.push(vec![
            ra.n.to_string(),
            ra.passes.to_string(),
            row_cell(ra),
            row_cell(rb),
            overlap.to_string(),
        ]);
    }
    // Rows are in n order, and the pass count grows with n.
    let ordered = |rows: &[table1::Row]| rows.windows(2).all(|w| w[0].ms_median < w[1].ms_median);
    let order = |ok: bool| {
        if ok {
            "keeps the order of the pass counts"
        } else {
            "does NOT keep the order of the pass counts"
        }
    };
    let mut text = String::new();
    let _ = write!(
        text,
        "First run: {} Second run: {} α = {}.",
        measured_on(first),
        measured_on(second),
        alpha_a.unwrap_or(f32::NAN)
    );
    let blocks = vec![
        Block::Paragraph(text),
        Block::Table(
            [
                "n",
                "passes",
                "first run ms/frame [95 % CI]",
                "second run ms/frame [95 % CI]",
                "intervals overlap",
            ]
            .map(String::from)
            .to_vec(),
            rows,
        ),
        Block::Paragraph(format!(
            "The intervals overlap on {overlapping} of {} rows; the first run {}, the second {}.",
            a.len(),
            order(ordered(&a)),
            order(ordered(&b))
        )),
    ];
    Ok(markdown(&blocks))
}

/// One step of the main job, as `scripts/run.sh` records it in `reports/main_job.json`.
#[derive(serde::Deserialize)]
struct Step {
    name: String,
    seconds: u64,
    peak_kb: Option<u64>,
}

#[derive(serde::Deserialize)]
struct MainJob {
    date: String,
    cpu: String,
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

/// One line per command: its last recorded run's total, date and machine, and its two
/// longest steps (the rest summed), read from `main_job.json` and `tests/test_timing.json`.
fn job_costs_region(reports: &Path) -> Result<String, ReadmeError> {
    let read = |name: &str| -> Result<MainJob, ReadmeError> {
        let path = reports.join(name);
        let text = mirrorbox_files::read_bounded_text(&path, 1 << 20, "a job record")
            .map_err(|e| ReadmeError(e.to_string()))?;
        serde_json::from_str(&text).map_err(|e| ReadmeError(format!("{}: {e}", path.display())))
    };
    let row = |command: &str, what: &str, job: &MainJob| {
        let mut steps: Vec<&Step> = job.steps.iter().collect();
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
        vec![
            format!("`{command}`"),
            what.to_string(),
            format!(
                "{}, {}",
                job.date.split('T').next().unwrap_or(&job.date),
                job.cpu
            ),
            format!("**{}**", job.seconds),
            parts.join("; "),
        ]
    };
    Ok(markdown(&[Block::Table(
        [
            "command",
            "what",
            "last recorded run",
            "seconds",
            "where the time went",
        ]
        .map(String::from)
        .to_vec(),
        vec![
            row("scripts/test.sh", "the tests", &read(TEST_JOB)?),
            row("scripts/run.sh", "the main job", &read("main_job.json")?),
        ],
    )]))
}

/// Every region ID there is: the reports' ([`REGIONS`]), then the caller's `extra`, comma
/// separated.
pub fn known_regions(extra: &[Region]) -> String {
    REGIONS
        .iter()
        .map(|r| r.0)
        .chain(extra.iter().map(|r| r.id))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Generates the region `id` from the reports under `reports`.
pub fn generate(id: &str, reports: &Path) -> Result<Region, ReadmeError> {
    let (id, source, _) = REGIONS
        .iter()
        .find(|(name, _, _)| *name == id)
        .ok_or_else(|| {
            ReadmeError(format!(
                "unknown generated region {id:?} (known: {})",
                REGIONS.iter().map(|r| r.0).collect::<Vec<_>>().join(", ")
            ))
        })?;
    let folder = |name: &str| -> PathBuf { reports.join(name) };
    let text = match *id {
        "table1" | "gpu-table1" => table1_region(&load_sweep(&folder(source))?)?,
        "table1-summary" => table1_summary_region(&load_sweep(&folder(source))?)?,
        "job-costs" => job_costs_region(reports)?,
        "table1-repeat" => repeat_region(
            &load_sweep(&folder("table1"))?,
            &load_sweep(&folder(source))?,
        )?,
        "depth-scaling" | "gpu-depth-scaling" => {
            depth_scaling_region(&load_sweep(&folder(source))?, false)?
        }
        "depth-scaling-table" => depth_scaling_region(&load_sweep(&folder(source))?, true)?,
        "symmetry-scaling" => symmetry_region(&load_sweep(&folder(source))?)?,
        "lighting" | "lighting-room" => lighting_region(&load_sweep(&folder(source))?)?,
        "lighting-trace-cost" => trace_cost_region(&folder(source))?,
        "uneven-mirrors" | "uneven-mirrors-single" => uneven_region(&load_sweep(&folder(source))?)?,
        "stereo" => stereo_region(&load_sweep(&folder(source))?)?,
        "gpu-column" => device_column_region(
            &load_sweep(&folder("table1"))?,
            &load_sweep(&folder(source))?,
        )?,
        "gpu-room" => crate::runs::room_region(&folder(source))?,
        "gpu-trace-threads" => {
            let cpu_file = folder("gpu/cpu.txt");
            let cpu = mirrorbox_files::read_bounded_text(&cpu_file, 4096, "a CPU name")
                .map_err(|e| ReadmeError(e.to_string()))?;
            crate::runs::threads_region(&folder(source), cpu.trim())?
        }
        "main-job" => main_job_region(&folder(source))?,
        "motion" => {
            let (info, records) =
                crate::motion::read_motion(&folder(source)).map_err(ReadmeError)?;
            crate::motion::readme_region(&info, &records)
        }
        "viewer-frame-rates" | "tracer-bench" => report_body_region(&folder(source))?,
        "tracer-bench-summary" => report_summary_region(&folder(source))?,
        _ => unreachable!("every ID in REGIONS has a generator"),
    };
    Ok(Region {
        id,
        text: without_relative_links(&text),
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
/// else generated from the reports.
fn region_text(id: &str, reports: &Path, extra: &[Region]) -> Result<String, ReadmeError> {
    match extra.iter().find(|r| r.id == id) {
        Some(r) => Ok(r.text.clone()),
        None if extra.is_empty() || REGIONS.iter().any(|r| r.0 == id) => {
            generate(id, reports).map(|r| r.text)
        }
        None => Err(ReadmeError(format!(
            "unknown generated region {id:?} (known: {})",
            known_regions(extra)
        ))),
    }
}

/// The README with every region replaced by its generated text.
pub fn fill(readme: &str, reports: &Path) -> Result<String, ReadmeError> {
    fill_with(readme, reports, &[])
}

/// [`fill`], with the regions of `extra` (made by the caller, e.g. from the CLI's argument
/// parser) filled from `extra` instead of the reports.
pub fn fill_with(readme: &str, reports: &Path, extra: &[Region]) -> Result<String, ReadmeError> {
    let mut out = String::with_capacity(readme.len());
    let mut at = 0;
    for f in find_regions(readme)? {
        let text = region_text(&f.id, reports, extra)?;
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
    stale_regions_with(readme, reports, &[])
}

/// [`stale_regions`], with the regions of `extra` compared against `extra`'s text.
pub fn stale_regions_with(
    readme: &str,
    reports: &Path,
    extra: &[Region],
) -> Result<Vec<(String, String, String)>, ReadmeError> {
    let mut stale = Vec::new();
    for f in find_regions(readme)? {
        let generated = region_text(&f.id, reports, extra)?;
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
        assert!(err("<!-- generated: main-job -->\n<!-- generated: table1 -->\n<!-- end generated: main-job -->\n").contains("begins inside"));
        assert!(
            err("x\n<!-- end generated: main-job -->\n").contains("line 2: an end marker without")
        );
        let twice = "<!-- generated: main-job -->\n<!-- end generated: main-job -->\n";
        assert!(err(&twice.repeat(2)).contains("appears twice"));
        // A region whose report is missing names the file.
        assert!(
            err("<!-- generated: table1 -->\n<!-- end generated: table1 -->\n")
                .contains("table1/sweep.json")
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
        let filled = fill_with(text, dir.path(), &extra).unwrap();
        assert!(
            filled.starts_with("<!-- generated: cli -->\nusage\n<!-- end generated: cli -->\n")
        );
        assert!(filled.contains("took 5 s"));
        assert!(
            stale_regions_with(&filled, dir.path(), &extra)
                .unwrap()
                .is_empty()
        );
        let stale = stale_regions_with(text, dir.path(), &extra).unwrap();
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
            fill_with(other, dir.path(), &extra)
                .unwrap_err()
                .0
                .contains(", cli)")
        );
    }

    #[test]
    fn job_costs_name_both_commands_and_their_longest_steps() {
        let dir = tempfile::tempdir().unwrap();
        main_job(dir.path(), 300);
        std::fs::create_dir(dir.path().join("tests")).unwrap();
        std::fs::write(
            dir.path().join(TEST_JOB),
            r#"{"date":"2026-11-23T10:00:00Z","cpu":"a test CPU","seconds":60,
               "steps":[{"name":"a","seconds":5},{"name":"build","seconds":40},
                        {"name":"b","seconds":3},{"name":"tests","seconds":12}]}"#,
        )
        .unwrap();
        let text = generate("job-costs", dir.path()).unwrap().text;
        assert!(text.contains(
            "| `scripts/test.sh` | the tests | 2026-11-23, a test CPU | **60** | `build` 40 s; `tests` 12 s; 2 other steps 8 s |"
        ), "{text}");
        assert!(text.contains("| `scripts/run.sh` | the main job | 2026-11-22, a test CPU | **300** | `cargo build` 300 s |"), "{text}");
    }
}
