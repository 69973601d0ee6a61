//! The document model every report is written in — blocks that render to Markdown and HTML
//! alike — and the formatting rules its sentences and tables share (digits scaled to an
//! interval, ties said as ties, errors at the floor not ranked). Report sections import this
//! module; none imports the writer (`write.rs`), which imports them: no import circle.
//! An experiment's own report section (`mirrorbox-experiments`) is written in it too: a
//! [`Section`] returns blocks, the writer places them.

use crate::Record;
use crate::plot::Chart;
use std::fmt::Write as _;

/// A report section: the blocks it adds to a sweep's report, or none where the sweep's
/// records are not its experiment's (every section is offered every sweep).
pub type Section = fn(&crate::SweepInfo, &[Record]) -> Vec<Block>;

pub enum Block {
    Heading(u8, String),
    Paragraph(String),
    Bullets(Vec<String>),
    Table(Vec<String>, Vec<Vec<String>>),
    /// Images side by side: (caption, path relative to the report).
    Images(Vec<(String, String)>),
    /// An SVG chart, written to `file` and embedded in the HTML — only where it is drawable
    /// ([`Chart::is_drawable`]); the writer adds its footer.
    Chart(String, Box<Chart>),
}

/// The x axis of a chart against the depth cap, the same words in every report.
pub const DEPTH_CAP_AXIS: &str = "depth cap (most mirrors along a path)";

/// Bytes in a mebibyte (the tables' memory unit).
pub(crate) const MIB: f64 = 1024.0 * 1024.0;

pub fn f(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        "–".into()
    }
}

/// `a` and `b` with the fewest decimals (2 to 4) that print them apart, or `None` where they
/// agree to four: "1.38–1.38×" had said nothing of 1.3807 and 1.3813.
pub fn apart(a: f64, b: f64) -> Option<(String, String)> {
    (2..=4)
        .find(|&d| format!("{a:.d$}") != format!("{b:.d$}"))
        .map(|d| (format!("{a:.d$}"), format!("{b:.d$}")))
}

/// Decimals for a time: at least `digits`, and enough for three significant digits below 100
/// (a GPU frame of 0.403 ms must not print as "0.4"), at most six.
pub fn ms_digits(v: f64, digits: usize) -> usize {
    if !(v.is_finite() && v > 0.0) || v >= 100.0 {
        return digits;
    }
    let needed = (2.0 - v.log10().floor()).max(0.0) as usize;
    digits.max(needed.min(6))
}

/// A time in ms with [`ms_digits`] decimals.
pub fn ms(v: f64, digits: usize) -> String {
    f(v, ms_digits(v, digits))
}

/// `values` without repeats, in first-seen order (a report's rows and series).
pub fn distinct<T: PartialEq>(values: impl Iterator<Item = T>) -> Vec<T> {
    let mut out: Vec<T> = Vec::new();
    for v in values {
        if !out.contains(&v) {
            out.push(v);
        }
    }
    out
}

pub fn sci(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.3e}")
    } else {
        "–".into()
    }
}

/// The paired 95 % interval of `a`'s median time over `b`'s, where both were timed in the
/// same interleaved rounds of the same run ([`crate::stats::paired_ratio_interval`]).
pub fn paired_ratio(a: &Record, b: &Record) -> Option<crate::stats::Interval> {
    let same_rounds = a.timing_order == "interleaved"
        && b.timing_order == "interleaved"
        && a.run.is_some()
        && a.run == b.run;
    same_rounds
        .then(|| crate::stats::paired_ratio_interval(&a.frames_ms, &b.frames_ms))
        .flatten()
}

/// "median [low–high]" (older records: "median (min m)"), all with the median's decimals.
pub fn ms_cell(r: &Record, digits: usize) -> String {
    match r.ms_interval {
        Some([low, high]) => {
            let digits = interval_digits(low, high);
            format!(
                "{} [{}–{}]",
                f(r.ms_median, digits),
                f(low, digits),
                f(high, digits)
            )
        }
        None => {
            let digits = ms_digits(r.ms_median, digits);
            format!("{} (min {})", f(r.ms_median, digits), f(r.ms_min, digits))
        }
    }
}

/// The heading of a column of [`ms_cell`]s: "`label` [95 % CI]" where every record has an
/// interval, "`label` (min)" where none has one (fewer than
/// [`crate::stats::MIN_FRAMES_FOR_INTERVAL`] frames: the median and the fastest frame), and
/// both where the column mixes them — a heading never promises intervals its cells lack.
pub fn ms_heading<'a>(label: &str, records: impl IntoIterator<Item = &'a Record>) -> String {
    let (mut with, mut without) = (false, false);
    for r in records {
        match r.ms_interval {
            Some(_) => with = true,
            None => without = true,
        }
    }
    match (with, without) {
        (_, false) => format!("{label} [95 % CI]"),
        (false, true) => format!("{label} (min)"),
        (true, true) => format!("{label} [95 % CI] or (min)"),
    }
}

/// Decimals for a value printed with its interval `[low, high]`: two significant digits of
/// the interval's width — what the interval can tell apart, and no more (an interval from six
/// frames does not know a fourth digit). A zero-width interval gets three significant digits
/// of its value.
pub fn interval_digits(low: f64, high: f64) -> usize {
    let width = (high - low).abs();
    let basis = if width > 0.0 && width.is_finite() {
        width
    } else {
        low.abs().max(1e-12) / 10.0
    };
    (1.0 - basis.log10().floor()).clamp(0.0, 8.0) as usize
}

/// Those of `candidates` within [`TIE_TOLERANCE`] of the lowest `value`: one winner, or a tie.
pub fn lowest_with_ties<'a>(
    candidates: impl Iterator<Item = &'a Record>,
    value: impl Fn(&Record) -> f64,
) -> Vec<&'a Record> {
    let all: Vec<&Record> = candidates.collect();
    let Some(best) = all.iter().map(|r| value(r)).min_by(f64::total_cmp) else {
        return Vec::new();
    };
    all.into_iter()
        .filter(|r| value(r) <= best * (1.0 + TIE_TOLERANCE) + f64::EPSILON)
        .collect()
}

/// `a`, `a and b`, `a, b and c`.
pub fn join_words(words: &[String]) -> String {
    match words {
        [] => String::new(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// Two errors within 2 % of each other are a tie: the spread of one method's error between
/// runs of the same sweep is of that order.
pub const TIE_TOLERANCE: f64 = 0.02;

/// A point's name in a row or caption: its variant with its count (`auxiliary n=2`,
/// `portal depth=8`, `symmetry p=3`) or its swept option (`cubemap cube-size=128
/// history=16`), and `k=…` for a mirrored-lights depth.
pub fn label(r: &Record) -> String {
    let name = variant(r);
    let at = match (r.n, r.depth, r.planes()) {
        (Some(n), _, _) => format!("{name} n={n}"),
        (None, Some(d), _) => format!("{name} depth={d}"),
        (None, None, Some(p)) => format!("{name} p={p}"),
        // A swept option (cubemap's cube-size) is in the key, not the options: the key names
        // the point whole, where two cube sizes had read alike.
        _ if !r.is_external() && !swept_label(r).is_empty() => r.method_key().to_string(),
        _ => name,
    };
    match r.lights_depth() {
        Some(k) => format!("{at} k={k}"),
        None => at,
    }
}

/// A point's error counts as at the floor up to this multiple of the floor's FLIP mean: the
/// floor itself varies by that much between renders of the same scene.
pub const FLOOR_FACTOR: f64 = 1.5;

/// Whether `r`'s whole-image FLIP mean is at or under the floor `fl` (within [`FLOOR_FACTOR`]):
/// not resolved by the comparison, so not ranked.
pub fn at_or_under_floor(r: &Record, fl: &Record) -> bool {
    r.metrics.flip_mean <= FLOOR_FACTOR * fl.metrics.flip_mean
}

/// The setting a point's method was swept at, for a chart's point labels: `n=2`, `d=64`, or
/// the swept option read from the point's key (`cube-size=128`); empty for a method with none.
pub fn swept_label(r: &Record) -> String {
    if let Some(n) = r.n {
        return format!("n={n}");
    }
    if let Some(d) = r.depth {
        return format!("d={d}");
    }
    let method = r.method_key();
    let options: Vec<&str> = r.method_options.split_whitespace().collect();
    method
        .split_whitespace()
        .skip(1)
        .filter(|w| !options.contains(w))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Each point's label in one series: its swept setting ([`swept_label`]) and its scene axes
/// ([`crate::axis::label`]), each kept only where it varies among the series' points — a part
/// every point shares says nothing about which point is which, and an axis left out had left
/// the points of a camera-turn sweep without a word. A series of one point, or of points
/// alike in every part, is labelled by its swept setting alone.
pub fn point_labels(pts: &[&Record]) -> Vec<String> {
    let names = distinct(pts.iter().flat_map(|r| r.axes.keys().cloned()));
    let columns: Vec<Vec<String>> = std::iter::once(pts.iter().map(|r| swept_label(r)).collect())
        .chain(names.iter().map(|n| {
            pts.iter()
                .map(|r| {
                    r.axis(n)
                        .map_or(String::new(), |v| crate::axis::label(n, v))
                })
                .collect()
        }))
        .collect();
    let varying: Vec<&Vec<String>> = columns
        .iter()
        .filter(|c| c.iter().any(|v| v != &c[0]))
        .collect();
    if varying.is_empty() {
        return columns[0].clone();
    }
    (0..pts.len())
        .map(|i| {
            varying
                .iter()
                .map(|c| c[i].as_str())
                .filter(|v| !v.is_empty())
                .collect::<Vec<_>>()
                .join(", ")
        })
        .collect()
}

/// Text for HTML, in an element or an attribute: `&`, `<`, `>` and `"` escaped.
pub fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Whether an image block is a truth | raster | FLIP row (its last caption names FLIP).
pub fn is_flip_row(images: &[(String, String)]) -> bool {
    images.len() == 3 && images[2].0.starts_with("FLIP")
}

/// The Markdown line under a FLIP row: the ramp its map is painted with.
pub const COLOUR_BAR_MD: &str =
    "FLIP per pixel: black 0 → purple → red → orange → yellow → white 1.";

pub(crate) use mirrorbox_files::remove_stale;

/// The blocks as Markdown (charts and images as links to their files).
pub fn markdown(blocks: &[Block]) -> String {
    let mut md = String::new();
    for b in blocks {
        match b {
            Block::Heading(level, t) => {
                let _ = writeln!(md, "{} {t}\n", "#".repeat(*level as usize));
            }
            Block::Paragraph(t) => {
                let _ = writeln!(md, "{t}\n");
            }
            Block::Bullets(items) => {
                for i in items {
                    let _ = writeln!(md, "- {i}");
                }
                md.push('\n');
            }
            Block::Table(head, rows) => {
                let _ = writeln!(md, "| {} |", head.join(" | "));
                let _ = writeln!(md, "|{}", "---|".repeat(head.len()));
                for r in rows {
                    let _ = writeln!(md, "| {} |", r.join(" | "));
                }
                md.push('\n');
            }
            Block::Images(images) => {
                let line: Vec<String> = images
                    .iter()
                    .map(|(cap, p)| format!("![{cap}]({p})"))
                    .collect();
                let _ = writeln!(md, "{}\n", line.join(" "));
                if is_flip_row(images) {
                    let _ = writeln!(md, "{}\n", COLOUR_BAR_MD);
                }
                if let [(cap, _)] = &images[..]
                    && cap.contains("inset")
                {
                    let _ = writeln!(md, "{cap}\n");
                }
            }
            Block::Chart(file, chart) => {
                if chart.is_drawable() {
                    let _ = writeln!(md, "![{file}]({file})\n");
                }
            }
        }
    }
    md
}

/// A variant's name in a legend beside `others` (the chart's variants): a bare method name
/// (its defaults) where the chart also has the method with options says so, "ssr (defaults)":
/// alone beside "ssr ssr-fallback=none" it read as ssr in general.
pub fn legend_name(variant: &str, others: &[&str]) -> String {
    let prefix = format!("{variant} ");
    if !variant.contains(' ') && others.iter().any(|o| o.starts_with(&prefix)) {
        format!("{variant} (defaults)")
    } else {
        variant.to_string()
    }
}

pub fn variant(r: &Record) -> String {
    // An outside renderer's variant (`mirrorbox score`) is named by its method alone: its
    // knobs are in its report's table and variants.md, not in every legend.
    if r.method_options.is_empty() || r.is_external() {
        r.method.clone()
    } else {
        format!("{} {}", r.method, r.method_options)
    }
}

/// Records for tests: this crate's and the experiments' (whose sections are tested on them).
#[doc(hidden)]
pub mod fixtures {
    use crate::{MetricValues, Record};

    pub fn record(n: u32, ms: f64, passes: usize, flip: f64) -> Record {
        Record {
            key: format!("auxiliary n={n}"),
            kind: "point".into(),
            scene: "s.json".into(),
            scene_hash: "00".into(),
            method: "auxiliary".into(),
            method_options: String::new(),
            axes: Default::default(),
            values: Default::default(),
            legacy: Default::default(),
            stereo: None,
            device: None,
            n: Some(n),
            depth: None,
            alpha: 0.7,
            width: 16,
            height: 16,
            ssaa: 1,
            ms_median: ms,
            ms_interval: None,
            frames_ms: Vec::new(),
            timing_order: "back-to-back".into(),
            run: None,
            peak_memory_bytes: None,
            plan_ms: None,
            encode_ms: None,
            gpu_buffer_bytes: None,
            gpu_texture_bytes: None,
            ms_min: ms,
            timing_source: "gpu-timestamps".into(),
            frames: 1,
            passes,
            draws: 2 * passes,
            texture_renders: passes - 1,
            reflections: n as usize + 2,
            triangles: None,
            paths: None,
            paths_pruned: None,
            metrics: MetricValues {
                rmse: flip,
                relmse: flip,
                smape: flip,
                max_abs: flip,
                psnr: Some(30.0),
                ssim: 0.9,
                flip_mean: flip,
                flip_p95: flip,
                flip_p99: flip,
            },
            mirror_metrics: None,
            mirror_pixel_share: None,
            split: None,
            adapter: "test".into(),
            backend: "vulkan".into(),
            color_format: "rgba32float".into(),
            truth_image: "t.png".into(),
            raster_image: "r.png".into(),
            heatmap_image: "h.png".into(),
        }
    }
}

/// A point's place on its method's axis: n, the depth, or the symmetry planes p.
pub fn setting(r: &Record) -> f64 {
    r.n.or(r.depth).or(r.planes()).map_or(0.0, f64::from)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A column's heading names what its cells hold: intervals, the fastest frame, or both.
    /// A method at its defaults is named so in a legend only beside its own variants with
    /// options: "ssr (defaults)" beside "ssr ssr-fallback=none", "ssr" alone, and a
    /// variant with options or another method's prefix ("ssr" beside "ssr-x y") as it is.
    #[test]
    fn a_method_at_its_defaults_says_so_beside_its_variants() {
        let chart = ["ssr", "ssr ssr-fallback=none", "portal depth=64", "naive"];
        assert_eq!(legend_name("ssr", &chart), "ssr (defaults)");
        assert_eq!(
            legend_name("ssr ssr-fallback=none", &chart),
            "ssr ssr-fallback=none"
        );
        assert_eq!(legend_name("naive", &chart), "naive");
        assert_eq!(legend_name("ssr", &["ssr", "portal depth=8"]), "ssr");
        assert_eq!(legend_name("ssr", &["ssr", "ssr-x y"]), "ssr");
    }

    /// A label says what tells a series' points apart: the camera turn where only it varies,
    /// the swept n where only it does, both where both do; n alone for one point.
    #[test]
    fn point_labels_name_what_varies_within_the_series() {
        let turned = |n: u32, yaw: f64| {
            let mut r = fixtures::record(n, 1.0, 1, 0.1);
            r.axes.insert(crate::axis::YAW_DEG.into(), yaw);
            r
        };
        let (a, b, c) = (turned(2, -22.5), turned(2, 45.0), turned(3, 45.0));
        assert_eq!(point_labels(&[&a, &b]), ["yaw -22.5°", "yaw 45°"]);
        assert_eq!(point_labels(&[&b, &c]), ["n=2", "n=3"]);
        assert_eq!(point_labels(&[&a, &c]), ["n=2, yaw -22.5°", "n=3, yaw 45°"]);
        assert_eq!(point_labels(&[&a]), ["n=2"]);
        assert_eq!(point_labels(&[&b, &b]), ["n=2", "n=2"]);
        let plain = fixtures::record(1, 1.0, 1, 0.1);
        assert_eq!(point_labels(&[&plain, &a]), ["n=1", "n=2, yaw -22.5°"]);
    }

    /// Two points of a swept option (cube sizes) are named apart, as their key names them.
    #[test]
    fn a_label_names_the_swept_option() {
        let mut r = fixtures::record(0, 1.0, 1, 0.1);
        (r.n, r.method) = (None, "cubemap".into());
        r.method_options = "history=16".into();
        r.key = "cubemap cube-size=128 history=16|alpha=1|320x180".into();
        assert_eq!(label(&r), "cubemap cube-size=128 history=16");
        r.key = "cubemap history=16|alpha=1|320x180".into();
        assert_eq!(label(&r), "cubemap history=16");
    }

    #[test]
    fn ms_heading_promises_only_what_the_cells_hold() {
        let with = Record {
            ms_interval: Some([0.9, 1.1]),
            ..fixtures::record(0, 1.0, 1, 0.1)
        };
        let without = Record {
            ms_interval: None,
            ..fixtures::record(1, 2.0, 1, 0.1)
        };
        assert!(ms_cell(&with, 2).contains('['));
        assert!(ms_cell(&without, 2).contains("(min "));
        assert_eq!(ms_heading("ms", [&with]), "ms [95 % CI]");
        assert_eq!(ms_heading("ms", [&without]), "ms (min)");
        assert_eq!(ms_heading("ms", [&with, &without]), "ms [95 % CI] or (min)");
    }
}
