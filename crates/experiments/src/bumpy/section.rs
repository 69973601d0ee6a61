//! Uneven mirrors (issue 16, seed 002's "uneven mirrors") in a report: the error each raster
//! trick (`bump=…` and its parameters among the method options) leaves against the traced
//! truth, and its cost, against the bump's steepest tilt (`bump_amplitude_deg`).
//!
//! The report knows the options' names (`bump`, `bump-strength`, `proxy-distance`,
//! `march-steps`, `texture-margin`), not the rasterizer.

use mirrorbox_report::Record;
use mirrorbox_report::document::{
    Block, distinct, join_words, lowest_with_ties, markdown, ms_cell, sci,
};
use mirrorbox_report::plot::{Chart, Marker, Series, Style, method_style, our_styles};
use mirrorbox_report::readme::{ReadmeError, RegionSource, measured_on};
use mirrorbox_report::{Sweep, SweepInfo, load_sweep};

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

/// A trick family's style in its host method's colour: one marker and dash per family in every
/// chart (`march`, the default, solid with a filled circle); a family added later gets the
/// circle, hollow, dashed.
fn trick_style(host: &str, family: &str) -> Style {
    let (marker, dash, hollow) = match family {
        "march" => (Marker::Circle, "", false),
        "flat" => (Marker::Cross, "2 3", false),
        "distort" => (Marker::Square, "7 4", false),
        "distort-distance" => (Marker::Diamond, "8 3 2 3", false),
        "proxy" => (Marker::TriangleUp, "12 3", false),
        _ => (Marker::Circle, "12 3 2 3 2 3", true),
    };
    Style {
        color: method_style(host).color,
        marker,
        dash,
        hollow,
    }
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
        .filter(|r| r.kind == "point" && r.tilt_deg().is_some())
        .collect()
}

fn amplitudes(points: &[&Record]) -> Vec<f32> {
    let mut a = distinct(points.iter().filter_map(|r| r.tilt_deg()));
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
            .filter(|r| r.tilt_deg() == Some(a))
            .collect();
        let flip = |r: &Record| r.metrics.flip_mean;
        let name = |r: &Record| format!("`{}`", variant_of(r, &main, bump_methods));
        // Winners within 2 % of the lowest error are a tie, said as one.
        let winners = lowest_with_ties(at.iter().copied(), flip);
        let Some(win) = winners.first().copied() else {
            continue;
        };
        let flat = at
            .iter()
            .copied()
            .find(|r| variant_of(r, &main, bump_methods) == "flat");
        let mut s = if winners.len() == 1 {
            format!(
                "At {a}°: {} is closest to the truth, FLIP mean {} (relMSE {}) at {} ms/frame",
                name(win),
                sci(win.metrics.flip_mean),
                sci(win.metrics.relmse),
                ms_cell(win, 1)
            )
        } else {
            let lo = sci(winners
                .iter()
                .map(|r| flip(r))
                .fold(f64::INFINITY, f64::min));
            let hi = sci(winners.iter().map(|r| flip(r)).fold(0.0, f64::max));
            let range = if lo == hi {
                format!("FLIP mean {lo} each")
            } else {
                format!("FLIP mean {lo}–{hi}, within 2 %")
            };
            format!(
                "At {a}°: {} tie for closest to the truth ({range})",
                join_words(&winners.iter().map(|r| name(r)).collect::<Vec<_>>())
            )
        };
        if let Some(f) = flat {
            s.push_str(&format!(
                "; ignoring the bump (`{main}`) gives {}",
                sci(f.metrics.flip_mean)
            ));
        }
        let distorts = lowest_with_ties(
            at.iter()
                .copied()
                .filter(|r| variant_of(r, &main, bump_methods).starts_with("distort ")),
            flip,
        );
        match distorts.len() {
            0 => {}
            1 => s.push_str(&format!(
                "; the best distortion strength is {} ({})",
                name(distorts[0]),
                sci(distorts[0].metrics.flip_mean)
            )),
            n => s.push_str(&format!(
                "; {n} distortion strengths tie ({}, within 2 % of {})",
                join_words(&distorts.iter().map(|r| name(r)).collect::<Vec<_>>()),
                sci(distorts[0].metrics.flip_mean.min(flip(distorts[n - 1])))
            )),
        }
        // The main method's best other trick, where it beats every distortion strength: a
        // sentence naming only the distortions would hide it.
        let other = at
            .iter()
            .copied()
            .filter(|r| {
                let v = variant_of(r, &main, bump_methods);
                !v.contains(": ")
                    && v != "flat"
                    && !v.starts_with("distort ")
                    && !winners.iter().any(|w| std::ptr::eq(*w, *r))
            })
            .min_by(|a, b| flip(a).total_cmp(&flip(b)));
        if let Some(o) = other
            && distorts.first().is_some_and(|d| flip(o) < flip(d))
        {
            s.push_str(&format!(
                "; {} ({}) is closer than any distortion strength",
                name(o),
                sci(o.metrics.flip_mean)
            ));
        }
        s.push('.');
        out.push(s);
    }
    out
}

/// Every trick's time and error at every tilt, one row per trick; `relmse` adds the relMSE
/// columns.
pub fn table(records: &[Record], bump_methods: &[String], relmse: bool) -> Block {
    let pts = points(records);
    let amps = amplitudes(&pts);
    let main = main_method(&pts);
    let tricks = distinct(pts.iter().map(|r| variant_of(r, &main, bump_methods)));
    let mut header = vec![
        "trick".to_string(),
        mirrorbox_report::document::ms_heading("ms/frame median", pts.iter().copied()),
    ];
    header.extend(amps.iter().map(|a| format!("FLIP at {a}°")));
    if relmse {
        header.extend(amps.iter().map(|a| format!("relMSE at {a}°")));
    }
    let find = |t: &str, a: f32| {
        pts.iter()
            .copied()
            .find(|r| variant_of(r, &main, bump_methods) == t && r.tilt_deg() == Some(a))
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
pub fn uneven_section(records: &[Record], bump_methods: &[String]) -> Vec<Block> {
    let pts = points(records);
    if pts.is_empty() {
        return Vec::new();
    }
    let amps = amplitudes(&pts);
    let main = main_method(&pts);
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
    // One chart per method that reads the bump: its trick families (flat, distort, proxy,
    // march), each at its setting with the lowest mean error over the tilts (the table lists
    // every setting), beside the methods that show the mirror flat. The question: which trick
    // errs least as the tilt grows.
    let family = |t: &str| t.split([' ', ',']).next().unwrap_or_default().to_string();
    let tilt = |r: &Record| f64::from(r.tilt_deg().unwrap_or(0.0));
    let curve = |rs: &[&Record]| -> Vec<(f64, f64)> {
        let mut p: Vec<(f64, f64)> = rs.iter().map(|r| (tilt(r), r.metrics.flip_mean)).collect();
        p.sort_by(|a, b| a.0.total_cmp(&b.0));
        p
    };
    let flat_only: Vec<String> = methods
        .iter()
        .filter(|m| {
            pts.iter()
                .filter(|r| &&method_of(r) == m)
                .all(|r| !bump_methods.contains(&r.method))
        })
        .cloned()
        .collect();
    let flat_bases: Vec<String> = flat_only
        .iter()
        .map(|f| {
            pts.iter()
                .find(|r| &method_of(r) == f)
                .map_or(f.clone(), |r| r.method.clone())
        })
        .collect();
    // The methods shown flat beside the host's tricks keep their own styles.
    let flat_styles = our_styles(
        &flat_bases
            .iter()
            .map(|b| (b.as_str(), ""))
            .collect::<Vec<_>>(),
    );
    for (chart_index, m) in methods
        .iter()
        .filter(|m| !flat_only.contains(m))
        .enumerate()
    {
        let mine: Vec<&Record> = pts.iter().copied().filter(|r| &method_of(r) == m).collect();
        let base = mine.first().map_or(String::new(), |r| r.method.clone());
        let mut series = Vec::new();
        let fams = distinct(mine.iter().map(|r| family(&trick_of(r, bump_methods))));
        // A trick has one marker and dash in every chart and report (`trick_style`), in its host
        // method's colour: each chart is one host's tricks, so the marker says the trick, not the
        // method (`flat` had been a cross, a square and a triangle in three charts).
        let styles: Vec<Style> = fams.iter().map(|f| trick_style(&base, f)).collect();
        for (fam, &style) in fams.iter().zip(&styles) {
            let settings = distinct(
                mine.iter()
                    .filter(|r| &family(&trick_of(r, bump_methods)) == fam)
                    .map(|r| trick_of(r, bump_methods)),
            );
            let of = |t: &String| -> Vec<&Record> {
                mine.iter()
                    .copied()
                    .filter(|r| &trick_of(r, bump_methods) == t)
                    .collect()
            };
            let mean = |t: &String| {
                let e: Vec<f64> = of(t).iter().map(|r| r.metrics.flip_mean).collect();
                e.iter().sum::<f64>() / e.len().max(1) as f64
            };
            let Some(best) = settings.iter().min_by(|a, b| mean(a).total_cmp(&mean(b))) else {
                continue;
            };
            let name = if settings.len() > 1 {
                format!("{best} (best of {} settings)", settings.len())
            } else {
                best.clone()
            };
            series.push(Series::new(name, style, curve(&of(best))));
        }
        for (f, &style) in flat_only.iter().zip(&flat_styles) {
            let rs: Vec<&Record> = pts.iter().copied().filter(|r| &method_of(r) == f).collect();
            series.push(Series::new(format!("{f}: flat"), style, curve(&rs)));
        }
        let file = if chart_index == 0 {
            "plot_uneven_error_vs_tilt.svg".to_string()
        } else {
            format!(
                "plot_uneven_error_vs_tilt_{}.svg",
                m.replace([' ', '='], "_")
            )
        };
        out.push(Block::Chart(
            file,
            Box::new(Chart {
                y_log: true,
                series,
                x_ticks_at_data: true,
                ..Chart::new(
                    // One trick measured is no choice of settings: said as what it is.
                    match fams.as_slice() {
                        [one] => format!("FLIP over the image vs tilt: {m} with its {one} trick"),
                        _ => format!(
                            "FLIP over the image vs tilt: {m}'s tricks, each at its best setting"
                        ),
                    },
                    "the bump's steepest tilt (degrees)",
                    "FLIP mean over the image",
                )
            }),
        ));
    }
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
            .filter(|r| r.tilt_deg() == Some(a))
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

/// The section, offered every sweep's records; empty where none carries the tilt.
pub fn section(info: &SweepInfo, records: &[Record]) -> Vec<Block> {
    uneven_section(records, &info.bump_methods)
}

fn uneven_region(s: &Sweep) -> Result<String, ReadmeError> {
    let sentences = sentences(&s.records, &s.info.bump_methods);
    if sentences.is_empty() {
        return Err(ReadmeError(format!(
            "{}: no bump-amplitude sweep, nothing to quote",
            s.info.scene
        )));
    }
    Ok(markdown(&[
        Block::Paragraph(measured_on(s)),
        table(&s.records, &s.info.bump_methods, false),
        Block::Bullets(sentences),
    ]))
}

/// The regions of the uneven-mirrors chapter: the rippled box and the hammered mirror.
pub const REGIONS: &[RegionSource] = &[
    RegionSource {
        id: "uneven-mirrors",
        source: "uneven_mirrors",
        about: "uneven mirrors on the rippled box: every trick's error against the tilt, and its cost",
        generate: |reports| uneven_region(&load_sweep(&reports.join("uneven_mirrors"))?),
    },
    RegionSource {
        id: "uneven-mirrors-single",
        source: "uneven_mirrors_single",
        about: "the same on the hammered single mirror",
        generate: |reports| uneven_region(&load_sweep(&reports.join("uneven_mirrors_single"))?),
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    fn bump() -> Vec<String> {
        vec!["auxiliary".into(), "path-textures".into()]
    }

    /// A trick looks the same under every host but for the host's colour, and no two tricks
    /// alike.
    #[test]
    fn a_trick_has_one_marker_and_dash_under_every_host() {
        let families = ["march", "flat", "distort", "distort-distance", "proxy"];
        for f in families {
            let (a, b) = (trick_style("auxiliary", f), trick_style("naive", f));
            assert_eq!((a.marker, a.dash, a.hollow), (b.marker, b.dash, b.hollow));
            assert_eq!(a.color, method_style("auxiliary").color);
        }
        for (i, f) in families.iter().enumerate() {
            for g in &families[..i] {
                assert_ne!(
                    trick_style("naive", f).marker,
                    trick_style("naive", g).marker
                );
            }
        }
    }

    fn record(options: &str, a: f32, flip: f64) -> Record {
        let mut r = mirrorbox_report::document::fixtures::record(2, 10.0, 1, flip);
        r.key = format!("{options} {a}");
        r.method_options = options.into();
        r.axes
            .insert(mirrorbox_report::axis::BUMP_DEG.into(), f64::from(a));
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

    /// A trick is drawn alike in every host's chart: `march` as the fifth of one host's
    /// tricks and the only one of another's had taken two styles.
    #[test]
    fn a_trick_has_one_style_in_every_chart() {
        let mut records = Vec::new();
        for tilt in [0.0, 5.0] {
            for options in ["bump=flat", "bump=distort", "bump=proxy", ""] {
                records.push(record(options, tilt, 0.1));
            }
            let mut other = record("", tilt, 0.2);
            other.n = Some(4);
            other.key = format!("n4 {tilt}");
            records.push(other);
        }
        let blocks = uneven_section(&records, &bump());
        let march: Vec<_> = blocks
            .iter()
            .filter_map(|b| match b {
                Block::Chart(_, c) => c.series.iter().find(|s| s.name.starts_with("march")),
                _ => None,
            })
            .map(|s| (s.style.marker, s.style.dash, s.style.hollow))
            .collect();
        assert_eq!(march.len(), 2, "march in both hosts' charts");
        assert_eq!(march[0], march[1]);
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
        assert!(!s.contains("closer than any distortion"), "{s}");
        // Another trick of the method that beats every distortion strength is named too.
        let mut more = records.clone();
        more.push(record("bump=proxy", 5.0, 0.1));
        let s = sentences(&more, &bump()).join("\n");
        assert!(
            s.contains("; `proxy at 2` (1.000e-1) is closer than any distortion strength."),
            "{s}"
        );
        assert!(uneven_section(&records, &bump()).len() >= 5);
        let mut plain = records[0].clone();
        plain.axes.remove(mirrorbox_report::axis::BUMP_DEG);
        assert!(uneven_section(&[plain], &bump()).is_empty());
    }
}
