//! The tracer's cost against the mirrored-light depth k (`scripts/lighting-trace-cost.sh`,
//! experiment `lighting-trace-cost`): the region that quotes its runs.

use mirrorbox_report::document::{Block, markdown};
use mirrorbox_report::readme::{ReadmeError, RegionSource};
use mirrorbox_report::{read_lines, stats};
use std::path::Path;

/// One `trace --json` run of `scripts/lighting-trace-cost.sh`.
#[derive(serde::Deserialize)]
struct TraceRun {
    scene: String,
    mirrored_lights: u32,
    render_seconds: f64,
    rays: u64,
    threads: usize,
    lighting: TraceLighting,
    /// Where and when it ran (runs recorded since 2026-11-27 carry them).
    #[serde(default)]
    measured: Option<Measured>,
}

#[derive(serde::Deserialize)]
struct Measured {
    date: String,
    commit: String,
    cpu: String,
}

#[derive(serde::Deserialize)]
struct TraceLighting {
    light_images: usize,
}

fn trace_cost_region(path: &Path) -> Result<String, ReadmeError> {
    let runs: Vec<TraceRun> = read_lines(path)?;
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
    let when = runs
        .first()
        .and_then(|r| r.measured.as_ref())
        .map_or(String::new(), |m| {
            format!(" Measured {} at commit {} on {}.", m.date, m.commit, m.cpu)
        });
    Ok(markdown(&[
        Block::Paragraph(format!(
            "`scripts/lighting-trace-cost.sh`: `mirrorbox trace --mirrored-lights k --spp 1` at \
             640×360 with shadows, {threads} threads, runs interleaved.{when}"
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

/// The region of the lighting chapter that the script's runs fill.
pub const REGIONS: &[RegionSource] = &[RegionSource {
    id: "lighting-trace-cost",
    source: "lighting/trace_cost.jsonl",
    about: "the tracer's time against the mirrored-light depth k on both lit scenes",
    generate: |reports| trace_cost_region(&reports.join("lighting/trace_cost.jsonl")),
}];
