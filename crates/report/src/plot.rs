//! Small SVG line charts (log or linear axes, markers, legend, horizontal reference lines).
//! Hand-written to keep the report free of font and rendering dependencies.

use std::fmt::Write;

pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    /// A short label drawn beside each point (e.g. "n=2"); empty for none.
    pub labels: Vec<String>,
    /// An interval around each point's x (e.g. a 95 % confidence interval of a median time),
    /// drawn as a horizontal error bar; empty, or `None` for a point without one.
    pub x_intervals: Vec<Option<[f64; 2]>>,
    /// The same for y, drawn as a vertical error bar.
    pub y_intervals: Vec<Option<[f64; 2]>>,
}

pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    pub series: Vec<Series>,
    /// Dashed horizontal lines: (name, y).
    pub reference_lines: Vec<(String, f64)>,
}

const PALETTE: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf",
];
/// Width of the plot area; the legend's column is added to its right, as wide as its longest
/// entry needs.
const PLOT_W: f64 = 450.0;
const H: f64 = 420.0;
const LEFT: f64 = 80.0;
/// Approximate advance of one character of the 12 px sans-serif legend text.
const LEGEND_CHAR_W: f64 = 7.0;
/// The legend column: its margin, the sample line and the gap before the text.
const LEGEND_PAD: f64 = 14.0 + 28.0 + 10.0;
const TOP: f64 = 40.0;
/// Half-length of an error bar's end caps, px.
const ERROR_CAP: f64 = 4.0;
const BOTTOM: f64 = 50.0;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
}

impl Axis {
    fn new(values: impl Iterator<Item = f64>, log: bool) -> Axis {
        let v: Vec<f64> = values
            .filter(|x| x.is_finite() && (!log || *x > 0.0))
            .collect();
        let (mut lo, mut hi) = v
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        if !lo.is_finite() {
            (lo, hi) = if log { (0.1, 10.0) } else { (0.0, 1.0) };
        }
        if log {
            lo = 10f64.powf(lo.log10().floor());
            hi = 10f64.powf(hi.log10().ceil().max(lo.log10() + 1.0));
        } else {
            let pad = ((hi - lo) * 0.08).max(1e-12);
            lo = if lo >= 0.0 && lo - pad < 0.0 {
                0.0
            } else {
                lo - pad
            };
            hi += pad;
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
    fn ticks(&self) -> Vec<f64> {
        if self.log {
            let (a, b) = (
                self.lo.log10().round() as i32,
                self.hi.log10().round() as i32,
            );
            (a..=b).map(|e| 10f64.powi(e)).collect()
        } else {
            let raw = (self.hi - self.lo) / 5.0;
            let mag = 10f64.powf(raw.log10().floor());
            let step = [1.0, 2.0, 5.0, 10.0]
                .iter()
                .map(|m| m * mag)
                .find(|s| *s >= raw)
                .unwrap_or(raw);
            let mut t = (self.lo / step).ceil() * step;
            let mut out = Vec::new();
            while t <= self.hi + 1e-12 {
                out.push(t);
                t += step;
            }
            out
        }
    }
}

fn fmt_tick(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e4 || v.abs() < 1e-3 {
        format!("{v:.0e}")
    } else {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

impl Chart {
    pub fn to_svg(&self) -> String {
        // The axes span the points and their error bars.
        let bounds = |i: &[Option<[f64; 2]>]| -> Vec<f64> {
            i.iter().flatten().flatten().copied().collect()
        };
        let xs = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0).chain(bounds(&s.x_intervals)));
        let ys = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1).chain(bounds(&s.y_intervals)))
            .chain(self.reference_lines.iter().map(|r| r.1));
        let (ax, ay) = (Axis::new(xs, self.x_log), Axis::new(ys, self.y_log));
        let legend_chars = self
            .series
            .iter()
            .map(|s| s.name.chars().count())
            .chain(
                self.reference_lines
                    .iter()
                    .map(|(n, y)| n.chars().count() + 3 + fmt_tick(*y).len() + " (off axis)".len()),
            )
            .max()
            .unwrap_or(0);
        let (pw, ph) = (PLOT_W, H - TOP - BOTTOM);
        let w = (LEFT + pw + LEGEND_PAD + LEGEND_CHAR_W * legend_chars as f64).ceil();
        let px = |x: f64| LEFT + ax.t(x) * pw;
        let py = |y: f64| TOP + (1.0 - ay.t(y)) * ph;
        let mut s = String::new();
        let _ = writeln!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{H}" viewBox="0 0 {w} {H}" font-family="sans-serif" font-size="12">"#
        );
        let _ = writeln!(s, r#"<rect width="{w}" height="{H}" fill="white"/>"#);
        let _ = writeln!(
            s,
            r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
            LEFT + pw / 2.0,
            esc(&self.title)
        );
        for t in ax.ticks() {
            let x = px(t);
            let _ = writeln!(
                s,
                r##"<line x1="{x:.1}" y1="{TOP}" x2="{x:.1}" y2="{:.1}" stroke="#e5e5e5"/><text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
                TOP + ph,
                TOP + ph + 16.0,
                fmt_tick(t)
            );
        }
        for t in ay.ticks() {
            let y = py(t);
            let _ = writeln!(
                s,
                r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e5e5e5"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
                LEFT + pw,
                LEFT - 6.0,
                y + 4.0,
                fmt_tick(t)
            );
        }
        let _ = writeln!(
            s,
            r#"<rect x="{LEFT}" y="{TOP}" width="{pw}" height="{ph}" fill="none" stroke="black"/>"#
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            LEFT + pw / 2.0,
            H - 12.0,
            esc(&self.x_label)
        );
        let _ = writeln!(
            s,
            r#"<text x="18" y="{:.1}" text-anchor="middle" transform="rotate(-90 18 {:.1})">{}</text>"#,
            TOP + ph / 2.0,
            TOP + ph / 2.0,
            esc(&self.y_label)
        );
        let mut legend_y = TOP + 10.0;
        let lx = LEFT + pw + 14.0;
        for (name, y) in &self.reference_lines {
            if !(y.is_finite() && (!ay.log || *y > 0.0)) {
                // Not drawable (e.g. 0 on a log axis): say so in the legend.
                let _ = writeln!(
                    s,
                    r##"<text x="{lx}" y="{}">{} = {} (off axis)</text>"##,
                    legend_y + 4.0,
                    esc(name),
                    fmt_tick(*y)
                );
                legend_y += 18.0;
                continue;
            }
            let yy = py(*y);
            let _ = writeln!(
                s,
                r##"<line x1="{LEFT}" y1="{yy:.1}" x2="{:.1}" y2="{yy:.1}" stroke="#555" stroke-dasharray="6 4"/>"##,
                LEFT + pw
            );
            let _ = writeln!(
                s,
                r##"<line x1="{lx}" y1="{legend_y}" x2="{}" y2="{legend_y}" stroke="#555" stroke-dasharray="6 4"/><text x="{}" y="{}">{}</text>"##,
                lx + 22.0,
                lx + 28.0,
                legend_y + 4.0,
                esc(name)
            );
            legend_y += 18.0;
        }
        for (i, series) in self.series.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            let pts: Vec<(f64, f64)> = series
                .points
                .iter()
                .copied()
                .filter(|(x, y)| {
                    x.is_finite() && y.is_finite() && (!ax.log || *x > 0.0) && (!ay.log || *y > 0.0)
                })
                .collect();
            let path: Vec<String> = pts
                .iter()
                .map(|&(x, y)| format!("{:.1},{:.1}", px(x), py(y)))
                .collect();
            let _ = writeln!(
                s,
                r#"<polyline points="{}" fill="none" stroke="{color}" stroke-width="2"/>"#,
                path.join(" ")
            );
            for (k, &(x, y)) in series.points.iter().enumerate() {
                if !pts.contains(&(x, y)) {
                    continue;
                }
                let drawable = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
                if let Some([lo, hi]) = series.x_intervals.get(k).copied().flatten()
                    && drawable(lo, ax.log)
                    && drawable(hi, ax.log)
                {
                    let (x0, x1, yy) = (px(lo), px(hi), py(y));
                    let _ = writeln!(
                        s,
                        r#"<path d="M{x0:.1},{yy:.1}H{x1:.1}M{x0:.1},{:.1}V{:.1}M{x1:.1},{:.1}V{:.1}" stroke="{color}" stroke-width="1.2" fill="none"/>"#,
                        yy - ERROR_CAP,
                        yy + ERROR_CAP,
                        yy - ERROR_CAP,
                        yy + ERROR_CAP
                    );
                }
                if let Some([lo, hi]) = series.y_intervals.get(k).copied().flatten()
                    && drawable(lo, ay.log)
                    && drawable(hi, ay.log)
                {
                    let (y0, y1, xx) = (py(lo), py(hi), px(x));
                    let _ = writeln!(
                        s,
                        r#"<path d="M{xx:.1},{y0:.1}V{y1:.1}M{:.1},{y0:.1}H{:.1}M{:.1},{y1:.1}H{:.1}" stroke="{color}" stroke-width="1.2" fill="none"/>"#,
                        xx - ERROR_CAP,
                        xx + ERROR_CAP,
                        xx - ERROR_CAP,
                        xx + ERROR_CAP
                    );
                }
                let _ = writeln!(
                    s,
                    r#"<circle cx="{:.1}" cy="{:.1}" r="3.5" fill="{color}"/>"#,
                    px(x),
                    py(y)
                );
                if let Some(label) = series.labels.get(k).filter(|l| !l.is_empty()) {
                    let _ = writeln!(
                        s,
                        r#"<text x="{:.1}" y="{:.1}" font-size="10" fill="{color}">{}</text>"#,
                        px(x) + 5.0,
                        py(y) - 5.0,
                        esc(label)
                    );
                }
            }
            let _ = writeln!(
                s,
                r#"<line x1="{lx}" y1="{legend_y}" x2="{}" y2="{legend_y}" stroke="{color}" stroke-width="2"/><text x="{}" y="{}">{}</text>"#,
                lx + 22.0,
                lx + 28.0,
                legend_y + 4.0,
                esc(&series.name)
            );
            legend_y += 18.0;
        }
        s.push_str("</svg>\n");
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chart_places_points_inside_the_plot_area() {
        let c = Chart {
            title: "t".into(),
            x_label: "ms".into(),
            y_label: "err".into(),
            x_log: true,
            y_log: false,
            series: vec![Series {
                name: "a <b>".into(),
                points: vec![(10.0, 0.5), (1000.0, 0.1)],
                labels: vec!["n=0".into(), "n=4".into()],
                x_intervals: vec![Some([8.0, 12.0]), None],
                y_intervals: vec![None, Some([0.05, 0.2])],
            }],
            reference_lines: vec![("floor (no mirrors)".into(), 0.05)],
        };
        let svg = c.to_svg();
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert!(svg.contains("a &lt;b&gt;"), "names are escaped");
        assert_eq!(svg.matches("<circle").count(), 2);
        for cap in svg.split("<circle cx=\"").skip(1) {
            let cx: f64 = cap.split('"').next().unwrap().parse().unwrap();
            assert!((LEFT..=LEFT + PLOT_W).contains(&cx), "{cx}");
        }
        assert!(svg.contains("stroke-dasharray"));
        // One horizontal and one vertical error bar, each with its caps, inside the plot:
        // the x axis reaches down to the interval's 8 ms, below the lowest point.
        let bars: Vec<&str> = svg.split("<path d=\"M").skip(1).collect();
        assert_eq!(bars.len(), 2);
        let first_x: f64 = bars[0].split(',').next().unwrap().parse().unwrap();
        assert!((LEFT..=LEFT + PLOT_W).contains(&first_x), "{first_x}");
        assert!(bars[0].contains('H') && bars[1].starts_with(|c: char| c.is_ascii_digit()));
        // The legend's column is wide enough for its longest entry.
        let width: f64 = svg
            .split("width=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!(
            width
                >= LEFT
                    + PLOT_W
                    + LEGEND_CHAR_W * "floor (no mirrors) = 0.05 (off axis)".len() as f64
        );
    }
}
