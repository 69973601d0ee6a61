//! The symmetry-scaling report section (the symmetry methods' cost against the planes p) and
//! the region that quotes it.

use super::planes::variant;
use mirrorbox_report::document::{Block, f, markdown, ms_cell, ms_heading, sci, setting};
use mirrorbox_report::plot::{Chart, Reference, Series};
use mirrorbox_report::readme::{ReadmeError, RegionSource, measured_on, prose};
use mirrorbox_report::{Record, Sweep, SweepInfo, load_sweep, value};

/// The section, offered every sweep's records; empty where none carries a plane count.
pub fn section(_: &SweepInfo, records: &[Record]) -> Vec<Block> {
    symmetry_section(records)
}

/// ms/frame against the symmetry planes p for each symmetry method (seed 001), with the 2^p
/// growth of the seed's copies beside it, the copies drawn, the bake, and the computed
/// sentences: where baking starts to win, how much pruning removes.
pub fn symmetry_section(records: &[Record]) -> Vec<Block> {
    use super::planes::{
        BAKED_METHOD, PRUNED_METHOD, crossover_sentence, plane_scaling, pruning_sentence,
    };
    let groups = plane_scaling(records);
    if groups.is_empty() {
        return Vec::new();
    }
    let ms_column = ms_heading("ms/frame median", groups.iter().flat_map(|g| &g.points));
    let styles = mirrorbox_report::plot::styles_for(
        &groups.iter().map(|g| g.method.as_str()).collect::<Vec<_>>(),
    );
    let names: Vec<&str> = groups.iter().map(|g| g.name.as_str()).collect();
    let bars = mirrorbox_report::ms_bars_for(groups.iter().flat_map(|g| &g.points));
    let series: Vec<Series> = groups
        .iter()
        .zip(styles)
        .map(|(g, style)| {
            let mut s = Series::new(
                mirrorbox_report::document::legend_name(&g.name, &names),
                style,
                g.points.iter().map(|r| (setting(r), r.ms_median)).collect(),
            );
            s.bars = bars;
            s.y_intervals = g.points.iter().map(|r| r.ms_bars(s.bars)).collect();
            s
        })
        .collect();
    // The seed's worst case: 2^p times the cost of one copy (the first method's p = 0 time).
    let mut references = Vec::new();
    if let Some(base) = groups[0].points.first().filter(|r| r.planes() == Some(0)) {
        references.push(Reference::Curve(
            format!("2^p × {}'s p = 0 time", groups[0].name),
            groups[0]
                .points
                .iter()
                .filter_map(|r| r.planes())
                .map(|p| (f64::from(p), base.ms_median * f64::from(1u32 << p.min(31))))
                .collect(),
        ));
    }
    let opt = |v: Option<usize>| v.map_or("–".into(), |x| x.to_string());
    let mut out = vec![
        Block::Heading(2, "Symmetry planes: cost against p".into()),
        Block::Chart(
            "plot_ms_vs_planes.svg".into(),
            Box::new(Chart {
                y_log: true,
                series,
                references,
                x_ticks_at_data: true,
                ..Chart::new(
                    "Cost of the symmetry methods vs planes p",
                    "symmetry planes p",
                    "ms/frame (median, 95 % CI bars)",
                )
            }),
        ),
        Block::Table(
            [
                "method",
                "p",
                "copies drawn / 2^p",
                "triangles",
                "bake ms (CPU, once)",
                ms_column.as_str(),
                "FLIP mean (image)",
            ]
            .map(String::from)
            .to_vec(),
            groups
                .iter()
                .flat_map(|g| &g.points)
                .map(|r| {
                    vec![
                        variant(r),
                        opt(r.planes().map(|p| p as usize)),
                        format!(
                            "{} / {}",
                            opt(r.value(value::COPIES_DRAWN).map(|c| c as usize)),
                            opt(r.value(value::COPIES_TOTAL).map(|c| c as usize))
                        ),
                        opt(r.triangles),
                        r.value(value::BAKE_MS).map_or("–".into(), |ms| f(ms, 2)),
                        ms_cell(r, 2),
                        sci(r.metrics.flip_mean),
                    ]
                })
                .collect(),
        ),
    ];
    let mut sentences = Vec::new();
    if let Some(baked) = groups.iter().find(|g| g.method == BAKED_METHOD) {
        for other in groups.iter().filter(|g| g.method != BAKED_METHOD) {
            sentences.push(crossover_sentence(baked, other));
        }
    }
    sentences.extend(
        groups
            .iter()
            .filter(|g| g.method == PRUNED_METHOD)
            .filter_map(pruning_sentence),
    );
    if !sentences.is_empty() {
        out.push(Block::Bullets(sentences));
    }
    out
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

/// The region of the symmetry chapter.
pub const REGIONS: &[RegionSource] = &[RegionSource {
    id: "symmetry-scaling",
    source: "symmetry_scaling",
    about: "the symmetry methods against p: every point, the crossover, the pruning",
    generate: |reports| symmetry_region(&load_sweep(&reports.join("symmetry_scaling"))?),
}];
