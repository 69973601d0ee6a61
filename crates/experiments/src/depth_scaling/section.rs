//! The depth-scaling report section (the exact methods' cost against the depth cap, per
//! bounce) and the regions that quote it.

use mirrorbox_report::document::{Block, distinct, markdown, ms_cell, ms_heading, sci, setting};
use mirrorbox_report::plot::{Chart, Reference, Series};
use mirrorbox_report::readme::{ReadmeError, RegionSource, measured_on, prose};
use mirrorbox_report::{Record, Sweep, SweepInfo, load_sweep};

/// The section: every sweep's records are offered it; empty where no exact method was swept
/// over depth.
pub fn section(info: &SweepInfo, records: &[Record]) -> Vec<Block> {
    let floor = Record::our_floor(records);
    depth_scaling(info, records, floor)
}

/// ms/frame against the depth cap for each exact method with several depths.
pub fn depth_scaling(info: &SweepInfo, records: &[Record], floor: Option<&Record>) -> Vec<Block> {
    let groups = super::exact::depth_scaling(&info.exact_methods, records);
    if groups.is_empty() {
        return Vec::new();
    }
    let ms_column = ms_heading("ms/frame median", groups.iter().flat_map(|g| &g.points));
    let mut out = vec![
        Block::Heading(2, "Exact methods: cost against depth".into()),
        Block::Chart("plot_ms_vs_depth.svg".into(), {
            let styles = mirrorbox_report::plot::styles_for(
                &groups.iter().map(|g| g.method.as_str()).collect::<Vec<_>>(),
            );
            let alphas = distinct(groups.iter().map(|g| g.alpha.to_bits()));
            let bars = mirrorbox_report::ms_bars_for(groups.iter().flat_map(|g| &g.points));
            Box::new(Chart {
                x_log: true,
                y_log: true,
                x_ticks_at_data: true,
                series: groups
                    .iter()
                    .zip(styles)
                    .map(|(g, style)| {
                        let name = if alphas.len() > 1 {
                            format!("{}, α={}", g.name(), g.alpha)
                        } else {
                            g.name()
                        };
                        let mut s = Series::new(
                            name,
                            style,
                            g.points.iter().map(|r| (setting(r), r.ms_median)).collect(),
                        );
                        s.bars = bars;
                        s.y_intervals = g.points.iter().map(|r| r.ms_bars(s.bars)).collect();
                        // Where the scene runs out of reflections before the cap, the cap is
                        // not what the point shows: say how many it does.
                        s.labels = g
                            .points
                            .iter()
                            .map(|r| {
                                if (r.reflections as f64) < setting(r) {
                                    format!("{} reflections shown", r.reflections)
                                } else {
                                    String::new()
                                }
                            })
                            .collect();
                        s
                    })
                    .collect(),
                references: floor
                    .map(|fl| vec![Reference::Level("one full-scene pass".into(), fl.ms_median)])
                    .unwrap_or_default(),
                ..Chart::new(
                    "Cost of the exact methods vs depth cap",
                    mirrorbox_report::document::DEPTH_CAP_AXIS,
                    "ms/frame (median, 95 % CI bars)",
                )
            })
        }),
        Block::Table(
            [
                "method",
                "α",
                "depth cap",
                "reflections shown",
                "paths kept (pruned)",
                "passes",
                "draws",
                "triangles",
                ms_column.as_str(),
                "FLIP mean (image)",
            ]
            .map(String::from)
            .to_vec(),
            groups
                .iter()
                .flat_map(|g| g.points.iter().map(move |r| (g, r)))
                .map(|(g, r)| {
                    let opt = |v: Option<usize>| v.map_or("–".into(), |x| x.to_string());
                    vec![
                        g.name(),
                        r.alpha.to_string(),
                        opt(r.depth.map(|d| d as usize)),
                        r.reflections.to_string(),
                        format!("{} ({})", opt(r.paths), opt(r.paths_pruned)),
                        r.passes.to_string(),
                        r.draws.to_string(),
                        opt(r.triangles),
                        ms_cell(r, 2),
                        sci(r.metrics.flip_mean),
                    ]
                })
                .collect(),
        ),
    ];
    out.push(Block::Bullets(
        groups
            .iter()
            .map(|g| {
                // The floor timed beside the group's own points (a score's second `--with`
                // sweep has its own), else the one given.
                let beside = g.points.first().and_then(|p| p.floor_beside(records));
                super::exact::bounce_sentence(g, beside.or(floor).map(|fl| fl.ms_median))
            })
            .collect(),
    ));
    out
}

/// The depth-scaling section's cost per bounce (and with `table`, every point).
fn depth_scaling_region(s: &Sweep, table: bool) -> Result<String, ReadmeError> {
    let floor = Record::our_floor(&s.records);
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

/// The sweep in `reports/<folder>`'s cost per bounce (with `table`, every point too).
pub fn region_of(
    reports: &std::path::Path,
    folder: &str,
    table: bool,
) -> Result<String, ReadmeError> {
    depth_scaling_region(&load_sweep(&reports.join(folder))?, table)
}

/// The regions of the exact methods' chapter.
pub const REGIONS: &[RegionSource] = &[
    RegionSource {
        id: "depth-scaling",
        source: "depth_scaling",
        about: "the exact methods' cost per bounce",
        generate: |reports| region_of(reports, "depth_scaling", false),
    },
    RegionSource {
        id: "depth-scaling-table",
        source: "depth_scaling",
        about: "the exact methods' cost against depth, every point, and per bounce",
        generate: |reports| region_of(reports, "depth_scaling", true),
    },
];

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_report::document::fixtures::record;

    /// "One full-scene pass" is our floor's time: a scored folder lists the clients' floors
    /// too, and the first of them (Babylon's 2.10 ms, wall clock) had stood for ours.
    #[test]
    fn a_pass_is_our_floor_not_a_clients() {
        let point = |depth: u32| {
            let mut r = record(0, 10.0 + 0.5 * depth as f64, 1, 0.01);
            r.method = "unrolled".into();
            r.depth = Some(depth);
            r.reflections = depth as usize;
            r
        };
        let floor = |ms: f64, external: bool| {
            let mut r = record(0, ms, 1, 0.0);
            r.kind = "floor".into();
            r.method = "floor".into();
            if external {
                r.timing_order = mirrorbox_report::EXTERNAL_TIMING.into();
            }
            r
        };
        let info = SweepInfo {
            exact_methods: vec!["unrolled".into()],
            ..Default::default()
        };
        let mut records = vec![floor(2.1, true), floor(5.0, false)];
        records.extend([1, 4, 16, 64].map(point));
        let text = mirrorbox_report::document::markdown(&section(&info, &records));
        assert!(
            text.contains("takes 5.00 ms, so one more bounce costs 10.0 %"),
            "{text}"
        );
    }
}
