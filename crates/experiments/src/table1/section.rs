//! Table 1's report section and the README/book regions that quote it: the paper's rows beside
//! ours, the exact methods beside the paper's method, and two runs (or two devices) side by side.

use super::rows::{self as table1, Row};
use mirrorbox_report::document::{
    Block, f, interval_digits, label, markdown, ms, ms_cell, ms_digits, ms_heading, paired_ratio,
    sci,
};
use mirrorbox_report::readme::{ReadmeError, measured_on, prose};
use mirrorbox_report::stats;
use mirrorbox_report::{Record, Sweep, SweepInfo, floor_paragraph, load_sweep};
use std::fmt::Write as _;
use std::path::Path;

/// A Table 1 row's cell: "median [low–high]", or "median [min m]" for older records.
pub fn row_cell(r: &Row) -> String {
    let digits = match stats::median_interval(&r.frames_ms) {
        Some(i) => interval_digits(i.low, i.high),
        None => ms_digits(r.ms_median, 1),
    };
    format!("{} [{}]", f(r.ms_median, digits), row_interval(r, digits))
}

/// A Table 1 row's interval, "low–high", or "min m" for older records.
fn row_interval(r: &Row, digits: usize) -> String {
    match stats::median_interval(&r.frames_ms) {
        Some(i) => {
            let d = interval_digits(i.low, i.high);
            format!("{}–{}", f(i.low, d), f(i.high, d))
        }
        None => format!("min {}", f(r.ms_min, digits)),
    }
}

/// The exact methods beside the paper's method at the Table 1 α: time and error.
fn exact_comparison(info: &SweepInfo, records: &[Record], rows: &[Row], alpha: f32) -> Vec<Block> {
    let exact = crate::depth_scaling::exact::comparison_points(&info.exact_methods, records, alpha);
    if exact.is_empty() {
        return Vec::new();
    }
    let aux: Vec<&Record> = rows
        .iter()
        .filter_map(|row| {
            records.iter().find(|r| {
                r.kind == "point"
                    && r.method == table1::PAPER_METHOD
                    && r.n == Some(row.n)
                    && r.alpha == alpha
            })
        })
        .collect();
    let line = |r: &Record| {
        vec![
            label(r),
            ms_cell(r, 1),
            r.passes.to_string(),
            r.draws.to_string(),
            r.reflections.to_string(),
            sci(r.metrics.flip_mean),
            sci(r.metrics.relmse),
        ]
    };
    let ms_column = ms_heading("ms/frame median", aux.iter().chain(&exact).copied());
    let mut out = vec![
        Block::Heading(3, format!("The exact methods beside it (α = {alpha})")),
        Block::Table(
            [
                "method",
                ms_column.as_str(),
                "passes",
                "draws",
                "reflections shown",
                "FLIP mean (image)",
                "relMSE",
            ]
            .map(String::from)
            .to_vec(),
            aux.iter().chain(&exact).map(|r| line(r)).collect(),
        ),
    ];
    // A speed ratio is stated only where the 95 % intervals of the two medians are apart.
    // Where both points were timed in the same interleaved rounds, the ratio also gets its
    // paired interval (rounds resampled jointly), which drift of the machine cannot widen.
    let times = |a: &Record, e: &Record| {
        let ratio = a.ms_median / e.ms_median;
        let paired = paired_ratio(a, e).map(|i| {
            if ratio >= 1.0 {
                format!("{:.2}–{:.2}×", i.low, i.high)
            } else {
                format!("{:.2}–{:.2}×", 1.0 / i.high, 1.0 / i.low)
            }
        });
        let paired_note = |claim: bool| match (&paired, claim) {
            (Some(p), true) => format!(" (paired by round: {p})"),
            (Some(p), false) => format!("; paired by round the ratio is {ratio:.2}× [{p}]"),
            (None, _) => String::new(),
        };
        match (a.ms_ci(), e.ms_ci()) {
            (Some(ia), Some(ie)) if ia.overlaps(&ie) => format!(
                "not shown apart in time at 95 % on this device (intervals overlap){}",
                paired_note(false)
            ),
            (Some(_), Some(_)) if ratio >= 1.0 => {
                format!("{ratio:.2}× faster{}", paired_note(true))
            }
            (Some(_), Some(_)) => format!("{:.2}× slower{}", 1.0 / ratio, paired_note(true)),
            _ => "no time comparison (too few frames for intervals)".to_string(),
        }
    };
    let lower_error = |a: &Record, e: &Record| {
        let (fa, fe) = (a.metrics.flip_mean, e.metrics.flip_mean);
        if fe > 0.0 && fa > fe {
            format!("{:.0}× lower error", fa / fe)
        } else {
            format!("FLIP {} against {}", sci(fe), sci(fa))
        }
    };
    let sentences: Vec<String> = exact
        .iter()
        .map(|e| {
            let against: Vec<String> = aux
                .iter()
                .filter(|a| matches!(a.n, Some(2) | Some(4)))
                .map(|a| {
                    format!(
                        "against {} (FLIP {}, {} ms): {}, {}",
                        label(a),
                        sci(a.metrics.flip_mean),
                        ms_cell(a, 1),
                        lower_error(a, e),
                        times(a, e)
                    )
                })
                .collect();
            format!(
                "{} shows {} reflections with FLIP {} in {} ms; {}.",
                label(e),
                e.reflections,
                sci(e.metrics.flip_mean),
                ms_cell(e, 1),
                against.join("; ")
            )
        })
        .collect();
    out.push(Block::Bullets(sentences));
    out
}

/// The reproduction of the paper's Table 1 with the exact methods beside it — only in the
/// paper's experiment ([`table1::is_papers_sweep`]); empty otherwise.
pub fn table1_section(info: &SweepInfo, records: &[Record]) -> Vec<Block> {
    let mut b = Vec::new();
    let (alpha, rows) = table1::rows(records);
    if table1::is_papers_sweep(&info.scene, &rows) {
        b.push(Block::Heading(
            2,
            "Reproduction of the paper's Table 1".into(),
        ));
        b.push(Block::Paragraph(format!(
            "Auxiliary method; ours at α = {}, the median ms/frame over the timed frames with \
             its 95 % bootstrap interval (frames timed interleaved: one per point per round, the \
             points in an order shuffled per round), the GPU's time from the first pass to the \
             resolve (planning and encoding on the CPU not included), on this device at this \
             size. The paper's column is its Table 1: \"processing time per frame, tested on \
             Safari\", its scene, size and hardware not stated, measured before it introduces \
             attenuation. The paper gives no pass counts: its ms/pass divides its times by ours, \
             assuming its recursion is ours. A step ratio is a row's ms/frame over the row \
             before's (how much one more auxiliary mirror costs).",
            alpha.unwrap_or(f32::NAN)
        )));
        let step = |s: Option<f64>| s.map_or("–".into(), |v| format!("{v:.2}"));
        b.push(Block::Table(
            [
                "n",
                "paper ms/frame",
                "ours ms/frame median [95 % CI]",
                "passes",
                "ours ms/pass",
                "paper ms ÷ our passes",
                "step ratio paper",
                "step ratio ours",
            ]
            .map(String::from)
            .to_vec(),
            rows.iter()
                .map(|r| {
                    vec![
                        r.n.to_string(),
                        f(r.paper_ms, 0),
                        row_cell(r),
                        r.passes.to_string(),
                        ms(r.ms_median / r.passes as f64, 2),
                        ms(r.paper_ms / r.passes as f64, 2),
                        step(r.paper_step),
                        step(r.ours_step),
                    ]
                })
                .collect(),
        ));
        b.push(Block::Paragraph(table1::growth_sentence(&rows)));
        if let Some(a) = alpha {
            b.extend(exact_comparison(info, records, &rows, a));
        }
    }
    b
}

/// A sweep with no Table 1 to quote, named by its scene (its folder is named by the caller,
/// [`in_folder`]).
fn not_the_papers(s: &Sweep) -> ReadmeError {
    let scene = match s.info.scene.as_str() {
        "" => "no scene named".to_string(),
        scene => format!("scene {scene}"),
    };
    ReadmeError(format!(
        "a sweep of {scene}, not the paper's experiment (every n of Table 1 on {}): nothing \
         to quote",
        table1::PAPER_SCENE
    ))
}

/// A region's error with the sweep folder it was made from in front.
fn in_folder(dir: &Path, region: Result<String, ReadmeError>) -> Result<String, ReadmeError> {
    region.map_err(|e| ReadmeError(format!("{}: {}", dir.display(), e.0)))
}

pub fn table1_region(s: &Sweep) -> Result<String, ReadmeError> {
    let mut blocks = vec![Block::Paragraph(measured_on(s))];
    let section = prose(table1_section(&s.info, &s.records));
    if section.is_empty() {
        return Err(not_the_papers(s));
    }
    blocks.extend(section);
    if let Some(fl) = Record::our_floor(&s.records) {
        blocks.push(floor_paragraph(fl));
    }
    Ok(markdown(&blocks))
}

/// The short form of [`table1_region`]: the device, the table of every method's point (the
/// paper's auxiliary n = 0…4 and the exact methods) and the floor.
fn table1_summary_region(s: &Sweep) -> Result<String, ReadmeError> {
    let table = prose(table1_section(&s.info, &s.records))
        .into_iter()
        .rfind(|b| matches!(b, Block::Table(..)))
        .ok_or_else(|| not_the_papers(s))?;
    let mut blocks = vec![Block::Paragraph(measured_on(s)), table];
    if let Some(fl) = Record::our_floor(&s.records) {
        blocks.push(floor_paragraph(fl));
    }
    Ok(markdown(&blocks))
}

/// Whether two resume keys name the same point measured with any number of timed rounds (Table
/// 1 moved from 9 to 15: issue 54; another device's run may have either).
fn same_point(a: &str, b: &str) -> bool {
    let without_frames = |k: &str| -> Vec<String> {
        k.split('|')
            .filter(|p| !p.starts_with("frames="))
            .map(String::from)
            .collect()
    };
    without_frames(a) == without_frames(b)
}

/// The points two sweeps of one configuration share, measured on two devices, side by side:
/// each one's ms/frame and FLIP, and how many times faster the second device is. Times compare
/// only as ratios of medians here (the devices ran at different times); errors should agree up
/// to each device's floor, which the last row shows.
fn device_column_region(first: &Sweep, second: &Sweep) -> Result<String, ReadmeError> {
    let device = |s: &Sweep| s.info.adapter.clone();
    let mut rows = Vec::new();
    for a in &first.records {
        let Some(b) = second
            .records
            .iter()
            .find(|b| same_point(&b.key, &a.key) && b.kind == a.kind)
        else {
            continue;
        };
        let name = if a.kind == "floor" {
            "floor (no mirrors)".to_string()
        } else {
            label(a)
        };
        rows.push(vec![
            name,
            format!("{}", a.alpha),
            ms_cell(a, 1),
            ms_cell(b, 1),
            format!("{:.0}×", a.ms_median / b.ms_median),
            sci(a.metrics.flip_mean),
            sci(b.metrics.flip_mean),
        ]);
    }
    if rows.is_empty() {
        return Err(ReadmeError(format!(
            "{} and {}: no point in common",
            first.info.command, second.info.command
        )));
    }
    Ok(markdown(&[
        Block::Paragraph(format!(
            "First: {} Second: {}",
            measured_on(first),
            measured_on(second)
        )),
        Block::Table(
            vec![
                "point".into(),
                "α".into(),
                format!("{} ms/frame [95 % CI]", device(first)),
                format!("{} ms/frame [95 % CI]", device(second)),
                "ratio of medians".into(),
                format!("FLIP {}", device(first)),
                format!("FLIP {}", device(second)),
            ],
            rows,
        ),
    ]))
}

/// Table 1's rows of two runs side by side: whether each row's intervals overlap, and whether
/// each run's times keep the order of the pass counts.
fn repeat_region(first: &Sweep, second: &Sweep) -> Result<String, ReadmeError> {
    let (alpha_a, a) = table1::rows(&first.records);
    let (alpha_b, b) = table1::rows(&second.records);
    if a.len() != table1::PAPER_MS.len() || b.len() != a.len() || alpha_a != alpha_b {
        return Err(ReadmeError(
            "reports/table1 and reports/table1_repeat do not both hold Table 1's rows at one α"
                .into(),
        ));
    }
    let interval = |r: &Row| stats::median_interval(&r.frames_ms);
    let mut rows = Vec::new();
    let mut overlapping = 0;
    for (ra, rb) in a.iter().zip(&b) {
        let overlap = match (interval(ra), interval(rb)) {
            (Some(x), Some(y)) if x.overlaps(&y) => {
                overlapping += 1;
                "yes"
            }
            (Some(_), Some(_)) => "no",
            _ => "–",
        };
        rows.push(vec![
            ra.n.to_string(),
            ra.passes.to_string(),
            row_cell(ra),
            row_cell(rb),
            overlap.to_string(),
        ]);
    }
    // Rows are in n order, and the pass count grows with n.
    let ordered = |rows: &[Row]| rows.windows(2).all(|w| w[0].ms_median < w[1].ms_median);
    let order = |ok: bool| {
        if ok {
            "keeps the order of the pass counts"
        } else {
            "does NOT keep the order of the pass counts"
        }
    };
    let mut text = String::new();
    let _ = write!(
        text,
        "First run: {} Second run: {} α = {}.",
        measured_on(first),
        measured_on(second),
        alpha_a.unwrap_or(f32::NAN)
    );
    let mut blocks = vec![
        Block::Paragraph(text),
        Block::Table(
            [
                "n",
                "passes",
                "first run ms/frame [95 % CI]",
                "second run ms/frame [95 % CI]",
                "intervals overlap",
            ]
            .map(String::from)
            .to_vec(),
            rows,
        ),
        Block::Paragraph(format!(
            "The intervals overlap on {overlapping} of {} rows; {}.",
            a.len(),
            // Said once where both runs agree ("the first run keeps the order …, the second
            // keeps the order …" had read as a stutter).
            match (ordered(&a), ordered(&b)) {
                (true, true) => "both runs' times keep the order of the pass counts (each \
                                 row's median above the one before)"
                    .to_string(),
                (false, false) => {
                    "neither run's times keep the order of the pass counts".to_string()
                }
                (x, y) => format!("the first run {}, the second {}", order(x), order(y)),
            }
        )),
    ];
    blocks.extend(verdicts_held(first, second));
    Ok(markdown(&blocks))
}

/// Whether every speed verdict of the first run holds in the second (issue 54): each exact
/// method at depth 64 against the paper's n = 2, paired by round, faster / slower / not shown
/// apart in each run ([`table1::speed_verdict`]).
fn verdicts_held(first: &Sweep, second: &Sweep) -> Vec<Block> {
    let pair = |s: &Sweep, m: &str| {
        let base = table1::point_at(&s.records, table1::PAPER_METHOD, Some(2), None)?;
        let p = table1::point_at(&s.records, m, None, Some(64))?;
        Some((base.ms_median / p.ms_median, paired_ratio(base, p)?))
    };
    let mut bullets = Vec::new();
    let mut broken = 0;
    for m in &first.info.exact_methods {
        let (Some((ra, ia)), Some((rb, ib))) = (pair(first, m), pair(second, m)) else {
            continue;
        };
        let (va, vb) = (table1::speed_verdict(ia), table1::speed_verdict(ib));
        broken += usize::from(va != vb);
        bullets.push(format!(
            "{m} depth=64 against n=2: {va} in the first run ({ra:.2}× [{:.2}–{:.2}×]), {vb} in \
             the second ({rb:.2}× [{:.2}–{:.2}×]): {}",
            ia.low,
            ia.high,
            ib.low,
            ib.high,
            if va == vb { "holds" } else { "does NOT hold" }
        ));
    }
    if bullets.is_empty() {
        return Vec::new();
    }
    let summary = if broken == 0 {
        format!(
            "Every speed verdict of the first run holds in the second ({} of {}), paired by round:",
            bullets.len(),
            bullets.len()
        )
    } else {
        format!(
            "{broken} of {} speed verdicts of the first run do NOT hold in the second, paired by round:",
            bullets.len()
        )
    };
    vec![Block::Paragraph(summary), Block::Bullets(bullets)]
}

/// Several runs of Table 1 (`reports/<folder>` each, in the order they ran) in one table: per
/// run, the paper's method at n = 2 and each exact method at depth 64 (α of [`table1::rows`]),
/// with the exact method's paired speed ratio against n = 2 — whether a speed verdict survives
/// a repeat, and a repeat in the other order (issue 54), on one device.
pub fn runs_region(reports: &Path, folders: &[&str]) -> Result<String, ReadmeError> {
    let mut exact: Vec<String> = Vec::new();
    let mut runs = Vec::new();
    for folder in folders {
        let s = load_sweep(&reports.join(folder))?;
        let (Some(alpha), _) = table1::rows(&s.records) else {
            return Err(ReadmeError(format!(
                "reports/{folder} holds no row of the paper's method"
            )));
        };
        let at = |method: &str, n: Option<u32>, depth: Option<u32>| {
            table1::point_at(&s.records, method, n, depth)
        };
        let Some(base) = at(table1::PAPER_METHOD, Some(2), None).cloned() else {
            return Err(ReadmeError(format!(
                "reports/{folder} holds no point of {} n=2",
                table1::PAPER_METHOD
            )));
        };
        for m in &s.info.exact_methods {
            if at(m, None, Some(64)).is_some() && !exact.contains(m) {
                exact.push(m.clone());
            }
        }
        let points: Vec<Option<Record>> = exact
            .iter()
            .map(|m| at(m, None, Some(64)).cloned())
            .collect();
        runs.push((folder.to_string(), s.info.clone(), alpha, base, points));
    }
    // Mesa's shader cache decided lavapipe's verdicts (issue 54): said per run where recorded.
    let caches = runs
        .iter()
        .any(|(_, info, ..)| !info.shader_cache.is_empty());
    let mut header = vec!["run".to_string(), "started".to_string()];
    if caches {
        header.push("shader cache".to_string());
    }
    header.push(format!("{} n=2 ms [95 % CI]", table1::PAPER_METHOD));
    for m in &exact {
        header.push(format!("{m} depth=64 ms [95 % CI]"));
        header.push(format!("{m}: times faster than n=2, paired [95 % CI]"));
    }
    let mut rows = Vec::new();
    for (folder, info, alpha, base, points) in &runs {
        let started = base.run.as_deref().unwrap_or(&info.date);
        let mut row = vec![
            format!("`{folder}` (α = {alpha})"),
            started.get(..19).unwrap_or(started).replace('T', " "),
        ];
        if caches {
            row.push(match info.shader_cache.as_str() {
                "" => "not recorded".to_string(),
                c => c.to_string(),
            });
        }
        row.push(ms_cell(base, 3));
        for p in exact
            .iter()
            .enumerate()
            .map(|(i, _)| points.get(i).cloned().flatten())
        {
            match p {
                Some(p) => {
                    row.push(ms_cell(&p, 3));
                    row.push(match paired_ratio(base, &p) {
                        Some(i) => format!(
                            "{:.2}× [{:.2}–{:.2}×]",
                            base.ms_median / p.ms_median,
                            i.low,
                            i.high
                        ),
                        None => "–".into(),
                    });
                }
                None => row.extend(["–".to_string(), "–".to_string()]),
            }
        }
        rows.push(row);
    }
    // Per exact method: does every run give the same verdict, and do their intervals meet?
    let mut verdicts = Vec::new();
    for (i, m) in exact.iter().enumerate() {
        let intervals: Vec<stats::Interval> = runs
            .iter()
            .filter_map(|(_, _, _, base, points)| {
                let p = points.get(i)?.as_ref()?;
                paired_ratio(base, p)
            })
            .collect();
        if intervals.len() < 2 {
            continue;
        }
        verdicts.push(format!(
            "{m} against n=2: {}",
            table1::RunsVerdict::of(&intervals).sentence(intervals.len())
        ));
    }
    let devices: Vec<String> = mirrorbox_report::document::distinct(
        runs.iter()
            .map(|(_, info, ..)| format!("{} on {}", info.adapter_description(), info.cpu)),
    );
    let blocks = vec![
        Block::Paragraph(format!(
            "Measured on {}; the runs in the order they started.",
            devices.join("; ")
        )),
        Block::Table(header, rows),
        Block::Bullets(verdicts),
    ];
    Ok(markdown(&blocks))
}

/// The regions of Table 1's chapter: the first run, its summary, and the two runs.
pub const REGIONS: &[mirrorbox_report::readme::RegionSource] = &[
    mirrorbox_report::readme::RegionSource {
        id: "table1",
        source: "table1",
        about: "the reproduction of Table 1, the exact methods beside it, the floor",
        generate: |reports| {
            let dir = reports.join("table1");
            in_folder(&dir, table1_region(&load_sweep(&dir)?))
        },
    },
    mirrorbox_report::readme::RegionSource {
        id: "table1-summary",
        source: "table1",
        about: "Table 1's methods at one glance: ms/frame, passes, reflections and error of each point",
        generate: |reports| {
            let dir = reports.join("table1");
            in_folder(&dir, table1_summary_region(&load_sweep(&dir)?))
        },
    },
];

/// Every committed run of Table 1 on lavapipe with the timing commands' default (every
/// shader compiled afresh), in the order they ran: the main job's two (`table1`,
/// `table1_repeat`), then four run back to back in both orders (experiment `table1-runs`),
/// then the other order in the fresh clone of the main job (`fresh_e_repeat`, then
/// `fresh_f_table1`, by hand: `experiment table1-repeat`, then `table1`, each `--out`).
pub const LAVAPIPE_RUNS: &[&str] = &[
    "table1",
    "table1_repeat",
    "table1_runs/a_table1",
    "table1_runs/b_repeat",
    "table1_runs/c_repeat",
    "table1_runs/d_table1",
    "table1_runs/fresh_e_repeat",
    "table1_runs/fresh_f_table1",
];

/// Table 1 with Mesa's disk shader cache cold, warm and off, twice over (experiment
/// `table1-runs`): what decided lavapipe's verdicts before issue 54.
pub const SHADER_CACHE_RUNS: &[&str] = &[
    "table1_runs/cache_1_cold",
    "table1_runs/cache_2_warm",
    "table1_runs/cache_3_off",
    "table1_runs/cache_4_cold",
    "table1_runs/cache_5_warm",
    "table1_runs/cache_6_off",
];

/// The repeat's region: both runs side by side, and whether the first run's verdicts hold.
pub const REPEAT_REGIONS: &[mirrorbox_report::readme::RegionSource] = &[
    mirrorbox_report::readme::RegionSource {
        id: "table1-repeat",
        source: "table1_repeat",
        about: "Table 1's rows from two consecutive runs side by side, and whether the first run's speed verdicts hold in the second",
        generate: |reports| {
            repeat_region(
                &load_sweep(&reports.join("table1"))?,
                &load_sweep(&reports.join("table1_repeat"))?,
            )
        },
    },
];

/// The regions of `table1-runs`: every lavapipe run's paired speed ratios with their
/// verdicts, and the runs with the shader cache cold, warm and off.
pub const RUNS_REGIONS: &[mirrorbox_report::readme::RegionSource] = &[
    mirrorbox_report::readme::RegionSource {
        id: "table1-runs",
        source: "table1_runs",
        about: "every committed lavapipe run of Table 1: the exact methods' paired speed ratios and whether the runs agree",
        generate: |reports| runs_region(reports, LAVAPIPE_RUNS),
    },
    mirrorbox_report::readme::RegionSource {
        id: "table1-shader-cache",
        source: "table1_runs",
        about: "Table 1 with Mesa's disk shader cache cold, warm and off: the exact methods' paired speed ratios",
        generate: |reports| runs_region(reports, SHADER_CACHE_RUNS),
    },
];

/// Table 1 (the first run) against the same sweep on another device, `reports/<folder>`.
pub fn device_column(reports: &Path, folder: &str) -> Result<String, ReadmeError> {
    device_column_region(
        &load_sweep(&reports.join("table1"))?,
        &load_sweep(&reports.join(folder))?,
    )
}

/// [`table1_region`] of the sweep in `reports/<folder>` (another device's Table 1).
pub fn region_of(reports: &Path, folder: &str) -> Result<String, ReadmeError> {
    let dir = reports.join(folder);
    in_folder(&dir, table1_region(&load_sweep(&dir)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_report::document::fixtures::record;
    use mirrorbox_report::{Section, write_report};

    /// This module's section as the registry offers it.
    const SECTION: Section = table1_section;

    /// `r` timed in 9 interleaved rounds of one run, round k taking `ms · drift(k)`.
    fn interleaved(mut r: Record, drift: &dyn Fn(usize) -> f64) -> Record {
        r.frames_ms = (0..9).map(|k| r.ms_median * drift(k)).collect();
        r.ms_median = stats::median(&r.frames_ms);
        r.ms_interval = stats::median_interval(&r.frames_ms).map(|i| [i.low, i.high]);
        r.timing_order = "interleaved".into();
        r.run = Some("2026-11-22T10:00:00Z".into());
        r
    }

    /// A Table 1 run in `reports/<folder>`: n = 2 at 10 ms, unrolled depth 64 at `unrolled_ms`,
    /// each timed in 9 interleaved rounds with round k slower by `drift(k)`.
    fn write_run(reports: &Path, folder: &str, unrolled_ms: f64, drift: &dyn Fn(usize) -> f64) {
        let dir = reports.join(folder);
        std::fs::create_dir_all(&dir).unwrap();
        let mut exact = interleaved(record(0, unrolled_ms, 1, 1e-4), drift);
        exact.method = "unrolled".into();
        exact.key = "unrolled depth=64".into();
        (exact.n, exact.depth) = (None, Some(64));
        let records = [interleaved(record(2, 10.0, 15, 0.01), drift), exact];
        let info = SweepInfo {
            scene: "scenes/mirror_box.json".into(),
            exact_methods: vec!["unrolled".into()],
            ..SweepInfo::default()
        };
        write_report(&dir, &info, &records, &[]).unwrap();
        let lines: Vec<String> = records
            .iter()
            .map(|r| serde_json::to_string(r).unwrap())
            .collect();
        std::fs::write(dir.join("results.jsonl"), lines.join("\n") + "\n").unwrap();
        std::fs::write(
            dir.join("sweep.json"),
            serde_json::to_string(&info).unwrap(),
        )
        .unwrap();
    }

    #[test]
    fn runs_agree_only_where_every_run_gives_the_same_verdict() {
        let reports = tempfile::tempdir().unwrap();
        let wobble = |k: usize| 1.0 + 0.01 * (k % 3) as f64;
        write_run(reports.path(), "a", 5.0, &wobble);
        write_run(reports.path(), "b", 5.0, &|k| 1.3 * wobble(k));
        let text = runs_region(reports.path(), &["a", "b"]).unwrap();
        // A slower machine in the second run (both points alike) leaves the paired ratio.
        assert!(
            text.contains(
                "unrolled against n=2: faster in all 2 runs, their paired intervals sharing 2.00×"
            ),
            "{text}"
        );
        assert!(text.contains("| `a` (α = 0.7) |"), "{text}");
        // No shader cache recorded in any run: no column for it.
        assert!(!text.contains("shader cache"), "{text}");
        // The exact method slower in the second run only: one verdict, sizes apart, said.
        write_run(reports.path(), "c", 8.0, &wobble);
        let text = runs_region(reports.path(), &["a", "c"]).unwrap();
        assert!(
            text.contains("faster in all 2 runs, though their paired intervals do not all overlap"),
            "{text}"
        );
        // Slower than n = 2 in a third run: the runs disagree.
        write_run(reports.path(), "d", 12.5, &wobble);
        let text = runs_region(reports.path(), &["a", "c", "d"]).unwrap();
        assert!(
            text.contains(
                "the runs disagree: faster in 2, slower in 1 (paired intervals from 0.80× to 2.00×)"
            ),
            "{text}"
        );
        assert!(runs_region(reports.path(), &["a", "missing"]).is_err());
    }

    #[test]
    fn points_are_the_same_whatever_their_number_of_timed_rounds() {
        let k =
            |frames| format!("portal depth=64|alpha=0.7|640x360|ssaa=1|frames={frames}|scene=ee52");
        assert!(same_point(&k(9), &k(15)));
        assert!(!same_point(&k(9), &k(9).replace("depth=64", "depth=32")));
    }

    #[test]
    fn the_repeat_says_whether_each_verdict_of_the_first_run_holds() {
        let reports = tempfile::tempdir().unwrap();
        let wobble = |k: usize| 1.0 + 0.01 * (k % 3) as f64;
        write_run(reports.path(), "a", 5.0, &wobble);
        write_run(reports.path(), "b", 6.0, &|k| 1.3 * wobble(k));
        write_run(reports.path(), "c", 12.5, &wobble);
        let sweep = |f: &str| load_sweep(&reports.path().join(f)).unwrap();
        let text = markdown(&verdicts_held(&sweep("a"), &sweep("b")));
        assert!(
            text.contains("Every speed verdict of the first run holds in the second (1 of 1)"),
            "{text}"
        );
        assert!(
            text.contains("unrolled depth=64 against n=2: faster in the first run (2.00× [2.00–2.00×]), faster in the second (1.67× [1.67–1.67×]): holds"),
            "{text}"
        );
        let text = markdown(&verdicts_held(&sweep("a"), &sweep("c")));
        assert!(
            text.contains("1 of 1 speed verdicts of the first run do NOT hold in the second")
                && text.contains("slower in the second (0.80× [0.80–0.80×]): does NOT hold"),
            "{text}"
        );
    }

    #[test]
    fn report_files_hold_the_table_and_the_points() {
        let dir = tempfile::tempdir().unwrap();
        let records = vec![
            record(0, 20.0, 3, 0.1),
            record(1, 45.0, 7, 0.05),
            record(2, 100.0, 15, 0.02),
            record(3, 300.0, 46, 0.01),
            record(4, 900.0, 139, 0.005),
        ];
        let info = |scene: &str| SweepInfo {
            scene: scene.into(),
            ..Default::default()
        };
        write_report(
            dir.path(),
            &info("scenes/mirror_box.json"),
            &records,
            &[SECTION],
        )
        .unwrap();
        let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
        assert!(md.contains("Reproduction of the paper's Table 1"));
        assert!(md.contains("| 2 | 142 | 100.0 [min 100.0] | 15 |"), "{md}");
        let html = std::fs::read_to_string(dir.path().join("report.html")).unwrap();
        assert!(html.contains("<svg") && html.contains("<table>"));
        let csv = std::fs::read_to_string(dir.path().join("results.csv")).unwrap();
        assert_eq!(csv.lines().count(), 6);
        // A custom sweep of the method (another scene, or not every n) has no Table 1.
        for (scene, points) in [
            ("scenes/tilted_pair.json", 5),
            ("scenes/mirror_box.json", 3),
        ] {
            let other = tempfile::tempdir().unwrap();
            write_report(other.path(), &info(scene), &records[..points], &[SECTION]).unwrap();
            let md = std::fs::read_to_string(other.path().join("report.md")).unwrap();
            assert!(!md.contains("Table 1"), "{scene}, {points} points: {md}");
            // Nor a region to quote: its error names the scene (and the folder, below).
            let sweep = Sweep {
                info: info(scene),
                records: records[..points].to_vec(),
            };
            let e = table1_region(&sweep).unwrap_err().0;
            assert!(
                e.starts_with(&format!("a sweep of scene {scene}, not")),
                "{e}"
            );
        }
        let e = in_folder(Path::new("reports/x"), Err(ReadmeError("why".into())));
        assert_eq!(e.unwrap_err().0, "reports/x: why");
        let unnamed = Sweep {
            info: info(""),
            records: records[..3].to_vec(),
        };
        let e = table1_region(&unnamed).unwrap_err().0;
        assert!(
            e.starts_with("a sweep of no scene named, not the paper's"),
            "{e}"
        );
        for f in [
            "plot_flip_vs_ms.svg",
            "plot_relmse_vs_ms.svg",
            "plot_flip_vs_n.svg",
        ] {
            assert!(dir.path().join(f).is_file(), "{f}");
        }
    }

    #[test]
    fn speed_claims_need_intervals_apart_and_carry_the_paired_ratio() {
        let info = SweepInfo {
            scene: "scenes/mirror_box.json".into(),
            exact_methods: vec!["unrolled".into()],
            bump_methods: Vec::new(),
            ..SweepInfo::default()
        };
        let exact_point = |ms: f64, drift: &dyn Fn(usize) -> f64| {
            let mut e = interleaved(record(0, ms, 1, 1e-4), drift);
            e.method = "unrolled".into();
            e.key = "unrolled depth=64".into();
            (e.n, e.depth) = (None, Some(64));
            e
        };
        let passes = [3, 7, 15, 46, 139];
        let sentences = |drift: &dyn Fn(usize) -> f64, unrolled_ms: f64| {
            let mut records: Vec<Record> = (0..5)
                .map(|n| {
                    interleaved(
                        record(
                            n,
                            10.0 * passes[n as usize] as f64,
                            passes[n as usize],
                            0.01,
                        ),
                        drift,
                    )
                })
                .collect();
            records.push(exact_point(unrolled_ms, drift));
            let dir = tempfile::tempdir().unwrap();
            write_report(dir.path(), &info, &records, &[SECTION]).unwrap();
            let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
            md.lines()
                .find(|l| l.starts_with("- unrolled depth=64 shows"))
                .unwrap_or_else(|| panic!("{md}"))
                .to_string()
        };
        // Steady machine (±1 %): 150 ms against 40 ms, apart; the paired ratio is exact.
        let steady = sentences(&|k| 1.0 + 0.0025 * k as f64, 40.0);
        assert!(
            steady.contains("3.75× faster (paired by round: 3.75–3.75×)"),
            "{steady}"
        );
        // A machine slowing down 10 % per round: the medians' intervals of 150 ms and 120 ms
        // overlap, so no claim; paired by round the ratio is still visibly 1.25.
        let drifting = sentences(&|k| 1.0 + 0.1 * k as f64, 120.0);
        assert!(
            drifting.contains("against auxiliary n=2 (FLIP")
                && drifting.contains("not shown apart in time at 95 % on this device (intervals overlap); paired by round the ratio is 1.25× [1.25–1.25×]"),
            "{drifting}"
        );
    }
}
