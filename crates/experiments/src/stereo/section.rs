//! Stereo mirrors (issue 17, seed 002) in a report: each method's stereo pair (both eyes as
//! one frame) against each eye's truth, per-eye mirror textures against the head's shared ones
//! (`stereo-mirrors=shared` among the method options), across the interpupillary distance;
//! the pair's cost against the mono frame; and the disparity of a marked object's first
//! reflection (`marker` of each eye) against the truth's.
//!
//! Disparity is `x_right − x_left` of the marker's centroid, in pixels: with off-axis eyes it
//! is zero at the convergence distance and grows (positive) with depth beyond it. A reflection lies behind
//! the mirror, so its true disparity is larger than the mirror surface's; the shared shortcut
//! paints it at the mirror's.

use mirrorbox_report::Record;
use mirrorbox_report::document::{Block, distinct, f, markdown, ms_cell, sci};
use mirrorbox_report::plot::{Chart, Series, method_style, styles_for};
use mirrorbox_report::readme::{ReadmeError, RegionSource, measured_on};
use mirrorbox_report::{Sweep, load_sweep};

/// The method option that chooses shared mirror textures (crates/raster/src/stereo_mirrors.rs).
const SHARED_OPTION: &str = "stereo-mirrors";

/// The method a point measured without its stereo choice: `auxiliary n=2`.
fn method_of(r: &Record) -> String {
    r.method_without(&[SHARED_OPTION])
}

/// Whether the point shares the head's mirror textures between the eyes.
fn is_shared(r: &Record) -> bool {
    r.option(SHARED_OPTION) == Some("shared")
}

/// A point's row and series name: `auxiliary n=2, shared`.
fn variant_of(r: &Record) -> String {
    format!(
        "{}, {}",
        method_of(r),
        if is_shared(r) { "shared" } else { "per-eye" }
    )
}

/// The stereo points, and whether the sweep has any.
fn pairs(records: &[Record]) -> Vec<&Record> {
    records
        .iter()
        .filter(|r| r.kind == "point" && r.stereo.is_some())
        .collect()
}

fn ipd(r: &Record) -> f32 {
    r.stereo.as_ref().map_or(0.0, |s| s.ipd)
}

fn ipds(points: &[&Record]) -> Vec<f32> {
    let mut d = distinct(points.iter().map(|r| ipd(r)));
    d.sort_by(f32::total_cmp);
    d
}

/// The mono frame of the same method and variant (a `mono` value of the sweep's `--ipd`).
fn mono_of<'a>(records: &'a [Record], pair: &Record) -> Option<&'a Record> {
    records.iter().find(|r| {
        r.kind == "point"
            && r.stereo.is_none()
            && r.method == pair.method
            && r.method_options == pair.method_options
            && r.n == pair.n
            && r.depth == pair.depth
            && r.alpha == pair.alpha
    })
}

/// The marker's disparity in a pair ([`mirrorbox_report::StereoRecord::disparity`]).
pub fn disparity(r: &Record, truth: bool) -> Option<f64> {
    r.stereo.as_ref()?.disparity(truth)
}

fn find<'a>(points: &[&'a Record], variant: &str, d: f32) -> Option<&'a Record> {
    points
        .iter()
        .copied()
        .find(|r| variant_of(r) == variant && ipd(r) == d)
}

fn px(v: Option<f64>) -> String {
    v.map_or("–".into(), |v| f(v, 2))
}

/// The pair's time against the mono frame: one row per variant, at the largest IPD.
pub fn cost_table(records: &[Record]) -> Block {
    let pts = pairs(records);
    let widest = ipds(&pts).last().copied().unwrap_or(0.0);
    let timed = || records.iter().filter(|r| r.kind == "point");
    let header = vec![
        "method, mirrors".to_string(),
        mirrorbox_report::document::ms_heading("mono ms/frame", timed()),
        mirrorbox_report::document::ms_heading(
            &format!("stereo pair ms/frame at IPD {widest}"),
            timed(),
        ),
        "pair ÷ two mono frames".into(),
        "scene passes per pair".into(),
    ];
    let rows = distinct(pts.iter().map(|r| variant_of(r)))
        .iter()
        .filter_map(|v| find(&pts, v, widest))
        .map(|r| {
            let mono = mono_of(records, r);
            vec![
                variant_of(r),
                mono.map_or("–".into(), |m| ms_cell(m, 1)),
                ms_cell(r, 1),
                mono.map_or("–".into(), |m| f(r.ms_median / (2.0 * m.ms_median), 2)),
                r.passes.to_string(),
            ]
        })
        .collect();
    Block::Table(header, rows)
}

/// FLIP (the mean of both eyes', each against its own truth) per variant and IPD.
pub fn error_table(records: &[Record]) -> Block {
    let pts = pairs(records);
    let ds = ipds(&pts);
    let mut header = vec!["method, mirrors".to_string()];
    header.extend(ds.iter().map(|d| format!("FLIP at IPD {d}")));
    let rows = distinct(pts.iter().map(|r| variant_of(r)))
        .iter()
        .map(|v| {
            let mut row = vec![v.clone()];
            row.extend(
                ds.iter()
                    .map(|&d| find(&pts, v, d).map_or("–".into(), |r| sci(r.metrics.flip_mean))),
            );
            row
        })
        .collect();
    Block::Table(header, rows)
}

/// The marker's disparity per variant and IPD, the truth's first.
pub fn disparity_table(records: &[Record]) -> Block {
    let pts = pairs(records);
    let ds = ipds(&pts);
    let mut header = vec!["marker's reflection disparity (px)".to_string()];
    header.extend(ds.iter().map(|d| format!("IPD {d}")));
    let mut truth = vec!["truth".to_string()];
    truth.extend(ds.iter().map(|&d| {
        px(pts
            .iter()
            .find(|r| ipd(r) == d)
            .and_then(|r| disparity(r, true)))
    }));
    let mut rows = vec![truth];
    for v in distinct(pts.iter().map(|r| variant_of(r))) {
        let mut row = vec![v.clone()];
        row.extend(
            ds.iter()
                .map(|&d| px(find(&pts, &v, d).and_then(|r| disparity(r, false)))),
        );
        rows.push(row);
    }
    Block::Table(header, rows)
}

/// For each method measured both ways, at the widest IPD: what sharing saves and what it
/// costs in error and disparity.
/// Shared textures against per-eye ones at the widest IPD, error and disparity only (no speed
/// claim): for the first method with both, "`naive` at IPD 0.1: sharing … raises FLIP over the
/// image from a to b; the marker's reflection …", or `None`.
pub fn flattening(records: &[Record]) -> Option<String> {
    let pts = pairs(records);
    let widest = *ipds(&pts).last()?;
    distinct(pts.iter().map(|r| method_of(r)))
        .into_iter()
        .find_map(|m| {
            let at = |shared: bool| {
                pts.iter()
                    .copied()
                    .find(|r| method_of(r) == m && is_shared(r) == shared && ipd(r) == widest)
            };
            let (own, shared) = (at(false)?, at(true)?);
            let (t, a, b) = (
                disparity(own, true)?,
                disparity(own, false)?,
                disparity(shared, false)?,
            );
            Some(format!(
                "`{m}` at IPD {widest}: sharing the head's mirror textures between the eyes \
                 raises FLIP over the image from {} to {}, and the marker's reflection has a \
                 disparity of {} px shared against {} px per-eye and the truth's {} px: shared \
                 puts it at the mirror's depth instead of behind it",
                sci(own.metrics.flip_mean),
                sci(shared.metrics.flip_mean),
                f(b, 2),
                f(a, 2),
                f(t, 2)
            ))
        })
}

pub fn sentences(records: &[Record]) -> Vec<String> {
    let pts = pairs(records);
    let Some(&widest) = ipds(&pts).last() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for m in distinct(pts.iter().map(|r| method_of(r))) {
        let at = |shared: bool| {
            pts.iter()
                .copied()
                .find(|r| method_of(r) == m && is_shared(r) == shared && ipd(r) == widest)
        };
        let (Some(own), Some(shared)) = (at(false), at(true)) else {
            continue;
        };
        let saved = own.ms_median - shared.ms_median;
        let ratio =
            mirrorbox_report::document::paired_ratio(shared, own).map_or(String::new(), |i| {
                format!(
                    " (shared ÷ per-eye: 95 % CI [{}, {}])",
                    f(i.low, 2),
                    f(i.high, 2)
                )
            });
        let mut s = format!(
            "`{m}` at IPD {widest}: sharing the head's mirror textures saves {} ms per stereo \
             pair ({} % of per-eye's {} ms){ratio} and raises FLIP from {} to {}",
            f(saved, 1),
            f(100.0 * saved / own.ms_median, 0),
            f(own.ms_median, 1),
            sci(own.metrics.flip_mean),
            sci(shared.metrics.flip_mean),
        );
        if let (Some(t), Some(a), Some(b)) = (
            disparity(own, true),
            disparity(own, false),
            disparity(shared, false),
        ) {
            s.push_str(&format!(
                "; the marker's reflection has a disparity of {} px per-eye and {} px shared, \
                 against the truth's {} px (shared is off by {} px: it lies at the mirror's \
                 depth instead of behind it)",
                f(a, 2),
                f(b, 2),
                f(t, 2),
                f(b - t, 2)
            ));
        }
        s.push('.');
        out.push(s);
    }
    out
}

fn chart(records: &[Record], name: &str, title: &str, y_label: &str, y_log: bool) -> Block {
    let pts = pairs(records);
    let value = |r: &Record| -> Option<f64> {
        if y_log {
            Some(r.metrics.flip_mean)
        } else {
            disparity(r, false)
        }
    };
    let variants = distinct(pts.iter().map(|r| variant_of(r)));
    // Each variant the style its name has in every report: its method, keyed by its count
    // and options (`n=2 stereo-mirrors=shared`; `auxiliary n=2` per eye as elsewhere).
    let firsts: Vec<&Record> = variants
        .iter()
        .filter_map(|v| pts.iter().copied().find(|r| &variant_of(r) == v))
        .collect();
    let names: Vec<String> = firsts.iter().map(|r| r.method_without(&[])).collect();
    let styles = styles_for(&names.iter().map(String::as_str).collect::<Vec<_>>());
    let mut series: Vec<Series> = variants
        .iter()
        .zip(styles)
        .map(|(v, style)| {
            let mut rs: Vec<&Record> = pts
                .iter()
                .copied()
                .filter(|r| &variant_of(r) == v)
                .collect();
            rs.sort_by(|p, q| ipd(p).total_cmp(&ipd(q)));
            Series::new(
                v.clone(),
                style,
                rs.iter()
                    .filter_map(|r| Some((f64::from(ipd(r)), value(r)?)))
                    .collect(),
            )
        })
        .collect();
    if !y_log {
        let mut truth: Vec<(f64, f64)> = ipds(&pts)
            .iter()
            .filter_map(|&d| {
                let r = pts.iter().find(|r| ipd(r) == d)?;
                Some((f64::from(d), disparity(r, true)?))
            })
            .collect();
        truth.sort_by(|a, b| a.0.total_cmp(&b.0));
        series.insert(0, Series::new("truth", method_style("truth"), truth));
    }
    series.retain(|s| !s.points.is_empty());
    Block::Chart(
        name.into(),
        Box::new(Chart {
            y_log,
            series,
            x_ticks_at_data: true,
            ..Chart::new(title, "interpupillary distance (scene units)", y_label)
        }),
    )
}

/// The report section of an `--ipd` sweep (empty for any other sweep).
pub fn stereo_section(records: &[Record]) -> Vec<Block> {
    let pts = pairs(records);
    if pts.is_empty() {
        return Vec::new();
    }
    let mut out = vec![
        Block::Heading(2, "Stereo mirrors: per-eye against shared".into()),
        Block::Paragraph(
            "Each stereo point renders both eyes of the camera's rig (off-axis, converging at \
             look_at unless the scene says otherwise) as one frame — both eyes' passes in one \
             command buffer, timed from the first pass to the second eye's resolve — and \
             compares each eye with its own eye's truth (docs/shading.md, \"Stereo\"). \
             `per-eye` renders every mirror texture from each eye (seed 002's per-eye mirror \
             cameras); `shared` renders them once from the head's centre and projects them \
             onto the mirror in both eyes, the shortcut many VR engines ship. The exact \
             geometry method (`unrolled`) draws every reflection path from each eye. FLIP is \
             the mean of the two eyes'; a mono frame of each method is the baseline of the \
             cost."
                .into(),
        ),
        cost_table(records),
        error_table(records),
        chart(
            records,
            "plot_stereo_error_vs_ipd.svg",
            "FLIP over the image (both eyes) vs interpupillary distance",
            "FLIP mean over the image",
            true,
        ),
    ];
    if pts.iter().any(|r| disparity(r, true).is_some()) {
        out.push(Block::Paragraph(
            "The disparity check: the marked object's first reflection is found in each eye \
             by its colour (the largest blob of its albedo's chromaticity), raster and truth \
             alike; its disparity is `x_right − x_left` of the centroids, in pixels (positive: \
             behind the plane where the eyes converge). Centroids of whole pixels (no \
             anti-aliasing at one sample per pixel) move in steps: read ±0.5 px."
                .into(),
        ));
        out.push(disparity_table(records));
        out.push(chart(
            records,
            "plot_stereo_disparity_vs_ipd.svg",
            "The marker's reflection disparity vs interpupillary distance",
            "disparity (pixels)",
            false,
        ));
    }
    let s = sentences(records);
    if !s.is_empty() {
        out.push(Block::Bullets(s));
    }
    // Image rows at the widest IPD: per method measured both ways, the truth's anaglyph
    // beside per-eye's and shared's, then the side-by-side FLIP maps.
    let Some(&widest) = ipds(&pts).last() else {
        return out;
    };
    for m in distinct(pts.iter().map(|r| method_of(r))) {
        let at: Vec<&Record> = pts
            .iter()
            .copied()
            .filter(|r| method_of(r) == m && ipd(r) == widest)
            .collect();
        let Some(first) = at.first() else { continue };
        let stereo = first.stereo.as_ref().expect("a stereo point");
        out.push(Block::Heading(
            3,
            format!("{m} at IPD {widest}: red–cyan anaglyphs"),
        ));
        let mut images = vec![("truth".to_string(), stereo.truth_anaglyph_image.clone())];
        for r in &at {
            let s = r.stereo.as_ref().expect("a stereo point");
            images.push((variant_of(r), s.anaglyph_image.clone()));
        }
        out.push(Block::Images(images));
        out.push(Block::Images(
            at.iter()
                .map(|r| {
                    (
                        format!("{}: FLIP, left | right", variant_of(r)),
                        r.heatmap_image.clone(),
                    )
                })
                .collect(),
        ));
    }
    out
}

/// The section, offered every sweep's records; empty where none is a stereo pair.
pub fn section(_: &mirrorbox_report::SweepInfo, records: &[Record]) -> Vec<Block> {
    stereo_section(records)
}

fn stereo_region(s: &Sweep) -> Result<String, ReadmeError> {
    let sentences = sentences(&s.records);
    if sentences.is_empty() {
        return Err(ReadmeError(format!(
            "{}: no stereo sweep measuring per-eye and shared, nothing to quote",
            s.info.scene
        )));
    }
    Ok(markdown(&[
        Block::Paragraph(measured_on(s)),
        cost_table(&s.records),
        error_table(&s.records),
        disparity_table(&s.records),
        Block::Bullets(sentences),
    ]))
}

/// The region of the stereo chapter.
pub const REGIONS: &[RegionSource] = &[RegionSource {
    id: "stereo",
    source: "stereo",
    about: "stereo mirrors: the pair's cost against mono, per-eye against shared, and the disparity check",
    generate: |reports| stereo_region(&load_sweep(&reports.join("stereo"))?),
}];

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_report::{EyeRecord, MarkerRecord, StereoRecord};

    fn eye(name: &str, flip: f64, x: f64, truth_x: f64) -> EyeRecord {
        let mut metrics = mirrorbox_report::document::fixtures::record(2, 1.0, 1, flip).metrics;
        metrics.flip_mean = flip;
        let at = |x| {
            Some(MarkerRecord {
                x,
                y: 10.0,
                pixels: 40,
            })
        };
        EyeRecord {
            eye: name.into(),
            metrics,
            marker: at(x),
            truth_marker: at(truth_x),
        }
    }

    fn pair(options: &str, d: f32, ms: f64, flip: f64, x_right: f64) -> Record {
        let mut r = mirrorbox_report::document::fixtures::record(2, ms, 30, flip);
        r.key = format!("{options} {d}");
        r.method_options = options.into();
        r.frames_ms = vec![ms; 6];
        r.stereo = Some(StereoRecord {
            ipd: d,
            eyes: vec![
                eye("left", flip, 100.0, 100.0),
                eye("right", flip, x_right, 97.0),
            ],
            anaglyph_image: format!("images/{options}{d}_anaglyph.png"),
            truth_anaglyph_image: format!("images/truth_ipd{d}_anaglyph.png"),
        });
        r
    }

    #[test]
    fn sharing_is_weighed_by_its_saving_error_and_disparity() {
        let mut mono = mirrorbox_report::document::fixtures::record(2, 50.0, 15, 0.01);
        mono.key = "mono".into();
        let records = vec![
            pair("", 0.1, 110.0, 0.01, 97.0),
            pair("stereo-mirrors=shared", 0.1, 60.0, 0.05, 99.5),
            pair("", 0.0, 110.0, 0.01, 100.0),
            mono,
        ];
        let s = sentences(&records).join("\n");
        assert!(
            s.contains("saves 50.0 ms per stereo pair (45 % of per-eye's 110.0 ms)"),
            "{s}"
        );
        assert!(s.contains("raises FLIP from 1.000e-2 to 5.000e-2"), "{s}");
        assert!(
            s.contains("-3.00 px per-eye and -0.50 px shared, against the truth's -3.00 px (shared is off by 2.50 px"),
            "{s}"
        );
        let Block::Table(_, rows) = cost_table(&records) else {
            panic!("a table")
        };
        // Per-eye: 110 ms against two mono frames of 50 ms.
        assert_eq!(rows[0][3], "1.10");
        assert!(stereo_section(&records).len() >= 8);
        assert!(stereo_section(&records[3..]).is_empty());
    }
}
