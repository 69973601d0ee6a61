//! Uneven mirrors (issue 16, seed 002's "uneven mirrors") in a report: the error each raster
//! trick (`bump=…` and its parameters among the method options) leaves against the traced
//! truth, and its cost, against the bump's steepest tilt (`bump_amplitude_deg`).
//!
//! The report knows the options' names (`bump`, `bump-strength`, `proxy-distance`,
//! `march-steps`, `texture-margin`), not the rasterizer.

use crate::Record;
use crate::plot::{Chart, Series};
use crate::write::{Block, distinct, ms_cell, sci};

/// The raster options of an uneven-mirror trick (crates/raster/src/uneven.rs).
const TRICK_OPTIONS: [&str; 5] = [
    "bump",
    "bump-strength",
    "proxy-distance",
    "march-steps",
    "texture-margin",
];

/// The method a point measured without its trick options: `auxiliary n=2`.
pub fn method_of(r: &Record) -> String {
    r.method_without(&TRICK_OPTIONS)
}

/// The trick in words, from the options (absent options are at their defaults: `march`,
/// strength 0.5, proxy at 2, 48 steps, no margin): `distort ×1`, `march, margin 16 px`.
/// A method not in `bump_methods` (the sweep's registry: those with a `bump` option) shows an
/// uneven mirror flat: it has no texture to read.
pub fn trick_of(r: &Record, bump_methods: &[String]) -> String {
    if !bump_methods.contains(&r.method) {
        return "flat (no texture to read)".into();
    }
    let option = |name: &str| r.option(name).map(String::from);
    let bump = option("bump").unwrap_or_else(|| "march".into());
    let mut words = match bump.as_str() {
        "distort" | "distort-distance" => {
            format!(
                "{bump} ×{}",
                option("bump-strength").unwrap_or("0.5".into())
            )
        }
        "proxy" => format!(
            "proxy at {}",
            option("proxy-distance").unwrap_or("2".into())
        ),
        "march" => match option("march-steps") {
            Some(s) => format!("march, {s} steps"),
            None => "march".into(),
        },
        other => other.to_string(),
    };
    if let Some(m) = option("texture-margin") {
        words.push_str(&format!(", margin {m} px"));
    }
    words
}

/// The sweep's main method: the one most of its points measured.
fn main_method(points: &[&Record]) -> String {
    let methods = distinct(points.iter().map(|r| method_of(r)));
    methods
        .iter()
        .max_by_key(|m| points.iter().filter(|r| &&method_of(r) == m).count())
        .cloned()
        .unwrap_or_default()
}

/// A point's row and series name: its trick, prefixed with its method where that is not the
/// main method (`auxiliary n=4: march`).
fn variant_of(r: &Record, main: &str, bump_methods: &[String]) -> String {
    let m = method_of(r);
    if m == main {
        trick_of(r, bump_methods)
    } else {
        format!("{m}: {}", trick_of(r, bump_methods))
    }
}

fn points(records: &[Record]) -> Vec<&Record> {
    records
        .iter()
        .filter(|r| r.kind == "point" && r.bump_amplitude_deg.is_some())
        .collect()
}

fn amplitudes(points: &[&Record]) -> Vec<f32> {
    let mut a = distinct(points.iter().filter_map(|r| r.bump_amplitude_deg));
    a.sort_by(f32::total_cmp);
    a
}

/// Which trick wins at each tilt, by how much, and what the best distortion strength is.
pub fn sentences(records: &[Record], bump_methods: &[String]) -> Vec<String> {
    let pts = points(records);
    let main = main_method(&pts);
    let mut out = Vec::new();
    for a in amplitudes(&pts) {
        let at: Vec<&Record> = pts
            .iter()
            .copied()
            .filter(|r| r.bump_amplitude_deg == Some(a))
            .collect();
        let best = |filter: &dyn Fn(&Record) -> bool| {
            at.iter()
                .copied()
                .filter(|r| filter(r))
                .min_by(|p, q| p.metrics.flip_mean.total_cmp(&q.metrics.flip_mean))
        };
        let Some(win) = best(&|_| true) else {
            continue;
        };
        let flat = best(&|r| variant_of(r, &main, bump_methods) == "flat");
        let distort = best(&|r| variant_of(r, &main, bump_methods).starts_with("distort "));
        let mut s = format!(
            "At {a}°: `{}` is closest to the truth, FLIP mean {} (relMSE {}) at {} ms/frame",
            variant_of(win, &main, bump_methods),
            sci(win.metrics.flip_mean),
            sci(win.metrics.relmse),
            ms_cell(win, 1)
        );
        if let Some(f) = flat {
            s.push_str(&format!(
                "; ignoring the bump (`{main}`) gives {}",
                sci(f.metrics.flip_mean)
            ));
        }
        if let Some(d) = distort {
            s.push_str(&format!(
                "; the best distortion strength is `{}` ({})",
                variant_of(d, &main, bump_methods),
                sci(d.metrics.flip_mean)
            ));
        }
        s.push('.');
        out.push(s);
    }
    out
}

/// Every trick's time and error at every tilt, one row per trick; `relmse` adds the relMSE
/// columns.
pub(crate) fn table(records: &[Record], bump_methods: &[String], relmse: bool) -> Block {
    let pts = points(records);
    let amps = amplitudes(&pts);
    let main = main_method(&pts);
    let tricks = distinct(pts.iter().map(|r| variant_of(r, &main, bump_methods)));
    let mut header = vec!["trick".to_string(), "ms/frame median [95 % CI]".into()];
    header.extend(amps.iter().map(|a| format!("FLIP at {a}°")));
    if relmse {
        header.extend(amps.iter().map(|a| format!("relMSE at {a}°")));
    }
    let find = |t: &str, a: f32| {
        pts.iter()
            .copied()
            .find(|r| variant_of(r, &main, bump_methods) == t && r.bump_amplitude_deg == Some(a))
    };
    let rows = tricks
        .iter()
        .map(|t| {
            // The time at the steepest tilt (the march's cost depends on where rays go).
            let timed = amps.last().and_then(|&a| find(t, a));
            let mut row = vec![t.clone(), timed.map_or("–".into(), |r| ms_cell(r, 2))];
            row.extend(
                amps.iter()
                    .map(|&a| find(t, a).map_or("–".into(), |r| sci(r.metrics.flip_mean))),
            );
            if relmse {
                row.extend(
                    amps.iter()
                        .map(|&a| find(t, a).map_or("–".into(), |r| sci(r.metrics.relmse))),
                );
            }
            row
        })
        .collect();
    Block::Table(header, rows)
}

/// The report section of a bump-amplitude sweep (empty for any other sweep).
pub(crate) fn uneven_section(records: &[Record], bump_methods: &[String]) -> Vec<Block> {
    let pts = points(records);
    if pts.is_empty() {
        return Vec::new();
    }
    let amps = amplitudes(&pts);
    let main = main_method(&pts);
    let tricks = distinct(pts.iter().map(|r| variant_of(r, &main, bump_methods)));
    let methods = distinct(pts.iter().map(|r| method_of(r)));
    let mut out = vec![
        Block::Heading(
            2,
            "Uneven mirrors: the engines' tricks against the truth".into(),
        ),
        Block::Paragraph(format!(
            "The truth reflects about the perturbed normal at every mirror hit, to any depth \
             (docs/shading.md, \"Uneven mirrors\"); each raster point reads its mirror textures \
             with the trick named beside it (crates/raster/src/uneven.rs): `flat` ignores the \
             bump, `distort` moves the lookup on screen by the normal (three.js Water, Unity), \
             `proxy` intersects the reflected ray with a plane at a fixed distance (Unreal), \
             `march` marches it through the texture's distances. Methods: {}. The tilt is the \
             bump's steepest (the ripple's amplitude; the normal map's strength set so that \
             its steepest texel tilts that much).",
            methods.join(", ")
        )),
    ];
    let series: Vec<Series> = tricks
        .iter()
        .map(|t| {
            let mut rs: Vec<&Record> = pts
                .iter()
                .copied()
                .filter(|r| &variant_of(r, &main, bump_methods) == t)
                .collect();
            rs.sort_by(|p, q| {
                p.bump_amplitude_deg
                    .unwrap_or(0.0)
                    .total_cmp(&q.bump_amplitude_deg.unwrap_or(0.0))
            });
            Series {
                name: t.clone(),
                points: rs
                    .iter()
                    .map(|r| {
                        (
                            f64::from(r.bump_amplitude_deg.unwrap_or(0.0)),
                            r.metrics.flip_mean,
                        )
                    })
                    .collect(),
                labels: Vec::new(),
                x_intervals: Vec::new(),
                y_intervals: Vec::new(),
            }
        })
        .collect();
    out.push(Block::Chart(
        "plot_uneven_error_vs_tilt.svg".into(),
        Chart {
            title: "FLIP mean vs the bump's steepest tilt, by trick".into(),
            x_label: "steepest tilt (degrees)".into(),
            y_label: "FLIP mean".into(),
            x_log: false,
            y_log: true,
            series,
            reference_lines: Vec::new(),
        }
        .to_svg(),
    ));
    out.push(table(records, bump_methods, true));
    let s = sentences(records, bump_methods);
    if !s.is_empty() {
        out.push(Block::Bullets(s));
    }
    // Image rows: truth | trick | FLIP for the best and worst non-flat trick at a small and
    // at the largest tilt.
    let small = amps.iter().copied().find(|&a| a > 0.0);
    let large = amps.last().copied();
    for a in distinct([small, large].into_iter().flatten()) {
        let mut at: Vec<&Record> = pts
            .iter()
            .copied()
            .filter(|r| r.bump_amplitude_deg == Some(a))
            .collect();
        at.sort_by(|p, q| p.metrics.flip_mean.total_cmp(&q.metrics.flip_mean));
        let chosen = distinct(
            [
                at.first().copied(),
                at.iter()
                    .copied()
                    .find(|r| variant_of(r, &main, bump_methods) == "flat"),
            ]
            .into_iter()
            .flatten()
            .map(|r| r.key.clone()),
        );
        out.push(Block::Heading(
            3,
            format!("Truth | trick | FLIP error at {a}°"),
        ));
        for key in chosen {
            let Some(r) = at.iter().find(|r| r.key == key) else {
                continue;
            };
            out.push(Block::Paragraph(format!(
                "{}, {}, tilt {a}°: FLIP mean {}",
                method_of(r),
                trick_of(r, bump_methods),
                sci(r.metrics.flip_mean)
            )));
            out.push(Block::Images(vec![
                (format!("truth ({a}°)"), r.truth_image.clone()),
                (variant_of(r, &main, bump_methods), r.raster_image.clone()),
                ("FLIP error".into(), r.heatmap_image.clone()),
            ]));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bump() -> Vec<String> {
        vec!["auxiliary".into(), "path-textures".into()]
    }

    fn record(options: &str, a: f32, flip: f64) -> Record {
        let mut r = crate::write::tests::record(2, 10.0, 1, flip);
        r.key = format!("{options} {a}");
        r.method_options = options.into();
        r.bump_amplitude_deg = Some(a);
        r.metrics.flip_mean = flip;
        r
    }

    #[test]
    fn tricks_are_read_from_the_options() {
        let r = record("bump=distort bump-strength=2", 5.0, 0.1);
        assert_eq!(trick_of(&r, &bump()), "distort ×2");
        assert_eq!(method_of(&r), "auxiliary n=2");
        assert_eq!(trick_of(&record("", 5.0, 0.1), &bump()), "march");
        assert_eq!(
            trick_of(&record("bump=march texture-margin=16", 5.0, 0.1), &bump()),
            "march, margin 16 px"
        );
        assert_eq!(
            trick_of(&record("bump=proxy", 5.0, 0.1), &bump()),
            "proxy at 2"
        );
        let mut exact = record("", 5.0, 0.1);
        exact.method = "unrolled".into();
        exact.n = None;
        exact.depth = Some(64);
        assert_eq!(trick_of(&exact, &bump()), "flat (no texture to read)");
        let main = main_method(&[
            &record("", 5.0, 0.1),
            &record("bump=flat", 5.0, 0.1),
            &exact,
        ]);
        assert_eq!(main, "auxiliary n=2");
        assert_eq!(
            variant_of(&exact, &main, &bump()),
            "unrolled depth=64: flat (no texture to read)"
        );
    }

    #[test]
    fn the_winner_per_tilt_is_the_lowest_flip() {
        let records = vec![
            record("bump=flat", 5.0, 0.3),
            record("bump=distort", 5.0, 0.2),
            record("bump=distort bump-strength=1", 5.0, 0.15),
            record("", 5.0, 0.05),
            record("bump=flat", 0.0, 0.01),
            record("", 0.0, 0.02),
        ];
        let s = sentences(&records, &bump()).join("\n");
        assert!(s.contains("At 0°: `flat` is closest"), "{s}");
        assert!(
            s.contains("At 5°: `march` is closest to the truth, FLIP mean 5.000e-2"),
            "{s}"
        );
        assert!(
            s.contains("ignoring the bump (`auxiliary n=2`) gives 3.000e-1"),
            "{s}"
        );
        assert!(
            s.contains("best distortion strength is `distort ×1` (1.500e-1)"),
            "{s}"
        );
        assert!(uneven_section(&records, &bump()).len() >= 5);
        let mut plain = records[0].clone();
        plain.bump_amplitude_deg = None;
        assert!(uneven_section(&[plain], &bump()).is_empty());
    }
}
