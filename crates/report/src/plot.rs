//! The reports' SVG charts: one question per chart, one fixed style per method.
//!
//! Rules every chart follows (issue 38), enforced here rather than by each report section:
//! - a method has one colour and one marker in every report ([`method_style`]); a variant of a
//!   method (its options, α, a lighting or stereo variant) keeps the colour and changes the
//!   dash, the marker's fill and from its third variant the marker ([`method_variant`]), the
//!   one its key gives it in every report ([`keyed_styles`]); the colours are Okabe and Ito's
//!   colour-blind-safe set;
//! - a series is joined by a line only when its points are one variable swept
//!   ([`Series::joined`]); otherwise it is markers only;
//! - log axes are tight to the data (not rounded out to whole decades); the comparison's floor
//!   is an annotation (a shaded band, or a note when it lies far below the data), never a
//!   reason to stretch the axis;
//! - reference curves (2^p, one full-scene pass) are dashed grey and named "reference: …";
//! - point labels never overprint: a label that would touch another is left out, and so is
//!   one that would lie as near another point as its own (it would read as that point's);
//! - markers of series that coincide are drawn as rings around each other, and the legend says
//!   which series it coincides with;
//! - a footer names the scene, size, device, date and commit ([`Chart::footer`]);
//! - a chart with fewer than two distinct x is not drawn at all ([`Chart::is_drawable`]).
//!
//! Hand-written rather than `plotters`: these rules are most of the code either way, the
//! text needs no font files (plotters' SVG backend measures text with a font backend or not
//! at all), and the test build's budget (≤ 10 min on 2 cores) has no room for another
//! dependency tree.

use std::fmt::Write;

/// Okabe & Ito's palette without its yellow (too light on white), plus a dark grey.
const COLORS: [&str; 7] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#333333",
];
/// The least distance between two tick labels' centres, pixels: a y label's height with a
/// little air, and an x label's width ("5e-16").
const Y_TICK_GAP: f64 = 13.0;
const X_TICK_GAP: f64 = 34.0;
/// Reference curves and floors.
const REFERENCE_GREY: &str = "#888888";
/// The dash of the i-th reference (cycled), in the plot and its legend alike: two references
/// of one chart (a Pareto front and a budget) are told apart by their dash.
const REFERENCE_DASHES: [&str; 3] = ["5 4", "1.5 3", "9 3 2 3"];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    Circle,
    Square,
    TriangleUp,
    Diamond,
    TriangleDown,
    Cross,
    Plus,
}

impl Marker {
    pub const ALL: [Marker; 7] = [
        Marker::Circle,
        Marker::Square,
        Marker::TriangleUp,
        Marker::Diamond,
        Marker::TriangleDown,
        Marker::Cross,
        Marker::Plus,
    ];
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Style {
    pub color: &'static str,
    pub marker: Marker,
    /// SVG `stroke-dasharray` of the series' line; empty for solid.
    pub dash: &'static str,
    /// Hollow markers (a method's variants after its first).
    pub hollow: bool,
}

/// Solid, dashed, dotted, dash-dot, long dash, dash-dot-dot: each told from the others at a
/// glance ("2 2 6 2" had read as the dash-dot).
const DASHES: [&str; 6] = ["", "7 4", "2 3", "8 3 2 3", "12 3", "12 3 2 3 2 3"];

/// A method's colour, its own marker, and the markers its variants take besides it: no other
/// method of its colour has any of them as its own or its variants', so that a variant of one
/// method never looks like another method or its variants (`ssr`'s planar fallback had taken
/// `feedback`'s diamond); nor does a variant take the own marker of a method whose colour is
/// near its own (orange and vermilion, blue and sky blue: the palette's pairs a reader can
/// confuse at a marker's size; tested). A name not in the table (a method added later) gets a colour and a
/// marker from its name's hash, in grey's place never, and no markers besides: the table is
/// the place to give a new method its own.
fn method_entry(method: &str) -> (&'static str, Marker, &'static [Marker]) {
    use Marker::*;
    match method {
        "naive" => (COLORS[4], TriangleDown, &[TriangleUp, Diamond]),
        "symmetry-baked" => (COLORS[4], Square, &[Cross, Plus]),
        "auxiliary" => (COLORS[1], Circle, &[TriangleUp, Diamond, Cross, Plus]),
        "path-textures" => (COLORS[3], Diamond, &[Circle]),
        "symmetry-pruned" => (COLORS[3], TriangleUp, &[Square]),
        "cubemap" => (COLORS[3], Cross, &[TriangleDown, Plus]),
        "portal" => (
            COLORS[2],
            Square,
            &[Circle, TriangleUp, Diamond, TriangleDown, Cross, Plus],
        ),
        "unrolled" => (COLORS[0], Plus, &[TriangleUp, TriangleDown, Cross]),
        "symmetry" => (COLORS[5], Circle, &[TriangleDown]),
        "feedback" => (COLORS[5], Diamond, &[Cross]),
        "ssr" => (COLORS[5], Square, &[TriangleUp]),
        "ray-query" => (
            COLORS[6],
            TriangleUp,
            &[Circle, Square, Diamond, TriangleDown, Plus],
        ),
        "truth" => (COLORS[6], Cross, &[]),
        other => {
            let h = other
                .bytes()
                .fold(0u32, |h, b| h.wrapping_mul(31).wrapping_add(u32::from(b)));
            let markers = Marker::ALL;
            (
                COLORS[h as usize % 6],
                markers[(h / 7) as usize % markers.len()],
                &[],
            )
        }
    }
}

/// The fixed style of every raster method (and the truth), the same in every report.
pub fn method_style(method: &str) -> Style {
    let (color, marker, _) = method_entry(method);
    Style {
        color,
        marker,
        dash: "",
        hollow: false,
    }
}

/// How many looks a method's points can take where no line shows the dash: its markers
/// (its own and its variants', [`method_entry`]), filled and hollow.
fn point_looks(method: &str) -> usize {
    2 * (1 + method_entry(method).2.len())
}

/// The `k`-th variant of `method`: its colour; hollow for odd `k`; the marker its own for
/// k = 0, 1, then the next of the method's variant markers every two `k` (so that variants
/// drawn as points alone, where no dash shows, stay apart: `ssr`'s fallbacks); the dash one
/// of six in turn. k = 0 is [`method_style`].
pub fn method_variant(method: &str, k: usize) -> Style {
    let (color, own, more) = method_entry(method);
    let markers = 1 + more.len();
    let at = (k / 2) % markers;
    Style {
        color,
        marker: if at == 0 { own } else { more[at - 1] },
        dash: DASHES[k % DASHES.len()],
        hollow: k % 2 == 1,
    }
}

/// The settings a sweep varies along one series (auxiliary's n, the depth cap, the symmetry
/// planes p, a history length, a cube size): where a chart draws one series per setting, the
/// setting tells them apart; where it draws one, the series looks as the method's series
/// along that setting does in the charts that sweep it.
const SETTINGS: [&str; 5] = ["n", "depth", "p", "history", "cube-size"];

/// A variant key's words as (options, settings) ([`SETTINGS`]), each in the order given, the
/// words split at spaces and commas (`n=2, mirrored, shadow maps 256²`).
fn split_settings(variant: &str) -> (String, String) {
    let (mut options, mut settings) = (Vec::new(), Vec::new());
    for w in variant.split([' ', ',']).filter(|w| !w.is_empty()) {
        if w.split_once('=')
            .is_some_and(|(n, _)| SETTINGS.contains(&n))
        {
            settings.push(w);
        } else {
            options.push(w);
        }
    }
    (options.join(" "), settings.join(" "))
}

/// What decides a series' style: its method, its variant's key (its options and count, a
/// lighting variant, "α=0.7"; empty at the method's defaults), and whether an outside renderer
/// (`mirrorbox score`) drew it.
#[derive(Clone, Copy, Debug)]
pub struct StyleKey<'a> {
    pub method: &'a str,
    pub variant: &'a str,
    pub outside: bool,
}

/// The styles of a chart's series: the method's own style for its defaults, and for a variant
/// the [`method_variant`] its key hashes to — the same variant keeps its style in every chart
/// of every report where no other variant of its method hashed to its place first
/// ("auxiliary n=2" is one marker and dash wherever it is drawn), where an index by order had
/// given it whatever place its chart's other variants left. A setting in the key
/// ([`SETTINGS`]: `n=2`, `cube-size=128`) counts only where the chart holds the same variant
/// at another setting. A key of α alone takes the method's marker, hollow, first (a second
/// other α the next place). A variant takes only its own method's markers
/// ([`method_entry`]), so another method's series never moves it. While the method's looks
/// last, no two series of one chart share one (marker and fill; then the dash tells them
/// apart, and past that the legend alone): a key whose look another variant of its method
/// took passes on to the next free one (hollow first for an outside renderer's).
pub fn keyed_styles(keys: &[StyleKey]) -> Vec<Style> {
    // Each key as (options, settings): the settings count only where the chart has another
    // series of the same method and options at other settings.
    let parts: Vec<(String, String)> = keys.iter().map(|k| split_settings(k.variant)).collect();
    let variants: Vec<String> = keys
        .iter()
        .zip(&parts)
        .map(|(k, (options, settings))| {
            let apart = keys.iter().zip(&parts).any(|(o, (oo, os))| {
                (o.method, o.outside) == (k.method, k.outside) && oo == options && os != settings
            });
            if apart {
                format!("{options} {settings}").trim().to_string()
            } else {
                options.clone()
            }
        })
        .collect();
    let keys: Vec<StyleKey> = keys
        .iter()
        .zip(&variants)
        .map(|(k, variant)| StyleKey { variant, ..*k })
        .collect();
    // What a reader tells markers apart by where no line shows the dash.
    let look = |s: &Style| (s.color, s.marker, s.hollow);
    let mut styles: Vec<Option<Style>> = vec![None; keys.len()];
    let mut taken: Vec<Style> = Vec::new();
    // The methods' defaults first: each keeps its own style whatever variants come before it.
    for (i, key) in keys.iter().enumerate() {
        let s = method_style(key.method);
        if key.variant.is_empty() && !key.outside && !taken.iter().any(|t| look(t) == look(&s)) {
            taken.push(s);
            styles[i] = Some(s);
        }
    }
    for (i, key) in keys.iter().enumerate() {
        if styles[i].is_some() {
            continue;
        }
        let looks = point_looks(key.method);
        // FNV-1a: fixed across runs and platforms, unlike std's hasher. A variant that is
        // the method at another α (a scene's, not the method's, setting) keeps the method's
        // marker first, hollow and dashed (Table 1's α = 0.7 had taken other methods' shapes).
        let alpha_only = key.variant.split_whitespace().all(|w| w.starts_with("α="));
        let h = if alpha_only {
            0
        } else {
            let h = key.variant.bytes().fold(0x811c_9dc5_u32, |h, b| {
                (h ^ u32::from(b)).wrapping_mul(0x0100_0193)
            });
            // MurmurHash3's finaliser: keys a byte apart (`n=1`, `n=2`) had fallen on
            // neighbouring places, alike markers side by side.
            let h = (h ^ (h >> 16)).wrapping_mul(0x85eb_ca6b);
            let h = (h ^ (h >> 13)).wrapping_mul(0xc2b2_ae35);
            (h ^ (h >> 16)) as usize
        };
        // The variants' places, from the one the key hashes to: every look but the method's
        // own; for an outside renderer's the hollow ones first.
        let rotated = |mut v: Vec<usize>| {
            if !v.is_empty() {
                let n = v.len();
                v.rotate_left(h % n);
            }
            v
        };
        let slots: Vec<usize> = if key.outside {
            let mut v = rotated((1..looks).filter(|k| k % 2 == 1).collect());
            v.extend((1..looks).filter(|k| k % 2 == 0));
            v
        } else {
            rotated((1..looks).collect())
        };
        let s = slots
            .iter()
            .map(|&k| method_variant(key.method, k))
            .find(|s| !taken.iter().any(|t| look(t) == look(s)))
            .or_else(|| {
                // Every look taken: another dash, for a joined series.
                (looks..looks + 12)
                    .map(|k| method_variant(key.method, k))
                    .find(|s| !taken.contains(s))
            })
            .unwrap_or(method_variant(key.method, 1));
        taken.push(s);
        styles[i] = Some(s);
    }
    styles.into_iter().flatten().collect()
}

/// [`keyed_styles`] of our own series, each given as (method, variant key).
pub fn our_styles(keys: &[(&str, &str)]) -> Vec<Style> {
    keyed_styles(
        &keys
            .iter()
            .map(|&(method, variant)| StyleKey {
                method,
                variant,
                outside: false,
            })
            .collect::<Vec<_>>(),
    )
}

/// The styles of a chart's series named "method options…" (a record's variant,
/// `document::variant`): [`keyed_styles`] with the words after the method as the key.
pub fn styles_for(names: &[&str]) -> Vec<Style> {
    let keys: Vec<StyleKey> = names
        .iter()
        .map(|n| {
            let n = n.trim();
            let (method, variant) = n.split_once(' ').unwrap_or((n, ""));
            StyleKey {
                method,
                variant: variant.trim(),
                outside: false,
            }
        })
        .collect();
    keyed_styles(&keys)
}

pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    /// A short label drawn beside each point (e.g. "n=2"); empty for none. Left out where it
    /// would touch another label.
    pub labels: Vec<String>,
    /// An interval around each point's x (e.g. a 95 % confidence interval of a median time),
    /// drawn as a horizontal error bar; empty, or `None` for a point without one.
    pub x_intervals: Vec<Option<[f64; 2]>>,
    /// The same for y, drawn as a vertical error bar.
    pub y_intervals: Vec<Option<[f64; 2]>>,
    pub style: Style,
    /// Joined by a line, in the order given: only when the points are one variable swept
    /// (n, depth, p, tilt, IPD), never across methods or unrelated settings.
    pub joined: bool,
    /// What the intervals are: the axis label says it ([`CI_BARS`], [`RANGE_BARS`]).
    pub bars: Bars,
}

/// What a series' error bars show.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Bars {
    /// The 95 % interval of the median (six frames or more).
    #[default]
    Ci95,
    /// Each point's fastest to slowest frame: points timed on too few frames for a 95 %
    /// interval (with 5, [min, max] holds the median 94 % of the time).
    FrameRange,
}

impl Series {
    /// A joined series in `style` with no labels and no error bars.
    pub fn new(name: impl Into<String>, style: Style, points: Vec<(f64, f64)>) -> Series {
        Series {
            name: name.into(),
            points,
            labels: Vec::new(),
            x_intervals: Vec::new(),
            y_intervals: Vec::new(),
            style,
            joined: true,
            bars: Bars::Ci95,
        }
    }
}

/// A reference the data are read against — not a measurement: drawn dashed grey, named
/// "reference: …" in the legend; or a mark on one of the data's points (the answer a figure
/// gives, e.g. the advisor's pick): a black ring around it, named as given.
pub enum Reference {
    /// A horizontal line across the plot.
    Level(String, f64),
    /// A curve through points (e.g. 2^p × a base time).
    Curve(String, Vec<(f64, f64)>),
    /// A ring around the point (x, y), named in the legend as it is, without "reference:".
    Mark(String, (f64, f64)),
}

/// The radius of a [`Reference::Mark`]'s ring: around a marker and its coincidence rings.
const MARK_R: f64 = 12.5;

/// What an axis label adds when its points carry their 95 % intervals as bars
/// (`"ms/frame (median, 95 % CI bars)"`); [`Chart::axis_label`] drops it where none is drawn.
pub const CI_BARS: &str = ", 95 % CI bars";
/// What [`CI_BARS`] becomes where the bars are each point's range of frames ([`Bars::FrameRange`]).
pub const RANGE_BARS: &str = ", bars: fastest to slowest frame";

pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    pub series: Vec<Series>,
    pub references: Vec<Reference>,
    /// The comparison's floor (raster vs trace without mirrors): errors at or below it are not
    /// resolved. Shaded from the bottom of the plot up to it, or noted under the plot when it
    /// lies below the axis.
    pub floor: Option<f64>,
    /// Ticks at the data's distinct x (n, depth, p) instead of round numbers.
    pub x_ticks_at_data: bool,
    /// The x values are counts (frames): round ticks at whole numbers only, never 0.5.
    pub x_whole: bool,
    /// Scene, size, device, date and commit; set by the report writer for every chart.
    pub footer: String,
}

impl Chart {
    /// An axis label as drawn: a label that promises interval bars ([`CI_BARS`]) keeps the
    /// promise only where some series draws an interval on that axis (issue 54: every
    /// frontier chart said "95 % CI bars" and drew none), and says "fastest to slowest frame"
    /// ([`RANGE_BARS`]) where the bars drawn are ranges of frames.
    fn axis_label(&self, label: &str, intervals: fn(&Series) -> &Vec<Option<[f64; 2]>>) -> String {
        let drawn: Vec<Bars> = self
            .series
            .iter()
            .filter(|s| intervals(s).iter().any(Option::is_some))
            .map(|s| s.bars)
            .collect();
        if drawn.is_empty() {
            label.replace(CI_BARS, "")
        } else if drawn.contains(&Bars::FrameRange) {
            label.replace(CI_BARS, RANGE_BARS)
        } else {
            label.to_string()
        }
    }

    /// A chart with no series yet, log axes as given, no footer.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Chart {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_log: false,
            y_log: false,
            series: Vec::new(),
            references: Vec::new(),
            floor: None,
            x_ticks_at_data: false,
            x_whole: false,
            footer: String::new(),
        }
    }

    /// The distinct drawable x of the chart's series.
    fn distinct_x(&self) -> Vec<f64> {
        let mut xs: Vec<f64> = self
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|(x, y)| drawable(*x, self.x_log) && drawable(*y, self.y_log))
            .map(|p| p.0)
            .collect();
        xs.sort_by(f64::total_cmp);
        xs.dedup();
        xs
    }

    /// A chart answers a question about a variable only where the variable takes two values:
    /// one x draws a vertical stack of points, which says nothing the table does not.
    pub fn is_drawable(&self) -> bool {
        self.distinct_x().len() >= 2
    }
}

/// Width of the plot area; the legend's column is added to its right, as wide as its longest
/// entry needs.
const PLOT_W: f64 = 450.0;
/// The title's width per character (15 px sans-serif, generous).
const TITLE_CHAR_W: f64 = 8.5;
const PLOT_H: f64 = 330.0;
const LEFT: f64 = 80.0;
/// Approximate advance of one character of the 12 px sans-serif legend text.
const LEGEND_CHAR_W: f64 = 7.0;
/// Approximate advance of one character of the 10 px label and footer text.
const SMALL_CHAR_W: f64 = 6.8;
/// The legend column: its margin, the sample line and the gap before the text.
const LEGEND_PAD: f64 = 14.0 + 28.0 + 10.0;
const LEGEND_ROW: f64 = 18.0;
const TOP: f64 = 40.0;
/// Below the plot: tick labels, the axis label, the floor note and the footer.
const BOTTOM: f64 = 92.0;
/// Half-length of an error bar's end caps, px.
const ERROR_CAP: f64 = 4.0;
const MARKER_R: f64 = 4.0;
/// How far past the plot's frame the markers' clip reaches: a marker on the frame (a point at
/// x = 0 on an axis starting there) is drawn whole, not cut in half. Lines, error bars and
/// the rings of coinciding points keep the frame's own clip (rings grow over the tick
/// labels); a mark's ring is larger than the margin and is cut there.
const CLIP_MARGIN: f64 = 2.5 * MARKER_R;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn drawable(v: f64, log: bool) -> bool {
    v.is_finite() && (!log || v > 0.0)
}

struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
}

impl Axis {
    /// Tight to the values: a log axis pads 4 % of its span in decades on each side (at least a
    /// factor 1.15), a linear one 6 %, starting at 0 where the values are non-negative and
    /// close to it — and then 6 % below 0, so that markers at or near 0 are drawn whole.
    fn new(values: impl Iterator<Item = f64>, log: bool) -> Axis {
        let (mut lo, mut hi) = values
            .filter(|x| drawable(*x, log))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
        if !lo.is_finite() {
            (lo, hi) = if log { (0.1, 10.0) } else { (0.0, 1.0) };
        }
        if log {
            let (a, b) = (lo.log10(), hi.log10());
            let pad = ((b - a) * 0.04).max(0.06);
            // Kept finite: a record's 1e300 padded to infinity had asked for 2^31 ticks.
            // (Down to the least subnormal: a value below f64::MIN_POSITIVE stays inside.)
            lo = 10f64.powf(a - pad).max(f64::from_bits(1));
            hi = 10f64.powf(b + pad).min(f64::MAX);
        } else {
            let span = hi - lo;
            let pad = if span > 0.0 {
                span * 0.06
            } else {
                lo.abs().max(1.0) * 0.1
            };
            lo = if lo >= 0.0 && lo - pad < 0.0 || (lo > 0.0 && lo < span * 0.25) {
                // From 0, and a little below it, so that markers at or near 0 (and the rings
                // of points coinciding there) are drawn whole, not cut by the frame.
                if span > 0.0 { -pad } else { 0.0 }
            } else {
                lo - pad
            };
            hi += pad;
            (lo, hi) = (lo.max(-f64::MAX), hi.min(f64::MAX));
        }
        Axis { lo, hi, log }
    }
    fn t(&self, x: f64) -> f64 {
        if self.log {
            (x.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())
        } else {
            (x - self.lo) / (self.hi - self.lo)
        }
    }
    fn contains(&self, v: f64) -> bool {
        drawable(v, self.log) && (-1e-9..=1.0 + 1e-9).contains(&self.t(v))
    }
    /// [`Axis::ticks`] as drawn on an axis `len` pixels long: a 2× or 5× step (beyond the
    /// outer decades, or between the two of a short axis) is left out where its label would
    /// come within `gap` pixels of a kept one (the outermost first, which keeps the far points in reach of a tick: 16 decades in
    /// the plot's height had printed "1e-15", "5e-16" and "2e-16" over one another).
    fn ticks_drawn(&self, len: f64, gap: f64) -> Vec<f64> {
        let ticks = self.ticks();
        if !self.log {
            return ticks;
        }
        let decade = |v: f64| (v.log10() - v.log10().round()).abs() < 1e-9;
        let decades: Vec<f64> = ticks.iter().copied().filter(|&v| decade(v)).collect();
        let (Some(&first), Some(&last)) = (decades.first(), decades.last()) else {
            return ticks;
        };
        let px = |v: f64| self.t(v) * len;
        let mut kept = decades.clone();
        let below: Vec<f64> = ticks.iter().copied().filter(|&v| v < first).collect();
        let mut above: Vec<f64> = ticks.iter().copied().filter(|&v| v > last).collect();
        above.reverse();
        // The steps between two decades (an axis of at most two, [`Axis::ticks`]).
        let between: Vec<f64> = ticks
            .iter()
            .copied()
            .filter(|&v| v > first && v < last && !decade(v))
            .collect();
        for side in [below, above, between] {
            let mut side_kept: Vec<f64> = Vec::new();
            for v in side {
                let clear = |o: f64| (px(v) - px(o)).abs() >= gap;
                if side_kept.iter().all(|&o| clear(o)) && kept.iter().all(|&o| clear(o)) {
                    side_kept.push(v);
                }
            }
            kept.extend(side_kept);
        }
        kept.sort_by(f64::total_cmp);
        kept
    }

    fn ticks(&self) -> Vec<f64> {
        if self.log {
            // Decades; where fewer than two fall inside, the 2× and 5× steps as well; where two,
            // those between them too (below).
            let (a, b) = (
                self.lo.log10().floor() as i32,
                self.hi.log10().ceil() as i32,
            );
            let decades: Vec<f64> = (a..=b)
                .map(|e| 10f64.powi(e))
                .filter(|&v| self.contains(v))
                .collect();
            if let [first, .., last] = decades[..] {
                // Beyond the outer decades, the 2× and 5× steps too: no point lies more than
                // a factor 2.5 past the outermost tick (issue 54: points below the lowest).
                // Across at most two decades, between them too: "1" and "10" alone had left a
                // 2 ms budget and its points 1.8–2.2 ms with no tick near.
                let few = decades.len() <= 2;
                let mut out: Vec<f64> = (a..=b)
                    .flat_map(|e| [2.0, 5.0].map(|m| m * 10f64.powi(e)))
                    .filter(|&v| (few || v < first || v > last) && self.contains(v))
                    .chain(decades)
                    .collect();
                out.sort_by(f64::total_cmp);
                return out;
            }
            let mut out: Vec<f64> = (a..=b)
                .flat_map(|e| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(e)))
                .filter(|&v| self.contains(v))
                .collect();
            if out.len() < 2 {
                // Less than a factor 2.5 of range: round linear steps inside it.
                out = linear_ticks(self.lo, self.hi)
                    .into_iter()
                    .filter(|&v| v > 0.0 && self.contains(v))
                    .collect();
            }
            out
        } else {
            linear_ticks(self.lo, self.hi)
        }
    }
}

/// About five round ticks (1, 2 or 5 × a power of ten apart) from `lo` to `hi`.
fn linear_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let raw = (hi - lo) / 5.0;
    if !(raw.is_finite() && raw > 0.0) {
        return Vec::new();
    }
    let mag = 10f64.powf(raw.log10().floor());
    // The round step nearest a fifth of the span, not the first above it: an axis padded
    // below 0 (0 to 1.06 wide) had got steps of 0.5, two ticks.
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw * 0.75)
        .unwrap_or(raw);
    // The k-th step by multiplication, not by adding steps: far from 0 (a record's 1e20 and
    // 1e20 + 1) an added step is lost in rounding and the loop never ended.
    let first = (lo / step).ceil();
    let last = ((hi + 1e-12 * hi.abs().max(1.0)) / step).floor();
    if !(first.is_finite() && last.is_finite() && last - first <= 50.0) {
        return Vec::new();
    }
    // A multiple of the step snaps to its decimals (0.1 + 0.2 is not 0.3 in binary); + 0.0
    // makes a −0 0.
    (first as i64..=last as i64)
        .map(|k| k as f64 * step + 0.0)
        .collect()
}

/// An axis's tick labels: [`fmt_tick`]'s, but on a log axis where some tick needs the
/// exponent form (below 0.01), every tick below 1 takes it too, so that one axis does not read
/// "0.1, 0.01, 1e-3" (two notations for one scale).
fn tick_labels(ticks: &[f64], log: bool) -> Vec<String> {
    let exponent = log && ticks.iter().any(|&t| t != 0.0 && t.abs() < 1e-2);
    ticks
        .iter()
        .map(|&t| {
            if exponent && t != 0.0 && t.abs() < 1.0 {
                exponent_form(t)
            } else {
                fmt_tick(t)
            }
        })
        .collect()
}

/// A tick or annotation value, with as few digits as it needs.
pub fn fmt_tick(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e4 || v.abs() < 1e-2 {
        exponent_form(v)
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// `v` as "5e-3" or "1.5e-3": one decimal of mantissa, none where it is 0.
fn exponent_form(v: f64) -> String {
    format!("{v:.1e}").replace(".0e", "e")
}

/// A 10-px label's width as the layout reckons it (an estimate: no font is measured).
fn text_width(text: &str) -> f64 {
    SMALL_CHAR_W * text.chars().count() as f64
}

/// An axis-aligned box in pixels, for keeping labels apart.
#[derive(Clone, Copy)]
struct Rect {
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

/// Pixels kept clear beside a placed label: two labels side by side had read as one
/// ("d=4d=4").
const LABEL_GAP: f64 = 4.0;

impl Rect {
    /// The square a marker of radius `r` at `(x, y)` covers.
    fn around((x, y): (f64, f64), r: f64) -> Rect {
        Rect {
            x0: x - r,
            y0: y - r,
            x1: x + r,
            y1: y + r,
        }
    }

    /// A label's box, `lw` pixels wide, its text's baseline starting at `(lx, ly)`.
    fn text_at(lx: f64, ly: f64, lw: f64) -> Rect {
        Rect {
            x0: lx,
            y0: ly - 9.0,
            x1: lx + lw,
            y1: ly + 1.0,
        }
    }

    /// The plot's frame.
    const PLOT: Rect = Rect {
        x0: LEFT,
        y0: TOP,
        x1: LEFT + PLOT_W,
        y1: TOP + PLOT_H,
    };

    /// Whether the box lies within the plot's frame.
    fn inside_plot(&self) -> bool {
        let p = Rect::PLOT;
        self.x0 >= p.x0 && self.x1 <= p.x1 && self.y0 >= p.y0 && self.y1 <= p.y1
    }

    /// A placed label's box with [`LABEL_GAP`] around it, as later labels must keep clear of it.
    fn spaced(self) -> Rect {
        Rect {
            x0: self.x0 - LABEL_GAP,
            y0: self.y0 - 1.0,
            x1: self.x1 + LABEL_GAP,
            y1: self.y1 + 1.0,
        }
    }

    fn overlaps(&self, o: &Rect) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }

    /// Whether the segment from `a` to `b` passes through the box's inside (its edges alone
    /// do not count): Liang–Barsky's clip of the segment's parameter to each slab.
    fn crossed_by(&self, a: (f64, f64), b: (f64, f64)) -> bool {
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for (p, q) in [
            (a.0 - b.0, a.0 - self.x0),
            (b.0 - a.0, self.x1 - a.0),
            (a.1 - b.1, a.1 - self.y0),
            (b.1 - a.1, self.y1 - a.1),
        ] {
            if p == 0.0 {
                if q <= 0.0 {
                    return false;
                }
            } else {
                let t = q / p;
                if p < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
            }
        }
        t0 < t1
    }
}

/// Whether a marker at `a` would hide most of one at `b` (pixels): their centres nearer than
/// a marker's radius. The later is then drawn as a ring around the place (the same place
/// alone had been ringed, and a point 1–3 px from another vanished under it).
fn hides(a: (f64, f64), b: (f64, f64)) -> bool {
    (a.0 - b.0).hypot(a.1 - b.1) < MARKER_R
}

/// A straight piece of a drawn line: from, to (in pixels, or in data coordinates where said).
type Stroke = ((f64, f64), (f64, f64));

/// A series' error bars the frame draws, in data coordinates, each from its low end to its
/// high one and whether it lies across x (at the point's y) or across y (at its x), point by
/// point (a point the frame does not show, or an end an axis cannot, draws none).
fn bars(series: &Series, f: &Frame) -> Vec<(bool, Stroke)> {
    let mut out = Vec::new();
    for (k, &(x, y)) in series.points.iter().enumerate() {
        if !f.shows((x, y)) {
            continue;
        }
        if let Some([lo, hi]) = series.x_intervals.get(k).copied().flatten()
            && drawable(lo, f.ax.log)
            && drawable(hi, f.ax.log)
        {
            out.push((true, ((lo, y), (hi, y))));
        }
        if let Some([lo, hi]) = series.y_intervals.get(k).copied().flatten()
            && drawable(lo, f.ay.log)
            && drawable(hi, f.ay.log)
        {
            out.push((false, ((x, lo), (x, hi))));
        }
    }
    out
}

/// Where a point's label goes, `lw` pixels wide beside the marker of radius `r` at `(xx, yy)`:
/// the first of right-above, right-below, left-above, left-below, right, left, above and below
/// that stays inside the plot, crosses none of `strokes` (other series' lines, reference lines,
/// error bars),
/// touches nothing `taken` (markers and placed labels; its own marker aside) and lies nearer
/// its own point than any other of `markers` (else it would read as that point's label).
/// `None`: the label is left out. Returns the text's baseline origin and its box.
fn place_label(
    (xx, yy): (f64, f64),
    r: f64,
    lw: f64,
    markers: &[(f64, f64)],
    taken: &[Rect],
    strokes: &[Stroke],
) -> Option<(f64, f64, Rect)> {
    // The four corners first, then beside and over and under the marker: a label the
    // corners could not take (the frontier's crowded fronts) finds a place more often.
    let candidates = [
        (xx + r + 2.0, yy - r - 1.0),
        (xx + r + 2.0, yy + r + 9.0),
        (xx - r - 2.0 - lw, yy - r - 1.0),
        (xx - r - 2.0 - lw, yy + r + 9.0),
        (xx + r + 3.0, yy + 4.0),
        (xx - r - 3.0 - lw, yy + 4.0),
        (xx - lw / 2.0, yy - r - 3.0),
        (xx - lw / 2.0, yy + r + 11.0),
    ];
    let own = Rect::around((xx, yy), r);
    candidates.iter().find_map(|&(lx, ly)| {
        let rect = Rect::text_at(lx, ly, lw);
        let inside = rect.inside_plot();
        let gap = |(px, py): (f64, f64)| {
            let dx = (rect.x0 - px).max(px - rect.x1).max(0.0);
            let dy = (rect.y0 - py).max(py - rect.y1).max(0.0);
            dx.hypot(dy)
        };
        let mine = gap((xx, yy));
        let ambiguous = markers.iter().any(|&m| m != (xx, yy) && gap(m) <= mine);
        (inside
            && !ambiguous
            && !taken
                .iter()
                .any(|t| t.overlaps(&rect) && !(t.x0 == own.x0 && t.y0 == own.y0))
            && !strokes.iter().any(|&(a, b)| rect.crossed_by(a, b)))
        .then_some((lx, ly, rect))
    })
}

/// Where a point's label goes when no place beside its marker is free ([`place_label`]): a
/// little away from it, in one of eight directions at two distances, joined to the marker by a
/// thin leader line in the series' colour — a label that would have been left out (a swept
/// cube size under two other methods' points, a crowded front) is said, and the leader ties
/// it to its point. The box keeps the same rules (inside the plot, clear of everything
/// `taken`, across none of `strokes`), and the leader crosses nothing `taken` but the point's
/// own marker — and, `through_own_place`, anything drawn over its own point (a coinciding
/// unlabelled point's marker, the pick's ring).
/// Returns the text's baseline origin, its box and the leader's ends.
#[allow(clippy::type_complexity)]
fn place_label_away(
    (xx, yy): (f64, f64),
    r: f64,
    lw: f64,
    taken: &[Rect],
    strokes: &[Stroke],
    through_own_place: bool,
) -> Option<(f64, f64, Rect, Stroke)> {
    let own = Rect::around((xx, yy), r);
    [14.0, 26.0].iter().find_map(|&d| {
        let e = d * std::f64::consts::FRAC_1_SQRT_2;
        // Baseline origins: right, left, above, below, then the four diagonals.
        let candidates = [
            (xx + r + d, yy + 4.0),
            (xx - r - d - lw, yy + 4.0),
            (xx - lw / 2.0, yy - r - d),
            (xx - lw / 2.0, yy + r + d + 9.0),
            (xx + r + e, yy - r - e),
            (xx + r + e, yy + r + e + 9.0),
            (xx - r - e - lw, yy - r - e),
            (xx - r - e - lw, yy + r + e + 9.0),
        ];
        candidates.iter().find_map(|&(lx, ly)| {
            let rect = Rect::text_at(lx, ly, lw);
            // The leader: from the marker's edge to the box's nearest point.
            let near = (xx.clamp(rect.x0, rect.x1), yy.clamp(rect.y0, rect.y1));
            let (dx, dy) = (near.0 - xx, near.1 - yy);
            let len = dx.hypot(dy);
            if len <= r {
                return None;
            }
            let from = (xx + dx / len * (r + 1.0), yy + dy / len * (r + 1.0));
            let inside = rect.inside_plot();
            // The leader leaves through whatever is drawn over its own point: its marker, a
            // coinciding point's, the pick's ring (it had barred every leader of a ringed
            // point, so the advisor's pick went unlabelled).
            let mine = |t: &Rect| {
                (t.x0 == own.x0 && t.y0 == own.y0)
                    || (through_own_place && t.x0 <= xx && xx <= t.x1 && t.y0 <= yy && yy <= t.y1)
            };
            (inside
                && !taken.iter().any(|t| t.overlaps(&rect))
                && !taken.iter().any(|t| !mine(t) && t.crossed_by(from, near))
                && !strokes.iter().any(|&(a, b)| rect.crossed_by(a, b))
                // Nor within 2 px of another line or bar: a leader across an error bar read
                // as the label of the bar's point, and one ending at a bar's cap as a whisker.
                && !strokes
                    .iter()
                    .any(|&(a, b)| segments_distance((from, near), (a, b)) < 2.0))
            .then_some((lx, ly, rect, (from, near)))
        })
    })
}

/// The least distance between two segments, pixels (0 where they cross).
fn segments_distance((p0, p1): Stroke, (q0, q1): Stroke) -> f64 {
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let (d1, d2) = (cross(q0, q1, p0), cross(q0, q1, p1));
    let (d3, d4) = (cross(p0, p1, q0), cross(p0, p1, q1));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return 0.0;
    }
    let to_segment = |p: (f64, f64), (a, b): Stroke| {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len2 = dx * dx + dy * dy;
        let t = if len2 > 0.0 {
            (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
    };
    to_segment(p0, (q0, q1))
        .min(to_segment(p1, (q0, q1)))
        .min(to_segment(q0, (p0, p1)))
        .min(to_segment(q1, (p0, p1)))
}

/// The points of a reference's line as the frame shows them: a level across the plot, a
/// curve's drawable points; none for a mark, a level off a log axis, or a line no piece of
/// which crosses the plot (a budget left or right of every point: it drew nothing and had a
/// legend row). None: no line, and no legend entry.
fn reference_line(r: &Reference, f: &Frame) -> Vec<(f64, f64)> {
    let pts: Vec<(f64, f64)> = match r {
        Reference::Level(_, y) if drawable(*y, f.ay.log) => vec![(f.ax.lo, *y), (f.ax.hi, *y)],
        Reference::Level(..) | Reference::Mark(..) => Vec::new(),
        Reference::Curve(_, pts) => pts.iter().copied().filter(|&p| f.shows(p)).collect(),
    };
    let px = |(x, y): (f64, f64)| (f.px(x), f.py(y));
    if pts
        .windows(2)
        .any(|w| Rect::PLOT.crossed_by(px(w[0]), px(w[1])))
    {
        pts
    } else {
        Vec::new()
    }
}

fn marker_svg(s: &mut String, style: &Style, x: f64, y: f64, r: f64, hollow: bool) {
    let c = style.color;
    let (fill, stroke) = if hollow {
        (
            "white".to_string(),
            format!(r#"stroke="{c}" stroke-width="1.6""#),
        )
    } else {
        (c.to_string(), format!(r#"stroke="{c}" stroke-width="1""#))
    };
    let _ = match style.marker {
        Marker::Circle => writeln!(
            s,
            r#"<circle cx="{x:.1}" cy="{y:.1}" r="{r:.1}" fill="{fill}" {stroke}/>"#
        ),
        Marker::Square => writeln!(
            s,
            r#"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="{fill}" {stroke}/>"#,
            x - r * 0.9,
            y - r * 0.9,
            r * 1.8,
            r * 1.8
        ),
        Marker::TriangleUp | Marker::TriangleDown | Marker::Diamond => {
            let k = r * 1.25;
            let pts = match style.marker {
                Marker::TriangleUp => {
                    [(x, y - k), (x + k, y + k * 0.8), (x - k, y + k * 0.8)].to_vec()
                }
                Marker::TriangleDown => {
                    [(x, y + k), (x + k, y - k * 0.8), (x - k, y - k * 0.8)].to_vec()
                }
                _ => [(x, y - k), (x + k, y), (x, y + k), (x - k, y)].to_vec(),
            };
            let p: Vec<String> = pts.iter().map(|(a, b)| format!("{a:.1},{b:.1}")).collect();
            writeln!(
                s,
                r#"<polygon points="{}" fill="{fill}" {stroke}/>"#,
                p.join(" ")
            )
        }
        // Hollow, a plus or a cross is its outline (a thin stroke alone read as the filled
        // one where points are not joined: two variants alike).
        Marker::Cross | Marker::Plus if hollow => {
            let (arm, half) = (r * 1.35, r * 0.45);
            let turn = if style.marker == Marker::Cross {
                std::f64::consts::FRAC_PI_4
            } else {
                0.0
            };
            let outline = [
                (half, half),
                (arm, half),
                (arm, -half),
                (half, -half),
                (half, -arm),
                (-half, -arm),
                (-half, -half),
                (-arm, -half),
                (-arm, half),
                (-half, half),
                (-half, arm),
                (half, arm),
            ];
            let (sin, cos) = turn.sin_cos();
            let p: Vec<String> = outline
                .iter()
                .map(|(a, b)| format!("{:.1},{:.1}", x + a * cos - b * sin, y + a * sin + b * cos))
                .collect();
            writeln!(
                s,
                r#"<polygon points="{}" fill="{fill}" {stroke}/>"#,
                p.join(" ")
            )
        }
        Marker::Cross | Marker::Plus => {
            let k = r * 1.1;
            let d = if style.marker == Marker::Cross {
                format!(
                    "M{:.1},{:.1}L{:.1},{:.1}M{:.1},{:.1}L{:.1},{:.1}",
                    x - k,
                    y - k,
                    x + k,
                    y + k,
                    x - k,
                    y + k,
                    x + k,
                    y - k
                )
            } else {
                format!(
                    "M{:.1},{y:.1}H{:.1}M{x:.1},{:.1}V{:.1}",
                    x - k * 1.2,
                    x + k * 1.2,
                    y - k * 1.2,
                    y + k * 1.2
                )
            };
            writeln!(
                s,
                r#"<path d="{d}" stroke="{c}" stroke-width="{}" fill="none"/>"#,
                2.2
            )
        }
    };
}

/// Splits `text` into lines of at most `max` characters at spaces.
fn wrap(text: &str, max: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in text.split(' ') {
        let last = lines.last_mut().expect("one line");
        if !last.is_empty() && last.chars().count() + 1 + word.chars().count() > max {
            lines.push(word.to_string());
        } else {
            if !last.is_empty() {
                last.push(' ');
            }
            last.push_str(word);
        }
    }
    lines
}

thread_local! {
    /// Where [`Chart::to_svg`] reports each chart's [`Chart::lint`] while
    /// [`collect_lint`] runs; `None` otherwise.
    static LINT: std::cell::RefCell<Option<Vec<String>>> = const { std::cell::RefCell::new(None) };
}

/// Runs `f` and returns, beside its result, every lint message of every chart drawn meanwhile
/// on this thread, each prefixed by the chart's title: the figure check of the tests (issue
/// 54), run over every report they regenerate.
pub fn collect_lint<T>(f: impl FnOnce() -> T) -> (T, Vec<String>) {
    LINT.with(|l| *l.borrow_mut() = Some(Vec::new()));
    let out = f();
    let messages = LINT.with(|l| l.borrow_mut().take().unwrap_or_default());
    (out, messages)
}

impl Chart {
    /// What a reviewer would send back about this chart (issue 54): two series drawn alike
    /// (one colour, marker and fill; the dash too where joined), a legend entry for a series
    /// with nothing drawn, points the axis cannot show (≤ 0 on a log axis, not finite), a line
    /// joining points whose x goes back or repeats (a sweep axis other than the chart's x).
    pub fn lint(&self) -> Vec<String> {
        let mut out = Vec::new();
        // The title says what is measured: an error metric with its domain (the image or the
        // mirror pixels), or a cost.
        let error_metric = ["FLIP", "relMSE", "SSIM", "PSNR", "RMSE"]
            .iter()
            .any(|m| self.title.contains(m));
        let domain = ["image", "mirror pixels"]
            .iter()
            .any(|d| self.title.contains(d));
        let cost = ["cost", "Cost", "ms/frame", "disparity"]
            .iter()
            .any(|c| self.title.contains(c));
        if error_metric && !domain {
            out.push("the title names an error metric without its domain (the image or the mirror pixels)".into());
        } else if !error_metric && !cost {
            out.push(
                "the title names no metric (FLIP, relMSE, … with its domain) and no cost".into(),
            );
        }
        let ok = |v: f64, log: bool| drawable(v, log);
        for r in &self.references {
            if let Reference::Mark(name, (x, y)) = r
                && !(ok(*x, self.x_log) && ok(*y, self.y_log))
            {
                out.push(format!(
                    "the mark \"{name}\" has a legend entry and cannot be drawn on this axis"
                ));
            }
        }
        let shown = |s: &Series| {
            s.points
                .iter()
                .filter(|(x, y)| ok(*x, self.x_log) && ok(*y, self.y_log))
                .count()
        };
        for (i, a) in self.series.iter().enumerate() {
            let n = shown(a);
            if n == 0 {
                out.push(format!(
                    "\"{}\" has a legend entry and no point drawn",
                    a.name
                ));
                continue;
            }
            if n < a.points.len() {
                out.push(format!(
                    "{} of the points of \"{}\" cannot be drawn on this axis (≤ 0 on a log axis, or not finite)",
                    a.points.len() - n,
                    a.name
                ));
            }
            for b in self.series[..i].iter().filter(|b| shown(b) > 0) {
                let (sa, sb) = (&a.style, &b.style);
                let alike = sa.color == sb.color
                    && sa.marker == sb.marker
                    && sa.hollow == sb.hollow
                    && (sa.dash == sb.dash || !(a.joined && b.joined));
                if alike {
                    out.push(format!(
                        "\"{}\" and \"{}\" are drawn alike (colour, marker, fill)",
                        b.name, a.name
                    ));
                }
            }
            if a.joined && a.points.windows(2).any(|w| w[1].0 <= w[0].0) {
                out.push(format!(
                    "\"{}\" joins points whose x goes back or repeats (a line across another axis)",
                    a.name
                ));
            }
        }
        // Every point within reach of a tick: at most a factor 2.5 past the outermost tick of
        // a log axis, one step past that of a linear one.
        let (ax, ay) = self.axes();
        let mut axes = vec![("y", &ay, false)];
        if !self.x_ticks_at_data {
            axes.push(("x", &ax, true));
        }
        for (name, axis, is_x) in axes {
            let ticks = if is_x {
                axis.ticks_drawn(PLOT_W, X_TICK_GAP)
            } else {
                axis.ticks_drawn(PLOT_H, Y_TICK_GAP)
            };
            let (Some(&first), Some(&last)) = (ticks.first(), ticks.last()) else {
                out.push(format!("the {name} axis has no tick"));
                continue;
            };
            let beyond = |v: f64| {
                if axis.log {
                    (first / v).max(v / last) > 2.5 * (1.0 + 1e-9)
                } else {
                    let step = ticks.get(1).map_or(f64::INFINITY, |t| t - first);
                    v < first - step * (1.0 + 1e-9) || v > last + step * (1.0 + 1e-9)
                }
            };
            let far = self
                .series
                .iter()
                .flat_map(|s| s.points.iter())
                .map(|&(x, y)| if is_x { x } else { y })
                .filter(|v| drawable(*v, axis.log) && beyond(*v))
                .count();
            if far > 0 {
                out.push(format!(
                    "{far} point(s) lie beyond the outermost tick of the {name} axis ({} to {})",
                    fmt_tick(first),
                    fmt_tick(last)
                ));
            }
        }
        out
    }

    /// The chart's axes: they span the points, their error bars, the floor where it is near
    /// the data, and the reference curves' points that lie within the data's x (a reference
    /// never widens x).
    fn axes(&self) -> (Axis, Axis) {
        let bounds = |i: &[Option<[f64; 2]>]| -> Vec<f64> {
            i.iter().flatten().flatten().copied().collect()
        };
        // The x axis holds the reference curves too: a budget faster than every point is
        // where the figure's question is (the advisor's; it had been drawn nowhere).
        let xs: Vec<f64> = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0).chain(bounds(&s.x_intervals)))
            .chain(self.references.iter().flat_map(|r| match r {
                Reference::Curve(_, pts) => pts.iter().map(|p| p.0).collect(),
                _ => Vec::new(),
            }))
            .collect();
        let ax = Axis::new(xs.iter().copied(), self.x_log);
        let ys: Vec<f64> = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1).chain(bounds(&s.y_intervals)))
            .collect();
        let data_lo = self.data_lo_y(self.y_log);
        // The floor joins the y range only when it is near the data (within a factor 10 on a
        // log axis); otherwise it is a note under the plot.
        let floor_near = self.floor.filter(|&f| {
            drawable(f, self.y_log) && (!self.y_log || !data_lo.is_finite() || f >= data_lo / 10.0)
        });
        let ay = Axis::new(
            ys.iter().copied().chain(floor_near).chain(
                self.references
                    .iter()
                    .flat_map(|r| match r {
                        Reference::Level(_, y) | Reference::Mark(_, (_, y)) => vec![*y],
                        Reference::Curve(_, pts) => pts
                            .iter()
                            .filter(|p| ax.contains(p.0))
                            .map(|p| p.1)
                            .collect(),
                    })
                    .filter(|y| !data_lo.is_finite() || !self.y_log || *y >= data_lo / 100.0),
            ),
            self.y_log,
        );
        (ax, ay)
    }

    /// The lowest drawable y of the data (points and error bars), `inf` with none.
    fn data_lo_y(&self, log: bool) -> f64 {
        self.series
            .iter()
            .flat_map(|s| {
                s.points
                    .iter()
                    .map(|p| p.1)
                    .chain(s.y_intervals.iter().flatten().flatten().copied())
            })
            .filter(|v| drawable(*v, log))
            .fold(f64::INFINITY, f64::min)
    }

    pub fn to_svg(&self) -> String {
        LINT.with(|l| {
            if let Some(v) = l.borrow_mut().as_mut() {
                v.extend(
                    self.lint()
                        .into_iter()
                        .map(|m| format!("{}: {m}", self.title)),
                );
            }
        });
        let (ax, ay) = self.axes();
        let f = Frame { ax, ay };
        let legend = self.legend(&f);
        let legend_chars = legend
            .iter()
            .map(|(n, _)| n.chars().count())
            .max()
            .unwrap_or(0);
        // Wide enough for the legend and for the title (which never runs off the canvas).
        let title_w = TITLE_CHAR_W * self.title.chars().count() as f64;
        let w = (LEFT + PLOT_W + LEGEND_PAD + LEGEND_CHAR_W * legend_chars as f64)
            .max(title_w + 16.0)
            .ceil()
            .max(LEFT + PLOT_W + 40.0);
        let footer_lines = wrap(&self.footer, ((w - 20.0) / SMALL_CHAR_W) as usize);
        let legend_bottom = TOP + 10.0 + LEGEND_ROW * legend.len() as f64;
        let h = (TOP + PLOT_H + BOTTOM + 12.0 * footer_lines.len().saturating_sub(1) as f64)
            .max(legend_bottom + 20.0)
            .ceil();

        let mut s = String::new();
        let _ = writeln!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
        );
        let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
        // Centred over the plot, moved right as far as a long title needs to stay inside.
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
            (LEFT + PLOT_W / 2.0).max(title_w / 2.0 + 8.0),
            esc(&self.title)
        );
        // The floor band first, under everything; its label over the grid lines.
        let mut floor_label = String::new();
        let floor_note = self.floor_band(&mut s, &mut floor_label, &f);
        self.grid_and_axes(&mut s, &f);
        s.push_str(&floor_label);
        let mut below = TOP + PLOT_H + 54.0;
        if let Some(note) = floor_note {
            let _ = writeln!(
                s,
                r##"<text x="{LEFT}" y="{below:.1}" font-size="10" fill="#555">{}</text>"##,
                esc(&note)
            );
        }
        below += 16.0;
        for line in &footer_lines {
            let _ = writeln!(
                s,
                r##"<text x="10" y="{below:.1}" font-size="10" fill="#777">{}</text>"##,
                esc(line)
            );
            below += 12.0;
        }
        // Clip the lines to the plot area: reference lines, then series lines and error bars;
        // then the markers (rings where an earlier marker sits) and labels that touch no
        // other, clipped a marker's size further out, so that one on the frame is whole.
        let _ = writeln!(
            s,
            r#"<clipPath id="plot"><rect x="{LEFT}" y="{TOP}" width="{PLOT_W}" height="{PLOT_H}"/></clipPath><g clip-path="url(#plot)">"#
        );
        self.reference_lines(&mut s, &f);
        self.series_lines(&mut s, &f);
        self.error_bars(&mut s, &f);
        s.push_str("</g>\n");
        let _ = writeln!(
            s,
            r#"<clipPath id="marks"><rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}"/></clipPath><g clip-path="url(#marks)">"#,
            LEFT - CLIP_MARGIN,
            TOP - CLIP_MARGIN,
            PLOT_W + 2.0 * CLIP_MARGIN,
            PLOT_H + 2.0 * CLIP_MARGIN
        );
        let mut rings = String::new();
        self.markers_and_labels(&mut s, &mut rings, &f);
        s.push_str("</g>\n");
        // The coincidence rings inside the frame: around a point on it (x = 0) they grow
        // over the tick labels.
        let _ = writeln!(s, r#"<g clip-path="url(#plot)">"#);
        s.push_str(&rings);
        s.push_str("</g>\n");
        legend_svg(&mut s, &legend);
        s.push_str("</svg>\n");
        s
    }

    /// The legend's entries: each series (with a note where it coincides with an earlier
    /// one), then the references, then what a ring means where no series' name says it.
    fn legend(&self, f: &Frame) -> Vec<(String, Shows<'_>)> {
        let mut legend: Vec<(String, Shows)> = Vec::new();
        // Points drawn as rings (an earlier marker at the same place) in a series whose
        // legend entry does not say which series it lies on.
        let mut seen: Vec<(f64, f64)> = Vec::new();
        let mut unexplained_rings = false;
        for (i, series) in self.series.iter().enumerate() {
            let visible = f.visible(series);
            let mine: Vec<_> = visible.iter().map(|&p| f.key(p)).collect();
            let same = self.series[..i].iter().find(|o| {
                let theirs: Vec<_> = f.visible(o).into_iter().map(|p| f.key(p)).collect();
                !mine.is_empty() && mine.iter().all(|k| theirs.contains(k))
            });
            // The legend draws a line where the plot draws one: a joined series of one
            // visible point is a marker alone (its legend had shown a line).
            let line = series.joined && visible.len() >= 2;
            for p in visible {
                let at = (f.px(p.0), f.py(p.1));
                if seen.iter().any(|&q| hides(q, at)) {
                    unexplained_rings |= same.is_none();
                } else {
                    seen.push(at);
                }
            }
            let name = match same {
                Some(o) => format!("{} (on {})", series.name, o.name),
                None => series.name.clone(),
            };
            legend.push((name, Shows::Series(series, line)));
        }
        for r in &self.references {
            if !matches!(r, Reference::Mark(..)) && reference_line(r, f).is_empty() {
                continue;
            }
            let name = match r {
                Reference::Level(n, _) | Reference::Curve(n, _) => format!("reference: {n}"),
                Reference::Mark(n, _) => n.clone(),
            };
            legend.push((name, Shows::Reference(r)));
        }
        if unexplained_rings {
            legend.push((
                "ring: a point hidden by an earlier one's marker".into(),
                Shows::Ring,
            ));
        }
        legend
    }

    /// The floor band's label where the plot shows the band: its text, and the right end and
    /// baseline it is drawn at.
    fn floor_label(&self, f: &Frame) -> Option<(String, f64, f64)> {
        let v = self
            .floor
            .filter(|v| drawable(*v, f.ay.log) && f.ay.t(*v) > 0.0)?;
        let yf = f.py(v.min(f.ay.hi));
        Some((
            format!("floor (no mirrors) {}: not resolved below", fmt_tick(v)),
            LEFT + PLOT_W - 4.0,
            (yf + 11.0).min(TOP + PLOT_H - 3.0),
        ))
    }

    /// The floor's band (grey, under everything) where the y axis shows it, with its label in
    /// `label` (drawn after the grid, which would cross it); else the note that says where it
    /// is, returned for the space under the plot.
    fn floor_band(&self, s: &mut String, label: &mut String, f: &Frame) -> Option<String> {
        let mut floor_note = self.floor.filter(|v| !drawable(*v, f.ay.log)).map(|v| {
            format!(
                "floor of the comparison (no mirrors): {}, every difference above it is the method's",
                fmt_tick(v)
            )
        });
        if let Some(v) = self.floor.filter(|v| drawable(*v, f.ay.log)) {
            if let Some((text, x, y)) = self.floor_label(f) {
                let yf = f.py(v.min(f.ay.hi));
                let _ = writeln!(
                    s,
                    r##"<rect x="{LEFT}" y="{yf:.1}" width="{PLOT_W}" height="{:.1}" fill="#000" fill-opacity="0.07"/>"##,
                    TOP + PLOT_H - yf
                );
                let _ = writeln!(
                    label,
                    r##"<text x="{x:.1}" y="{y:.1}" font-size="10" fill="#555" text-anchor="end" stroke="white" stroke-width="3" paint-order="stroke">{text}</text>"##,
                );
            } else {
                floor_note = Some(format!(
                    "floor of the comparison (no mirrors): {}, below the axis",
                    fmt_tick(v)
                ));
            }
        }
        floor_note
    }

    /// The grid lines with their tick labels, the plot's frame and the axis labels.
    fn grid_and_axes(&self, s: &mut String, f: &Frame) {
        let x_ticks: Vec<f64> = if self.x_ticks_at_data {
            // Thinned so that labels ~40 px apart never touch.
            let mut out: Vec<f64> = Vec::new();
            for x in self.distinct_x() {
                if out.last().is_none_or(|&l| f.px(x) - f.px(l) >= 28.0) {
                    out.push(x);
                }
            }
            out
        } else {
            let ticks = f.ax.ticks_drawn(PLOT_W, X_TICK_GAP);
            if self.x_whole {
                ticks.into_iter().filter(|t| t.fract() == 0.0).collect()
            } else {
                ticks
            }
        };
        let x_labels = tick_labels(&x_ticks, f.ax.log);
        for (t, label) in x_ticks.into_iter().zip(x_labels) {
            let x = f.px(t);
            let _ = writeln!(
                s,
                r##"<line x1="{x:.1}" y1="{TOP}" x2="{x:.1}" y2="{:.1}" stroke="#e5e5e5"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{label}</text>"##,
                TOP + PLOT_H,
                TOP + PLOT_H + 16.0,
            );
        }
        let y_ticks = f.ay.ticks_drawn(PLOT_H, Y_TICK_GAP);
        let y_labels = tick_labels(&y_ticks, f.ay.log);
        for (t, label) in y_ticks.into_iter().zip(y_labels) {
            let y = f.py(t);
            let _ = writeln!(
                s,
                r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e5e5e5"/><text x="{:.1}" y="{:.1}" text-anchor="end">{label}</text>"##,
                LEFT + PLOT_W,
                LEFT - 6.0,
                y + 4.0,
            );
        }
        let _ = writeln!(
            s,
            r#"<rect x="{LEFT}" y="{TOP}" width="{PLOT_W}" height="{PLOT_H}" fill="none" stroke="black"/>"#
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            LEFT + PLOT_W / 2.0,
            TOP + PLOT_H + 36.0,
            esc(&self.axis_label(&self.x_label, |s| &s.x_intervals))
        );
        let _ = writeln!(
            s,
            r#"<text x="18" y="{:.1}" text-anchor="middle" transform="rotate(-90 18 {:.1})">{}</text>"#,
            TOP + PLOT_H / 2.0,
            TOP + PLOT_H / 2.0,
            esc(&self.axis_label(&self.y_label, |s| &s.y_intervals))
        );
    }

    /// The reference levels and curves, grey, each its own dash: the `i`-th drawn takes the
    /// `i`-th dash, as its legend entry does (one that draws nothing has neither).
    fn reference_lines(&self, s: &mut String, f: &Frame) {
        let lines = self
            .references
            .iter()
            .map(|r| reference_line(r, f))
            .filter(|pts| !pts.is_empty());
        for (i, pts) in lines.enumerate() {
            let dash = REFERENCE_DASHES[i % REFERENCE_DASHES.len()];
            let _ = writeln!(
                s,
                r#"<polyline points="{}" fill="none" stroke="{REFERENCE_GREY}" stroke-width="1.5" stroke-dasharray="{dash}"/>"#,
                f.polyline(&pts)
            );
        }
    }

    /// Each joined series' line, in its style.
    fn series_lines(&self, s: &mut String, f: &Frame) {
        for series in &self.series {
            let pts = f.visible(series);
            if series.joined && pts.len() >= 2 {
                let dash = if series.style.dash.is_empty() {
                    String::new()
                } else {
                    format!(r#" stroke-dasharray="{}""#, series.style.dash)
                };
                let _ = writeln!(
                    s,
                    r#"<polyline points="{}" fill="none" stroke="{}" stroke-width="1.8"{dash}/>"#,
                    f.polyline(&pts),
                    series.style.color
                );
            }
        }
    }

    /// Each point's intervals as capped bars, in its series' colour.
    fn error_bars(&self, s: &mut String, f: &Frame) {
        for series in &self.series {
            let color = series.style.color;
            for (across_x, ((x0, y0), (x1, y1))) in bars(series, f) {
                let (x0, y0, x1, y1) = (f.px(x0), f.py(y0), f.px(x1), f.py(y1));
                // The caps across the bar at both ends.
                let d = if across_x {
                    format!(
                        "M{x0:.1},{y0:.1}H{x1:.1}M{x0:.1},{:.1}V{:.1}M{x1:.1},{:.1}V{:.1}",
                        y0 - ERROR_CAP,
                        y0 + ERROR_CAP,
                        y0 - ERROR_CAP,
                        y0 + ERROR_CAP
                    )
                } else {
                    format!(
                        "M{x0:.1},{y0:.1}V{y1:.1}M{:.1},{y0:.1}H{:.1}M{:.1},{y1:.1}H{:.1}",
                        x0 - ERROR_CAP,
                        x0 + ERROR_CAP,
                        x0 - ERROR_CAP,
                        x0 + ERROR_CAP
                    )
                };
                let _ = writeln!(
                    s,
                    r#"<path d="{d}" stroke="{color}" stroke-width="1.2" fill="none"/>"#
                );
            }
        }
    }

    /// The lines drawn, as pixel segments with the series whose line they are (`None`: a
    /// reference line or an error bar, which no label may cross).
    fn strokes(&self, f: &Frame) -> Vec<(Option<usize>, Stroke)> {
        let px = |(x, y): (f64, f64)| (f.px(x), f.py(y));
        let mut out = Vec::new();
        for (i, series) in self.series.iter().enumerate() {
            let pts = f.visible(series);
            if series.joined {
                out.extend(pts.windows(2).map(|w| (Some(i), (px(w[0]), px(w[1])))));
            }
            out.extend(
                bars(series, f)
                    .into_iter()
                    .map(|(_, (a, b))| (None, (px(a), px(b)))),
            );
        }
        for r in &self.references {
            let pts = reference_line(r, f);
            out.extend(pts.windows(2).map(|w| (None, (px(w[0]), px(w[1])))));
        }
        out
    }

    /// The markers (a ring, into `rings`, around an earlier marker at the same place, so both
    /// show), the marks' rings over them, then the labels, each where it covers no marker or
    /// label.
    fn markers_and_labels(&self, s: &mut String, rings: &mut String, f: &Frame) {
        // A marker drawn whole: its centre, how many points lie on it, and the labels queued
        // there (with their places in `label_queue`).
        struct Place<'l> {
            centre: (f64, f64),
            points: usize,
            labels: Vec<(&'l str, usize)>,
        }
        let mut occupied: Vec<Place> = Vec::new();
        // The floor's label is there first: a point's label had been drawn over it.
        let mut taken: Vec<Rect> = self
            .floor_label(f)
            .map(|(text, x, y)| {
                let w = text_width(&text);
                Rect::text_at(x - w, y, w).spaced()
            })
            .into_iter()
            .collect();
        let mut label_queue: Vec<(usize, f64, f64, f64, &str, &'static str)> = Vec::new();
        // Every marker's centre, and whether it has a label: a label must lie nearer its own
        // point than any other.
        let mut markers: Vec<((f64, f64), bool)> = Vec::new();
        for (i, series) in self.series.iter().enumerate() {
            for (k, &(x, y)) in series.points.iter().enumerate() {
                if !f.shows((x, y)) {
                    continue;
                }
                let (xx, yy) = (f.px(x), f.py(y));
                let label = series.labels.get(k).filter(|l| !l.is_empty());
                let spot = match occupied.iter().position(|p| hides(p.centre, (xx, yy))) {
                    Some(at) => at,
                    None => {
                        occupied.push(Place {
                            centre: (xx, yy),
                            points: 0,
                            labels: Vec::new(),
                        });
                        occupied.len() - 1
                    }
                };
                let place = &mut occupied[spot];
                let under = place.points;
                place.points += 1;
                let r = MARKER_R + 2.6 * under as f64;
                // A label the place has already (two series' d=2 there) is said once, placed
                // beside the outermost ring.
                let label = match label.and_then(|l| place.labels.iter().find(|(t, _)| *t == l)) {
                    Some(&(_, queued)) => {
                        label_queue[queued].3 = r;
                        None
                    }
                    None => label,
                };
                if let Some(l) = label {
                    place.labels.push((l, label_queue.len()));
                }
                if under > 0 {
                    let _ = writeln!(
                        rings,
                        r#"<circle cx="{xx:.1}" cy="{yy:.1}" r="{:.1}" fill="none" stroke="{}" stroke-width="1.6"/>"#,
                        r + 1.5,
                        series.style.color
                    );
                } else {
                    marker_svg(s, &series.style, xx, yy, r, series.style.hollow);
                }
                taken.push(Rect::around((xx, yy), r));
                markers.push(((xx, yy), label.is_some()));
                if let Some(label) = label {
                    label_queue.push((i, xx, yy, r, label, series.style.color));
                }
            }
        }
        // The marks' rings, over the markers; no label may cover them.
        for r in &self.references {
            if let Reference::Mark(_, (x, y)) = r
                && f.shows((*x, *y))
            {
                let (xx, yy) = (f.px(*x), f.py(*y));
                let _ = writeln!(
                    s,
                    r#"<circle cx="{xx:.1}" cy="{yy:.1}" r="{MARK_R}" fill="none" stroke="black" stroke-width="2"/>"#
                );
                taken.push(Rect::around((xx, yy), MARK_R));
            }
        }
        // What a label must not cross: every series' line, its own where a place allows (a
        // label beside its own point may touch its own line, and reads as that line's), the
        // reference lines and every error bar (issue: "n=1" on the other α's line, "d=64" on
        // a CI bar).
        let strokes = self.strokes(f);
        // A label said at one x is not said again at that x (the fallbacks of one camera turn
        // share its x, its off-screen share: three "yaw 45°" had stood in one column; the α
        // series' "n=0" at n = 0).
        let mut said: Vec<(&str, f64)> = Vec::new();
        for (i, xx, yy, r, label, color) in label_queue {
            if said
                .iter()
                .any(|&(t, x)| t == label && (x - xx).abs() < 1.0)
            {
                continue;
            }
            let lw = text_width(label);
            let others: Vec<Stroke> = strokes
                .iter()
                .filter(|(owner, _)| *owner != Some(i))
                .map(|&(_, st)| st)
                .collect();
            let all: Vec<Stroke> = strokes.iter().map(|&(_, st)| st).collect();
            // A point at the same place without a label of its own (a ring around this one)
            // is no other point to mistake the label for: it had kept every label off a
            // coinciding pair. Coinciding points with labels of their own still are.
            let rivals: Vec<(f64, f64)> = markers
                .iter()
                .filter(|&&(m, labelled)| labelled || !hides(m, (xx, yy)))
                .map(|&(m, _)| m)
                .collect();
            // Through what is drawn over its own place, unless another labelled point is
            // there too (whose label it would then be mistaken for). (The point itself is
            // among the rivals: alone is one there.)
            let alone = rivals.iter().filter(|&&m| hides(m, (xx, yy))).count() <= 1;
            // Clear of its own line too where a place allows (a label struck through by its
            // own line in about a hundred figures), beside its point, else away with a
            // leader; only then across its own line, as before.
            let place = [&all, &others].into_iter().find_map(|strokes| {
                place_label((xx, yy), r, lw, &rivals, &taken, strokes)
                    .map(|p| (p, None))
                    .or_else(|| {
                        place_label_away((xx, yy), r, lw, &taken, strokes, alone)
                            .map(|(lx, ly, rect, leader)| ((lx, ly, rect), Some(leader)))
                    })
            });
            if let Some(((lx, ly, rect), leader)) = place {
                said.push((label, xx));
                taken.push(rect.spaced());
                if let Some(((x0, y0), (x1, y1))) = leader {
                    let _ = writeln!(
                        s,
                        r#"<line x1="{x0:.1}" y1="{y0:.1}" x2="{x1:.1}" y2="{y1:.1}" stroke="{color}" stroke-width="0.8"/>"#
                    );
                }
                // Anchored at the box's side nearest the point: the box's width is an
                // estimate, so a label left of its point had ended short of it (by 35 px for
                // a long one).
                let (ax, anchor) = if rect.x1 <= xx {
                    (rect.x1, "end")
                } else if rect.x0 >= xx {
                    (lx, "start")
                } else {
                    ((rect.x0 + rect.x1) / 2.0, "middle")
                };
                let _ = writeln!(
                    s,
                    r#"<text x="{ax:.1}" y="{ly:.1}" font-size="10" fill="{color}" text-anchor="{anchor}">{}</text>"#,
                    esc(label)
                );
            }
        }
    }
}

/// A chart's data-to-pixel mapping onto its plot area.
struct Frame {
    ax: Axis,
    ay: Axis,
}

impl Frame {
    fn px(&self, x: f64) -> f64 {
        LEFT + self.ax.t(x) * PLOT_W
    }

    fn py(&self, y: f64) -> f64 {
        TOP + (1.0 - self.ay.t(y)) * PLOT_H
    }

    /// Whether the axes can show the point (a log axis no value ≤ 0).
    fn shows(&self, (x, y): (f64, f64)) -> bool {
        drawable(x, self.ax.log) && drawable(y, self.ay.log)
    }

    /// The 2-px cell a point's marker falls in: points in one cell are drawn as rings.
    fn key(&self, (x, y): (f64, f64)) -> (i64, i64) {
        (
            (self.px(x) / 2.0).round() as i64,
            (self.py(y) / 2.0).round() as i64,
        )
    }

    /// The points of `s` the axes can show.
    fn visible(&self, s: &Series) -> Vec<(f64, f64)> {
        s.points
            .iter()
            .copied()
            .filter(|&p| self.shows(p))
            .collect()
    }

    /// An SVG polyline's `points` for `pts`.
    fn polyline(&self, pts: &[(f64, f64)]) -> String {
        pts.iter()
            .map(|&(x, y)| format!("{:.1},{:.1}", self.px(x), self.py(y)))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// What a legend entry shows beside its name.
enum Shows<'a> {
    /// A series, and whether the plot draws its line.
    Series(&'a Series, bool),
    Reference(&'a Reference),
    /// What a ring around a marker means, where a series' name does not say it.
    Ring,
}

/// The legend, right of the plot: each entry's line or marker, then its name.
fn legend_svg(s: &mut String, legend: &[(String, Shows)]) {
    let lx = LEFT + PLOT_W + 14.0;
    let mut ly = TOP + 10.0;
    let mut references_drawn = 0;
    for (name, shows) in legend {
        match shows {
            Shows::Series(series, line) => {
                let st = &series.style;
                if *line {
                    let dash = if st.dash.is_empty() {
                        String::new()
                    } else {
                        format!(r#" stroke-dasharray="{}""#, st.dash)
                    };
                    let _ = writeln!(
                        s,
                        r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{}" stroke-width="1.8"{dash}/>"#,
                        lx + 24.0,
                        st.color
                    );
                }
                marker_svg(s, st, lx + 12.0, ly, MARKER_R, st.hollow);
            }
            Shows::Reference(Reference::Mark(..)) => {
                let _ = writeln!(
                    s,
                    r#"<circle cx="{}" cy="{ly}" r="7" fill="none" stroke="black" stroke-width="2"/>"#,
                    lx + 12.0
                );
            }
            Shows::Ring => {
                let _ = writeln!(
                    s,
                    r#"<circle cx="{}" cy="{ly}" r="{:.1}" fill="none" stroke="{REFERENCE_GREY}" stroke-width="1.6"/>"#,
                    lx + 12.0,
                    MARKER_R + 1.5
                );
            }
            Shows::Reference(_) => {
                let dash = REFERENCE_DASHES[references_drawn % REFERENCE_DASHES.len()];
                references_drawn += 1;
                let _ = writeln!(
                    s,
                    r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{REFERENCE_GREY}" stroke-width="1.5" stroke-dasharray="{dash}"/>"#,
                    lx + 24.0
                );
            }
        }
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}">{}</text>"#,
            lx + 30.0,
            ly + 4.0,
            esc(name)
        );
        ly += LEGEND_ROW;
    }
}

#[cfg(test)]
mod tests {
    /// Points past the outer decades of a log axis (2e-4 under a lowest decade of 1e-3, 3
    /// left of 10) get 2× and 5× ticks there, so none lies far below the lowest tick.
    #[test]
    fn log_axes_tick_the_stretches_beyond_their_outer_decades() {
        let mut c = Chart::new("FLIP over the mirror pixels vs cost", "ms", "FLIP");
        (c.x_log, c.y_log) = (true, true);
        c.series.push(Series::new(
            "portal",
            method_style("portal"),
            vec![(3.0, 0.1), (10.0, 0.01), (30.0, 1e-3), (100.0, 2e-4)],
        ));
        assert!(c.lint().is_empty(), "{:?}", c.lint());
        let (ax, ay) = c.axes();
        assert!(ax.ticks().contains(&5.0), "{:?}", ax.ticks());
        assert!(ay.ticks().contains(&5e-4), "{:?}", ay.ticks());
        // The decades stay the only ticks between them.
        assert!(!ay.ticks().contains(&0.02), "{:?}", ay.ticks());
    }

    /// An axis of at most two decades is ticked between them too: an advice's front from 0.8
    /// to 25 ms had "1" and "10" only, and its 2 ms budget no tick near.
    #[test]
    fn a_short_log_axis_is_ticked_between_its_decades() {
        let mut c = Chart::new("FLIP vs cost", "ms", "FLIP");
        (c.x_log, c.y_log) = (true, true);
        c.series.push(Series::new(
            "portal",
            method_style("portal"),
            vec![(0.8, 0.1), (2.0, 0.01), (25.0, 1e-3)],
        ));
        let (ax, _) = c.axes();
        let drawn = ax.ticks_drawn(PLOT_W, 24.0);
        for t in [1.0, 2.0, 5.0, 10.0, 20.0] {
            assert!(drawn.contains(&t), "{t} not in {drawn:?}");
        }
    }

    /// One notation per log axis: where a tick needs the exponent form, every tick below 1
    /// has it ("5e-1 … 1e-3", not "0.5 … 0.01, 1e-3"); ticks from 1 up keep theirs, and an axis
    /// that needs no exponent keeps plain decimals.
    #[test]
    fn a_log_axis_writes_its_ticks_in_one_notation() {
        assert_eq!(
            tick_labels(&[1e-3, 0.01, 0.1, 0.5, 1.0, 20.0], true),
            ["1e-3", "1e-2", "1e-1", "5e-1", "1", "20"]
        );
        assert_eq!(tick_labels(&[0.01, 0.1, 0.5], true), ["0.01", "0.1", "0.5"]);
        assert_eq!(tick_labels(&[1.5e-3, 2e-3], true), ["1.5e-3", "2e-3"]);
        assert_eq!(
            tick_labels(&[0.0, 0.005, 0.01], false),
            ["0", "5e-3", "0.01"]
        );
    }

    /// The figure check flags what a reviewer would send back, and nothing in a clean chart.
    #[test]
    fn lint_flags_look_alike_series_empty_legends_undrawable_points_and_zigzags() {
        let style = method_style("portal");
        let mut c = Chart::new("FLIP over the image vs cost", "x", "y");
        c.x_log = true;
        c.y_log = true;
        c.series
            .push(Series::new("a", style, vec![(1.0, 1.0), (2.0, 2.0)]));
        assert!(c.lint().is_empty(), "{:?}", c.lint());
        c.series.push(Series::new("b", style, vec![(3.0, 1.0)]));
        c.series
            .push(Series::new("c", method_style("naive"), vec![]));
        c.series.push(Series::new(
            "d",
            method_style("unrolled"),
            vec![(1.0, 0.0), (2.0, 1.0)],
        ));
        c.series.push(Series::new(
            "e",
            method_style("feedback"),
            vec![(2.0, 1.0), (1.0, 2.0)],
        ));
        let lint = c.lint().join("\n");
        assert!(lint.contains("\"a\" and \"b\" are drawn alike"), "{lint}");
        assert!(
            lint.contains("\"c\" has a legend entry and no point drawn"),
            "{lint}"
        );
        assert!(
            lint.contains("1 of the points of \"d\" cannot be drawn"),
            "{lint}"
        );
        assert!(
            lint.contains("\"e\" joins points whose x goes back"),
            "{lint}"
        );
        // A variant of the method is told apart.
        c.series[1].style = method_variant("portal", 1);
        assert!(!c.lint().join("\n").contains("drawn alike"));
        // A title without the metric's domain, or without any metric.
        c.title = "FLIP vs cost".into();
        assert!(c.lint().join("\n").contains("without its domain"));
        c.title = "Error vs depth".into();
        assert!(c.lint().join("\n").contains("names no metric"));
    }

    /// A variant keeps its style whatever else its chart holds, the defaults keep the
    /// method's own, an outside renderer's is hollow, and no two series of a chart look alike.
    #[test]
    fn a_variant_keeps_its_style_in_every_chart() {
        let key = |method, variant| StyleKey {
            method,
            variant,
            outside: false,
        };
        let passes = key("auxiliary", "max-passes=9");
        let alone = keyed_styles(&[passes])[0];
        let among = keyed_styles(&[
            key("auxiliary", "res=0.5"),
            key("portal", ""),
            key("auxiliary", ""),
            passes,
        ])[3];
        assert_eq!(alone, among);
        assert_ne!(alone, method_style("auxiliary"));
        assert_eq!(
            styles_for(&["ssr ssr-fallback=none", "ssr"])[1],
            method_style("ssr")
        );
        assert_eq!(
            styles_for(&["ssr ssr-fallback=none"])[0],
            styles_for(&["ssr", "ssr ssr-fallback=planar", "ssr ssr-fallback=none"])[2]
        );
        let outside = keyed_styles(&[StyleKey {
            method: "unrolled",
            variant: "three.js",
            outside: true,
        }])[0];
        assert!(outside.hollow);
        assert_eq!(outside.color, method_style("unrolled").color);
        // Eleven series of three methods sharing a colour (ssr, symmetry, feedback; 14 looks
        // in all): every look distinct.
        let names: Vec<String> = (0..3)
            .flat_map(|i| {
                [
                    format!("ssr opt={i}"),
                    format!("feedback history={i}"),
                    format!("symmetry draws={i}"),
                ]
            })
            .chain(["ssr".into(), "feedback".into()])
            .collect();
        let styles = styles_for(&names.iter().map(String::as_str).collect::<Vec<_>>());
        for (i, a) in styles.iter().enumerate() {
            for b in &styles[..i] {
                assert!(
                    (a.color, a.marker, a.hollow) != (b.color, b.marker, b.hollow),
                    "{i}: {a:?}"
                );
            }
        }
        assert_eq!(styles[9], method_style("ssr"));
        assert_eq!(styles[10], method_style("feedback"));
        // The variants that share charts in the committed reports take distinct places by
        // their keys alone, so that neither moves the other.
        let pair = ["ssr ssr-fallback=none", "ssr ssr-fallback=planar"];
        let both = styles_for(&pair);
        assert_eq!(both[0], styles_for(&pair[..1])[0]);
        assert_eq!(both[1], styles_for(&pair[1..])[0]);
        // A setting (n, a cube size) keys a series only beside the same method at another
        // setting: alone, `auxiliary n=2` looks as `auxiliary` along n does.
        for pair in [
            ["auxiliary n=1", "auxiliary n=2"],
            [
                "cubemap cube-size=128 history=16",
                "cubemap cube-size=512 history=16",
            ],
        ] {
            let method = pair[0].split(' ').next().unwrap();
            assert_eq!(styles_for(&pair[..1])[0], method_style(method));
            let both = styles_for(&pair);
            assert_ne!(both[0], both[1], "{pair:?}");
        }
        assert_eq!(
            styles_for(&["auxiliary n=2 res=0.5"])[0],
            styles_for(&["auxiliary res=0.5"])[0]
        );
        // The method at another α keeps its marker, hollow.
        let at_alpha = styles_for(&["portal", "portal α=0.7"])[1];
        assert_eq!(at_alpha.marker, method_style("portal").marker);
        assert!(at_alpha.hollow);
    }

    /// The palette's pairs a reader can confuse at a marker's size (indices into `COLORS`):
    /// orange and vermilion, blue and sky blue.
    const NEAR_COLOURS: [(usize, usize); 2] = [(4, 1), (0, 5)];

    /// A method's variants take markers no other method of its colour has, so that a variant
    /// never looks like another method's series.
    #[test]
    fn the_methods_of_one_colour_own_disjoint_markers() {
        let methods = [
            "naive",
            "auxiliary",
            "path-textures",
            "portal",
            "unrolled",
            "symmetry",
            "symmetry-pruned",
            "symmetry-baked",
            "feedback",
            "cubemap",
            "ssr",
            "ray-query",
            "truth",
        ];
        for (i, a) in methods.iter().enumerate() {
            let (ca, ma, more_a) = method_entry(a);
            assert!(!more_a.contains(&ma), "{a}");
            for b in &methods[..i] {
                let (cb, mb, more_b) = method_entry(b);
                if ca != cb {
                    continue;
                }
                let own_a: Vec<Marker> =
                    std::iter::once(ma).chain(more_a.iter().copied()).collect();
                assert!(
                    !own_a.contains(&mb) && !more_b.iter().any(|m| own_a.contains(m)),
                    "{a} and {b} share a marker"
                );
            }
            // No variant takes the own marker of a method of a near colour.
            for b in &methods {
                let (cb, mb, _) = method_entry(b);
                let near = NEAR_COLOURS.iter().any(|&(i, j)| {
                    (ca, cb) == (COLORS[i], COLORS[j]) || (ca, cb) == (COLORS[j], COLORS[i])
                });
                assert!(
                    !(near && more_a.contains(&mb)),
                    "{a}'s variants take {b}'s marker"
                );
            }
            // Every variant of the method within its looks is its own.
            let looks: Vec<Style> = (0..point_looks(a)).map(|k| method_variant(a, k)).collect();
            for (k, s) in looks.iter().enumerate() {
                assert!(
                    !looks[..k]
                        .iter()
                        .any(|t| (t.marker, t.hollow) == (s.marker, s.hollow))
                );
            }
        }
    }

    /// An axis label claims interval bars only where some series draws one on that axis.
    #[test]
    fn an_axis_promises_ci_bars_only_where_they_are_drawn() {
        let label = "ms/frame (median, 95 % CI bars)";
        let mut chart = Chart {
            series: vec![Series::new(
                "a",
                method_style("naive"),
                vec![(1.0, 2.0), (3.0, 4.0)],
            )],
            ..Chart::new("t", label, "FLIP")
        };
        let svg = chart.to_svg();
        assert!(svg.contains(">ms/frame (median)<"), "{svg}");
        chart.series[0].x_intervals = vec![Some([0.9, 1.1]), None];
        assert!(chart.to_svg().contains(">ms/frame (median, 95 % CI bars)<"));
    }

    use super::*;

    /// Values at the ends of f64 (a record's or an outside client's) give an axis with a
    /// bounded number of finite ticks, at once: a timing of 1e300 ms had padded the log axis
    /// to infinity and asked for 2^31 ticks, and linear steps far from 0 were lost in rounding
    /// and never reached the axis's end.
    #[test]
    fn an_axis_of_extreme_values_has_few_finite_ticks() {
        for (values, log) in [
            (vec![1e300], true),
            (vec![1e-300, 1e300], true),
            (vec![f64::MAX], true),
            (vec![f64::MAX, -f64::MAX], false),
            (vec![1e20, 1e20 + 1e5], false),
            (vec![1e-310, 1e-3], true),
            (vec![1e300], false),
        ] {
            let axis = Axis::new(values.iter().copied(), log);
            let ticks = axis.ticks_drawn(400.0, 12.0);
            assert!(
                ticks.len() <= 700 && ticks.iter().all(|t| t.is_finite()),
                "{values:?}: {} ticks",
                ticks.len()
            );
            assert!(axis.lo.is_finite() && axis.hi.is_finite() && axis.lo < axis.hi);
        }
    }

    fn chart(series: Vec<Series>) -> Chart {
        Chart {
            x_log: true,
            series,
            references: vec![Reference::Level("one full-scene pass".into(), 0.05)],
            floor: Some(0.01),
            footer: "scenes/mirror_box.json · 640x360 · llvmpipe · 2026-11-26 · commit abc".into(),
            ..Chart::new("t", "ms", "err")
        }
    }

    /// [`chart`] with one series, "a", in auxiliary's style.
    fn chart_of(points: Vec<(f64, f64)>) -> Chart {
        chart(vec![Series::new("a", method_style("auxiliary"), points)])
    }

    /// The number in quotes right after the first `prefix` in `svg` (an attribute's value).
    fn number_after(svg: &str, prefix: &str) -> f64 {
        svg.split(prefix)
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap()
            .parse()
            .unwrap()
    }

    fn width(svg: &str) -> f64 {
        number_after(svg, "width=\"")
    }

    /// Two references (the advisor's Pareto front and its budget) are told apart: each has
    /// its own dash, the same in the plot and in its legend row.
    #[test]
    fn each_reference_has_its_own_dash_in_plot_and_legend() {
        let mut c = chart_of(vec![(1.0, 0.5), (10.0, 0.1)]);
        c.references.push(Reference::Curve(
            "budget".into(),
            vec![(5.0, 0.1), (5.0, 0.5)],
        ));
        let svg = c.to_svg();
        for dash in &REFERENCE_DASHES[..2] {
            let n = svg.matches(&format!("stroke-dasharray=\"{dash}\"")).count();
            assert_eq!(n, 2, "dash {dash}: {n} strokes (plot and legend)");
        }
    }

    /// A mark rings its point in the plot and in the legend (named as given, not as a
    /// reference), takes no dash from the lines after it, and one the axis cannot show is
    /// flagged by the figure check.
    #[test]
    fn a_mark_rings_its_point_and_takes_no_dash() {
        let mut c = chart_of(vec![(1.0, 0.5), (10.0, 0.1)]);
        c.y_log = true;
        c.references = vec![Reference::Mark("the pick: a".into(), (10.0, 0.1))];
        c.references.push(Reference::Curve(
            "budget".into(),
            vec![(5.0, 0.1), (5.0, 0.5)],
        ));
        let svg = c.to_svg();
        let rings = svg
            .matches(r#"fill="none" stroke="black" stroke-width="2"/>"#)
            .count();
        assert_eq!(rings, 2, "one ring in the plot, one in the legend:\n{svg}");
        // The plot's ring is centred on the point's own marker (10, 0.1).
        let centre = |tag: &str| {
            let at = |k: &str| {
                let v = tag.split(&format!("{k}=\"")).nth(1).unwrap();
                v[..v.find('"').unwrap()].to_string()
            };
            (at("cx"), at("cy"))
        };
        let ring = svg
            .lines()
            .find(|l| l.contains(&format!(r#"r="{MARK_R}""#)))
            .unwrap();
        let markers: Vec<_> = svg
            .lines()
            .filter(|l| l.starts_with("<circle") && l.contains(r#"r="4.0""#))
            .map(centre)
            .collect();
        assert_eq!(
            markers.len(),
            3,
            "two points and the legend's swatch:\n{svg}"
        );
        assert_eq!(centre(ring), markers[1], "{svg}");
        assert!(svg.contains(">the pick: a</text>"), "{svg}");
        assert!(!svg.contains("reference: the pick"), "{svg}");
        // The budget after the mark is the first line: the first dash, in plot and legend.
        let dash = |i: usize| format!("stroke-dasharray=\"{}\"", REFERENCE_DASHES[i]);
        assert_eq!(svg.matches(&dash(0)).count(), 2, "{svg}");
        assert_eq!(svg.matches(&dash(1)).count(), 0, "{svg}");
        assert!(
            !c.lint().iter().any(|m| m.contains("mark")),
            "{:?}",
            c.lint()
        );
        c.references
            .push(Reference::Mark("zero".into(), (10.0, 0.0)));
        assert!(
            c.lint().iter().any(|m| m.contains("the mark \"zero\"")),
            "{:?}",
            c.lint()
        );
    }

    /// Every marker's hollow form is an outline with an inside (white fill), not the filled
    /// form drawn thinner: a plus or cross drawn as two thin strokes read as the filled one
    /// where points are not joined (two variants alike).
    #[test]
    fn every_hollow_marker_is_an_outline_apart_from_its_filled_form() {
        for marker in Marker::ALL {
            let style = Style {
                marker,
                ..method_style("cubemap")
            };
            let (mut filled, mut hollow) = (String::new(), String::new());
            marker_svg(&mut filled, &style, 50.0, 50.0, MARKER_R, false);
            marker_svg(&mut hollow, &style, 50.0, 50.0, MARKER_R, true);
            assert!(hollow.contains(r#"fill="white""#), "{marker:?}: {hollow}");
            let shape = |svg: &str| svg.split_whitespace().next().unwrap().to_string();
            if matches!(marker, Marker::Plus | Marker::Cross) {
                assert_ne!(shape(&filled), shape(&hollow), "{marker:?}");
            }
        }
    }

    /// A point a pixel or two from another's marker is drawn as a ring around it, and the
    /// legend says what a ring is: before, only points at the same place were, and naive's
    /// marker vanished under auxiliary n=0's 1–3 px away.
    #[test]
    fn a_point_under_another_marker_is_ringed() {
        let mut c = chart_of(vec![(1.0, 0.5), (10.0, 0.1)]);
        c.series.push(Series::new(
            "b",
            method_style("naive"),
            vec![(1.02, 0.5), (3.0, 0.3)],
        ));
        let svg = c.to_svg();
        let ring = format!(
            r#"r="{:.1}" fill="none" stroke="{}""#,
            MARKER_R + 2.6 + 1.5,
            method_style("naive").color
        );
        assert_eq!(svg.matches(&ring).count(), 1, "{svg}");
        assert!(
            svg.contains("ring: a point hidden by an earlier one"),
            "{svg}"
        );
        assert!(hides((0.0, 0.0), (3.9, 0.0)) && !hides((0.0, 0.0), (4.0, 0.0)));
        // Both points at one place labelled alike: the label is said once.
        c.series[1].points[0] = (1.0, 0.5);
        c.series[0].labels = vec!["d=2".into(), String::new()];
        c.series[1].labels = vec!["d=2".into(), String::new()];
        assert_eq!(c.to_svg().matches(">d=2</text>").count(), 1);
    }

    /// No point's label is drawn over the floor band's label: points just above the floor at
    /// the plot's right end, at a run of heights, label themselves elsewhere or not at all.
    #[test]
    fn a_label_keeps_off_the_floor_label() {
        for k in 0..12 {
            let y = 0.0105 * 1.04f64.powi(k);
            let mut c = chart_of(vec![(1.0, 0.5), (9.0, y), (10.0, y * 1.02)]);
            c.series[0].labels = vec!["n=0".into(), "long label 1".into(), "long label 2".into()];
            let f = {
                let (ax, ay) = c.axes();
                Frame { ax, ay }
            };
            let (text, x1, base) = c.floor_label(&f).unwrap();
            let floor = Rect {
                x0: x1 - SMALL_CHAR_W * text.chars().count() as f64,
                y0: base - 9.0,
                x1,
                y1: base + 1.0,
            };
            let svg = c.to_svg();
            assert!(svg.contains(">n=0</text>"), "labels are drawn: {svg}");
            for label in ["long label 1", "long label 2"] {
                let Some(at) = svg.find(&format!(">{label}</text>")) else {
                    continue;
                };
                let tag = &svg[svg[..at].rfind("<text").unwrap()..at];
                let (lx, ly) = (number_after(tag, "x=\""), number_after(tag, "y=\""));
                let rect = Rect {
                    x0: lx,
                    y0: ly - 9.0,
                    x1: lx + SMALL_CHAR_W * label.len() as f64,
                    y1: ly + 1.0,
                };
                assert!(!rect.overlaps(&floor), "{k}: {label} at {lx} {ly}");
            }
        }
    }

    /// Sixteen decades in the plot's height: the 2× and 5× steps beyond the outer decades are
    /// kept only where their labels clear the others, the outermost first, so that the lowest
    /// point stays within a factor 2.5 of a tick.
    #[test]
    fn tick_labels_do_not_crowd_a_long_log_axis() {
        let ay = Axis::new([2.5e-16, 1.5].into_iter(), true);
        let ticks = ay.ticks_drawn(PLOT_H, Y_TICK_GAP);
        let px: Vec<f64> = ticks.iter().map(|&t| ay.t(t) * PLOT_H).collect();
        assert!(
            px.windows(2).all(|w| w[1] - w[0] >= Y_TICK_GAP),
            "{ticks:?} at {px:?}"
        );
        assert!(ticks[0] <= 2.5e-16 * 2.5, "{ticks:?}");
        assert!(ticks.len() < ay.ticks().len(), "{:?}", ay.ticks());
    }

    /// A point at x = 0 is drawn whole with the rings around it: the linear axis pads below 0
    /// (it had started at 0, and the point sat on the frame, its rings cut); the 0 tick is
    /// drawn, and no tick below it. The data's clip still reaches a marker's size past the
    /// frame.
    #[test]
    fn a_marker_at_zero_is_not_cut() {
        let mut c = chart_of(vec![(0.0, 0.5), (10.0, 0.1)]);
        c.x_log = false;
        let svg = c.to_svg();
        let clip_x = number_after(&svg, "<clipPath id=\"marks\"><rect x=\"");
        let cx = number_after(&svg, "<circle cx=\"");
        assert!(
            cx - LEFT > MARKER_R + 2.6 + 1.5,
            "the point at 0 and a ring around it inside the frame: {cx}"
        );
        assert!(clip_x <= LEFT - MARKER_R, "clip from {clip_x}");
        assert!(svg.contains(r#"text-anchor="middle">0</text>"#), "{svg}");
        assert!(!svg.contains(r#"text-anchor="middle">-"#), "{svg}");
    }

    /// A reference that draws no line (a curve with one visible point) has no legend entry,
    /// and the next one takes the first dash in plot and legend alike.
    #[test]
    fn a_reference_drawn_as_no_line_is_not_in_the_legend() {
        let mut c = chart_of(vec![(1.0, 0.5), (10.0, 0.1)]);
        c.y_log = true;
        c.references = vec![
            Reference::Curve("Pareto front".into(), vec![(1.0, 0.5)]),
            // Below every point on a log axis: off the y axis, drawn nowhere.
            Reference::Curve("early budget".into(), vec![(0.5, 1e-9), (20.0, 1e-9)]),
            Reference::Mark("the pick".into(), (10.0, 0.1)),
            Reference::Curve("budget".into(), vec![(5.0, 0.1), (5.0, 0.5)]),
            Reference::Level("one full-scene pass".into(), 0.3),
        ];
        let svg = c.to_svg();
        assert!(!svg.contains("Pareto front"), "{svg}");
        assert!(!svg.contains("early budget"), "{svg}");
        assert!(svg.contains("reference: budget"), "{svg}");
        // The budget takes the first dash and the level the second, a mark between them none:
        // each twice, in the plot and in the legend.
        for dash in &REFERENCE_DASHES[..2] {
            let dash = format!("stroke-dasharray=\"{dash}\"");
            assert_eq!(svg.matches(&dash).count(), 2, "{dash}: {svg}");
        }
        // A budget faster than every point widens the x axis to it and is drawn.
        c.references = vec![Reference::Curve(
            "budget".into(),
            vec![(0.2, 0.1), (0.2, 0.5)],
        )];
        let (ax, _) = c.axes();
        assert!(ax.contains(0.2), "{} – {}", ax.lo, ax.hi);
        assert!(c.to_svg().contains("reference: budget"));
    }

    /// The floor band's label is drawn after the grid lines, which would cross it.
    #[test]
    fn the_floor_label_lies_over_the_grid() {
        let mut c = chart_of(vec![(1.0, 0.5), (10.0, 0.1)]);
        c.floor = Some(0.2);
        let svg = c.to_svg();
        let label = svg
            .find("floor (no mirrors) 0.2")
            .expect("a band with its label");
        let last_grid = svg.rfind(r##"stroke="#e5e5e5""##).unwrap();
        assert!(label > last_grid, "{svg}");
    }

    #[test]
    fn chart_places_points_inside_the_plot_area() {
        let mut s = Series::new(
            "a <b>",
            method_style("auxiliary"),
            vec![(10.0, 0.5), (1000.0, 0.1)],
        );
        s.labels = vec!["n=0".into(), "n=4".into()];
        s.x_intervals = vec![Some([8.0, 12.0]), None];
        s.y_intervals = vec![None, Some([0.05, 0.2])];
        let svg = chart(vec![s]).to_svg();
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert!(svg.contains("a &lt;b&gt;"), "names are escaped");
        // Two markers in the plot, one in the legend.
        assert_eq!(svg.matches("<circle").count(), 3);
        for cap in svg.split("<circle cx=\"").skip(1).take(2) {
            let cx: f64 = cap.split('"').next().unwrap().parse().unwrap();
            assert!((LEFT..=LEFT + PLOT_W).contains(&cx), "{cx}");
        }
        assert!(svg.contains("reference: one full-scene pass"));
        assert!(svg.contains("commit abc"), "the footer is drawn");
        // One horizontal and one vertical error bar, each with its caps, inside the plot:
        // the x axis reaches down to the interval's 8 ms, below the lowest point.
        let bars: Vec<&str> = svg.split("<path d=\"M").skip(1).collect();
        assert_eq!(bars.len(), 2);
        let first_x: f64 = bars[0].split(',').next().unwrap().parse().unwrap();
        assert!((LEFT..=LEFT + PLOT_W).contains(&first_x), "{first_x}");
        // The legend's column is wide enough for its longest entry.
        assert!(
            width(&svg)
                >= LEFT + PLOT_W + LEGEND_CHAR_W * "reference: one full-scene pass".len() as f64
        );
    }

    #[test]
    fn a_log_axis_is_tight_and_a_far_floor_is_a_note() {
        let s = Series::new(
            "m",
            method_style("portal"),
            vec![(900.0, 2e-3), (1800.0, 3e-3)],
        );
        let mut c = chart(vec![s]);
        c.y_log = true;
        c.floor = Some(1e-14);
        c.references.clear();
        let svg = c.to_svg();
        assert!(svg.contains("below the axis"), "{svg}");
        // No tick at 1e4 (the data stop at 1.8e3) nor at 1e-14.
        assert!(!svg.contains(">1e4<") && !svg.contains("e-14<"), "{svg}");
    }

    #[test]
    fn one_distinct_x_is_not_a_chart() {
        let s = Series::new("m", method_style("portal"), vec![(64.0, 1.0), (64.0, 2.0)]);
        assert!(!chart(vec![s]).is_drawable());
        let s = Series::new("m", method_style("portal"), vec![(1.0, 1.0), (64.0, 2.0)]);
        assert!(chart(vec![s]).is_drawable());
    }

    #[test]
    fn coinciding_series_both_show_and_the_legend_says_so() {
        let pts = vec![(1.0, 1.0), (2.0, 2.0)];
        let a = Series::new("unrolled", method_style("unrolled"), pts.clone());
        let b = Series::new("portal", method_style("portal"), pts);
        let svg = chart(vec![a, b]).to_svg();
        assert!(svg.contains("portal (on unrolled)"), "{svg}");
        // Each of portal's points is a ring around unrolled's marker.
        assert_eq!(
            svg.matches("fill=\"none\" stroke=\"#009E73\"").count(),
            2 + 1
        );
        // The name says what its rings mean: no legend line for rings.
        assert!(
            !svg.contains("ring: a point hidden by an earlier one"),
            "{svg}"
        );
        // One point in common: a ring the names do not explain, so the legend does.
        let a = Series::new(
            "unrolled",
            method_style("unrolled"),
            vec![(1.0, 1.0), (2.0, 2.0)],
        );
        let b = Series::new(
            "portal",
            method_style("portal"),
            vec![(1.0, 1.0), (3.0, 3.0)],
        );
        let svg = chart(vec![a, b]).to_svg();
        assert!(!svg.contains("(on unrolled)"), "{svg}");
        assert!(
            svg.contains("ring: a point hidden by an earlier one's marker"),
            "{svg}"
        );
    }

    /// A count axis (frames) ticks whole numbers only: three frames read 0, 1, 2, not 0.5.
    #[test]
    fn a_count_axis_has_whole_ticks() {
        let s = Series::new(
            "m",
            method_style("feedback"),
            vec![(0.0, 1.0), (1.0, 2.0), (2.0, 3.0)],
        );
        let mut c = chart(vec![s]);
        (c.x_log, c.references) = (false, Vec::new());
        // The x axis' tick labels are centred under their ticks (the y axis' end-anchored).
        let x_tick = |v: &str| format!(r#"text-anchor="middle">{v}</text>"#);
        assert!(
            c.to_svg().contains(&x_tick("0.5")),
            "the plain axis ticks halves"
        );
        c.x_whole = true;
        let svg = c.to_svg();
        assert!(
            !svg.contains(&x_tick("0.5")) && svg.contains(&x_tick("1")),
            "{svg}"
        );
    }

    /// A label goes right-above its point unless another point lies as near that place as
    /// its own; then the next place, and none where every place is ambiguous.
    #[test]
    fn a_label_never_lies_nearer_another_point() {
        let (x, y, r, lw) = (LEFT + 200.0, TOP + 200.0, MARKER_R, 30.0);
        let own = [(x, y)];
        let (lx, ly, _) = place_label((x, y), r, lw, &own, &[], &[]).unwrap();
        assert!(lx > x && ly < y, "right-above: {lx} {ly}");
        // A point where the right-above label would sit: right-below instead.
        let above = [(x, y), (x + r + 2.0 + lw / 2.0, y - r - 5.0)];
        let (lx, ly, _) = place_label((x, y), r, lw, &above, &[], &[]).unwrap();
        assert!(lx > x && ly > y, "right-below: {lx} {ly}");
        // Points at every place: left out.
        let all = [
            (x, y),
            (x + r + 2.0 + lw / 2.0, y - r - 5.0),
            (x + r + 2.0 + lw / 2.0, y + r + 5.0),
            (x - r - 2.0 - lw / 2.0, y - r - 5.0),
            (x - r - 2.0 - lw / 2.0, y + r + 5.0),
        ];
        assert!(place_label((x, y), r, lw, &all, &[], &[]).is_none());
        // The four corners taken by other labels (each reaching 6 px from the marker's
        // centre): beside the marker, on the right.
        let corner = |x0: f64, y0: f64| Rect {
            x0,
            y0,
            x1: x0 + lw,
            y1: y0 + 8.0,
        };
        let corners = [
            corner(x + r + 2.0, y - 14.0),
            corner(x + r + 2.0, y + 6.0),
            corner(x - r - 2.0 - lw, y - 14.0),
            corner(x - r - 2.0 - lw, y + 6.0),
        ];
        assert!(
            place_label((x, y), r, lw, &own, &corners[..2], &[]).is_some_and(|(lx, _, _)| lx < x)
        );
        let (lx, ly, _) = place_label((x, y), r, lw, &own, &corners, &[]).unwrap();
        assert!(lx > x && (ly - (y + 4.0)).abs() < 1e-9, "right: {lx} {ly}");
        // Another series' line (or a reference line, or an error bar) through the right-above
        // place: right-below instead; lines along the box's edges do not count.
        let line: Stroke = ((x - 100.0, y - r - 5.0), (x + 100.0, y - r - 5.0));
        let (lx, ly, _) = place_label((x, y), r, lw, &own, &[], &[line]).unwrap();
        assert!(lx > x && ly > y, "right-below: {lx} {ly}");
        let b = Rect {
            x0: 0.0,
            y0: 0.0,
            x1: 10.0,
            y1: 10.0,
        };
        assert!(b.crossed_by((-5.0, 5.0), (15.0, 5.0)), "through");
        assert!(b.crossed_by((2.0, 2.0), (3.0, 3.0)), "inside");
        assert!(
            b.crossed_by((-5.0, -5.0), (5.0, 5.0)),
            "into a corner's inside"
        );
        assert!(!b.crossed_by((-5.0, 10.0), (15.0, 10.0)), "along an edge");
        assert!(!b.crossed_by((-5.0, 0.0), (0.0, -5.0)), "past a corner");
        assert!(!b.crossed_by((-5.0, 5.0), (5.0, -5.0)), "touching a corner");
        assert!(b.crossed_by((4.0, 4.0), (4.0, 4.0)), "a point inside");
        assert!(!b.crossed_by((0.0, 4.0), (0.0, 4.0)), "a point on an edge");
        assert!(!b.crossed_by((20.0, 0.0), (20.0, 10.0)), "beside");
        // A point just beyond the label's far end is farther from it than its own: no matter.
        let far = [(x, y), (x + r + 2.0 + lw + 3.0 * r, y - r - 5.0)];
        let (lx, ly, _) = place_label((x, y), r, lw, &far, &[], &[]).unwrap();
        assert!(lx > x && ly < y, "right-above: {lx} {ly}");
    }

    /// The legend shows a line only for a series the plot draws one for: a joined series of
    /// one point is a marker alone in both.
    #[test]
    fn a_legend_line_only_where_the_plot_draws_one() {
        let mut c = chart_of(vec![(1.0, 0.5), (10.0, 0.1)]);
        let one = Series::new("one point", method_style("naive"), vec![(5.0, 0.2)]);
        assert!(one.joined);
        c.series.push(one);
        let svg = c.to_svg();
        // The first series: its polyline and its legend line; the second: neither (the
        // fixture's reference draws a grey polyline of its own).
        let lines_of = |colour: &str| {
            svg.matches(&format!(r#"stroke="{colour}" stroke-width="1.8""#))
                .count()
        };
        assert_eq!(lines_of(method_style("auxiliary").color), 2, "{svg}");
        assert_eq!(lines_of(method_style("naive").color), 0, "{svg}");
        assert_eq!(svg.matches(r#"stroke-width="1.8""#).count(), 2, "{svg}");
    }

    /// A label is said once per x: a second series' point at the same x with the same label
    /// is left unlabelled; at another x, or with another label, it is labelled.
    #[test]
    fn a_label_is_said_once_at_one_x() {
        let mut c = chart_of(vec![(1.0, 0.5), (10.0, 0.02)]);
        c.series[0].labels = vec!["yaw 45°".into(), "yaw 0°".into()];
        let mut b = Series::new("b", method_style("naive"), vec![(1.0, 0.1), (10.0, 0.2)]);
        b.labels = vec!["yaw 45°".into(), "yaw 90°".into()];
        c.series.push(b);
        let svg = c.to_svg();
        assert_eq!(svg.matches(">yaw 45°</text>").count(), 1, "{svg}");
        assert_eq!(svg.matches(">yaw 90°</text>").count(), 1, "{svg}");
    }

    /// A point whose places beside its marker are all taken gets its label a little away,
    /// with a leader line from its marker; where those are taken too, none.
    #[test]
    fn a_crowded_label_goes_away_on_a_leader() {
        let (r, lw) = (MARKER_R, 30.0);
        let (x, y) = (LEFT + 200.0, TOP + 150.0);
        // Other points close around it: every place beside its marker lies as near one of
        // them as its own, so would read as theirs.
        let markers: Vec<(f64, f64)> = std::iter::once((x, y))
            .chain((0..8).map(|k| {
                // Between the eight directions a leader may take.
                let a = (f64::from(k) + 0.5) * std::f64::consts::FRAC_PI_4;
                (x + 14.0 * a.cos(), y + 14.0 * a.sin())
            }))
            .collect();
        let near: Vec<Rect> = markers[1..]
            .iter()
            .map(|&(mx, my)| Rect {
                x0: mx - r,
                y0: my - r,
                x1: mx + r,
                y1: my + r,
            })
            .collect();
        assert!(place_label((x, y), r, lw, &markers, &near, &[]).is_none());
        let (_, _, rect, (from, to)) = place_label_away((x, y), r, lw, &near, &[], false).unwrap();
        assert!(!near.iter().any(|t| t.overlaps(&rect)));
        assert!(
            (from.0 - x).hypot(from.1 - y) > r,
            "the leader starts at the marker's edge"
        );
        assert!(to.0 >= rect.x0 && to.0 <= rect.x1 && to.1 >= rect.y0 && to.1 <= rect.y1);
        // Everything around taken: no label.
        let all = [Rect {
            x0: LEFT,
            y0: TOP,
            x1: LEFT + PLOT_W,
            y1: TOP + PLOT_H,
        }];
        assert!(place_label_away((x, y), r, lw, &all, &[], false).is_none());
    }

    /// Segments' distance: 0 where they cross or touch, else the nearest ends' gap.
    #[test]
    fn segments_distance_is_zero_where_they_meet() {
        let d = |a: Stroke, b: Stroke| segments_distance(a, b);
        assert_eq!(
            d(((0.0, 0.0), (10.0, 10.0)), ((0.0, 10.0), (10.0, 0.0))),
            0.0
        );
        assert_eq!(
            d(((0.0, 0.0), (10.0, 0.0)), ((10.0, 0.0), (20.0, 0.0))),
            0.0
        );
        assert!((d(((0.0, 0.0), (10.0, 0.0)), ((0.0, 3.0), (10.0, 3.0))) - 3.0).abs() < 1e-12);
        assert!((d(((0.0, 0.0), (1.0, 0.0)), ((4.0, 4.0), (4.0, 9.0))) - 5.0).abs() < 1e-12);
    }

    /// A leader keeps 2 px from every other line and bar: with a bar across the first away
    /// place's way, the label goes elsewhere, its leader clear of the bar.
    #[test]
    fn a_leader_keeps_off_other_lines_and_bars() {
        let (r, lw) = (MARKER_R, 30.0);
        let (x, y) = (LEFT + 200.0, TOP + 150.0);
        let (_, _, _, first) = place_label_away((x, y), r, lw, &[], &[], false).unwrap();
        // A vertical bar across the first leader's middle.
        let mid = ((first.0.0 + first.1.0) / 2.0, (first.0.1 + first.1.1) / 2.0);
        let bar = ((mid.0, mid.1 - 30.0), (mid.0, mid.1 + 30.0));
        let (_, _, rect, leader) = place_label_away((x, y), r, lw, &[], &[bar], false).unwrap();
        assert!(segments_distance(leader, bar) >= 2.0, "{leader:?}");
        assert!(!rect.crossed_by(bar.0, bar.1));
    }

    /// A label keeps off its own series' line where a place allows: from the first point the
    /// line climbs through the first place tried (right, above), and the label had been
    /// drawn there, struck through (about a hundred figures).
    #[test]
    fn a_label_keeps_off_its_own_line() {
        let mut c = chart_of(vec![(1.0, 0.02), (2.1, 0.1), (30.0, 0.25)]);
        c.series[0].labels = vec!["first".into(), String::new(), String::new()];
        let svg = c.to_svg();
        let at = svg.find(">first</text>").expect("the label is drawn");
        let tag = &svg[svg[..at].rfind("<text").unwrap()..at];
        let (x, y, lw) = (
            number_after(tag, "x=\""),
            number_after(tag, "y=\""),
            text_width("first"),
        );
        let x0 = if tag.contains(r#"text-anchor="end""#) {
            x - lw
        } else if tag.contains(r#"text-anchor="middle""#) {
            x - lw / 2.0
        } else {
            x
        };
        let rect = Rect::text_at(x0, y, lw);
        let color = tag
            .split("fill=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap();
        let line = svg
            .split("<polyline points=\"")
            .find(|l| l.contains(&format!(r#"stroke="{color}" stroke-width="1.8""#)))
            .expect("the series' line");
        let pts: Vec<(f64, f64)> = line
            .split('"')
            .next()
            .unwrap()
            .split(' ')
            .map(|p| {
                let (a, b) = p.split_once(',').unwrap();
                (a.parse().unwrap(), b.parse().unwrap())
            })
            .collect();
        assert!(
            !pts.windows(2).any(|w| rect.crossed_by(w[0], w[1])),
            "{tag} across {pts:?}"
        );
    }

    /// A label left of its point ends at its box's right edge (text-anchor end), whatever
    /// the estimate of its width: a long one had ended 35 px short of its marker.
    #[test]
    fn a_label_left_of_its_point_is_anchored_at_its_end() {
        // The point at the plot's right end: only the places left of it are inside.
        let mut c = chart_of(vec![(1.0, 0.5), (10.0, 0.1)]);
        c.series[0].labels = vec![String::new(), "590 reflections shown".into()];
        let svg = c.to_svg();
        let at = svg.find(">590 reflections shown</text>").unwrap();
        let tag = &svg[svg[..at].rfind("<text").unwrap()..at];
        assert!(tag.contains(r#"text-anchor="end""#), "{tag}");
        let cx = number_after(
            &svg[svg.find("<circle cx=\"").unwrap() + 1..],
            "<circle cx=\"",
        );
        assert!(number_after(tag, "x=\"") < cx, "{tag} left of {cx}");
    }

    /// A label keeps a gap from one placed before it: a second label that would start where
    /// the first ends goes elsewhere.
    #[test]
    fn labels_side_by_side_keep_a_gap() {
        let (r, lw) = (MARKER_R, 20.0);
        let (x, y) = (LEFT + 100.0, TOP + 100.0);
        let (_, _, first) = place_label((x, y), r, lw, &[(x, y)], &[], &[]).unwrap();
        // A second point whose right-above label would begin one pixel after the first's end.
        let second = (first.x1 + 1.0 - r - 2.0, y);
        let markers = [(x, y), second];
        let (lx, ly, _) = place_label(second, r, lw, &markers, &[first], &[]).unwrap();
        assert_eq!(
            (lx, ly),
            (second.0 + r + 2.0, y - r - 1.0),
            "abutting is allowed unspaced"
        );
        let (lx, ly, _) = place_label(second, r, lw, &markers, &[first.spaced()], &[]).unwrap();
        assert_ne!(
            (lx, ly),
            (second.0 + r + 2.0, y - r - 1.0),
            "spaced: not beside the first"
        );
    }

    /// A labelled point with an unlabelled one at the same place (drawn as a ring around it),
    /// at the plot's left edge, is labelled: the other point had counted as a rival nearer to
    /// every place on the right, and its marker had barred every leader (an advisor's front
    /// point and its pick went unlabelled). With both labelled, the rule stands (below).
    #[test]
    fn a_point_with_an_unlabelled_twin_is_labelled() {
        let mut own = Series::new(
            "own",
            method_style("naive"),
            vec![(1.0, 1.0), (100.0, 10.0)],
        );
        own.labels = vec!["texture-scale=0.5".into(), String::new()];
        own.joined = false;
        let mut twin = Series::new("twin", method_style("auxiliary"), vec![(1.01, 1.0)]);
        twin.joined = false;
        let svg = chart(vec![own, twin]).to_svg();
        assert!(svg.contains(">texture-scale=0.5</text>"), "{svg}");
    }

    #[test]
    fn labels_that_would_overprint_are_left_out() {
        let mut s = Series::new(
            "m",
            method_style("auxiliary"),
            vec![(10.0, 1.0), (10.01, 1.0), (10.02, 1.0), (100.0, 2.0)],
        );
        s.labels = vec![
            "first".into(),
            "second".into(),
            "third".into(),
            "far".into(),
        ];
        s.joined = false;
        let svg = chart(vec![s]).to_svg();
        let drawn = ["first", "second", "third"]
            .iter()
            .filter(|l| svg.contains(&format!(">{l}</text>")))
            .count();
        assert!(drawn < 3, "{svg}");
        assert!(svg.contains(">far</text>"));
    }
}
