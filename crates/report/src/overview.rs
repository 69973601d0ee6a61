//! The overview of every committed report (issue 38): `reports/index.html` and
//! `reports/README.md`, headed by the harness's first question — across every method, what
//! error does each millisecond buy? — as one frontier chart per scene and device, then one row
//! per report with its scene, device, date and commit.
//!
//! The frontier takes every point of every sweep on the scene (no scene axis: lighting, tilt
//! and stereo sweeps answer their own questions), groups them by device, size and α, and draws
//! each method at its sweep points (markers, the method's fixed style) with the Pareto front
//! (the points no other point beats in both time and error) as a grey step line. Its error is
//! the FLIP mean over the mirror pixels where every point has it (the error a method makes,
//! undiluted by the pixels every method gets right), else over the image.

use crate::document::{distinct, remove_stale};
use crate::error::ReadmeError;
use crate::folder::{Sweep, load_sweep};
use crate::plot::{Chart, Reference, Series, styles_for};
use crate::{Record, SweepInfo};
use mirrorbox_files::write_atomically;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One report folder under `reports/`.
struct Entry {
    /// Relative to `reports/`.
    folder: String,
    /// The file a reader opens (relative to `reports/`).
    link: String,
    title: String,
    scene: String,
    device: String,
    date: String,
    commit: String,
}

/// A frontier panel's key: device slug, device, size, α's bits.
type GroupKey = (String, String, String, u32);

/// A chart of the overview: its file name (in `reports/`) and the chart.
pub struct Frontier {
    pub file: String,
    pub chart: Chart,
}

fn scene_stem(scene: &str) -> &str {
    Path::new(scene)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or(scene)
}

/// A device's short name for file names: `lavapipe`, else the adapter's first word with a digit
/// in it (its model: `h100` of "NVIDIA H100 80GB HBM3", `h200` of "NVIDIA H200"), else its
/// first word.
fn device_slug(adapter: &str) -> String {
    let a = adapter.to_lowercase();
    if a.contains("llvmpipe") {
        return "lavapipe".into();
    }
    let words: Vec<String> = a
        .split_whitespace()
        .map(|w| w.chars().filter(char::is_ascii_alphanumeric).collect())
        .filter(|w: &String| !w.is_empty())
        .collect();
    words
        .iter()
        .find(|w| w.chars().any(|c| c.is_ascii_digit()))
        .or(words.first())
        .cloned()
        .unwrap_or_else(|| "device".into())
}

/// The lead's Markdown as HTML: `## ` headings, `- ` items, a line `![alt](src)` an image,
/// other lines paragraphs; inline `**bold**`, `` `code` `` and `[text](link)`.
fn lead_html(md: &str) -> String {
    let mut out = String::new();
    let mut in_list = false;
    for line in md.lines() {
        if let Some((alt, src, len)) = line.strip_prefix('!').and_then(parse_link)
            && len == line.len() - 1
        {
            let esc = crate::document::escape_html;
            let _ = writeln!(
                out,
                "<p><img src=\"{}\" alt=\"{}\"></p>",
                esc(src),
                esc(alt)
            );
            continue;
        }
        let (tag, text) = if let Some(t) = line.strip_prefix("## ") {
            ("h2", t)
        } else if let Some(t) = line.strip_prefix("- ") {
            ("li", t)
        } else if line.trim().is_empty() {
            ("", "")
        } else {
            ("p", line)
        };
        if in_list && tag != "li" {
            out.push_str("</ul>\n");
            in_list = false;
        }
        if tag == "li" && !in_list {
            out.push_str("<ul>");
            in_list = true;
        }
        if !tag.is_empty() {
            let _ = writeln!(out, "<{tag}>{}</{tag}>", inline_markdown_html(text));
        }
    }
    if in_list {
        out.push_str("</ul>\n");
    }
    out
}

/// One line of Markdown's inline syntax (`**bold**`, `` `code` ``, `[text](link)`) as HTML.
fn inline_markdown_html(text: &str) -> String {
    let esc = crate::document::escape_html;
    let mut out = String::new();
    let mut rest = text;
    let (mut bold, mut code) = (false, false);
    while !rest.is_empty() {
        if !code && rest.starts_with("**") {
            out.push_str(if bold { "</strong>" } else { "<strong>" });
            bold = !bold;
            rest = &rest[2..];
        } else if rest.starts_with('`') {
            out.push_str(if code { "</code>" } else { "<code>" });
            code = !code;
            rest = &rest[1..];
        } else if let (false, Some(link)) = (code, parse_link(rest)) {
            let (label, target, len) = link;
            let _ = write!(
                out,
                "<a href=\"{}\">{}</a>",
                esc(target),
                inline_markdown_html(label)
            );
            rest = &rest[len..];
        } else {
            let c = rest.chars().next().unwrap_or_default();
            out.push_str(&esc(&c.to_string()));
            rest = &rest[c.len_utf8()..];
        }
    }
    out
}

/// `[label](target)` at the start of `s`: the label, the target and the length consumed.
fn parse_link(s: &str) -> Option<(&str, &str, usize)> {
    let s2 = s.strip_prefix('[')?;
    // The label ends at the first `]`, which must open the target (`[1.2–1.9×]` is text).
    let close = s2.find(']')?;
    if !s2[close..].starts_with("](") {
        return None;
    }
    let after = &s2[close + 2..];
    let end = after.find(')')?;
    Some((&s2[..close], &after[..end], 1 + close + 2 + end + 1))
}

/// A report the overview lists that is not a sweep folder: its Markdown, the file of its
/// measurements (whose commit the overview names) and its scenes, paths under `reports/`.
#[derive(Clone, Copy, Debug)]
pub struct OtherReport {
    pub report: &'static str,
    pub data: &'static str,
    pub scene: &'static str,
}

/// The sweep folders under `reports` (one level, and one below: a device's records such as
/// `gpu/`), sorted.
fn sweep_folders(reports: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut visit = |dir: &Path| {
        if let Ok(entries) = std::fs::read_dir(dir) {
            for e in entries.flatten() {
                let p = e.path();
                if p.join("sweep.json").is_file() {
                    out.push(p);
                }
            }
        }
    };
    visit(reports);
    if let Ok(entries) = std::fs::read_dir(reports) {
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() && !p.join("sweep.json").is_file() {
                visit(&p);
            }
        }
    }
    out.sort();
    out
}

/// The report's first Markdown heading, without its `#`s.
fn first_heading(path: &Path) -> Option<String> {
    let text = mirrorbox_files::read_bounded_text(path, 8 << 20, "a report").ok()?;
    text.lines()
        .find(|l| l.starts_with('#'))
        .map(|l| l.trim_start_matches('#').trim().replace('`', ""))
}

/// What a point's series in the frontier is: its method and non-default options.
fn series_name(r: &Record) -> String {
    crate::document::variant(r)
}

/// Points of a chart: (ms/frame, error).
type Points = Vec<(f64, f64)>;

/// The Pareto front of `(ms, error)` points: sorted by time, each point kept if no faster one
/// has an error as low; returned with the step line through the kept points.
pub fn pareto_steps(points: &[(f64, f64)]) -> (Points, Points) {
    let mut sorted: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite() && *x > 0.0 && *y > 0.0)
        .collect();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for p in sorted {
        if front.last().is_none_or(|l| p.1 < l.1) {
            front.push(p);
        }
    }
    let mut steps = Vec::new();
    for (i, p) in front.iter().enumerate() {
        if i > 0 {
            steps.push((p.0, front[i - 1].1));
        }
        steps.push(*p);
    }
    (front, steps)
}

/// The frontier charts of the sweeps in `sweeps`: per scene of `scenes` (file stems: the
/// experiments' frontier scenes, `mirrorbox_experiments::frontier::SCENES`), per device,
/// size and α with at least two methods. The headline of a scene, `frontier_<scene>.svg`, is a
/// real GPU's chart where one was measured (else lavapipe's, else another CPU rasterizer's),
/// the one with the most methods, then the most points; the others are named by device, size
/// and α.
pub(crate) fn frontiers(sweeps: &[(String, Sweep)], scenes: &[&str]) -> Vec<Frontier> {
    let mut out = Vec::new();
    for &scene in scenes {
        // (device slug, device text, size, α) → records.
        let mut groups: Vec<(GroupKey, Vec<&Record>, &SweepInfo)> = Vec::new();
        for (_, sweep) in sweeps {
            if scene_stem(&sweep.info.scene) != scene {
                continue;
            }
            // The scene as its file has it: a point with a scene axis (mirrored lights, a
            // tilt, a camera turn, …) or a stereo pair is another scene.
            // Our methods only (an outside renderer's variants have their own clock: their
            // report sets them beside ours), each on the device its record names (a scored
            // folder holds our sweep of another device beside them).
            for r in sweep.records.iter().filter(|r| {
                r.kind == "point"
                    && r.axes.is_empty()
                    && r.stereo.is_none()
                    && r.device.is_none()
                    && !r.is_external()
            }) {
                let (adapter, backend) = if r.adapter.is_empty() {
                    (sweep.info.adapter.clone(), sweep.info.backend.clone())
                } else {
                    (r.adapter.clone(), r.backend.clone())
                };
                let key = (
                    device_slug(&adapter),
                    format!("{adapter} ({backend})"),
                    format!("{}x{}", r.width, r.height),
                    r.alpha.to_bits(),
                );
                match groups.iter_mut().find(|g| g.0 == key) {
                    Some(g) => g.1.push(r),
                    None => groups.push((key, vec![r], &sweep.info)),
                }
            }
        }
        // A point measured in several sweeps (Table 1 and its repeat) is shown once: its
        // latest measurement.
        for g in &mut groups {
            let mut kept: Vec<&Record> = Vec::new();
            for r in g.1.drain(..) {
                match kept.iter_mut().find(|k| k.key == r.key) {
                    Some(k) if r.run > k.run => *k = r,
                    Some(_) => {}
                    None => kept.push(r),
                }
            }
            g.1 = kept;
        }
        groups.retain(|g| distinct(g.1.iter().map(|r| r.method.clone())).len() >= 2);
        // Panels of one setting side by side, lavapipe first, then each GPU: the same
        // question on each device (issue 57).
        let pixels = |size: &str| -> u64 {
            size.split('x')
                .map(|d| d.parse::<u64>().unwrap_or(0))
                .product()
        };
        groups.sort_by(|a, b| {
            let key = |g: &(GroupKey, Vec<&Record>, &SweepInfo)| {
                (pixels(&g.0.2), f32::from_bits(g.0.3), g.0.0 != "lavapipe")
            };
            let (ka, kb) = (key(a), key(b));
            ka.0.cmp(&kb.0)
                .then(kb.1.total_cmp(&ka.1))
                .then(ka.2.cmp(&kb.2))
                .then(a.0.0.cmp(&b.0.0))
        });
        // The headline (`frontier_<scene>.svg`, the README's figure): a real GPU's panel where
        // one was measured, else the CPU's; the one with most methods, then most points.
        let gpu = |info: &SweepInfo| info.device_type.contains("Gpu");
        let headline = groups
            .iter()
            .enumerate()
            .max_by_key(|(_, g)| {
                let methods = distinct(g.1.iter().map(|r| r.method.clone())).len();
                (gpu(g.2), g.0.0 == "lavapipe", methods, g.1.len())
            })
            .map(|(i, _)| i);
        for (i, ((slug, device, size, alpha), records, info)) in groups.iter().enumerate() {
            let alpha = f32::from_bits(*alpha);
            let file = if Some(i) == headline {
                format!("frontier_{scene}.svg")
            } else {
                format!("frontier_{scene}_{slug}_{size}_a{alpha}.svg")
            };
            out.push(Frontier {
                file,
                chart: frontier_chart(scene, device, size, alpha, records, info),
            });
        }
    }
    out
}

fn frontier_chart(
    scene: &str,
    device: &str,
    size: &str,
    alpha: f32,
    records: &[&Record],
    info: &SweepInfo,
) -> Chart {
    let mirror = records.iter().all(|r| r.mirror_metrics.is_some());
    let error = |r: &Record| match (&r.mirror_metrics, mirror) {
        (Some(m), true) => m.flip_mean,
        _ => r.metrics.flip_mean,
    };
    let names = distinct(records.iter().map(|r| series_name(r)));
    let all: Vec<(f64, f64)> = records.iter().map(|r| (r.ms_median, error(r))).collect();
    let (front, steps) = pareto_steps(&all);
    let on_front = |r: &Record| front.contains(&(r.ms_median, error(r)));
    let variants: Vec<&str> = names.iter().map(String::as_str).collect();
    let styles = styles_for(&variants);
    let bars = crate::ms_bars_for(records.iter().copied());
    let series: Vec<Series> = names
        .iter()
        .zip(styles)
        .map(|(name, style)| {
            let mut pts: Vec<&&Record> =
                records.iter().filter(|r| &series_name(r) == name).collect();
            pts.sort_by(|a, b| a.ms_median.total_cmp(&b.ms_median));
            let mut s = Series::new(
                crate::document::legend_name(name, &variants),
                style,
                pts.iter().map(|r| (r.ms_median, error(r))).collect(),
            );
            s.joined = false;
            s.bars = bars;
            s.x_intervals = pts.iter().map(|r| r.ms_bars(s.bars)).collect();
            // The front's points are labelled, and every point of a series of several (two
            // cube sizes had been two crosses alike, unnamed); the placement leaves out a
            // label with no free place.
            let several = pts.len() > 1;
            s.labels = pts
                .iter()
                .map(|r| {
                    if on_front(r) || several {
                        crate::document::swept_label(r)
                    } else {
                        String::new()
                    }
                })
                .collect();
            s
        })
        .collect();
    let mut chart = Chart {
        x_log: true,
        y_log: true,
        series,
        references: vec![Reference::Curve("Pareto front".into(), steps)],
        ..Chart::new(
            format!(
                "What each millisecond buys ({}): {scene}, {}, {size}, α = {alpha}",
                if mirror {
                    "FLIP over the mirror pixels"
                } else {
                    "FLIP over the image"
                },
                device.split(" (").next().unwrap_or(device)
            ),
            "ms/frame (median, 95 % CI bars)",
            if mirror {
                "FLIP mean over the mirror pixels"
            } else {
                "FLIP mean over the image"
            },
        )
    };
    let date = info.date.get(..10).unwrap_or(&info.date);
    let commit = if info.commit.is_empty() {
        format!("records committed in {}", info.records_commit)
    } else {
        format!("commit {}", info.commit)
    };
    chart.footer = format!(
        "{scene} · {size} · {device} on {} · {date} · {commit}",
        info.cpu
    );
    chart
}

/// The figure check of the overview's frontier charts ([`crate::plot::Chart::lint`]), drawn
/// from the sweep folders under `reports` as [`overview`] draws them, without writing.
pub fn lint_frontiers(reports: &Path, scenes: &[&str]) -> Result<Vec<String>, ReadmeError> {
    let mut sweeps = Vec::new();
    for dir in sweep_folders(reports) {
        sweeps.push((dir.display().to_string(), load_sweep(&dir)?));
    }
    Ok(frontiers(&sweeps, scenes)
        .iter()
        .filter(|c| c.chart.is_drawable())
        .flat_map(|c| {
            c.chart
                .lint()
                .into_iter()
                .map(move |m| format!("{}: {m}", c.file))
        })
        .collect())
}

/// [`overview`]'s lead: Markdown (links relative to `reports/`) set first on both pages — what
/// was found, before the charts.
pub struct Lead<'a>(pub &'a str);

/// The overview [`overview`] computes: the files with their text (`reports/index.html`,
/// `reports/README.md`, the frontier SVGs), the frontier charts of an earlier overview it
/// removes, and how many reports it lists. [`Overview::write`] writes it,
/// [`Overview::differences`] compares it with the files on disk.
pub struct Overview {
    pub files: Vec<(PathBuf, String)>,
    pub stale: Vec<PathBuf>,
    pub listed: usize,
}

impl Overview {
    /// Removes the stale charts, then writes the files.
    pub fn write(&self) -> Result<(), ReadmeError> {
        for path in &self.stale {
            remove_stale(path).map_err(|e| ReadmeError(e.to_string()))?;
        }
        for (path, text) in &self.files {
            write_atomically(path, text.as_bytes()).map_err(|e| ReadmeError(e.to_string()))?;
        }
        Ok(())
    }

    /// Where the files on disk differ from this overview (`report --index --check`): each
    /// file that is missing or different, each stale chart still there.
    pub fn differences(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (path, text) in &self.files {
            match std::fs::read_to_string(path) {
                Ok(on_disk) if on_disk == *text => {}
                Ok(_) => out.push(format!("{}: differs from the records", path.display())),
                Err(e) => out.push(format!("{}: {e}", path.display())),
            }
        }
        for path in &self.stale {
            out.push(format!(
                "{}: a chart no report draws any more",
                path.display()
            ));
        }
        out
    }
}

/// The overview of every report under `reports`, computed without writing.
/// `commit_of(path)` (a sweep folder, or a measurement's file) names the commit of one that
/// did not record the one that measured it (the commit that committed its records).
/// `about(folder)`: what the experiment that writes `folder` (relative to `reports`)
/// measures, from the experiment registry, where it knows the folder.
/// `others`: the reports that are not sweep folders (a sequence sweep's, a script's).
/// `frontier_scenes`: the scenes (file stems) a frontier chart is drawn for.
pub fn overview(
    reports: &Path,
    commit_of: &dyn Fn(&Path) -> String,
    about: &dyn Fn(&str) -> Option<String>,
    others: &[OtherReport],
    frontier_scenes: &[&str],
    lead: Lead,
) -> Result<Overview, ReadmeError> {
    let mut files: Vec<(PathBuf, String)> = Vec::new();
    let mut stale: Vec<PathBuf> = Vec::new();
    let rel = |p: &Path| {
        p.strip_prefix(reports)
            .unwrap_or(p)
            .to_string_lossy()
            .into_owned()
    };
    let mut sweeps: Vec<(String, Sweep)> = Vec::new();
    let mut entries: Vec<Entry> = Vec::new();
    for dir in sweep_folders(reports) {
        let mut sweep = load_sweep(&dir)?;
        if sweep.info.commit.is_empty() {
            sweep.info.records_commit = commit_of(&dir);
        }
        let folder = rel(&dir);
        entries.push(Entry {
            link: format!("{folder}/report.html"),
            title: about(&folder)
                .or_else(|| first_heading(&dir.join("report.md")))
                .unwrap_or_else(|| folder.clone()),
            scene: sweep.info.scene.clone(),
            device: format!("{} ({})", sweep.info.adapter, sweep.info.backend),
            date: sweep
                .info
                .date
                .get(..10)
                .unwrap_or(&sweep.info.date)
                .to_string(),
            commit: if sweep.info.commit.is_empty() {
                format!("records in {}", sweep.info.records_commit)
            } else {
                sweep.info.commit.clone()
            },
            folder: folder.clone(),
        });
        sweeps.push((folder, sweep));
    }
    // The other reports: a sequence sweep, benches and one-off measurements (the caller's,
    // from the experiments' rows), and the test job's times. Each with the file of its
    // measurements, whose commit the table names (the report beside it is rewritten with
    // every change of the report's text).
    let tests = OtherReport {
        report: "tests/test_times.md",
        data: "tests/test_times.md",
        scene: "–",
    };
    for OtherReport {
        report: file,
        data,
        scene,
    } in others.iter().chain([&tests])
    {
        let (file, data, scene) = (*file, *data, *scene);
        let path = reports.join(file);
        if !path.is_file() {
            continue;
        }
        let folder = Path::new(file)
            .parent()
            .map_or(String::new(), |p| p.to_string_lossy().into_owned());
        entries.push(Entry {
            link: file.to_string(),
            title: about(&folder)
                .or_else(|| first_heading(&path))
                .unwrap_or_else(|| file.to_string()),
            scene: scene.into(),
            device: "see the report".into(),
            date: "see the report".into(),
            commit: format!("records in {}", commit_of(&reports.join(data))),
            folder,
        });
    }

    let charts = frontiers(&sweeps, frontier_scenes);
    // Frontier files of an earlier overview that this one does not draw.
    if let Ok(dir) = std::fs::read_dir(reports) {
        for e in dir.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with("frontier_")
                && name.ends_with(".svg")
                && !charts
                    .iter()
                    .any(|c| c.file == name && c.chart.is_drawable())
            {
                stale.push(e.path());
            }
        }
    }
    let mut md = String::from(
        "# mirrorbox reports\n\nGenerated by `mirrorbox report --index reports` from the committed \
         records; every figure names its scene, size, device and date.\n\n",
    );
    md.push_str(lead.0.trim_end());
    md.push_str(
        "\n\n## What each millisecond buys\n\n\
         Every method at its sweep points on the bundled mirror scenes, error against ms/frame \
         (log–log, lower left is better); the grey step line is the Pareto front, labelled with \
         the settings on it. First each scene's headline panel (a GPU's where one was measured), \
         then one per device, size and α.\n\n",
    );
    let mut html = String::from(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>mirrorbox reports</title>\
         <meta name=\"viewport\" content=\"width=device-width\"><style>\
         body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em}\
         .chart svg{max-width:100%;height:auto}\
         .scroll{overflow-x:auto}table{border-collapse:collapse;margin:1em 0}\
         td,th{border:1px solid #ccc;padding:3px 8px;text-align:left;vertical-align:top}\
         th{background:#f3f3f3}td{overflow-wrap:break-word}\
         </style></head><body>\n<h1>mirrorbox reports</h1>\n<p>Generated by <code>mirrorbox report \
         --index reports</code> from the committed records; every figure names its scene, size, \
         device and date.</p>\n",
    );
    html.push_str(&lead_html(lead.0));
    html.push_str(
        "<h2>What each millisecond buys</h2>\n<p>Every method at its sweep \
         points on the bundled mirror scenes, error against ms/frame (log–log, lower left is \
         better); the grey step line is the Pareto front, labelled with the settings on it. First \
         each scene's headline panel (a GPU's where one was measured), then one per device, size \
         and α.</p>\n",
    );
    // The headline panel of each scene first (`frontier_<scene>.svg`: a GPU's where one was
    // measured), then every other device, size and α.
    let drawable: Vec<&Frontier> = charts.iter().filter(|c| c.chart.is_drawable()).collect();
    let (headlines, others): (Vec<&Frontier>, Vec<&Frontier>) =
        drawable.into_iter().partition(|c| {
            frontier_scenes
                .iter()
                .any(|s| c.file == format!("frontier_{s}.svg"))
        });
    for (i, c) in headlines.iter().chain(&others).enumerate() {
        if i == headlines.len() && !others.is_empty() {
            md.push_str("### Every other device, size and α\n\n");
            html.push_str("<h3>Every other device, size and α</h3>\n");
        }
        let svg = c.chart.to_svg();
        files.push((reports.join(&c.file), svg.clone()));
        let _ = writeln!(md, "![{}]({})\n", c.chart.title, c.file);
        let _ = writeln!(html, "<div class=\"chart\">{svg}</div>");
    }
    md.push_str("## Every report\n\n| report | what | scene | device | date | commit |\n|---|---|---|---|---|---|\n");
    html.push_str(
        "<h2>Every report</h2>\n<div class=\"scroll\"><table><tr><th>report</th><th>what</th>\
         <th>scene</th><th>device</th><th>date</th><th>commit</th></tr>\n",
    );
    let esc = crate::document::escape_html;
    for e in &entries {
        let md_link = if e.link.ends_with("report.html") {
            e.link.replace("report.html", "report.md")
        } else {
            e.link.clone()
        };
        let _ = writeln!(
            md,
            "| [{}]({md_link}) | {} | {} | {} | {} | {} |",
            e.folder, e.title, e.scene, e.device, e.date, e.commit
        );
        let _ = writeln!(
            html,
            "<tr><td><a href=\"{}\">{}</a></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            esc(&e.link),
            esc(&e.folder),
            // The title as the Markdown table shows it (`code` as code, not backticks).
            inline_markdown_html(&e.title),
            esc(&e.scene),
            esc(&e.device),
            esc(&e.date),
            esc(&e.commit)
        );
    }
    html.push_str("</table></div>\n</body></html>\n");
    files.push((reports.join("README.md"), md));
    files.push((reports.join("index.html"), html));
    Ok(Overview {
        files,
        stale,
        listed: entries.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pareto_front_keeps_only_points_nothing_beats() {
        let pts = [(1.0, 10.0), (2.0, 5.0), (3.0, 7.0), (4.0, 1.0), (5.0, 1.0)];
        let (front, steps) = pareto_steps(&pts);
        assert_eq!(front, vec![(1.0, 10.0), (2.0, 5.0), (4.0, 1.0)]);
        // A step line: each later point reached first horizontally.
        assert_eq!(
            steps,
            vec![(1.0, 10.0), (2.0, 10.0), (2.0, 5.0), (4.0, 5.0), (4.0, 1.0)]
        );
    }

    #[test]
    fn the_lead_renders_links_bold_and_code_and_leaves_intervals_as_text() {
        let html = lead_html(
            "## Found\n\n1. **A** `x` is 1.2× [1.1–1.3×] ([figure](a.svg)).\n\n![finding 1](a.svg)\n",
        );
        assert!(
            html.contains("<p><img src=\"a.svg\" alt=\"finding 1\"></p>"),
            "{html}"
        );
        assert_eq!(
            html,
            "<h2>Found</h2>\n<p>1. <strong>A</strong> <code>x</code> is 1.2× [1.1–1.3×] (<a href=\"a.svg\">figure</a>).</p>\n<p><img src=\"a.svg\" alt=\"finding 1\"></p>\n"
        );
    }

    #[test]
    fn a_device_is_named_by_its_model_in_file_names() {
        let slug = |adapter: &str| device_slug(adapter);
        assert_eq!(slug("llvmpipe (LLVM 15.0.6, 256 bits)"), "lavapipe");
        assert_eq!(slug("NVIDIA H100 80GB HBM3"), "h100");
        // Two GPUs of one vendor are two devices, not one "nvidia".
        assert_eq!(slug("NVIDIA H200"), "h200");
        assert_eq!(slug("Apple M3"), "m3");
        assert_eq!(slug("SwiftShader Device (Subzero)"), "swiftshader");
        assert_eq!(slug("Some GPU"), "some");
    }
}
