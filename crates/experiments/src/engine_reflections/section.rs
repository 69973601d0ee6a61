//! What engines ship (issue 39) in a report: screen-space reflections (`ssr`) and ray-query
//! reflections (`ray-query`) beside the exact raster methods and the paper's `auxiliary n=2`.
//! Two questions, each answered where the sweep's records hold it:
//!
//! - **Depth**: error and ms/frame against the depth cap for the depth-swept methods
//!   (`ray-query`, `unrolled`, `portal`), the one-setting methods drawn at the depth they
//!   show; how each method's cost grows (the last doubling of the depth's factor).
//! - **The screen**: `ssr`'s error over the mirror pixels against the share of them whose
//!   first reflection is off screen (`reflection_offscreen_share`, from the camera turns of
//!   `yaw_deg`), one series per fallback, and what each fallback buys.
//!
//! The report knows the methods' names and options (`ssr-fallback`), not the rasterizer.

use mirrorbox_report::document::{Block, distinct, f, ms_cell, sci};
use mirrorbox_report::plot::{Chart, Series, Style, StyleKey, keyed_styles};
use mirrorbox_report::{Record, value};

/// The yaw axis' name in a record's `axes` (the harness's `CAMERA_YAW`).
const YAW: &str = mirrorbox_report::axis::YAW_DEG;
/// The depth charts' x: the depth-swept methods at their cap, the others at the reflections
/// they show.
fn depth_axis() -> String {
    format!(
        "{}; the others at the reflections they show",
        mirrorbox_report::document::DEPTH_CAP_AXIS
    )
}

/// The exact methods whose depth is swept here.
const DEPTH_SWEPT: [&str; 4] = ["ray-query", "unrolled", "portal", "path-textures"];

fn points(records: &[Record]) -> Vec<&Record> {
    records.iter().filter(|r| r.kind == "point").collect()
}

/// `ssr`'s fallback (`cubemap` where the key leaves it at its default).
fn fallback(r: &Record) -> String {
    r.option("ssr-fallback").unwrap_or("cubemap").to_string()
}

/// A point's method as its key names it (`cubemap cube-size=128 history=16`,
/// `ssr ssr-fallback=none`, `auxiliary n=2`), without the depth: the table's column and the
/// depth charts' x.
fn key_name(r: &Record) -> String {
    r.method_key()
        .split_whitespace()
        .filter(|w| !w.starts_with("depth="))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A point's name in a legend or a row: [`key_name`], `(defaults)` added where a variant of
/// the method with options is among `others` (`ssr (defaults)` beside `ssr
/// ssr-fallback=none`, as the report's generic charts name them).
fn name(r: &Record, others: &[&str]) -> String {
    mirrorbox_report::document::legend_name(&key_name(r), others)
}

/// The points' names ([`key_name`]), each once.
fn variants_of(pts: &[&Record]) -> Vec<String> {
    distinct(pts.iter().map(|r| key_name(r)))
}

/// [`keyed_styles`] of the `fixed` methods at their defaults, then of each of `pts` keyed by
/// its options, as the generic charts key a variant whose counts are its points.
fn styles_of<'a>(fixed: impl Iterator<Item = &'a str>, pts: &[&'a Record]) -> Vec<Style> {
    let keys: Vec<StyleKey> = fixed
        .map(|method| StyleKey {
            method,
            variant: "",
            outside: false,
        })
        .chain(pts.iter().map(|r| StyleKey {
            method: &r.method,
            variant: &r.method_options,
            outside: r.is_external(),
        }))
        .collect();
    keyed_styles(&keys)
}

/// Spearman's rank correlation of `(x, y)` (ties at their mean rank).
pub(crate) fn spearman(points: &[(f64, f64)]) -> Option<f64> {
    let ranks = |v: Vec<f64>| -> Vec<f64> {
        let mut idx: Vec<usize> = (0..v.len()).collect();
        idx.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
        let mut r = vec![0.0; v.len()];
        let mut i = 0;
        while i < idx.len() {
            let mut j = i;
            while j + 1 < idx.len() && v[idx[j + 1]] == v[idx[i]] {
                j += 1;
            }
            for k in i..=j {
                r[idx[k]] = (i + j) as f64 / 2.0;
            }
            i = j + 1;
        }
        r
    };
    let xs = ranks(points.iter().map(|p| p.0).collect());
    let ys = ranks(points.iter().map(|p| p.1).collect());
    let pairs: Vec<(f64, f64)> = xs.into_iter().zip(ys).collect();
    let n = pairs.len() as f64;
    if pairs.len() < 3 {
        return None;
    }
    let (mx, my) = pairs
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let cov: f64 = pairs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let vx: f64 = pairs.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let vy: f64 = pairs.iter().map(|(_, y)| (y - my).powi(2)).sum();
    (vx > 0.0 && vy > 0.0).then(|| cov / (vx * vy).sqrt())
}

/// The section: nothing where the sweep measured neither `ssr` nor `ray-query`.
/// `truth`: the sweep's truth in words (the screen sweeps compare with the one-bounce truth).
pub fn engine_reflections_section(records: &[Record], truth: &str) -> Vec<Block> {
    let pts = points(records);
    if !pts
        .iter()
        .any(|r| r.method == "ssr" || r.method == "ray-query")
    {
        return Vec::new();
    }
    let mut out = vec![Block::Heading(
        2,
        "What engines ship: screen-space and ray-query reflections".into(),
    )];
    if pts.iter().any(|r| r.axis(YAW).is_some()) {
        out.extend(screen_blocks(&pts, truth));
    } else {
        out.extend(depth_blocks(&pts));
    }
    out
}

/// Error and cost against the depth cap.
fn depth_blocks(pts: &[&Record]) -> Vec<Block> {
    let mut out = Vec::new();
    let mut error = Chart::new(
        "FLIP over the mirror pixels against the depth cap",
        depth_axis(),
        "FLIP mean over the mirror pixels",
    );
    error.x_log = true;
    error.y_log = true;
    error.x_ticks_at_data = true;
    let mut cost = Chart::new(
        "Cost against the depth cap",
        depth_axis(),
        "ms/frame (median, 95 % CI bars)",
    );
    cost.x_log = true;
    cost.y_log = true;
    cost.x_ticks_at_data = true;
    let mut sentences = Vec::new();
    let bars = mirrorbox_report::ms_bars_for(pts.iter().copied());
    // The depth-swept methods, one series each along the depth.
    let swept: Vec<(&str, Vec<&Record>)> = DEPTH_SWEPT
        .iter()
        .map(|&m| {
            let mut of: Vec<&Record> = pts
                .iter()
                .copied()
                .filter(|r| r.method == m && r.depth.is_some())
                .collect();
            of.sort_by_key(|r| r.depth);
            (m, of)
        })
        .filter(|(_, of)| !of.is_empty())
        .collect();
    // The other methods by variant (method and options), each a series along its count or
    // swept option (auxiliary's n, cubemap's cube size), labelled as the generic charts label
    // them; joined where the reflections shown grow with it.
    let single: Vec<&Record> = pts
        .iter()
        .copied()
        .filter(|r| !DEPTH_SWEPT.contains(&r.method.as_str()))
        .collect();
    let variants = distinct(
        single
            .iter()
            .map(|r| mirrorbox_report::document::variant(r)),
    );
    let groups: Vec<Vec<&Record>> = variants
        .iter()
        .map(|v| {
            let mut of: Vec<&Record> = single
                .iter()
                .copied()
                .filter(|r| &mirrorbox_report::document::variant(r) == v)
                .collect();
            of.sort_by_key(|r| (r.reflections, r.n));
            of
        })
        .collect();
    let styles = styles_of(
        swept.iter().map(|(m, _)| *m),
        &groups.iter().map(|g| g[0]).collect::<Vec<_>>(),
    );
    for ((m, of), &style) in swept.iter().zip(&styles) {
        let d = |r: &Record| f64::from(r.depth.unwrap_or(0));
        error.series.push(Series::new(
            *m,
            style,
            of.iter().map(|r| (d(r), r.mirror_flip())).collect(),
        ));
        let mut s = Series::new(*m, style, of.iter().map(|r| (d(r), r.ms_median)).collect());
        s.bars = bars;
        s.y_intervals = of.iter().map(|r| r.ms_bars(s.bars)).collect();
        cost.series.push(s);
        // The last doubling's factor says how the cost grows: near 1 where a bounce costs
        // little beside the frame, near 2 where it grows linearly with the depth, far above
        // where the paths branch (the room).
        if let [.., prev, last] = &of[..]
            && let Some(first) = of.first()
        {
            sentences.push(format!(
                "`{m}`: {} ms/frame at depth {} and {} at depth {}; the last doubling of the \
                 depth ({} → {}) took the time ×{}.",
                ms_cell(first, 2),
                first.depth.unwrap_or(0),
                ms_cell(last, 2),
                last.depth.unwrap_or(0),
                prev.depth.unwrap_or(0),
                last.depth.unwrap_or(0),
                f(last.ms_median / prev.ms_median, 2)
            ));
        }
    }
    // Named as the report's other charts name them, "(defaults)" beside a variant.
    let names: Vec<&str> = variants.iter().map(String::as_str).collect();
    for ((v, of), &style) in variants.iter().zip(&groups).zip(&styles[swept.len()..]) {
        let legend = mirrorbox_report::document::legend_name(v, &names);
        let labels = mirrorbox_report::document::point_labels(of);
        let series = |y: fn(&Record) -> f64| {
            let points = of
                .iter()
                .map(|r| (r.reflections.max(1) as f64, y(r)))
                .collect();
            let mut s = Series::new(legend.clone(), style, points);
            s.joined = of.len() > 1 && s.points.windows(2).all(|w| w[1].0 > w[0].0);
            s.labels = labels.clone();
            s
        };
        error.series.push(series(Record::mirror_flip));
        // Every median with its bars, as the swept methods' (the axis says they are there).
        let mut timed = series(|r| r.ms_median);
        timed.bars = bars;
        timed.y_intervals = of.iter().map(|r| r.ms_bars(bars)).collect();
        cost.series.push(timed);
    }
    out.push(Block::Paragraph(
        "`ray-query` follows every mirror pixel's chain on the GPU; `unrolled` and `portal` \
         draw every reflection path of the scene as raster work; `auxiliary n=2` is the \
         paper's; `ssr` shows one bounce, what is on screen, and its fallback elsewhere. The \
         methods without a depth cap sit at the reflections they show, one series per variant \
         along its count or swept option (labelled: auxiliary's n, a cube size)."
            .into(),
    ));
    out.push(Block::Chart(
        "engine_error_depth.svg".into(),
        Box::new(error),
    ));
    out.push(Block::Chart("engine_ms_depth.svg".into(), Box::new(cost)));
    if !sentences.is_empty() {
        out.push(Block::Bullets(sentences));
    }
    out.push(table(pts, false));
    out
}

/// `ssr` against the share of reflections off screen, per fallback.
fn screen_blocks(pts: &[&Record], truth: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let ssr: Vec<&Record> = pts
        .iter()
        .copied()
        .filter(|r| r.method == "ssr" && r.value(value::REFLECTION_OFFSCREEN_SHARE).is_some())
        .collect();
    let mut chart = Chart::new(
        "ssr: FLIP over the mirror pixels against the reflections off screen",
        "share of mirror pixels whose first reflection is off screen",
        "FLIP mean over the mirror pixels",
    );
    let fallbacks = distinct(ssr.iter().map(|r| fallback(r)));
    let shown: Vec<&str> = ["none", "cubemap", "planar"]
        .into_iter()
        .filter(|f| fallbacks.iter().any(|g| g == f))
        .collect();
    // Each fallback's series named and drawn as the report's other charts have it: the
    // variant's name (`ssr ssr-fallback=none`, `ssr (defaults)`) and its keyed style.
    let firsts: Vec<&Record> = shown
        .iter()
        .filter_map(|fb| ssr.iter().copied().find(|r| fallback(r) == *fb))
        .collect();
    let variants = variants_of(&firsts);
    let names: Vec<&str> = variants.iter().map(String::as_str).collect();
    let styles = styles_of(std::iter::empty(), &firsts);
    let mut bullets = Vec::new();
    for ((fb, variant), style) in shown.iter().zip(&variants).zip(styles) {
        let mut of: Vec<&Record> = ssr.iter().copied().filter(|r| fallback(r) == *fb).collect();
        of.sort_by(|a, b| {
            a.value(value::REFLECTION_OFFSCREEN_SHARE)
                .unwrap_or(0.0)
                .total_cmp(&b.value(value::REFLECTION_OFFSCREEN_SHARE).unwrap_or(0.0))
        });
        let xy: Vec<(f64, f64)> = of
            .iter()
            .map(|r| {
                (
                    r.value(value::REFLECTION_OFFSCREEN_SHARE).unwrap_or(0.0),
                    r.mirror_flip(),
                )
            })
            .collect();
        let legend = mirrorbox_report::document::legend_name(variant, &names);
        let mut s = Series::new(legend, style, xy.clone());
        // Each point is a camera turn: x is not a swept variable, so no line.
        s.joined = false;
        s.labels = of
            .iter()
            .map(|r| mirrorbox_report::axis::label(YAW, r.axis(YAW).unwrap_or(0.0)))
            .collect();
        chart.series.push(s);
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
        };
        let rho = spearman(&xy).map_or("–".into(), |r| f(r, 2));
        bullets.push(format!(
            "fallback `{fb}`: FLIP over the mirror pixels from {} to {} over {} camera turns \
             (median {}); Spearman's ρ against the off-screen share {rho}; median {} ms/frame.",
            sci(xy.iter().map(|p| p.1).fold(f64::INFINITY, f64::min)),
            sci(xy.iter().map(|p| p.1).fold(0.0, f64::max)),
            xy.len(),
            sci(median(xy.iter().map(|p| p.1).collect())),
            f(median(of.iter().map(|r| r.ms_median).collect()), 2),
        ));
    }
    out.push(Block::Paragraph(format!(
        "Each point is one camera turn (`yaw_deg`, labelled): the same scene with more or less \
         of what its mirrors reflect on screen, against the truth `{truth}` — one bounce, what \
         `ssr` shows at best, so the error left is what the screen lacks and the march's \
         artefacts, not the deeper reflections. Where the share grows the fallback carries the \
         image; `planar` is exact at one bounce, so its error is the march's alone."
    )));
    out.push(Block::Chart("ssr_offscreen.svg".into(), Box::new(chart)));
    out.push(Block::Bullets(bullets));
    out.push(table(pts, true));
    out
}

/// Every point: method, depth, errors, cost (and the turn and off-screen share).
fn table(pts: &[&Record], screen: bool) -> Block {
    let mut header = vec!["method".to_string()];
    if screen {
        header.push("yaw".into());
        header.push("off screen".into());
    } else {
        header.push("reflections".into());
    }
    for h in ["FLIP mean", "FLIP, mirror pixels", "ms/frame", "passes"] {
        header.push(h.into());
    }
    let variants = variants_of(pts);
    let variants: Vec<&str> = variants.iter().map(String::as_str).collect();
    let rows = pts
        .iter()
        .map(|r| {
            let mut row = vec![format!("`{}`", name(r, &variants))];
            if screen {
                row.push(r.axis(YAW).map_or("–".into(), |y| format!("{y}°")));
                row.push(
                    r.value(value::REFLECTION_OFFSCREEN_SHARE)
                        .map_or("–".into(), |s| format!("{} %", f(100.0 * s, 1))),
                );
            } else {
                row.push(r.depth.unwrap_or(r.reflections as u32).to_string());
            }
            row.push(sci(r.metrics.flip_mean));
            row.push(
                r.mirror_metrics
                    .as_ref()
                    .map_or("–".into(), |m| sci(m.flip_mean)),
            );
            row.push(ms_cell(r, 2));
            row.push(r.passes.to_string());
            row
        })
        .collect();
    Block::Table(header, rows)
}

/// The section, offered every sweep's records; empty where no engine method was measured.
pub fn section(info: &mirrorbox_report::SweepInfo, records: &[Record]) -> Vec<Block> {
    engine_reflections_section(records, &info.truth)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point measured with `key` (method and options, then a count), at `reflections`.
    fn point(key: &str, reflections: usize, flip: f64) -> Record {
        let mut r = mirrorbox_report::document::fixtures::record(0, 5.0, 1, flip);
        let mut words = key.split_whitespace();
        r.method = words.next().unwrap().into();
        r.n = None;
        let mut options = Vec::new();
        for w in words {
            match w.split_once('=') {
                Some(("n", v)) => r.n = v.parse().ok(),
                Some(("depth", v)) => r.depth = v.parse().ok(),
                _ => options.push(w),
            }
        }
        r.method_options = options.join(" ");
        r.ms_interval = Some([4.5, 5.5]);
        r.key = format!("{key}|alpha=1|320x180");
        r.reflections = reflections;
        r
    }

    /// The depth charts: a depth-swept method joined along the depth; the paper's auxiliary
    /// mirrors one series along n, joined and labelled as the generic charts draw them; ssr's
    /// fallbacks named as the generic charts name them, its defaults in its own style; the
    /// table's rows named by their keys without the depth.
    #[test]
    fn the_depth_charts_draw_each_variant_along_its_count() {
        let records = [
            point("ray-query depth=1", 1, 0.1),
            point("ray-query depth=4", 4, 0.01),
            point("auxiliary n=1", 2, 0.05),
            point("auxiliary n=2", 4, 0.02),
            point("ssr", 1, 0.3),
            point("ssr ssr-fallback=none", 1, 0.4),
        ];
        let blocks = engine_reflections_section(&records, "truth");
        let Some(Block::Chart(_, error)) = blocks
            .iter()
            .find(|b| matches!(b, Block::Chart(f, _) if f == "engine_error_depth.svg"))
        else {
            panic!("no depth chart");
        };
        let names: Vec<&str> = error.series.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "ray-query",
                "auxiliary",
                "ssr (defaults)",
                "ssr ssr-fallback=none"
            ]
        );
        let aux = &error.series[1];
        assert!(aux.joined && aux.points == [(2.0, 0.05), (4.0, 0.02)]);
        assert_eq!(aux.labels, ["n=1", "n=2"]);
        assert_eq!(
            error.series[2].style,
            mirrorbox_report::plot::method_style("ssr")
        );
        assert_ne!(error.series[3].style, error.series[2].style);
        let Some(Block::Table(_, rows)) = blocks.iter().find(|b| matches!(b, Block::Table(..)))
        else {
            panic!("no table");
        };
        let first: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
        assert!(
            first.contains(&"`ray-query`") && first.contains(&"`auxiliary n=2`"),
            "{first:?}"
        );
        assert!(first.contains(&"`ssr (defaults)`"), "{first:?}");
        // The cost chart: every median with its bars, the methods without a depth cap too
        // (their medians had been drawn bare under an axis that says "bars").
        let Some(Block::Chart(_, cost)) = blocks
            .iter()
            .find(|b| matches!(b, Block::Chart(f, _) if f == "engine_ms_depth.svg"))
        else {
            panic!("no cost chart");
        };
        for s in &cost.series {
            assert!(
                s.y_intervals.len() == s.points.len() && s.y_intervals.iter().all(Option::is_some),
                "{}: {:?}",
                s.name,
                s.y_intervals
            );
        }
    }

    #[test]
    fn rank_correlation() {
        let rising = [(0.1, 1.0), (0.2, 4.0), (0.5, 9.0), (0.9, 20.0)];
        assert!((spearman(&rising).unwrap() - 1.0).abs() < 1e-12);
        let falling: Vec<(f64, f64)> = rising.iter().map(|&(x, y)| (x, -y)).collect();
        assert!((spearman(&falling).unwrap() + 1.0).abs() < 1e-12);
        assert_eq!(spearman(&rising[..2]), None);
    }
}
