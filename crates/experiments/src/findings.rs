//! What was found, computed from the committed records (issue 54): the results a reader
//! should take away, ranked, each one sentence with its number, its interval where it has
//! one, the device and the figure that shows it. One region (`findings`) quoted at the top of
//! the README, the book's introduction and the overview (`reports/README.md`, `index.html`),
//! so that the tests fail when a record changes and a sentence does not.
//!
//! A speed finding is a paired ratio and is stated as one verdict only where every committed
//! run of it gives the same verdict (faster, slower, not shown apart); otherwise the sentence
//! says that the runs disagree and by how much. Each finding names the book chapters that
//! open with it (regions `found-<chapter>`).

use crate::table1::rows::{self as table1};
use mirrorbox_report::document::{Block, markdown, ms, paired_ratio, sci};
use mirrorbox_report::readme::ReadmeError;
use mirrorbox_report::{Record, Sweep, load_sweep};
use std::path::Path;

/// The Table 1 runs of one device, in the order they ran, and what to call the device.
const TABLE1_RUNS: &[(&str, &[&str])] = &[
    (
        // The runs with the timing commands' default: every shader compiled afresh. With
        // Mesa's disk cache warm, `portal` had come out slower (the Table 1 chapter).
        "lavapipe (2 CPU cores, Mesa's shader cache off)",
        crate::table1::section::LAVAPIPE_RUNS,
    ),
    ("an NVIDIA H100", &["gpu/table1"]),
    (
        "an NVIDIA H200",
        &[
            "gpu/table1_h200",
            "gpu/table1_repeat_h200",
            "gpu/table1_repeat_h200_run2",
            "gpu/table1_h200_run2",
        ],
    ),
];

fn load(reports: &Path, folder: &str) -> Result<Sweep, ReadmeError> {
    load_sweep(&reports.join(folder))
}

/// A Table 1 run's two points the findings compare: the paper's `auxiliary` n = 2 and
/// `portal` at depth 64 (`folder` names the run in the error).
fn paper_against_portal<'s>(
    s: &'s Sweep,
    folder: &str,
) -> Result<(&'s Record, &'s Record), ReadmeError> {
    match (
        table1::point_at(&s.records, table1::PAPER_METHOD, Some(2), None),
        table1::point_at(&s.records, "portal", None, Some(64)),
    ) {
        (Some(aux), Some(portal)) => Ok((aux, portal)),
        _ => Err(ReadmeError(format!(
            "reports/{folder} lacks auxiliary n=2 or portal depth=64"
        ))),
    }
}

/// The first runs of Table 1 whose records hold the error over the mirror pixels, and their
/// devices (the H100's run predates that measure).
const TABLE1_ERROR_RUNS: &[(&str, &str)] = &[
    ("lavapipe", "table1"),
    ("an NVIDIA H200", "gpu/table1_h200"),
];

/// The exact method against the paper's: error over the mirror pixels, on each device's
/// Table 1 (the ratio differs from run to run: the rasterizers' rounding differs, and the
/// code between the runs, and with them the exact method's small error).
fn exact_error(reports: &Path) -> Result<String, ReadmeError> {
    let mut found = Vec::new();
    for (device, folder) in TABLE1_ERROR_RUNS {
        let s = load(reports, folder)?;
        let (aux, portal) = paper_against_portal(&s, folder)?;
        if aux.mirror_metrics.is_none() || portal.mirror_metrics.is_none() {
            return Err(ReadmeError(format!(
                "reports/{folder}: no error over the mirror pixels to quote"
            )));
        }
        let (aux, portal) = (aux.clone(), portal.clone());
        found.push((device, s, aux, portal));
    }
    let ratios: Vec<f64> = found
        .iter()
        .map(|(_, _, aux, portal)| aux.mirror_flip() / portal.mirror_flip())
        .collect();
    let (low, high) = ratios
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), &r| (l.min(r), h.max(r)));
    let each: Vec<String> = found
        .iter()
        .zip(&ratios)
        .map(|((device, s, aux, portal), r)| {
            // When and from which code each run is: the runs compared can be days and many
            // commits apart, and the exact method's small error moves with both.
            format!(
                "on {device} {r:.0}× (`portal` {}, `auxiliary` {}; {})",
                sci(portal.mirror_flip()),
                sci(aux.mirror_flip()),
                day_and_commit(s)
            )
        })
        .collect();
    let (_, s, _, portal) = &found[0];
    Ok(format!(
        "**Exact mirrors beat the paper's method on error by {low:.0}–{high:.0}×, run by run** \
         (each run its own device, day and code: the exact method's small error moves with \
         them): FLIP over the mirror pixels of `portal` at depth 64 ({} reflections) \
         against the paper's `auxiliary` n = 2, {} ({}, {}×{}, α = {}; \
         [figure](table1/plot_mirror_flip_vs_ms.svg)).",
        portal.reflections,
        each.join(", "),
        s.info.scene,
        portal.width,
        portal.height,
        portal.alpha
    ))
}

/// `portal` depth 64 against `auxiliary` n = 2, paired by round, in every committed run of
/// each device: one verdict where every run gives it, else the runs' spread.
fn exact_speed(reports: &Path) -> Result<String, ReadmeError> {
    let mut parts = Vec::new();
    for (device, folders) in TABLE1_RUNS {
        let mut intervals = Vec::new();
        // The host CPUs the runs shared (lavapipe's runs: its speed is theirs).
        let mut hosts: Vec<String> = Vec::new();
        for folder in *folders {
            let s = load(reports, folder)?;
            let host = s.info.cpu.split(',').next().unwrap_or_default().to_string();
            if !hosts.contains(&host) {
                hosts.push(host);
            }
            let (aux, portal) = paper_against_portal(&s, folder)?;
            if let Some(i) = paired_ratio(aux, portal) {
                intervals.push((aux.ms_median / portal.ms_median, i));
            }
        }
        if intervals.is_empty() {
            continue;
        }
        let ratios: Vec<f64> = intervals.iter().map(|(r, _)| *r).collect();
        let each: Vec<String> = intervals
            .iter()
            .map(|(r, i)| format!("{r:.2}× [{:.2}–{:.2}×]", i.low, i.high))
            .collect();
        let verdict =
            table1::RunsVerdict::of(&intervals.iter().map(|(_, i)| *i).collect::<Vec<_>>());
        parts.push(match (&verdict, intervals.len()) {
            (_, 1) => format!(
                "on {device}, {} as fast: {} (one run)",
                each[0],
                table1::speed_verdict(intervals[0].1)
            ),
            (table1::RunsVerdict::Agree { .. }, runs) => format!(
                "on {device}, {:.2}× as fast, the median of {runs} runs (their medians {}{}; {})",
                mirrorbox_report::stats::median(&ratios),
                spread(
                    ratios.iter().copied().fold(f64::INFINITY, f64::min),
                    ratios.iter().copied().fold(0.0, f64::max)
                ),
                match hosts.len() {
                    1 => String::new(),
                    n => format!(", on {n} host CPUs: {}", hosts.join(", ")),
                },
                verdict.sentence(runs)
            ),
            (table1::RunsVerdict::Disagree { .. }, runs) => format!(
                "on {device}, **no verdict**: {} ({})",
                verdict.sentence(runs),
                each.join(", ")
            ),
        });
    }
    Ok(format!(
        "**Speed, paired by round: `portal` at depth 64 against `auxiliary` n = 2** — {} \
         (mirror_box, 640×360, α = 0.7; the runs side by side: [lavapipe](../docs/book/src/table1.md), \
         [GPUs](../docs/book/src/gpu.md)).",
        parts.join("; ")
    ))
}

/// The runs' medians from `lo` to `hi`, with the decimals that tell them apart ("1.38× to
/// 1.38×" had said nothing), or the one value where they agree to four.
fn spread(lo: f64, hi: f64) -> String {
    match mirrorbox_report::document::apart(lo, hi) {
        Some((lo, hi)) => format!("{lo}× to {hi}×"),
        None => format!("all {lo:.2}×"),
    }
}

/// three.js' `Reflector` against our `naive` on each scene, and the floors on one device.
fn web_engines(reports: &Path) -> Result<String, ReadmeError> {
    let mut ratios = Vec::new();
    let mut floors = Vec::new();
    // How Reflector drew its mirror texture (the client's options, recorded with each point).
    let mut texture = String::new();
    for folder in ["web_engines", "web_engines_room", "web_engines_textured"] {
        let s = load(reports, folder)?;
        let find = |f: &dyn Fn(&Record) -> bool| s.records.iter().find(|r| f(r));
        let (Some(theirs), Some(ours)) = (
            find(&|r| r.method == "three-reflector"),
            find(&|r| !r.is_external() && r.method == "naive"),
        ) else {
            return Err(ReadmeError(format!(
                "reports/{folder} lacks three-reflector or naive"
            )));
        };
        ratios.push(theirs.mirror_flip() / ours.mirror_flip());
        if texture.is_empty() {
            let said: Vec<String> = [
                // The client's `target` is the texel type of Reflector's render target (at
                // the canvas size: clients/web/README.md), not its resolution.
                theirs.option("target").map(|t| match t {
                    "half" => "a half-float target".to_string(),
                    "float" => "a float target".to_string(),
                    "byte" => "an 8-bit target".to_string(),
                    t => format!("target type {t}"),
                }),
                theirs.option("msaa").map(|m| format!("{m}× MSAA")),
            ]
            .into_iter()
            .flatten()
            .collect();
            texture = said.join(", ");
        }
        if let (Some(a), Some(b)) = (
            find(&|r| r.is_external() && r.kind == "floor" && r.method == "three"),
            Record::our_floor(&s.records),
        ) {
            floors.push((a.metrics.flip_mean, b.metrics.flip_mean));
        }
    }
    let lo = ratios.iter().copied().fold(f64::MAX, f64::min);
    let hi = ratios.iter().copied().fold(f64::MIN, f64::max);
    let floor_gap = floors
        .iter()
        .map(|(a, b)| (a - b).abs() / b.max(1e-12))
        .fold(0.0f64, f64::max);
    Ok(format!(
        "**three.js' `Reflector` draws the paper's Algorithm 1** (one mirror texture per mirror, \
         as our `naive` does): over the mirror pixels its error is {lo:.2}–{hi:.2}× that of our `naive` \
         on mirror_box, mirror_room and textured_box (headless Chromium on SwiftShader, \
         320×180, α = 0.9), and on the same software rasterizer its no-mirror floor is ours \
         within {:.1} % — so the extra error comes with its mirrors, not with the shading of \
         the rest of the scene{} ([figure](web_engines_room/plot_mirror_flip_vs_ms.svg)).",
        // Rounded up: "within" must hold (a gap of 1.505 % had read "within 1.5 %").
        (1000.0 * floor_gap).ceil() / 10.0,
        if texture.is_empty() {
            String::new()
        } else {
            format!(
                " (it draws its mirror texture with {texture}: at 160×90 without the MSAA its \
                 error was lower, the MSAA smoothing the reflection's edges where the \
                 one-sample truth is sharp (clients/web/README.md); these records do not split \
                 it)"
            )
        }
    ))
}

/// The mirror room's Pareto front (error over the mirror pixels against time) on the GPU
/// panel the overview shows first.
fn room_front(reports: &Path) -> Result<String, ReadmeError> {
    let s = load(reports, "gpu/frontier_room")?;
    let pts: Vec<&Record> = s
        .records
        .iter()
        .filter(|r| r.kind == "point" && r.alpha == 1.0)
        .collect();
    let coords: Vec<(f64, f64)> = pts.iter().map(|r| (r.ms_median, r.mirror_flip())).collect();
    let (front, _) = mirrorbox_report::overview::pareto_steps(&coords);
    let mut names: Vec<(f64, String)> = pts
        .iter()
        .filter(|r| front.contains(&(r.ms_median, r.mirror_flip())))
        .map(|r| {
            // Other points within 1 % of this one on both axes: without intervals, the front
            // cannot tell them apart.
            let near = |a: f64, b: f64| (a - b).abs() <= 0.01 * a.abs().max(b.abs());
            let ties: Vec<String> = pts
                .iter()
                .filter(|o| {
                    !std::ptr::eq(**o, *r)
                        && near(o.ms_median, r.ms_median)
                        && near(o.mirror_flip(), r.mirror_flip())
                })
                .map(|o| mirrorbox_report::document::label(o))
                .collect();
            (
                r.ms_median,
                format!(
                    "{} ({} ms, FLIP {}{})",
                    mirrorbox_report::document::label(r),
                    mirrorbox_report::document::f(r.ms_median, 3),
                    sci(r.mirror_flip()),
                    if ties.is_empty() {
                        String::new()
                    } else {
                        format!("; {} within 1 % of both", ties.join(", "))
                    }
                ),
            )
        })
        .collect();
    names.sort_by(|a, b| a.0.total_cmp(&b.0));
    let cheapest_exact = names.iter().map(|(_, n)| n.clone()).collect::<Vec<_>>();
    // What the front cannot say: the methods the adapter could not run, and how precise each
    // point's time is.
    let missing: Vec<String> = s
        .info
        .unsupported
        .iter()
        .filter_map(|u| u.strip_prefix("--method ")?.split(' ').next())
        .map(|m| format!("`{m}`"))
        .collect();
    let mut caveats = Vec::new();
    if !missing.is_empty() {
        caveats.push(format!(
            "{} not measured, the adapter lacking a feature it needs",
            missing.join(", ")
        ));
    }
    if pts.iter().all(|r| r.ms_interval.is_none()) {
        let frames = pts.iter().map(|r| r.frames_ms.len()).max().unwrap_or(0);
        caveats.push(format!(
            "each time the median of {frames} frames, without an interval"
        ));
    }
    Ok(format!(
        "**What each millisecond buys in the mirror room**: on {} (320×180, α = 1) the methods no \
         other beats in both error and time are, from cheapest: {} ({}[figure](frontier_mirror_room.svg)).",
        s.info.adapter,
        cheapest_exact.join(", "),
        caveats.iter().map(|c| format!("{c}; ")).collect::<String>()
    ))
}

/// What one more bounce of `portal` costs, as a share of a full-scene pass, on each device
/// whose depth sweep is committed.
fn bounce_cost(reports: &Path) -> Result<String, ReadmeError> {
    let mut parts = Vec::new();
    for (folder, device) in [
        ("depth_scaling", "lavapipe"),
        ("gpu/depth_scaling", "an NVIDIA H100"),
    ] {
        let s = load(reports, folder)?;
        let groups = crate::depth_scaling::exact::depth_scaling(&s.info.exact_methods, &s.records);
        let floor = Record::our_floor(&s.records);
        let Some(g) = groups
            .iter()
            .find(|g| g.method == "portal" && g.variant.is_empty())
        else {
            return Err(ReadmeError(format!(
                "reports/{folder} holds no portal depth sweep"
            )));
        };
        let (Some(per_bounce), Some(i), Some(pass)) = (
            g.ms_per_bounce,
            g.ms_per_bounce_interval,
            floor.map(|f| f.ms_median),
        ) else {
            return Err(ReadmeError(format!(
                "reports/{folder}: no per-bounce fit or floor"
            )));
        };
        // Where one line does not fit, its slope is an average: say so, with the halves'.
        let bent = g.bent().map_or(String::new(), |h| {
            format!("; an average: {}", h.describe(2))
        });
        // Each device's run its own day and code: the two are not one experiment.
        parts.push(format!(
            "{} ms [{}–{}] on {device} ({:.1} % of its {} ms full-scene pass{bent}; {})",
            ms(per_bounce, 2),
            ms(i.low, 2),
            ms(i.high, 2),
            100.0 * per_bounce / pass,
            ms(pass, 2),
            day_and_commit(&s)
        ));
    }
    Ok(format!(
        "**An exact mirror's next bounce is cheap**: one more reflection of `portal` along a \
         path costs {} (mirror_box, 640×360, depth 1…1024, least squares with a 95 % interval \
         of the timing noise, not of the fit; [figure](depth_scaling/plot_ms_vs_depth.svg)).",
        parts.join(", ")
    ))
}

/// Screen-space reflections against the share of their reflections off screen (the camera
/// turns of the room), fallback `none`.
fn ssr_offscreen(reports: &Path) -> Result<String, ReadmeError> {
    let s = load(reports, "engine_reflections_ssr_room")?;
    let share = mirrorbox_report::value::REFLECTION_OFFSCREEN_SHARE;
    // Each turn once: its off-screen share, its error and its yaw (the span said is of the
    // same points as the count and ρ).
    let turns: Vec<(f64, f64, Option<f64>)> = s
        .records
        .iter()
        .filter(|r| r.method == "ssr" && r.option("ssr-fallback") == Some("none"))
        .filter_map(|r| {
            Some((
                r.value(share)?,
                r.mirror_flip(),
                r.axis(mirrorbox_report::axis::YAW_DEG),
            ))
        })
        .collect();
    let none: Vec<(f64, f64)> = turns.iter().map(|&(s, e, _)| (s, e)).collect();
    let rho = crate::engine_reflections::section::spearman(&none).ok_or_else(|| {
        ReadmeError("reports/engine_reflections_ssr_room: too few ssr turns".into())
    })?;
    let lo = none.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    let hi = none.iter().map(|p| p.1).fold(0.0, f64::max);
    // The turns' span, so that a reader sees what "camera turns" covered.
    let yaws: Vec<f64> = turns.iter().filter_map(|&(_, _, y)| y).collect();
    let span = match (
        yaws.iter().copied().reduce(f64::min),
        yaws.iter().copied().reduce(f64::max),
    ) {
        // A true minus sign, as the other findings print theirs.
        (Some(a), Some(b)) if a < b => format!(" from {a}° to {b}°").replace('-', "−"),
        _ => String::new(),
    };
    Ok(format!(
        "**Screen-space reflections fail where the screen lacks the reflection**: without a \
         fallback, `ssr`'s FLIP over the mirror pixels of the mirror room ranges {} to {} over \
         {} camera turns{span}, rank-correlated with the share of reflections off screen (Spearman's \
         ρ {:.2}; {}, {}, one-bounce truth; [figure](engine_reflections_ssr_room/ssr_offscreen.svg)).",
        sci(lo),
        sci(hi),
        none.len(),
        rho,
        measured_at(&s),
        s.info.adapter
    ))
}

/// Baking the symmetry copies on the CPU against the seed's instanced copies, paired by
/// round at the most planes measured, and how many copies pruning keeps. Times to at least
/// three significant digits and no decimals above 100 ms: the paired interval spans tens of
/// per cent, and "1714.77 ms" claimed more than the run measured.
fn symmetry(reports: &Path) -> Result<String, ReadmeError> {
    use crate::symmetry_scaling::planes::{
        BAKED_METHOD, PRUNED_METHOD, SEED_METHOD, plane_scaling, pruning_sentence,
    };
    let s = load(reports, "symmetry_scaling")?;
    let groups = plane_scaling(&s.records);
    let group = |m: &str| groups.iter().find(|g| g.name == m);
    let (Some(baked), Some(seed)) = (group(BAKED_METHOD), group(SEED_METHOD)) else {
        return Err(ReadmeError(
            "reports/symmetry_scaling lacks symmetry-baked or symmetry".into(),
        ));
    };
    let b = baked
        .points
        .last()
        .ok_or_else(|| ReadmeError("reports/symmetry_scaling: no baked point".into()))?;
    let o = seed
        .points
        .iter()
        .find(|o| o.planes() == b.planes())
        .ok_or_else(|| ReadmeError("reports/symmetry_scaling: no common p".into()))?;
    let i = paired_ratio(o, b).ok_or_else(|| {
        ReadmeError("reports/symmetry_scaling: no paired interval at the largest p".into())
    })?;
    let pruning = group(PRUNED_METHOD)
        .and_then(pruning_sentence)
        .map_or(String::new(), |p| format!("; {}", p.trim_end_matches('.')));
    // The like-for-like comparison of the culling: the pruned copies' time at the same p
    // (most of the baked mesh's lead is the cells it leaves out).
    let pruned_ms = group(PRUNED_METHOD)
        .and_then(|g| g.points.iter().find(|p| p.planes() == b.planes()))
        .map_or(String::new(), |p| {
            format!(", taking {} ms there", ms(p.ms_median, 0))
        });
    Ok(format!(
        "**Symmetry planes: the CPU's split-and-mirror mesh against the seed's 2^p copies** — at \
         p = {}, drawing the baked mesh once (`{BAKED_METHOD}`, {} ms) is {:.0}× [{:.0}–{:.0}×] \
         as fast as the seed's 2^p copies drawn by instancing \
         (`{SEED_METHOD}`, {} ms; the seed's own code draws each copy apart), paired by round: {} \
         (one run){pruning}{pruned_ms} ({}, {}, {}; [figure](symmetry_scaling/plot_ms_vs_planes.svg)).",
        b.planes().unwrap_or(0),
        ms(b.ms_median, 0),
        o.ms_median / b.ms_median,
        i.low,
        i.high,
        ms(o.ms_median, 0),
        table1::speed_verdict(i),
        s.info.scene,
        measured_at(&s),
        s.info.adapter
    ))
}

/// Per-eye mirror textures against the head's shared ones, at the widest IPD.
fn stereo(reports: &Path) -> Result<String, ReadmeError> {
    let s = load(reports, "stereo")?;
    let sentence = crate::stereo::section::flattening(&s.records).ok_or_else(|| {
        ReadmeError("reports/stereo holds no per-eye and shared pair with a marker".into())
    })?;
    Ok(format!(
        "**Stereo: sharing one set of mirror textures between the eyes flattens the mirror** — {sentence} ({}, {}, {}; [figure](stereo/plot_stereo_disparity_vs_ipd.svg)).",
        s.info.scene,
        measured_at(&s),
        s.info.adapter
    ))
}

/// Ignoring mirrored light, as today's raster does, against truths lit through k mirrors.
fn lighting(reports: &Path) -> Result<String, ReadmeError> {
    let s = load(reports, "lighting")?;
    let grows = crate::lighting::section::growth(&s.records)
        .ok_or_else(|| ReadmeError("reports/lighting holds no k sweep of lights=direct".into()))?;
    Ok(format!(
        "**Light through mirrors matters** (FLIP over the image): {} ({}, {}, {}; [figure](lighting/plot_lighting_error_vs_k.svg)).",
        lowercase_first(grows.trim_end_matches('.')),
        s.info.scene,
        measured_at(&s),
        s.info.adapter
    ))
}

/// The engines' tricks for uneven mirrors at the steepest bump measured.
fn uneven(reports: &Path) -> Result<String, ReadmeError> {
    let s = load(reports, "uneven_mirrors")?;
    let steepest = crate::bumpy::section::sentences(&s.records, &s.info.bump_methods)
        .pop()
        .ok_or_else(|| ReadmeError("reports/uneven_mirrors holds no tilt".into()))?;
    // One figure per base method: the finding names tricks of several bases, and the first
    // figure alone had not shown two of the three it called closest.
    let figures: Vec<String> =
        crate::bumpy::section::uneven_section(&s.records, &s.info.bump_methods)
            .iter()
            .filter_map(|b| match b {
                Block::Chart(file, chart) => {
                    // The base method, as the chart's title names it ("…: auxiliary n=4's
                    // tricks, …" or "…: auxiliary n=4 with its march trick").
                    let base = chart
                        .title
                        .split_once("tilt: ")
                        .and_then(|(_, t)| {
                            t.split_once("'s tricks")
                                .or_else(|| t.split_once(" with its "))
                        })
                        .map_or(file.as_str(), |(m, _)| m);
                    Some(format!("[{base}](uneven_mirrors/{file})"))
                }
                _ => None,
            })
            .collect();
    Ok(format!(
        "**Uneven mirrors: how far the engines' tricks stay from the truth** (FLIP over the image) — {} ({}, {}, {}; each base method's tricks: {}).",
        lowercase_first(steepest.trim_end_matches('.')),
        s.info.scene,
        measured_at(&s),
        s.info.adapter,
        figures.join(", ")
    ))
}

/// "measured DAY at COMMIT": when a run was made and from which code, for findings that set
/// runs of different days side by side.
fn day_and_commit(s: &Sweep) -> String {
    let day = s.info.date.get(..10).unwrap_or(&s.info.date);
    // Runs older than the field have none: said so ("at )" had been printed).
    match s.info.measured_by(7) {
        Some(commit) => format!("measured {day} at {commit}"),
        None => format!("measured {day}, its commit not recorded"),
    }
}

/// Where a sweep's points were measured, as a finding's closing parenthesis says it: the
/// image size and the α its points share (`320x180, α = 0.9`), so that no finding's numbers
/// read as the scene file's own size or α.
fn measured_at(s: &Sweep) -> String {
    let size = s
        .info
        .resolution
        .split(',')
        .next()
        .unwrap_or_default()
        .trim()
        .to_string();
    let alphas = mirrorbox_report::document::distinct(
        s.records
            .iter()
            .filter(|r| r.kind == "point")
            .map(|r| r.alpha_text()),
    );
    match alphas.as_slice() {
        [a] => format!("{size}, α = {a}"),
        _ => size,
    }
}

/// A report's sentence continued after a dash or colon: its first letter in lower case.
fn lowercase_first(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map_or(String::new(), |f| f.to_lowercase().chain(c).collect())
}

/// One finding: its sentence and the book chapters that open with it.
pub struct Finding {
    pub text: String,
    /// Chapters under `docs/book/src/`.
    pub chapters: &'static [&'static str],
}

/// Every finding, ranked: what a reader should take away first comes first.
pub fn ranked(reports: &Path) -> Result<Vec<Finding>, ReadmeError> {
    let finding = |text: String, chapters| Finding { text, chapters };
    Ok(vec![
        finding(exact_error(reports)?, &["table1.md"]),
        finding(exact_speed(reports)?, &["table1.md", "gpu.md"]),
        finding(room_front(reports)?, &["frontier.md"]),
        finding(bounce_cost(reports)?, &["exact-methods.md"]),
        finding(web_engines(reports)?, &["exchange.md"]),
        finding(ssr_offscreen(reports)?, &["engine-reflections.md"]),
        finding(stereo(reports)?, &["stereo.md"]),
        finding(lighting(reports)?, &["lighting.md"]),
        finding(symmetry(reports)?, &["symmetry.md"]),
        finding(uneven(reports)?, &["uneven-mirrors.md"]),
    ])
}

/// The findings, ranked, as blocks (a heading, then one numbered sentence each).
pub fn findings(reports: &Path) -> Result<Vec<Block>, ReadmeError> {
    let mut blocks = vec![Block::Heading(2, "What was found".into())];
    blocks.push(Block::Paragraph(
        "Computed from the committed records by `mirrorbox readme` and `mirrorbox report \
         --index`; the tests fail when a record changes and a \
         sentence does not."
            .into(),
    ));
    for (i, f) in ranked(reports)?.iter().enumerate() {
        blocks.push(Block::Paragraph(format!("{}. {}", i + 1, f.text)));
    }
    Ok(blocks)
}

/// [`findings`] with each finding's figure shown under it (the overview: one chart per
/// question, in the order of the findings).
pub fn findings_with_figures(reports: &Path) -> Result<Vec<Block>, ReadmeError> {
    let mut out = Vec::new();
    for (i, b) in findings(reports)?.into_iter().enumerate() {
        let figure = match &b {
            Block::Paragraph(text) => text
                .split("[figure](")
                .nth(1)
                .and_then(|rest| rest.split(')').next())
                .map(str::to_string),
            _ => None,
        };
        out.push(b);
        if let Some(f) = figure {
            out.push(Block::Paragraph(format!(
                "![the figure of finding {}]({f})",
                i - 1
            )));
        }
    }
    Ok(out)
}

/// The findings a chapter opens with (region `found-<chapter>`), numbered as in the ranked
/// list, their links as paths.
pub fn chapter_findings(reports: &Path, chapter: &str) -> Result<String, ReadmeError> {
    let blocks: Vec<Block> = ranked(reports)?
        .into_iter()
        .enumerate()
        .filter(|(_, f)| f.chapters.contains(&chapter))
        .map(|(i, f)| {
            Block::Paragraph(format!(
                "**Found** (finding {} of the book's introduction, computed from the records): {}",
                i + 1,
                f.text
            ))
        })
        .collect();
    if blocks.is_empty() {
        return Err(ReadmeError(format!("no finding opens {chapter}")));
    }
    Ok(with_paths(&blocks))
}

/// [`findings`] as Markdown with its links (written relative to `reports/`) made relative to
/// another file: `to_reports` is the way from that file's folder to `reports/`, `to_root` to
/// the repository root (the overview: `` and `../`).
pub fn rebased(blocks: &[Block], to_reports: &str, to_root: &str) -> String {
    const UP: &str = "\u{1}";
    markdown(blocks)
        .replace("](../", &format!("]({UP}"))
        .replace("](", &format!("]({to_reports}"))
        .replace(&format!("{to_reports}{UP}"), to_root)
}

/// [`findings`] for a region (the README, the book), where relative links cannot stay (a
/// region's text is the same in files at different depths): each `[label](target)` becomes
/// `label` and the target's path from the repository root in code, so it can still be found.
pub fn with_paths(blocks: &[Block]) -> String {
    let text = rebased(blocks, "reports/", "");
    let mut out = String::new();
    let mut rest = text.as_str();
    while let Some(open) = rest.find('[') {
        let after = &rest[open + 1..];
        let link = after
            .find(']')
            .filter(|c| after[*c..].starts_with("]("))
            .and_then(|c| {
                let target = &after[c + 2..];
                target
                    .find(')')
                    .map(|e| (&after[..c], &target[..e], c + 2 + e + 1))
            });
        match link {
            Some((label, target, len)) => {
                out.push_str(&rest[..open]);
                out.push_str(&format!("{label}: `{target}`"));
                rest = &after[len..];
            }
            None => {
                out.push_str(&rest[..open + 1]);
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_regions_links_become_paths_from_the_root_and_intervals_stay() {
        let b = [Block::Paragraph(
            "see [figure](table1/p.svg) and [book](../docs/x.md); 1.2× [1.1–1.3×] stays".into(),
        )];
        assert_eq!(
            with_paths(&b).trim(),
            "see figure: `reports/table1/p.svg` and book: `docs/x.md`; 1.2× [1.1–1.3×] stays"
        );
        assert!(rebased(&b, "", "../").contains("[book](../docs/x.md)"));
    }
}
