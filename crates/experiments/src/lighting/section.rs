//! Shadows and mirrored lights (issue 15, `docs/shading.md`) in a report: the error each
//! raster lighting variant leaves against a truth lit the same way, and its cost, against the
//! depth k of the mirrored lights (`lighting.mirrored_lights`).
//!
//! A point's lighting variant is read from its method options (`lights=…`, `shadows=…`,
//! `shadow-map-size=…`, `shadow-bias=…`): the report knows the options' names, not the
//! rasterizer.

use mirrorbox_report::Record;
use mirrorbox_report::document::{Block, f, markdown, ms_cell, ms_heading, sci};
use mirrorbox_report::plot::{Chart, Series, our_styles};
use mirrorbox_report::readme::{ReadmeError, RegionSource, measured_on};
use mirrorbox_report::{Sweep, load_sweep};

/// The raster option that chooses direct or mirrored lights.
pub const LIGHTS_OPTION: &str = "lights";

/// The raster options of a lighting variant (crates/raster/src/lighting.rs).
const LIGHTING_OPTIONS: [&str; 4] = [LIGHTS_OPTION, "shadows", "shadow-map-size", "shadow-bias"];

/// The method a point measured, without its lighting options: `auxiliary n=2`,
/// `unrolled depth=64`.
pub fn method_of(r: &Record) -> String {
    r.method_without(&LIGHTING_OPTIONS)
}

/// The point's lighting variant in words: `direct only, no shadows`, `mirrored, no
/// shadows`, `mirrored, shadow maps 1024²` (`, bias 0.01` where not the default). An option at
/// its default is absent from the record: mirrored lights (what the scene asks for), no
/// shadows, maps of 1024², the default bias.
pub fn lighting_of(r: &Record) -> String {
    let lights = if r.option(LIGHTS_OPTION) == Some("direct") {
        "direct only"
    } else {
        "mirrored"
    };
    if r.option("shadows") != Some("map") {
        return format!("{lights}, no shadows");
    }
    let size = r.option("shadow-map-size").unwrap_or("1024");
    let bias = r
        .option("shadow-bias")
        .map_or(String::new(), |b| format!(", bias {b}"));
    format!("{lights}, shadow maps {size}²{bias}")
}

/// [`lighting_of`] of a point with no lighting option: the scene's own lights, no shadows.
const DEFAULT_LIGHTING: &str = "mirrored, no shadows";

/// The key of a series' style ([`keyed_styles`]) named `method` (`auxiliary n=2`, or the
/// method alone where its counts are the series' points) and lit by `variant`: the words after
/// the method and the lighting where not the default — so that `auxiliary n=2` at the default
/// lighting has the style it has in every chart, and each lighting variant one of its own.
fn style_key(method: &str, variant: &str) -> String {
    let count = method
        .split_whitespace()
        .skip(1)
        .collect::<Vec<_>>()
        .join(" ");
    let lighting = if variant == DEFAULT_LIGHTING {
        ""
    } else {
        variant
    };
    format!("{count} {lighting}").trim().to_string()
}

/// Where a variant's rows go: direct before mirrored, no shadows before shadow maps, maps by
/// size (256² before 1024²), then by name.
fn variant_order(r: &Record) -> (bool, bool, u32, String) {
    let size = r.option("shadow-map-size").and_then(|s| s.parse().ok());
    (
        r.option(LIGHTS_OPTION) != Some("direct"),
        r.option("shadows") == Some("map"),
        size.unwrap_or(1024),
        lighting_of(r),
    )
}

/// The points of a mirrored-lights sweep.
fn lit_points(records: &[Record]) -> Vec<&Record> {
    records
        .iter()
        .filter(|r| r.kind == "point" && r.lights_depth().is_some())
        .collect()
}

use mirrorbox_report::document::distinct;

/// The method the sentences and the error-against-k chart follow: the first exact one
/// measured (`unrolled`, `portal`), else the first.
fn reference_method(points: &[&Record]) -> Option<String> {
    let methods = distinct(points.iter().map(|r| method_of(r)));
    methods
        .iter()
        .find(|m| m.starts_with("unrolled") || m.starts_with("portal"))
        .or(methods.first())
        .cloned()
}

/// What each lighting variant of `method` leaves and costs at depth `k`, in sentences.
pub fn sentences(records: &[Record]) -> Vec<String> {
    let points = lit_points(records);
    let Some(method) = reference_method(&points) else {
        return Vec::new();
    };
    let Some(k) = points.iter().filter_map(|r| r.lights_depth()).max() else {
        return Vec::new();
    };
    let at = |lighting: &str| {
        points.iter().copied().find(|r| {
            method_of(r) == method && r.lights_depth() == Some(k) && lighting_of(r) == lighting
        })
    };
    let variants = distinct(points.iter().map(|r| lighting_of(r)));
    let mut out = Vec::new();
    let describe = |r: &Record| {
        format!(
            "FLIP mean {}, RMSE {} at {} ms/frame",
            sci(r.metrics.flip_mean),
            sci(r.metrics.rmse),
            ms_cell(r, 1)
        )
    };
    if let Some(direct) = at("direct only, no shadows") {
        out.push(format!(
            "Ignoring mirrored light (`{method}` with `lights=direct`, today's raster) against the \
             truth lit through up to k = {k} mirrors: {}.",
            describe(direct)
        ));
    }
    for v in variants.iter().filter(|v| !v.starts_with("direct only")) {
        if let Some(r) = at(v) {
            out.push(format!("`{method}`, {v}: {}.", describe(r)));
        }
    }
    out.extend(growth(records));
    out
}

/// How the error of ignoring mirrored light grows with k (`sentences`' last, and the
/// overview's lighting finding): the first depth with mirrored light to miss against the
/// shallowest, then the deepest; `None` without such a k sweep of `lights=direct`.
pub fn growth(records: &[Record]) -> Option<String> {
    let points = lit_points(records);
    let method = reference_method(&points)?;
    let direct: Vec<&Record> = {
        let mut d: Vec<&Record> = points
            .iter()
            .copied()
            .filter(|r| method_of(r) == method && lighting_of(r) == "direct only, no shadows")
            .collect();
        d.sort_by_key(|r| r.lights_depth());
        d
    };
    // The first depth with mirrored light to miss, against the same depth lit through the
    // mirrors (its shading apart from that light: no shadows either), then the deepest. At
    // the shallowest depth (k = 0) nothing is mirrored: what is left there is the shadows.
    if let (Some(first), Some(second), Some(last)) = (direct.first(), direct.get(1), direct.last())
    {
        let k = |r: &Record| r.lights_depth().unwrap_or(0);
        let lit = points.iter().copied().find(|r| {
            method_of(r) == method && k(r) == k(second) && lighting_of(r) == "mirrored, no shadows"
        });
        return Some(format!(
            "The error of ignoring mirrored light (`{method}` with `lights=direct`, no shadows) \
             appears at the first mirrored depth: FLIP mean {} at k = {} (no mirrored light to \
             miss: what is left is the shadows), {} at k = {}{}{}.",
            sci(first.metrics.flip_mean),
            k(first),
            sci(second.metrics.flip_mean),
            k(second),
            lit.map_or(String::new(), |l| format!(
                " (lit through the mirrors: {})",
                sci(l.metrics.flip_mean)
            )),
            if k(last) == k(second) {
                String::new()
            } else {
                format!(", {} at k = {}", sci(last.metrics.flip_mean), k(last))
            }
        ));
    }
    None
}

/// The report section of a mirrored-lights sweep (empty for any other sweep).
pub fn lighting_section(records: &[Record]) -> Vec<Block> {
    let points = lit_points(records);
    if points.is_empty() {
        return Vec::new();
    }
    let k_max = points
        .iter()
        .filter_map(|r| r.lights_depth())
        .max()
        .unwrap_or(0);
    let variants = distinct(points.iter().map(|r| lighting_of(r)));
    // One series per method and lighting variant at k_max, joined along the method's swept
    // count (auxiliary's n) — the one variable that varies within a series; a method with
    // one setting is one marker.
    let kinds = distinct(points.iter().map(|r| r.method.clone()));
    let mut error_vs_ms: Vec<Series> = Vec::new();
    let bars = mirrorbox_report::ms_bars_for(points.iter().copied());
    for kind in &kinds {
        let mut mine: Vec<&Record> = points
            .iter()
            .copied()
            .filter(|r| &r.method == kind && r.lights_depth() == Some(k_max))
            .collect();
        mine.sort_by_key(|r| variant_order(r));
        let lightings = distinct(mine.iter().map(|r| lighting_of(r)));
        // Each lighting's points and the method they name: `auxiliary n=2` where they share
        // a count, else the method alone (the counts label the points).
        let groups: Vec<(&String, Vec<&Record>, String, bool)> = lightings
            .iter()
            .map(|v| {
                let mut at: Vec<&Record> = mine
                    .iter()
                    .copied()
                    .filter(|r| &lighting_of(r) == v)
                    .collect();
                at.sort_by_key(|r| (r.n, r.depth));
                let counts = distinct(at.iter().map(|r| method_of(r)));
                let named = if counts.len() == 1 {
                    counts[0].clone()
                } else {
                    kind.clone()
                };
                (v, at, named, counts.len() > 1)
            })
            .collect();
        let keys: Vec<String> = groups.iter().map(|(v, _, m, _)| style_key(m, v)).collect();
        let styles = our_styles(
            &keys
                .iter()
                .map(|k| (kind.as_str(), k.as_str()))
                .collect::<Vec<_>>(),
        );
        for ((v, at, named, counted), style) in groups.into_iter().zip(styles) {
            let name = format!("{named}, {v}");
            let mut s = Series::new(
                name,
                style,
                at.iter()
                    .map(|r| (r.ms_median, r.metrics.flip_mean))
                    .collect(),
            );
            if counted {
                s.labels = at
                    .iter()
                    .map(|r| r.n.map_or(String::new(), |n| format!("n={n}")))
                    .collect();
            }
            s.bars = bars;
            s.x_intervals = at.iter().map(|r| r.ms_bars(s.bars)).collect();
            error_vs_ms.push(s);
        }
    }
    let mut out = vec![
        Block::Heading(2, "Lighting: shadows and mirrored lights".into()),
        Block::Paragraph(format!(
            "The truth lights every diffuse point through the lights' images in chains of up to \
             k mirrors (the point's k), with the scene's shadows; each raster point uses the \
             lighting variant named beside its method: without shadows, or with shadow maps of \
             the size named (a cube map per light, one map per light image through its last \
             mirror, nearest texel). The plots take k = {k_max}."
        )),
        Block::Chart(
            "plot_lighting_error_vs_ms.svg".into(),
            Box::new(Chart {
                x_log: true,
                y_log: true,
                series: error_vs_ms,
                ..Chart::new(
                    format!("FLIP over the image vs cost of each lighting variant, k = {k_max}"),
                    "ms/frame (median, 95 % CI bars)",
                    "FLIP mean over the image",
                )
            }),
        ),
    ];
    if let Some(method) = reference_method(&points) {
        let base = method.split_whitespace().next().unwrap_or_default();
        // One method per chart (its title names it): the lighting alone keys the style, so
        // that a lighting variant looks the same in every report's chart.
        let keys: Vec<String> = variants.iter().map(|v| style_key(base, v)).collect();
        let styles = our_styles(&keys.iter().map(|k| (base, k.as_str())).collect::<Vec<_>>());
        let series: Vec<Series> = variants
            .iter()
            .zip(styles)
            .map(|(v, style)| {
                let mut pts: Vec<&Record> = points
                    .iter()
                    .copied()
                    .filter(|r| &lighting_of(r) == v && method_of(r) == method)
                    .collect();
                pts.sort_by_key(|r| r.lights_depth());
                Series::new(
                    v.clone(),
                    style,
                    pts.iter()
                        .map(|r| {
                            (
                                f64::from(r.lights_depth().unwrap_or(0)),
                                r.metrics.flip_mean,
                            )
                        })
                        .collect(),
                )
            })
            .collect();
        out.push(Block::Chart(
            "plot_lighting_error_vs_k.svg".into(),
            Box::new(Chart {
                y_log: true,
                series,
                x_ticks_at_data: true,
                ..Chart::new(
                    format!("FLIP over the image vs mirrored-light depth k, {method}"),
                    "k (most mirrors between a light and a surface)",
                    "FLIP mean over the image",
                )
            }),
        ));
    }
    let mut rows: Vec<&Record> = points.clone();
    rows.sort_by_key(|r| (method_of(r), variant_order(r), r.lights_depth()));
    let ms_column = ms_heading("ms/frame median", rows.iter().copied());
    out.push(Block::Table(
        [
            "method",
            "lighting",
            "k",
            ms_column.as_str(),
            "passes",
            "FLIP mean (image)",
            "RMSE",
            "SSIM",
        ]
        .map(String::from)
        .to_vec(),
        rows.iter()
            .map(|r| {
                vec![
                    method_of(r),
                    lighting_of(r),
                    r.lights_depth().map_or("–".into(), |k| k.to_string()),
                    ms_cell(r, 2),
                    r.passes.to_string(),
                    sci(r.metrics.flip_mean),
                    sci(r.metrics.rmse),
                    f(r.metrics.ssim, 4),
                ]
            })
            .collect(),
    ));
    let s = sentences(records);
    if !s.is_empty() {
        out.push(Block::Bullets(s));
    }
    out
}

/// The section, offered every sweep's records; empty where none carries the mirrored-light
/// depth.
pub fn section(_: &mirrorbox_report::SweepInfo, records: &[Record]) -> Vec<Block> {
    lighting_section(records)
}

fn lighting_region(s: &Sweep) -> Result<String, ReadmeError> {
    let sentences = sentences(&s.records);
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

/// The regions of the lighting chapter: the lit mirror box and the lit mirror room.
pub const REGIONS: &[RegionSource] = &[
    RegionSource {
        id: "lighting",
        source: "lighting",
        about: "shadows and mirrored lights on the lit mirror box: each lighting variant's error and cost",
        generate: |reports| lighting_region(&load_sweep(&reports.join("lighting"))?),
    },
    RegionSource {
        id: "lighting-room",
        source: "lighting_room",
        about: "the same on the lit mirror room",
        generate: |reports| lighting_region(&load_sweep(&reports.join("lighting_room"))?),
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    fn record(method: &str, options: &str, k: u32, flip: f64) -> Record {
        let mut r = mirrorbox_report::document::fixtures::record(0, 10.0, 1, flip);
        r.method = method.into();
        r.n = None;
        r.method_options = options.into();
        r.axes
            .insert(mirrorbox_report::axis::MIRRORED_LIGHTS.into(), f64::from(k));
        r.metrics.flip_mean = flip;
        if method == "unrolled" {
            r.depth = Some(64);
        }
        r
    }

    #[test]
    fn variants_are_read_from_the_options() {
        let r = record("unrolled", "lights=direct", 4, 0.1);
        assert_eq!(method_of(&r), "unrolled depth=64");
        assert_eq!(lighting_of(&r), "direct only, no shadows");
        let r = record("auxiliary", "lights=mirrored max-passes=9", 4, 0.1);
        assert_eq!(method_of(&r), "auxiliary max-passes=9");
        assert_eq!(lighting_of(&r), "mirrored, no shadows");
        assert_eq!(lighting_of(&record("portal", "", 0, 0.1)), DEFAULT_LIGHTING);
        assert_eq!(
            style_key(
                "portal depth=64",
                &lighting_of(&record("portal", "", 0, 0.1))
            ),
            "depth=64"
        );
        assert_eq!(
            style_key("auxiliary", "direct only, no shadows"),
            "direct only, no shadows"
        );
        let r = record("unrolled", "shadows=map shadow-map-size=256", 8, 0.1);
        assert_eq!(method_of(&r), "unrolled depth=64");
        assert_eq!(lighting_of(&r), "mirrored, shadow maps 256²");
        let r = record(
            "portal",
            "lights=direct shadows=map shadow-bias=0.02",
            8,
            0.1,
        );
        assert_eq!(lighting_of(&r), "direct only, shadow maps 1024², bias 0.02");
        // `shadows=none` is the default and never in a key; a stray one reads as no shadows.
        let r = record("portal", "shadows=none", 8, 0.1);
        assert_eq!(lighting_of(&r), "mirrored, no shadows");
    }

    #[test]
    fn sentences_follow_the_exact_method_at_the_deepest_k() {
        let records = vec![
            record("auxiliary", "lights=direct", 8, 0.5),
            record("unrolled", "lights=direct", 0, 0.01),
            record("unrolled", "lights=direct", 8, 0.2),
            record("unrolled", "", 8, 0.05),
        ];
        let s = sentences(&records).join("\n");
        assert!(
            s.contains("`unrolled depth=64` with `lights=direct`"),
            "{s}"
        );
        assert!(s.contains("up to k = 8 mirrors: FLIP mean 2.000e-1"), "{s}");
        assert!(
            s.contains("mirrored, no shadows: FLIP mean 5.000e-2"),
            "{s}"
        );
        assert!(
            s.contains(
                "1.000e-2 at k = 0 (no mirrored light to miss: what is left is the shadows), \
                 2.000e-1 at k = 8 (lit through the mirrors: 5.000e-2)."
            ),
            "{s}"
        );
        // With a depth between: the first mirrored depth against its lit twin, then the deepest.
        let mut deeper = records.clone();
        deeper.push(record("unrolled", "lights=direct", 1, 0.15));
        deeper.push(record("unrolled", "", 1, 0.03));
        let s = sentences(&deeper).join("\n");
        assert!(
            s.contains("1.500e-1 at k = 1 (lit through the mirrors: 3.000e-2), 2.000e-1 at k = 8."),
            "{s}"
        );
        assert!(lighting_section(&records).len() >= 5);
        // Not a mirrored-lights sweep: no section.
        let mut plain = records[0].clone();
        plain.axes.remove(mirrorbox_report::axis::MIRRORED_LIGHTS);
        assert!(lighting_section(&[plain]).is_empty());
    }
}
