//! One-off measurements kept as JSON lines (one `render --json` or `trace --json` object per
//! run, a `round` field added by the script that ran them), turned into README tables: the
//! mirror room at 1920×1080 against depth, and the tracer against its thread count
//! (`scripts/gpu-measure.sh`, steps `room` and `trace`).

use mirrorbox_report::document::{Block, markdown, ms};
use mirrorbox_report::readme::{ReadmeError, RegionSource, read_lines};
use mirrorbox_report::stats;
use std::collections::BTreeMap;
use std::path::Path;

/// A frame budget of 60 Hz, the usual line between real-time and not.
pub const REAL_TIME_MS: f64 = 1000.0 / 60.0;

/// One `render --json` run of the room step, or the refusal the script wrote in its place.
#[derive(serde::Deserialize)]
struct RenderRun {
    method: String,
    depth: u32,
    #[serde(default)]
    refused: Option<String>,
    #[serde(default)]
    frames_ms: Vec<f64>,
    #[serde(default)]
    triangles: u64,
    #[serde(default)]
    draws: u64,
    #[serde(default)]
    paths: Option<Paths>,
    #[serde(default)]
    adapter: String,
    #[serde(default)]
    backend: String,
    #[serde(default)]
    width: u32,
    #[serde(default)]
    height: u32,
    #[serde(default)]
    scene: String,
}

#[derive(serde::Deserialize)]
struct Paths {
    kept: u64,
}

/// Where real time ends for one method: the deepest depth within the budget and its ms, then
/// the first depth beyond it and what it took ("N ms" or "refused").
#[derive(Default)]
struct RealTimeEnd {
    within: Option<(u32, f64)>,
    beyond: Option<(u32, String)>,
}

/// The room at 1920×1080: per method and depth, the median frame over every round with its
/// 95 % interval, the paths and triangles drawn, or why the frame was refused; then where
/// real time ([`REAL_TIME_MS`]) ends for each method.
pub fn room_region(path: &Path) -> Result<String, ReadmeError> {
    let runs: Vec<RenderRun> = read_lines(path)?;
    let mut groups: BTreeMap<(String, u32), Vec<&RenderRun>> = BTreeMap::new();
    for r in &runs {
        groups
            .entry((r.method.clone(), r.depth))
            .or_default()
            .push(r);
    }
    let measured = runs
        .iter()
        .find(|r| r.refused.is_none())
        .ok_or_else(|| ReadmeError(format!("{}: every run was refused", path.display())))?;
    let mut rows = Vec::new();
    let mut ends: BTreeMap<&str, RealTimeEnd> = BTreeMap::new();
    for ((method, depth), of) in &groups {
        let end = ends.entry(method.as_str()).or_default();
        let done: Vec<&&RenderRun> = of.iter().filter(|r| r.refused.is_none()).collect();
        if done.is_empty() {
            let why = of[0].refused.as_deref().unwrap_or_default();
            let why = why.trim().trim_start_matches("error: ");
            let why = why.split(':').next().unwrap_or(why);
            rows.push(vec![
                method.clone(),
                depth.to_string(),
                "–".into(),
                "–".into(),
                "–".into(),
                format!("refused ({} runs): {why}", of.len()),
            ]);
            if end.beyond.is_none() {
                end.beyond = Some((*depth, "refused".into()));
            }
            continue;
        }
        let frames: Vec<f64> = done.iter().flat_map(|r| r.frames_ms.clone()).collect();
        let median = stats::median(&frames);
        let cell = match stats::median_interval(&frames) {
            Some(i) => format!("{} [{}–{}]", ms(median, 2), ms(i.low, 2), ms(i.high, 2)),
            None => ms(median, 2),
        };
        if median <= REAL_TIME_MS && end.beyond.is_none() {
            end.within = Some((*depth, median));
        } else if end.beyond.is_none() {
            end.beyond = Some((*depth, format!("{} ms", ms(median, 2))));
        }
        rows.push(vec![
            method.clone(),
            depth.to_string(),
            done[0]
                .paths
                .as_ref()
                .map_or("–".into(), |p| p.kept.to_string()),
            triangles(done[0].triangles),
            done[0].draws.to_string(),
            format!("{cell} ({} frames)", frames.len()),
        ]);
    }
    rows.sort_by_key(|r| (r[0].clone(), r[1].parse::<u32>().unwrap_or(0)));
    let bullets = ends
        .iter()
        .map(|(method, RealTimeEnd { within, beyond })| {
            let within = within.map_or("no depth".into(), |(d, m)| {
                format!("depth {d} ({} ms)", ms(m, 2))
            });
            let beyond = beyond
                .as_ref()
                .map_or("every depth measured fits".into(), |(d, what)| {
                    format!("depth {d} ({what})")
                });
            format!(
                "{method}: real time ({} ms/frame) holds up to {within}; the next depth measured, \
                 {beyond}, does not.",
                ms(REAL_TIME_MS, 2)
            )
        })
        .collect();
    Ok(markdown(&[
        Block::Paragraph(format!(
            "`{}` at {}×{} on adapter {} ({}): `render --json --frames 5 --warmup 2`, every \
             method and depth once per round, rounds in a shuffled order, GPU timestamps; the \
             median over every round's frames with its 95 % bootstrap interval. CPU planning \
             time is not in these figures.",
            measured.scene, measured.width, measured.height, measured.adapter, measured.backend
        )),
        Block::Table(
            [
                "method",
                "depth",
                "paths kept",
                "triangles",
                "draws",
                "ms/frame median [95 % CI]",
            ]
            .map(String::from)
            .to_vec(),
            rows,
        ),
        Block::Bullets(bullets),
    ]))
}

/// A triangle count: in full below a million, in millions above.
fn triangles(n: u64) -> String {
    if n < 1_000_000 {
        n.to_string()
    } else {
        format!("{:.2} M", n as f64 / 1e6)
    }
}

/// One `trace --json` run of the thread-count step.
#[derive(serde::Deserialize)]
struct TraceRun {
    threads: usize,
    render_seconds: f64,
    rays: u64,
    scene: String,
    width: u32,
    height: u32,
    spp: u32,
}

/// The tracer against its thread count: median render seconds with [min–max] over rounds,
/// the speed-up over one thread and the parallel efficiency (speed-up / threads).
pub fn threads_region(path: &Path, cpu: &str) -> Result<String, ReadmeError> {
    let runs: Vec<TraceRun> = read_lines(path)?;
    let mut groups: BTreeMap<usize, Vec<&TraceRun>> = BTreeMap::new();
    for r in &runs {
        groups.entry(r.threads).or_default().push(r);
    }
    let median_of =
        |of: &[&TraceRun]| stats::median(&of.iter().map(|r| r.render_seconds).collect::<Vec<_>>());
    let (&first_threads, first) = groups.iter().next().expect("read_lines refuses no runs");
    let base = median_of(first) * first_threads as f64;
    let rows = groups
        .iter()
        .map(|(&threads, of)| {
            let secs: Vec<f64> = of.iter().map(|r| r.render_seconds).collect();
            let (lo, hi) = secs
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
            let median = stats::median(&secs);
            let speedup = base / median;
            vec![
                threads.to_string(),
                format!("{median:.3} [{lo:.3}–{hi:.3}]"),
                format!("{:.1}", of[0].rays as f64 / median / 1e6),
                format!("{speedup:.2}×"),
                format!("{:.0} %", 100.0 * speedup / threads as f64),
                of.len().to_string(),
            ]
        })
        .collect();
    let r = &runs[0];
    Ok(markdown(&[
        Block::Paragraph(format!(
            "`RAYON_NUM_THREADS=t mirrorbox trace {}` at {}×{}, {} spp (Whitted, {:.1} M rays) on \
             {cpu}, thread counts in a shuffled order per round; speed-up against {} thread{}.",
            r.scene,
            r.width,
            r.height,
            r.spp,
            r.rays as f64 / 1e6,
            first_threads,
            if first_threads == 1 { "" } else { "s" }
        )),
        Block::Table(
            [
                "threads",
                "render s, median [min–max]",
                "Mrays/s",
                "speed-up",
                "efficiency",
                "runs",
            ]
            .map(String::from)
            .to_vec(),
            rows,
        ),
    ]))
}

/// Table 1 on the NVIDIA H200 of 2026-11-27, in the order the four runs started
/// (`scripts/gpu-measure.sh` steps `table1-pair`, then `table1-pair-reversed`).
const H200_TABLE1_RUNS: &[&str] = &[
    "gpu/table1_h200",
    "gpu/table1_repeat_h200",
    "gpu/table1_repeat_h200_run2",
    "gpu/table1_h200_run2",
];

/// The regions of the GPU chapter: Table 1, the depth scaling and the mirror room measured
/// on a GPU, and the tracer's threads on that machine's CPU.
pub const REGIONS: &[RegionSource] = &[
    RegionSource {
        id: "gpu-table1",
        source: "gpu/table1",
        about: "Table 1 and the exact methods beside it, measured on a GPU",
        generate: |reports| crate::table1::section::region_of(reports, "gpu/table1"),
    },
    RegionSource {
        id: "gpu-column",
        source: "gpu/table1",
        about: "Table 1's points on lavapipe (reports/table1) and on a GPU side by side",
        generate: |reports| crate::table1::section::device_column(reports, "gpu/table1"),
    },
    RegionSource {
        id: "gpu-table1-h200",
        source: "gpu/table1_h200",
        about: "Table 1 and the exact methods beside it, measured on an NVIDIA H200",
        generate: |reports| crate::table1::section::region_of(reports, "gpu/table1_h200"),
    },
    RegionSource {
        id: "gpu-table1-runs",
        source: "gpu/table1_h200",
        about: "four runs of Table 1 on one GPU, the repeat run first in the second pair: the exact methods' paired speed ratios",
        generate: |reports| crate::table1::section::runs_region(reports, H200_TABLE1_RUNS),
    },
    RegionSource {
        id: "gpu-depth-scaling",
        source: "gpu/depth_scaling",
        about: "the exact methods' cost per bounce, measured on a GPU",
        generate: |reports| {
            crate::depth_scaling::section::region_of(reports, "gpu/depth_scaling", false)
        },
    },
    RegionSource {
        id: "gpu-room",
        source: "gpu/room_1080p.jsonl",
        about: "the mirror room at 1920×1080 against depth on a GPU: where real time ends",
        generate: |reports| room_region(&reports.join("gpu/room_1080p.jsonl")),
    },
    RegionSource {
        id: "gpu-trace-threads",
        source: "gpu/trace_threads.jsonl",
        about: "the tracer against its thread count on the GPU machine's CPU",
        generate: |reports| {
            let cpu_file = reports.join("gpu/cpu.txt");
            let cpu = mirrorbox_files::read_bounded_text(&cpu_file, 4096, "a CPU name")
                .map_err(|e| ReadmeError(e.to_string()))?;
            threads_region(&reports.join("gpu/trace_threads.jsonl"), cpu.trim())
        },
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    fn write(lines: &[&str]) -> tempfile::NamedTempFile {
        let f = tempfile::NamedTempFile::new().unwrap();
        std::fs::write(f.path(), lines.join("\n")).unwrap();
        f
    }

    #[test]
    fn real_time_ends_where_the_median_first_exceeds_the_budget() {
        let run = |d: u32, ms: f64| {
            format!(
                r#"{{"method":"m","depth":{d},"frames_ms":[{ms},{ms},{ms},{ms},{ms},{ms}],"triangles":1000000,"draws":1,"paths":{{"kept":3}},"adapter":"A","backend":"vulkan","width":8,"height":4,"scene":"s.json"}}"#
            )
        };
        let refused = r#"{"method":"m","depth":64,"refused":"error: this frame would draw 9 triangles, above the limit: lower --depth"}"#;
        let (a, b, c) = (run(8, 5.0), run(16, 16.0), run(32, 40.0));
        let f = write(&[&c, &a, refused, &b]);
        let text = room_region(f.path()).unwrap();
        assert!(text.contains("holds up to depth 16 (16.00 ms)"), "{text}");
        assert!(text.contains("depth 32 (40.00 ms), does not"), "{text}");
        assert!(
            text.contains("refused (1 runs): this frame would draw 9 triangles"),
            "{text}"
        );
        // Rows in depth order, not text order (8 before 16 before 32 before 64).
        let at = |s: &str| text.find(s).unwrap();
        assert!(at("| m | 8 |") < at("| m | 16 |") && at("| m | 32 |") < at("| m | 64 |"));
    }

    #[test]
    fn the_speed_up_is_against_one_thread() {
        let run = |t: usize, s: f64| {
            format!(
                r#"{{"threads":{t},"render_seconds":{s},"rays":1000000,"scene":"s.json","width":8,"height":4,"spp":1}}"#
            )
        };
        let f = write(&[&run(4, 1.0), &run(1, 4.0), &run(1, 3.0), &run(1, 5.0)]);
        let text = threads_region(f.path(), "a CPU").unwrap();
        assert!(
            text.contains("| 1 | 4.000 [3.000–5.000] | 0.2 | 1.00× | 100 % | 3 |"),
            "{text}"
        );
        assert!(
            text.contains("| 4 | 1.000 [1.000–1.000] | 1.0 | 4.00× | 100 % | 1 |"),
            "{text}"
        );
        let bad = write(&["{\"threads\": 1}"]);
        let e = threads_region(bad.path(), "a CPU").err().unwrap();
        assert!(e.0.contains(":1:"), "{e}");
    }
}
