//! The exact methods (portal, unrolled) in a report: beside the paper's method in the Table 1
//! comparison, and their cost against reflection depth.
//!
//! The cost of one more bounce is the slope of a least-squares line of ms/frame against the
//! reflections actually shown (a depth cap above the scene's natural end adds none), read
//! against one full-scene pass: the floor point, which renders the scene without mirrors
//! once.

use mirrorbox_report::{Record, linear_fit};

/// Whether `r` is a point of one of the `exact` methods (names from the raster registry,
/// carried by [`mirrorbox_report::SweepInfo::exact_methods`]) at a reflection depth — the mirror
/// methods; the exact symmetry methods have no depth and are reported over p
/// (`symmetry-scaling`).
pub fn is_exact(exact: &[String], r: &Record) -> bool {
    r.kind == "point" && exact.contains(&r.method) && r.depth.is_some()
}

/// One method's cost against depth at one α, every other setting alike.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthScaling {
    pub method: String,
    /// What else sets these points apart from the method's other points of the sweep: its
    /// options but the depth, and the scene axes (`shadows=map, mirrored_lights=1`); empty
    /// where nothing does.
    pub variant: String,
    pub alpha: f32,
    /// Points in depth order.
    pub points: Vec<Record>,
    /// ms/frame per extra reflection shown (fit over every point).
    pub ms_per_bounce: Option<f64>,
    /// Its 95 % bootstrap interval: every point's frames resampled, medians refitted
    /// (`None` where a point has too few frames). It holds the timing noise only, not how
    /// far the points lie off one line ([`DepthScaling::bent`] says where they do).
    pub ms_per_bounce_interval: Option<mirrorbox_report::stats::Interval>,
    /// Whether one straight line fits; `None` with fewer than four points. Halves far apart
    /// make the one slope an average.
    pub half_slopes: Option<HalfSlopes>,
}

/// The least-squares slopes of the shallower and the deeper half of a method's points
/// (sharing the middle one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfSlopes {
    /// ms per reflection up to the middle point.
    pub shallow: f64,
    /// ms per reflection beyond it.
    pub deep: f64,
    /// The reflections shown at the middle point.
    pub mid: usize,
    /// The 95 % bootstrap interval of `deep − shallow` (every point's frames resampled, both
    /// halves refitted); `None` where a point has too few frames.
    pub difference_interval: Option<mirrorbox_report::stats::Interval>,
}

/// How far apart the halves' slopes must be shown to be before a report says the cost per
/// reflection is not one number: the 95 % interval of their difference wholly beyond a tenth
/// of the slope over every point, either way. (A ratio of the slopes would not do: where the
/// shallow half's slope is uncertain its resampled ratio crowds near 0 and excludes 1.)
/// Records without frames (no interval) are held to the slopes themselves a fifth apart.
pub const BENT_BY: f64 = 0.1;
const BENT_BY_WITHOUT_INTERVAL: f64 = 1.2;

impl DepthScaling {
    /// The method, with its variant where it has one: a series' and a row's name.
    pub fn name(&self) -> String {
        if self.variant.is_empty() {
            self.method.clone()
        } else {
            format!("{} ({})", self.method, self.variant)
        }
    }

    /// The halves where their slopes are shown apart ([`BENT_BY`]): the cost per reflection
    /// is then not one number (on lavapipe it falls with depth).
    pub fn bent(&self) -> Option<HalfSlopes> {
        let h = self.half_slopes?;
        let all = self.ms_per_bounce?;
        if h.shallow.min(h.deep) <= 0.0 || all <= 0.0 {
            return None;
        }
        let apart = match h.difference_interval {
            Some(i) => i.low > BENT_BY * all || i.high < -BENT_BY * all,
            None => !(1.0 / BENT_BY_WITHOUT_INTERVAL..=BENT_BY_WITHOUT_INTERVAL)
                .contains(&(h.deep / h.shallow)),
        };
        apart.then_some(h)
    }
}

impl HalfSlopes {
    /// "0.58 ms per reflection up to 32 reflections, 0.38 ms beyond, a difference of −0.19 ms
    /// [95 % CI −0.25 to −0.13]", with `digits` decimals.
    pub fn describe(&self, digits: usize) -> String {
        let interval = self.difference_interval.map_or(String::new(), |i| {
            format!(
                " [95 % CI {} to {}]",
                signed(i.low, digits),
                signed(i.high, digits)
            )
        });
        format!(
            "{} ms per reflection up to {} reflections, {} ms beyond, a difference of {} ms{interval}",
            ms(self.shallow, digits),
            self.mid,
            ms(self.deep, digits),
            signed(self.deep - self.shallow, digits)
        )
    }
}

/// What sets `r` apart besides its method, depth and α: its other options and its scene axes.
fn variant_of(r: &Record) -> String {
    let mut words: Vec<String> = r
        .method_options
        .split_whitespace()
        .map(str::to_string)
        .collect();
    words.extend(r.axes.iter().map(|(k, v)| format!("{k}={v}")));
    words.join(", ")
}

/// Groups the exact points by (method, variant, α), each with at least two depths: points
/// that differ in anything but the depth cap (the lighting sweep's shadows and mirrored
/// lights, all at one depth) are no cost against depth.
pub fn depth_scaling(exact: &[String], records: &[Record]) -> Vec<DepthScaling> {
    let mut out: Vec<DepthScaling> = Vec::new();
    for r in records.iter().filter(|r| is_exact(exact, r)) {
        let variant = variant_of(r);
        match out
            .iter_mut()
            .find(|g| g.method == r.method && g.variant == variant && g.alpha == r.alpha)
        {
            Some(g) => g.points.push(r.clone()),
            None => out.push(DepthScaling {
                method: r.method.clone(),
                variant,
                alpha: r.alpha,
                points: vec![r.clone()],
                ms_per_bounce: None,
                ms_per_bounce_interval: None,
                half_slopes: None,
            }),
        }
    }
    out.retain(|g| {
        let depths: std::collections::BTreeSet<_> = g.points.iter().map(|r| r.depth).collect();
        depths.len() >= 2
    });
    for g in &mut out {
        g.points.sort_by_key(|r| r.depth);
        let pts: Vec<(f64, f64)> = g
            .points
            .iter()
            .map(|r| (r.reflections as f64, r.ms_median))
            .collect();
        g.ms_per_bounce = linear_fit(&pts).map(|(_, b)| b);
        g.ms_per_bounce_interval = slope_interval(&g.points);
        if pts.len() >= 4 {
            let mid = pts.len() / 2;
            if let Some((shallow, deep)) = half_slopes(&pts, mid) {
                g.half_slopes = Some(HalfSlopes {
                    shallow,
                    deep,
                    mid: g.points[mid].reflections,
                    difference_interval: resampled(&g.points, |pts| {
                        half_slopes(pts, mid).map_or(f64::NAN, |(a, b)| b - a)
                    }),
                });
            }
        }
    }
    out
}

/// The slopes of `pts[..=mid]` and `pts[mid..]`.
fn half_slopes(pts: &[(f64, f64)], mid: usize) -> Option<(f64, f64)> {
    Some((linear_fit(&pts[..=mid])?.1, linear_fit(&pts[mid..])?.1))
}

/// The 95 % bootstrap interval of the least-squares slope of median ms/frame against the
/// reflections shown.
fn slope_interval(points: &[Record]) -> Option<mirrorbox_report::stats::Interval> {
    resampled(points, |pts| linear_fit(pts).map_or(f64::NAN, |(_, b)| b))
}

/// The 95 % bootstrap interval of `statistic` of the points (reflections shown, median
/// ms/frame), every point's frames resampled; `None` where a point has too few frames.
fn resampled(
    points: &[Record],
    statistic: impl Fn(&[(f64, f64)]) -> f64,
) -> Option<mirrorbox_report::stats::Interval> {
    use mirrorbox_report::stats::{BOOTSTRAP_SEED, MIN_FRAMES_FOR_INTERVAL, bootstrap, median};
    if points
        .iter()
        .any(|r| r.frames_ms.len() < MIN_FRAMES_FOR_INTERVAL)
    {
        return None;
    }
    let groups: Vec<&[f64]> = points.iter().map(|r| r.frames_ms.as_slice()).collect();
    bootstrap(
        &groups,
        |resampled| {
            let pts: Vec<(f64, f64)> = points
                .iter()
                .zip(resampled)
                .map(|(r, frames)| (r.reflections as f64, median(frames)))
                .collect();
            statistic(&pts)
        },
        BOOTSTRAP_SEED,
    )
}

use mirrorbox_report::document::{ms, ms_digits};

/// `x` with `digits` decimals and a true minus sign where negative.
fn signed(x: f64, digits: usize) -> String {
    let s = format!("{:.digits$}", x.abs());
    let zero = s.chars().all(|c| c == '0' || c == '.');
    if x < 0.0 && !zero {
        format!("−{s}")
    } else {
        s
    }
}

/// A sentence on the cost of one more bounce against one full-scene pass (`pass_ms`).
pub fn bounce_sentence(g: &DepthScaling, pass_ms: Option<f64>) -> String {
    let Some(b) = g.ms_per_bounce else {
        return format!("{}: too few distinct depths to fit.", g.name());
    };
    let deepest = g.points.iter().map(|r| r.reflections).max().unwrap_or(0);
    let interval = g.ms_per_bounce_interval.map_or(String::new(), |i| {
        let d = ms_digits(b, 3);
        format!(" [95 % CI {:.d$}–{:.d$}, frames resampled]", i.low, i.high)
    });
    let mut s = format!(
        "{}, α = {}: {} ms{interval} per extra reflection (least-squares over {} depths, up to {} reflections shown)",
        g.name(),
        g.alpha,
        ms(b, 3),
        g.points.len(),
        deepest
    );
    if let Some(h) = g.bent() {
        s.push_str(&format!("; not one straight line: {}", h.describe(3)));
    }
    if let Some(p) = pass_ms.filter(|p| *p > 0.0) {
        s.push_str(&format!(
            "; one full-scene pass (the floor point: the scene without mirrors, rendered once) takes {} ms, \
             so one more bounce costs {:.1} % of a pass",
            ms(p, 2),
            100.0 * b / p
        ));
    }
    s.push('.');
    s
}

/// Among the exact points at α, the one closest to depth 64 per method, for the Table 1
/// comparison.
pub fn comparison_points<'r>(
    exact: &[String],
    records: &'r [Record],
    alpha: f32,
) -> Vec<&'r Record> {
    let mut out: Vec<&Record> = Vec::new();
    for m in exact {
        let best = records
            .iter()
            .filter(|r| r.kind == "point" && &r.method == m && r.alpha == alpha)
            .min_by_key(|r| r.depth.unwrap_or(0).abs_diff(64));
        out.extend(best);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_is_fitted_exactly() {
        let pts: Vec<(f64, f64)> = (0..5).map(|i| (i as f64, 2.0 + 0.5 * i as f64)).collect();
        let (a, b) = linear_fit(&pts).unwrap();
        assert!((a - 2.0).abs() < 1e-12 && (b - 0.5).abs() < 1e-12);
        assert!(linear_fit(&[(1.0, 1.0), (1.0, 2.0)]).is_none());
    }

    #[test]
    fn the_cost_per_bounce_gets_an_interval_from_the_frames() {
        let point = |depth: u32, ms: f64, spread: f64| {
            let mut r: Record = serde_json::from_value(serde_json::json!({
                "key": format!("unrolled depth={depth}"), "kind": "point", "scene": "s",
                "scene_hash": "0", "method": "unrolled", "n": null, "depth": depth,
                "alpha": 1.0, "width": 8, "height": 8, "ssaa": 1, "ms_median": ms,
                "ms_min": ms, "timing_source": "gpu-timestamps", "frames": 9, "passes": 1,
                "draws": 7, "texture_renders": 0, "reflections": depth,
                "metrics": { "rmse": 0, "relmse": 0, "smape": 0, "max_abs": 0, "psnr": null,
                             "ssim": 1, "flip_mean": 0, "flip_p95": 0, "flip_p99": 0 },
                "adapter": "a", "backend": "b", "truth_image": "", "raster_image": "",
                "heatmap_image": ""
            }))
            .unwrap();
            r.frames_ms = (0..9).map(|k| ms + spread * (k as f64 - 4.0)).collect();
            r
        };
        let exact = vec!["unrolled".to_string()];
        // 10 ms + 0.5 ms per bounce, frames spread ±2 ms around each median.
        let records: Vec<Record> = [1, 4, 16, 64]
            .iter()
            .map(|&d| point(d, 10.0 + 0.5 * d as f64, 0.5))
            .collect();
        let g = &depth_scaling(&exact, &records)[0];
        let i = g.ms_per_bounce_interval.expect("9 frames per point");
        assert!(i.contains(0.5) && i.high - i.low < 0.1, "{i:?}");
        assert!(bounce_sentence(g, Some(10.0)).contains("[95 % CI "));
        // Older records without frames: no interval, and the sentence says none.
        let bare: Vec<Record> = records
            .iter()
            .map(|r| Record {
                frames_ms: Vec::new(),
                ..r.clone()
            })
            .collect();
        let g = &depth_scaling(&exact, &bare)[0];
        assert!(g.ms_per_bounce_interval.is_none());
        assert!(!bounce_sentence(g, None).contains("CI"));
        // A straight line: the halves agree, and the sentence says nothing of them.
        assert!(g.bent().is_none() && !bounce_sentence(g, None).contains("not one straight"));
        // Cheaper per bounce when deep (lavapipe's shape): the one slope is an average.
        let bent: Vec<Record> = [(1, 10.0), (4, 12.4), (16, 22.0), (64, 41.2), (256, 118.0)]
            .iter()
            .map(|&(d, ms)| point(d, ms, 0.5))
            .collect();
        let g = &depth_scaling(&exact, &bent)[0];
        let h = g.bent().expect("two slopes");
        assert!(
            (h.shallow - 0.8).abs() < 1e-9 && (h.deep - 0.4).abs() < 1e-9 && h.mid == 16,
            "{h:?}"
        );
        let i = h.difference_interval.expect("9 frames per point");
        let all = g.ms_per_bounce.unwrap();
        assert!(i.contains(-0.4) && i.high < -BENT_BY * all, "{i:?} {all}");
        assert!(
            bounce_sentence(g, None).contains(
                "not one straight line: 0.800 ms per reflection up to 16 reflections, 0.400 ms \
                 beyond, a difference of −0.400 ms [95 % CI −"
            ),
            "{}",
            bounce_sentence(g, None)
        );
        // The same bend in frames too noisy to show it: the interval holds a straight line,
        // and the sentence claims no bend.
        let noisy: Vec<Record> = [(1, 10.0), (4, 12.4), (16, 22.0), (64, 41.2), (256, 118.0)]
            .iter()
            .map(|&(d, ms)| point(d, ms, 40.0))
            .collect();
        let g = &depth_scaling(&exact, &noisy)[0];
        let h = g.half_slopes.expect("five points");
        assert!((h.deep / h.shallow - 0.5).abs() < 1e-9);
        assert!(g.bent().is_none(), "{:?}", h.difference_interval);
        // Points that differ in anything but the depth are apart: one depth under several
        // lightings is no cost against depth (the lighting sweep had 30 such rows), and two
        // depth sweeps of one method, with and without shadow maps, are two lines.
        let with = |r: &Record, options: &str, k: f64| {
            let mut r = r.clone();
            r.method_options = options.into();
            r.axes.insert("mirrored_lights".into(), k);
            r
        };
        let one_depth: Vec<Record> = (0..3)
            .map(|k| with(&records[3], "shadows=map", k as f64))
            .chain([with(&records[3], "", 0.0)])
            .collect();
        assert!(depth_scaling(&exact, &one_depth).is_empty());
        let two: Vec<Record> = records
            .iter()
            .map(|r| with(r, "shadows=map", 1.0))
            .chain(records.iter().cloned())
            .collect();
        let names: Vec<String> = depth_scaling(&exact, &two)
            .iter()
            .map(|g| g.name())
            .collect();
        assert_eq!(
            names,
            ["unrolled (shadows=map, mirrored_lights=1)", "unrolled"],
            "{names:?}"
        );
    }
}
