//! The reproduction of the seed paper's Table 1: ms/frame of the auxiliary method for
//! n = 0…4, the paper's (Safari) beside ours, with the pass counts that explain the growth.

/// The method the paper's Table 1 measures (a raster registry name; the harness's tests
/// check it is registered).
pub const PAPER_METHOD: &str = "auxiliary";

use mirrorbox_report::Record;

/// Table 1 of the seed paper: ms/frame for n = 0…4 auxiliary mirrors, "tested on Safari".
pub const PAPER_MS: [f64; 5] = [25.0, 61.0, 142.0, 435.0, 1330.0];

#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub n: u32,
    pub paper_ms: f64,
    pub ms_median: f64,
    pub ms_min: f64,
    /// Every timed frame (empty for records older than the field): the bootstrap of the
    /// exponent resamples them.
    pub frames_ms: Vec<f64>,
    pub passes: usize,
    /// Step ratios to the previous row (None for n = 0).
    pub paper_step: Option<f64>,
    pub ours_step: Option<f64>,
}

/// Rows for the auxiliary points with n = 0…4 at one α (0.7 — the paper's — if measured,
/// else the first α found), in n order; empty if none.
pub fn rows(records: &[Record]) -> (Option<f32>, Vec<Row>) {
    let aux: Vec<&Record> = records
        .iter()
        .filter(|r| r.kind == "point" && r.method == PAPER_METHOD)
        .collect();
    let alpha = aux
        .iter()
        .map(|r| r.alpha)
        .find(|a| (*a - 0.7).abs() < 1e-6)
        .or_else(|| aux.first().map(|r| r.alpha));
    let Some(alpha) = alpha else {
        return (None, Vec::new());
    };
    let mut rows: Vec<Row> = Vec::new();
    for n in 0..PAPER_MS.len() as u32 {
        let Some(r) = aux.iter().find(|r| r.n == Some(n) && r.alpha == alpha) else {
            continue;
        };
        let prev = rows.last().filter(|p| p.n + 1 == n);
        rows.push(Row {
            n,
            paper_ms: PAPER_MS[n as usize],
            ms_median: r.ms_median,
            ms_min: r.ms_min,
            frames_ms: r.frames_ms.clone(),
            passes: r.passes,
            paper_step: prev.map(|p| PAPER_MS[n as usize] / p.paper_ms),
            ours_step: prev.map(|p| r.ms_median / p.ms_median),
        });
    }
    (Some(alpha), rows)
}

/// Least-squares slope of log(ms) against log(passes): 1 means time proportional to passes.
pub fn slope(points: &[(f64, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(p, t)| *p > 0.0 && *t > 0.0)
        .map(|(p, t)| (p.ln(), t.ln()))
        .collect();
    mirrorbox_report::linear_fit(&pts).map(|(_, b)| b)
}

/// The scene in the arrangement of the paper's Figure 1 (two facing mirrors, objects between;
/// its sizes are ours: the paper gives none): Table 1 is reproduced only on it.
pub const PAPER_SCENE: &str = "mirror_box.json";

/// Whether a sweep is the paper's experiment — its method at every n of Table 1 on the paper's
/// scene — and so gets the Table 1 section; a custom sweep of the method does not.
pub fn is_papers_sweep(scene: &str, rows: &[Row]) -> bool {
    let on_papers_scene = std::path::Path::new(scene)
        .file_name()
        .is_some_and(|f| f == PAPER_SCENE);
    on_papers_scene && rows.len() == PAPER_MS.len()
}

/// `[low, high]` with the decimals the interval can tell apart (two significant digits of its
/// width, at least two decimals): a narrow interval must not print as "[0.47, 0.47]".
fn bracket(low: f64, high: f64) -> String {
    let d = mirrorbox_report::document::interval_digits(low, high).max(2);
    format!("[{low:.d$}, {high:.d$}]")
}

/// The 95 % bootstrap interval of our exponent: every row's frames resampled with
/// replacement, its median taken, the power law fitted again. `None` without frames.
pub fn exponent_interval(rows: &[Row]) -> Option<mirrorbox_report::stats::Interval> {
    if rows
        .iter()
        .any(|r| r.frames_ms.len() < mirrorbox_report::stats::MIN_FRAMES_FOR_INTERVAL)
    {
        return None;
    }
    let groups: Vec<&[f64]> = rows.iter().map(|r| r.frames_ms.as_slice()).collect();
    mirrorbox_report::stats::bootstrap(
        &groups,
        |resampled| {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .zip(resampled)
                .map(|(r, frames)| (r.passes as f64, mirrorbox_report::stats::median(frames)))
                .collect();
            slope(&pts).unwrap_or(f64::NAN)
        },
        mirrorbox_report::stats::BOOTSTRAP_SEED,
    )
}

/// A sentence saying whether our growth matches the paper's times' — computed: "matches"
/// only if their exponent against our pass counts lies inside our interval — and why.
pub fn growth_sentence(rows: &[Row]) -> String {
    if rows.len() < 2 {
        return "Too few points to compare growth.".into();
    }
    let ours = slope(
        &rows
            .iter()
            .map(|r| (r.passes as f64, r.ms_median))
            .collect::<Vec<_>>(),
    );
    let paper = slope(
        &rows
            .iter()
            .map(|r| (r.passes as f64, r.paper_ms))
            .collect::<Vec<_>>(),
    );
    let per_pass: Vec<f64> = rows.iter().map(|r| r.ms_median / r.passes as f64).collect();
    let paper_per_pass: Vec<f64> = rows.iter().map(|r| r.paper_ms / r.passes as f64).collect();
    // ("lo–hi", hi/lo): how far the cost of one pass moves across n.
    let range = |v: &[f64]| {
        let (lo, hi) = v
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
        let digits = mirrorbox_report::document::ms_digits(lo, 1);
        (format!("{lo:.digits$}–{hi:.digits$}"), hi / lo)
    };
    let ((ours_range, ours_ratio), (paper_range, paper_ratio)) =
        (range(&per_pass), range(&paper_per_pass));
    // ms = a + b·passes: a is the frame's fixed cost, b one pass's.
    let fixed = |ms: &dyn Fn(&Row) -> f64| {
        let pts: Vec<(f64, f64)> = rows.iter().map(|r| (r.passes as f64, ms(r))).collect();
        mirrorbox_report::linear_fit(&pts).map_or("–".into(), |(a, b)| {
            format!(
                "a = {} ms, b = {} ms",
                mirrorbox_report::document::ms(a, 1),
                mirrorbox_report::document::ms(b, 1)
            )
        })
    };
    let (Some(o), Some(p)) = (ours, paper) else {
        return "Growth could not be fitted.".into();
    };
    let interval = exponent_interval(rows);
    let verdict = match interval {
        Some(i) if i.contains(p) => format!(
            "matches: the paper's times' exponent {p:.2} lies inside our 95 % interval {} \
             (bootstrap over frames)",
            bracket(i.low, i.high)
        ),
        Some(i) => format!(
            "does not match: the paper's times' exponent {p:.2} lies {:.2} outside our 95 % \
             interval {} (bootstrap over frames)",
            (p - i.low).abs().min((p - i.high).abs()),
            bracket(i.low, i.high)
        ),
        None => format!(
            "cannot be judged: these records keep no frames to bound our exponent with \
             (the paper's is {p:.2})"
        ),
    };
    format!(
        "The growth {verdict}. Fitting log(ms/frame) against log(passes), our exponent is {o:.2} and the \
         paper's times' is {p:.2} (1 = time proportional to the number of scene passes). The paper \
         gives no pass counts and says only that its times grow \"exponentially\": its times are set \
         against our pass counts, which assumes its recursion is ours (every mirror camera recurses \
         into every unhidden auxiliary mirror on the other side; the count grows factorially with \
         n). One pass then costs {ours_range} ms here and {paper_range} ms in the paper's Safari \
         times (the dearest pass {ours_ratio:.2}× the cheapest here, {paper_ratio:.2}× in the \
         paper's). A straight line ms/frame = a + b·passes gives {} here and {} for the paper's \
         times: where the fixed cost a is large against b·passes, it hides the growth of the \
         passes and the exponent falls below 1.",
        fixed(&|r: &Row| r.ms_median),
        fixed(&|r: &Row| r.paper_ms),
    )
}

/// The point of `method` at count `n` or depth `depth` and Table 1's α ([`rows`]): how the
/// exact methods are set beside the paper's in a Table 1 sweep.
pub fn point_at<'a>(
    records: &'a [Record],
    method: &str,
    n: Option<u32>,
    depth: Option<u32>,
) -> Option<&'a Record> {
    let (alpha, _) = rows(records);
    records.iter().find(|r| {
        r.kind == "point"
            && r.method == method
            && r.n == n
            && r.depth == depth
            && alpha.is_some_and(|a| (r.alpha - a).abs() < 1e-6)
    })
}

/// What several runs' 95 % intervals of one ratio share, `(low, high)`, or `None` where two
/// of them do not overlap: one verdict, or runs that disagree.
pub fn shared_interval(
    intervals: impl IntoIterator<Item = mirrorbox_report::stats::Interval>,
) -> Option<(f64, f64)> {
    let (low, high) = intervals
        .into_iter()
        .fold((f64::MIN, f64::MAX), |(lo, hi), i| {
            (lo.max(i.low), hi.min(i.high))
        });
    (low <= high).then_some((low, high))
}

/// The verdict of one paired speed ratio `comparator ms / method ms` with its 95 % interval:
/// `"faster"` where the interval lies above 1, `"slower"` below, else `"not shown apart"`.
pub fn speed_verdict(i: mirrorbox_report::stats::Interval) -> &'static str {
    if i.low > 1.0 {
        "faster"
    } else if i.high < 1.0 {
        "slower"
    } else {
        "not shown apart"
    }
}

/// What several runs of one paired speed ratio say together (issue 54: a verdict stands only
/// where every run gives it).
#[derive(Clone, Debug, PartialEq)]
pub enum RunsVerdict {
    /// Every run gives `verdict`; `shared` is what their intervals share, `None` where two of
    /// them do not overlap (one verdict, sizes that differ).
    Agree {
        verdict: &'static str,
        shared: Option<(f64, f64)>,
    },
    /// The runs give different verdicts: how many give each, in the order first seen, and
    /// the lowest and highest interval ends.
    Disagree {
        counts: Vec<(&'static str, usize)>,
        low: f64,
        high: f64,
    },
}

impl RunsVerdict {
    pub fn of(intervals: &[mirrorbox_report::stats::Interval]) -> Self {
        let mut counts: Vec<(&'static str, usize)> = Vec::new();
        for i in intervals {
            let v = speed_verdict(*i);
            match counts.iter_mut().find(|(w, _)| *w == v) {
                Some((_, n)) => *n += 1,
                None => counts.push((v, 1)),
            }
        }
        match counts.as_slice() {
            [(verdict, _)] => RunsVerdict::Agree {
                verdict,
                shared: shared_interval(intervals.iter().copied()),
            },
            _ => RunsVerdict::Disagree {
                counts,
                low: intervals.iter().map(|i| i.low).fold(f64::MAX, f64::min),
                high: intervals.iter().map(|i| i.high).fold(f64::MIN, f64::max),
            },
        }
    }

    /// "faster in all 4 runs, their paired intervals sharing 1.38–1.40×", "slower in all 2
    /// runs, their paired intervals apart (0.71–0.95×)", or "the runs disagree: faster in 1,
    /// slower in 5 (paired intervals from 0.71× to 1.89×)".
    pub fn sentence(&self, runs: usize) -> String {
        match self {
            RunsVerdict::Agree {
                verdict,
                shared: Some((low, high)),
            } => {
                // Enough decimals to tell the ends apart ("1.38–1.38×" had said nothing).
                let shared = match mirrorbox_report::document::apart(*low, *high) {
                    Some((low, high)) => format!("{low}–{high}×"),
                    None => format!("{low:.2}×"),
                };
                format!("{verdict} in all {runs} runs, their paired intervals sharing {shared}")
            }
            RunsVerdict::Agree {
                verdict,
                shared: None,
            } => format!(
                "{verdict} in all {runs} runs, though their paired intervals do not all overlap"
            ),
            RunsVerdict::Disagree { counts, low, high } => {
                let each: Vec<String> = counts.iter().map(|(v, n)| format!("{v} in {n}")).collect();
                format!(
                    "the runs disagree: {} (paired intervals from {low:.2}× to {high:.2}×)",
                    each.join(", ")
                )
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_agree_only_on_one_verdict_each() {
        let i = |low, high| mirrorbox_report::stats::Interval { low, high };
        assert_eq!(speed_verdict(i(1.1, 1.3)), "faster");
        assert_eq!(speed_verdict(i(0.7, 0.9)), "slower");
        assert_eq!(speed_verdict(i(0.9, 1.1)), "not shown apart");
        // Ends that two decimals would print alike get more (the H200's "1.38–1.38×").
        assert!(
            RunsVerdict::of(&[i(1.3806, 1.3822), i(1.3801, 1.3830)])
                .sentence(2)
                .ends_with("sharing 1.381–1.382×"),
            "{}",
            RunsVerdict::of(&[i(1.3806, 1.3822), i(1.3801, 1.3830)]).sentence(2)
        );
        let agree = RunsVerdict::of(&[i(1.2, 1.5), i(1.4, 1.9)]);
        assert_eq!(
            agree.sentence(2),
            "faster in all 2 runs, their paired intervals sharing 1.40–1.50×"
        );
        // One verdict, sizes apart.
        let apart = RunsVerdict::of(&[i(1.1, 1.2), i(1.4, 1.9)]);
        assert_eq!(
            apart,
            RunsVerdict::Agree {
                verdict: "faster",
                shared: None
            }
        );
        // Intervals that overlap can still give two verdicts: no verdict then.
        let two = RunsVerdict::of(&[i(1.05, 1.3), i(0.95, 1.2), i(1.1, 1.4)]);
        assert_eq!(
            two.sentence(3),
            "the runs disagree: faster in 2, not shown apart in 1 (paired intervals from 0.95× to 1.40×)"
        );
    }

    #[test]
    fn slope_of_a_power_law() {
        let pts: Vec<(f64, f64)> = [3.0, 7.0, 15.0, 46.0, 139.0]
            .iter()
            .map(|&p| (p, 9.0 * p))
            .collect();
        assert!((slope(&pts).unwrap() - 1.0).abs() < 1e-12);
        let sq: Vec<(f64, f64)> = [1.0, 2.0, 4.0].iter().map(|&p| (p, p * p)).collect();
        assert!((slope(&sq).unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(slope(&[(1.0, 1.0)]), None);
    }

    #[test]
    fn the_papers_own_figures_grow_with_the_pass_count() {
        let rows: Vec<Row> = [3usize, 7, 15, 46, 139]
            .iter()
            .enumerate()
            .map(|(n, &passes)| Row {
                n: n as u32,
                paper_ms: PAPER_MS[n],
                ms_median: PAPER_MS[n],
                ms_min: PAPER_MS[n],
                frames_ms: Vec::new(),
                passes,
                paper_step: None,
                ours_step: None,
            })
            .collect();
        let s = growth_sentence(&rows);
        assert!(s.starts_with("The growth cannot be judged"), "{s}");
        assert!(s.contains("8.33–9.57 ms in the paper"), "{s}");
        // With frames spread ±2 % around the paper's figures, its exponent is inside.
        let spread = |ms: f64| (0..9).map(|k| ms * (0.98 + 0.005 * k as f64)).collect();
        let with_frames: Vec<Row> = rows
            .iter()
            .map(|r| Row {
                frames_ms: spread(r.paper_ms),
                ..r.clone()
            })
            .collect();
        let s = growth_sentence(&with_frames);
        assert!(s.starts_with("The growth matches"), "{s}");
        // Twice the time per pass at the top: a steeper exponent, outside the interval.
        let mut steep = with_frames.clone();
        steep[4].frames_ms = spread(4.0 * PAPER_MS[4]);
        steep[4].ms_median = 4.0 * PAPER_MS[4];
        let s = growth_sentence(&steep);
        assert!(s.starts_with("The growth does not match"), "{s}");
    }
}
