//! Writing the sweep's files. Markdown and HTML are rendered from one document model, so
//! they always say the same thing.

use crate::document::{
    Block, FLOOR_FACTOR, MIB, Section, at_or_under_floor, distinct, escape_html, f, label,
    markdown, ms, ms_cell, ms_heading, remove_stale, sci, setting,
};
use crate::plot::{Chart, Series};
use crate::{Record, SweepInfo};
use base64::Engine;
use mirrorbox_files::{FileError, write_atomically};
use std::fmt::Write as _;
use std::path::Path;

/// Largest `results.jsonl` read: a record is a few KB, so this is some hundred thousand
/// points; the bound keeps a wrong file from being read whole.
pub const MAX_RESULTS_BYTES: u64 = 1 << 30;

/// Largest image a report embeds in its HTML (a 4K PNG is some tens of MB).
const MAX_EMBEDDED_BYTES: u64 = 256 << 20;

/// Reads `results.jsonl` (absent: no records). It must be a regular file of at most
/// [`MAX_RESULTS_BYTES`], every line a record; a line that does not parse is refused naming
/// the file, its line and why — except a last line without its newline, which an interrupted
/// append leaves (a sweep appends each record with its newline in one write, and rewrites
/// such a file with its complete records before it appends again): that one is skipped. A key
/// written more than once (two sweeps, an older tool) counts once: its last record, at the
/// place of its first — whatever the file holds, a report shows each point once.
pub fn read_records(path: &Path) -> Result<Vec<Record>, FileError> {
    if std::fs::symlink_metadata(path).is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound) {
        return Ok(Vec::new());
    }
    let text = mirrorbox_files::read_bounded_text(path, MAX_RESULTS_BYTES, "a results file")?;
    let mut records: Vec<Record> = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut lines = text.lines().enumerate().peekable();
    while let Some((n, line)) = lines.next() {
        let mut record = match serde_json::from_str::<Record>(line) {
            Ok(record) => record,
            Err(_) if lines.peek().is_none() && !text.ends_with('\n') => continue,
            Err(e) => {
                return Err(FileError {
                    path: path.to_path_buf(),
                    message: format!("line {}: not a sweep record ({e})", n + 1),
                    refused: true,
                });
            }
        };
        if let Some(problem) = record.out_of_range() {
            return Err(FileError {
                path: path.to_path_buf(),
                message: format!("line {}: {problem}", n + 1),
                refused: true,
            });
        }
        if let Some((field, image)) = record.image_outside_folder() {
            return Err(FileError {
                path: path.to_path_buf(),
                message: format!(
                    "line {}: {field} {image:?} is not a path inside the sweep folder \
                     (relative, without `..`)",
                    n + 1
                ),
                refused: true,
            });
        }
        record.migrate();
        match index.get(&record.key) {
            Some(&i) => records[i] = record,
            None => {
                index.insert(record.key.clone(), records.len());
                records.push(record);
            }
        }
    }
    Ok(records)
}

/// A merged sweep whose shards ran on several devices: each device's points with their
/// times, one table per device (the time plots, which would mix them, are left out).
fn timings_by_device(devices: &[String], records: &[Record]) -> Vec<Block> {
    let mut out = vec![
        Block::Heading(2, "Timings by device".into()),
        Block::Paragraph(
            "The shards ran on different devices, so the times below are grouped by device \
             and the error-against-time plots are left out; error figures compare across \
             devices, times only within one table. Sections above or below that set times \
             side by side (Table 1, cost against depth) mix devices: read their times here."
                .into(),
        ),
    ];
    for d in devices {
        let on = || {
            records
                .iter()
                .filter(|r| r.device.as_deref() == Some(d.as_str()))
        };
        out.push(Block::Heading(3, format!("On {d}")));
        out.push(Block::Table(
            vec![
                "point".into(),
                "α".into(),
                ms_heading("ms/frame median", on()),
                "FLIP mean (image)".into(),
            ],
            on().map(|r| {
                vec![
                    if r.kind == "floor" {
                        "floor (no mirrors)".into()
                    } else {
                        label(r)
                    },
                    r.alpha_text(),
                    ms_cell(r, 2),
                    sci(r.metrics.flip_mean),
                ]
            })
            .collect(),
        ));
    }
    out
}

/// A merged sweep (`mirrorbox merge`): which shard ran where, and how to read its timings.
fn shards_section(info: &SweepInfo) -> Vec<Block> {
    let mut devices: Vec<String> = Vec::new();
    for s in &info.shards {
        let d = format!("{} on {}", s.device, s.cpu);
        if !devices.contains(&d) {
            devices.push(d);
        }
    }
    let timing = if devices.len() > 1 {
        format!(
            "The shards ran on {} devices: error figures merge freely, but timings compare only \
             within one device — read each point's time with its shard's device below.",
            devices.len()
        )
    } else {
        "Every shard ran on the same device; still, each shard interleaved the timing of its own \
         points only, so no paired ratio is computed across shards."
            .into()
    };
    vec![
        Block::Heading(2, "Shards".into()),
        Block::Paragraph(format!(
            "Merged from {} shards (`sweep --shard I/N`, then `mirrorbox merge`). {timing}",
            info.shards.len()
        )),
        Block::Table(
            vec![
                "shard".into(),
                "points".into(),
                "device".into(),
                "CPU".into(),
                "date".into(),
                "folder".into(),
            ],
            info.shards
                .iter()
                .map(|s| {
                    vec![
                        s.shard.clone(),
                        s.points.to_string(),
                        s.device.clone(),
                        s.cpu.clone(),
                        s.date.clone(),
                        format!("`{}`", s.folder),
                    ]
                })
                .collect(),
        ),
    ]
}

/// Writes `results.csv`, `report.md`, `report.html` and the `plot_*.svg` files into `dir`.
/// Each file is written atomically: a failure (a full disk) leaves the previous file or
/// none, and names the file.
pub fn write_report(
    dir: &Path,
    info: &SweepInfo,
    records: &[Record],
    sections: &[Section],
) -> Result<(), FileError> {
    let blocks = without_empty_chart_sections(document(info, records, sections));
    // A folder in a report file's place (a chart's included) is refused before any file is
    // written (results.csv and report.md had been rewritten before report.html failed).
    let mut outputs: Vec<(&str, std::path::PathBuf)> = ["results.csv", "report.md", "report.html"]
        .iter()
        .map(|f| ("report", dir.join(f)))
        .collect();
    outputs.extend(blocks.iter().filter_map(|b| match b {
        Block::Chart(file, _) => Some(("report", dir.join(file))),
        _ => None,
    }));
    mirrorbox_files::check_outputs(&outputs)?;
    write_csv(&dir.join("results.csv"), records)?;
    // Each truth | raster | FLIP row is followed by its 4× inset where its images are there.
    // A row none of whose images was kept (a lent GPU's 1920×1080 images stay behind: too
    // large to bring back) says so instead of linking files that are not there.
    let mut with_insets = Vec::with_capacity(blocks.len());
    for b in blocks {
        let b = match b {
            Block::Images(images)
                if !images.is_empty()
                    && images.iter().all(|(_, file)| !dir.join(file).is_file()) =>
            {
                Block::Paragraph(format!(
                    "(Images not kept with these records: {}.)",
                    images
                        .iter()
                        .map(|(_, file)| format!("`{file}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            }
            b => b,
        };
        let inset = match &b {
            Block::Images(images) if crate::document::is_flip_row(images) => {
                crate::image_rows::inset(dir, &images[0].1, &images[1].1)
            }
            _ => None,
        };
        with_insets.push(b);
        with_insets.extend(inset);
    }
    let mut blocks = with_insets;
    let mut footer = info.footer();
    if info.is_score()
        && let Some(ours) = ours_devices(records)
    {
        footer.push_str(&format!(" · our points on {ours}"));
    }
    for b in &mut blocks {
        if let Block::Chart(_, chart) = b {
            chart.footer = footer.clone();
        }
    }
    let mut html = String::from(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>mirrorbox report</title><style>\
         body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em}\
         .scroll{overflow-x:auto;max-width:100%}\
         table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}\
         td{white-space:nowrap}th{background:#f3f3f3}\
         table.images td,table.images th{border:0;padding:2px 4px;text-align:left;vertical-align:top;white-space:normal;font-weight:normal;font-size:12px;background:none;max-width:340px}\
         table.images img{max-width:340px;display:block}table.inset img{max-width:1040px}table.inset th{max-width:none}\
         .bar{max-width:340px;margin-top:2px}.ticks{display:flex;justify-content:space-between;font-size:11px}\
         .chart svg{max-width:100%;height:auto}\
         p,li{overflow-wrap:break-word}</style></head><body>\n",
    );
    for b in &blocks {
        match b {
            Block::Heading(level, t) => {
                let _ = writeln!(html, "<h{level}>{}</h{level}>", escape_html(t));
            }
            Block::Paragraph(t) => {
                let _ = writeln!(html, "<p>{}</p>", inline(t));
            }
            Block::Bullets(items) => {
                let _ = writeln!(
                    html,
                    "<ul>{}</ul>",
                    items
                        .iter()
                        .map(|i| format!("<li>{}</li>", inline(i)))
                        .collect::<String>()
                );
            }
            Block::Table(head, rows) => {
                let _ = write!(
                    html,
                    "<div class=\"scroll\"><table><tr>{}</tr>",
                    head.iter()
                        .map(|h| format!("<th>{}</th>", escape_html(h)))
                        .collect::<String>()
                );
                for r in rows {
                    let _ = write!(
                        html,
                        "<tr>{}</tr>",
                        r.iter()
                            .map(|c| format!("<td>{}</td>", inline(c)))
                            .collect::<String>()
                    );
                }
                html.push_str("</table></div>\n");
            }
            Block::Images(images) => {
                // A row of images with its captions as column headers; a FLIP map gets the
                // colour bar of its ramp; an inset spans the page.
                let inset = images.len() == 1 && images[0].0.contains("inset");
                html.push_str(if inset {
                    "<div class=\"scroll\"><table class=\"images inset\"><tr>"
                } else {
                    "<div class=\"scroll\"><table class=\"images\"><tr>"
                });
                for (cap, _) in images {
                    let _ = write!(html, "<th>{}</th>", inline(cap));
                }
                html.push_str("</tr><tr>");
                for (cap, p) in images {
                    // Bounded and regular (a FIFO named by a record had blocked the report), and
                    // inside the folder once links are followed (`images/x.png` linking to
                    // `/etc/passwd` is not embedded).
                    let file = dir.join(p);
                    let inside = match (std::fs::canonicalize(&file), std::fs::canonicalize(dir)) {
                        (Ok(file), Ok(folder)) => file.starts_with(folder),
                        _ => false,
                    };
                    let png = inside
                        .then(|| {
                            mirrorbox_files::read_bounded(&file, MAX_EMBEDDED_BYTES, "an image")
                                .ok()
                        })
                        .flatten();
                    let src = match png {
                        Some(bytes) => format!(
                            "data:image/png;base64,{}",
                            base64::engine::general_purpose::STANDARD.encode(bytes)
                        ),
                        None => p.clone(),
                    };
                    let bar = if cap.starts_with("FLIP") || cap.contains(": FLIP") {
                        crate::image_rows::colour_bar_html()
                    } else {
                        String::new()
                    };
                    let _ = write!(
                        html,
                        "<td><img src=\"{src}\" alt=\"{}\">{bar}</td>",
                        escape_html(cap)
                    );
                }
                html.push_str("</tr></table></div>\n");
            }
            Block::Chart(file, chart) => {
                let path = dir.join(file);
                if chart.is_drawable() {
                    let svg = chart.to_svg();
                    write_atomically(&path, svg.as_bytes())?;
                    let _ = writeln!(html, "<div class=\"chart\">{svg}</div>");
                }
            }
        }
    }
    html.push_str("</body></html>\n");
    // Charts an earlier report of this folder drew and this one does not (a section that no
    // longer applies, a chart with one x): a stale figure must not pass for a current one.
    let drawn: Vec<&str> = blocks
        .iter()
        .filter_map(|b| match b {
            Block::Chart(file, chart) if chart.is_drawable() => Some(file.as_str()),
            _ => None,
        })
        .collect();
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with("plot_")
                && name.ends_with(".svg")
                && !drawn.contains(&name.as_str())
            {
                remove_stale(&e.path())?;
            }
        }
    }
    write_atomically(&dir.join("report.md"), markdown(&blocks).as_bytes())?;
    write_atomically(&dir.join("report.html"), html.as_bytes())
}

/// `blocks` without the sections (a heading up to the next of its level or above) that hold
/// only charts and their captions and draw none of the charts: a score's one variant, or a
/// sweep with nothing swept, had left a heading and a caption over no figure.
fn without_empty_chart_sections(blocks: Vec<Block>) -> Vec<Block> {
    let mut keep = vec![true; blocks.len()];
    for (i, b) in blocks.iter().enumerate() {
        let Block::Heading(level, _) = b else {
            continue;
        };
        let end = blocks[i + 1..]
            .iter()
            .position(|b| matches!(b, Block::Heading(l, _) if l <= level))
            .map_or(blocks.len(), |k| i + 1 + k);
        let body = &blocks[i + 1..end];
        let charts_only = body
            .iter()
            .all(|b| matches!(b, Block::Chart(..) | Block::Paragraph(_)));
        let any_chart = body.iter().any(|b| matches!(b, Block::Chart(..)));
        let none_drawn = !body
            .iter()
            .any(|b| matches!(b, Block::Chart(_, c) if c.is_drawable()));
        if charts_only && any_chart && none_drawn {
            keep[i..end].iter_mut().for_each(|k| *k = false);
        }
    }
    blocks
        .into_iter()
        .zip(keep)
        .filter_map(|(b, k)| k.then_some(b))
        .collect()
}

/// Escaped text with Markdown's inline code (`x`) as `<code>`: the report's sentences are
/// written once, for both files.
fn inline(s: &str) -> String {
    let mut out = String::new();
    for (i, part) in s.split('`').enumerate() {
        if i % 2 == 1 && s.matches('`').count().is_multiple_of(2) {
            let _ = write!(out, "<code>{}</code>", escape_html(part));
        } else {
            if i % 2 == 1 {
                out.push('`');
            }
            out.push_str(&escape_html(part));
        }
    }
    out
}

/// A value of `r`'s error split ([`crate::ErrorSplit`]), empty where it has none.
fn split(r: &Record, value: impl Fn(&crate::ErrorSplit) -> Option<f64>) -> String {
    r.split
        .as_ref()
        .and_then(value)
        .map_or(String::new(), |v| v.to_string())
}

/// A text cell of results.csv (RFC 4180): quoted, with its quotes doubled, where it holds a
/// comma, a quote or a line break — a client's timing text ("… gl.finish(), interleaved")
/// had split into cells of its own.
fn csv_cell(text: &str) -> std::borrow::Cow<'_, str> {
    if text.contains([',', '"', '\n', '\r']) {
        csv_quoted(text).into()
    } else {
        text.into()
    }
}

/// A text cell always quoted (the adapter, the scene, the method's options: the columns
/// results.csv has always quoted), its quotes doubled.
fn csv_quoted(text: &str) -> String {
    format!("\"{}\"", text.replace('"', "\"\""))
}

/// results.csv's fixed columns before the axes' and values' and after them.
const CSV_HEAD: &str = "kind,method,n,depth,alpha,width,height,ssaa,ms_median,ms_ci_low,ms_ci_high,ms_min,timing_order,timing_source,frames,passes,draws,texture_renders,reflections,\
     rmse,relmse,smape,max_abs,psnr,ssim,flip_mean,flip_p95,flip_p99,adapter,backend,scene,scene_hash,color_format,peak_memory_bytes,plan_ms,encode_ms,gpu_buffer_bytes,gpu_texture_bytes,method_options";
const CSV_TAIL: &str = "marker_disparity_px,truth_marker_disparity_px,\
     mirror_flip_mean,truncation_flip_mean,approximation_flip_mean,truncation_mirror_flip_mean,approximation_mirror_flip_mean,truncation_relmse,approximation_relmse,\
     mirror_flip_p95,mirror_relmse,mirror_pixel_share";

/// `results.csv`: one row per point. The fixed columns every point has, then one column per
/// scene axis ([`Record::axes`]: `planes`, `yaw_deg`, …) and per extra value
/// ([`Record::values`]: `copies_drawn`, `reflection_offscreen_share`, …) that some point of
/// the sweep has, named by its key in the records and sorted by name, then the stereo and
/// error-split columns. Before, those were a fixed list under names of their own
/// (`symmetry_planes`, `bump_amplitude_deg`), empty in every other sweep, and a sweep of the
/// camera's yaw had no column for it.
fn write_csv(path: &Path, records: &[Record]) -> Result<(), FileError> {
    let keys = |map: fn(&Record) -> &std::collections::BTreeMap<String, f64>| {
        let mut keys: Vec<&str> = records
            .iter()
            .flat_map(|r| map(r).keys().map(String::as_str))
            .collect();
        keys.sort_unstable();
        keys.dedup();
        keys
    };
    let axes = keys(|r| &r.axes);
    let values = keys(|r| &r.values);
    // A key named as a fixed column, or a value named as an axis, would give two columns one
    // name: its column says which map it is from (no record has such a key today).
    let fixed: Vec<&str> = CSV_HEAD.split(',').chain(CSV_TAIL.split(',')).collect();
    let column = |key: &str, taken: bool, map: &str| {
        if taken || fixed.contains(&key) {
            format!("{map}.{key}")
        } else {
            key.to_string()
        }
    };
    let mut s = String::from(CSV_HEAD);
    for key in &axes {
        let _ = write!(s, ",{}", csv_cell(&column(key, false, "axes")));
    }
    for key in &values {
        let _ = write!(
            s,
            ",{}",
            csv_cell(&column(key, axes.contains(key), "values"))
        );
    }
    let _ = writeln!(s, ",{CSV_TAIL}");
    let cell = |v: Option<&f64>| v.map_or(String::new(), |x| x.to_string());
    for r in records {
        let m = &r.metrics;
        let opt = |v: Option<u32>| v.map_or(String::new(), |x| x.to_string());
        let _ = write!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            csv_cell(&r.kind),
            csv_cell(&r.method),
            opt(r.n),
            opt(r.depth),
            r.alpha,
            r.width,
            r.height,
            r.ssaa,
            r.ms_median,
            r.ms_interval.map_or(String::new(), |i| i[0].to_string()),
            r.ms_interval.map_or(String::new(), |i| i[1].to_string()),
            r.ms_min,
            csv_cell(&r.timing_order),
            csv_cell(&r.timing_source),
            r.frames,
            r.passes,
            r.draws,
            r.texture_renders,
            r.reflections,
            m.rmse,
            m.relmse,
            m.smape,
            m.max_abs,
            m.psnr.map_or("inf".into(), |p| p.to_string()),
            m.ssim,
            m.flip_mean,
            m.flip_p95,
            m.flip_p99,
            csv_quoted(&r.adapter),
            csv_cell(&r.backend),
            csv_quoted(&r.scene),
            csv_cell(&r.scene_hash),
            csv_cell(&r.color_format),
            r.peak_memory_bytes.map_or(String::new(), |b| b.to_string()),
            r.plan_ms.map_or(String::new(), |ms| ms.to_string()),
            r.encode_ms.map_or(String::new(), |ms| ms.to_string()),
            r.gpu_buffer_bytes.map_or(String::new(), |b| b.to_string()),
            r.gpu_texture_bytes.map_or(String::new(), |b| b.to_string()),
            csv_quoted(&r.method_options),
        );
        let mirror = |f: fn(&crate::MetricValues) -> f64| {
            r.mirror_metrics
                .as_ref()
                .map_or(String::new(), |m| f(m).to_string())
        };
        for key in &axes {
            let _ = write!(s, ",{}", cell(r.axes.get(*key)));
        }
        for key in &values {
            let _ = write!(s, ",{}", cell(r.values.get(*key)));
        }
        let _ = writeln!(
            s,
            ",{},{},{},{},{},{},{},{},{},{},{},{}",
            r.stereo
                .as_ref()
                .and_then(|s| s.disparity(false))
                .map_or(String::new(), |d| d.to_string()),
            r.stereo
                .as_ref()
                .and_then(|s| s.disparity(true))
                .map_or(String::new(), |d| d.to_string()),
            mirror(|m| m.flip_mean),
            split(r, |s| Some(s.truncation.flip_mean)),
            split(r, |s| Some(s.approximation.flip_mean)),
            split(r, |s| s.truncation_mirror.as_ref().map(|m| m.flip_mean)),
            split(r, |s| s.approximation_mirror.as_ref().map(|m| m.flip_mean)),
            split(r, |s| Some(s.truncation.relmse)),
            split(r, |s| Some(s.approximation.relmse)),
            // After the split's columns, so that the earlier columns keep their places.
            mirror(|m| m.flip_p95),
            mirror(|m| m.relmse),
            r.mirror_pixel_share
                .map_or(String::new(), |v| v.to_string()),
        );
    }
    write_atomically(path, s.as_bytes())
}

/// A count of `r`'s frame, "–" for an outside renderer's (its passes and draws are not known).
fn unknown_outside(r: &Record, count: usize) -> String {
    if r.is_external() {
        "–".into()
    } else {
        count.to_string()
    }
}

/// The devices of a score's own points (a `--with` sweep's), if it has any.
fn ours_devices(records: &[Record]) -> Option<String> {
    let ours = distinct(
        records
            .iter()
            .filter(|r| !r.is_external())
            .map(|r| format!("{} ({})", r.adapter, r.backend)),
    );
    (!ours.is_empty()).then(|| ours.join(", "))
}

/// Whose floor `fl` is: a scored client's and view's (its key, `client/floor|view|…`), or
/// ours on its adapter.
fn floor_name(fl: &Record) -> String {
    match (fl.scored_client(), fl.scored_view()) {
        (Some(client), Some(view)) => format!("{client}, view {view}"),
        (Some(client), None) => client.to_string(),
        (None, _) => format!("mirrorbox on {}", fl.adapter),
    }
}

/// Several floors (a score's clients and views, and ours): each in a row, each error read
/// against its own renderer's, and which one the figures shade.
fn floors_table(floors: &[&Record], shaded: Option<&Record>) -> Vec<Block> {
    let shading = match shaded {
        Some(fl) => format!("The figures shade the floor of {}.", floor_name(fl)),
        None => "No floor of mirrorbox's own is in this report (`score --with SWEEP` sets one \
                 beside): the figures shade none, and no point is called exact by its own \
                 renderer's floor, which says how closely that renderer follows the shading \
                 contract, not how exact its mirrors are."
            .into(),
    };
    vec![
        Block::Paragraph(format!(
            "Raster vs trace on the scene without its mirrors (nothing to truncate, same \
             sub-pixel grid), for each renderer and view: read each error against its own \
             renderer's floor. {shading}"
        )),
        Block::Table(
            ["floor of", "RMSE", "relMSE", "FLIP mean", "SSIM"]
                .map(String::from)
                .to_vec(),
            floors
                .iter()
                .map(|fl| {
                    vec![
                        floor_name(fl),
                        sci(fl.metrics.rmse),
                        sci(fl.metrics.relmse),
                        sci(fl.metrics.flip_mean),
                        f(fl.metrics.ssim, 6),
                    ]
                })
                .collect(),
        ),
    ]
}

/// What the comparison cannot resolve: raster vs trace without mirrors.
pub fn floor_paragraph(fl: &Record) -> Block {
    Block::Paragraph(format!(
        "Raster vs trace on the scene without its mirrors (nothing to truncate, same sub-pixel grid): \
         RMSE {}, relMSE {}, FLIP mean {}, SSIM {}. Errors are to be read against this floor.",
        sci(fl.metrics.rmse),
        sci(fl.metrics.relmse),
        sci(fl.metrics.flip_mean),
        f(fl.metrics.ssim, 6)
    ))
}

/// The colour formats the records were rendered into, e.g. `rgba32float` (several where a
/// sweep was resumed on another device).
fn color_formats(records: &[Record]) -> String {
    let mut formats: Vec<&str> = records.iter().map(|r| r.color_format.as_str()).collect();
    formats.sort_unstable();
    formats.dedup();
    if formats.is_empty() {
        "none recorded".into()
    } else {
        formats.join(", ")
    }
}

/// The report of a sweep (or a score) as blocks, in reading order: the header, how its runs
/// and devices combine, the floor, the experiments' own sections, the error charts, the
/// error split, every point's row and the image rows.
fn document(info: &SweepInfo, records: &[Record], sections: &[Section]) -> Vec<Block> {
    let mut b = header(info, records);
    let points: Vec<&Record> = records.iter().filter(|r| r.kind == "point").collect();
    // A score may hold several floors (each client's, each view's, and ours): the figures'
    // band and the at-floor test take ours, and only ours. A client's floor says how closely
    // it follows the shading contract; taken as the comparison's, a client that drew no
    // mirrors, or everything 30 % too bright, had its points called exact.
    let floors: Vec<&Record> = records.iter().filter(|r| r.kind == "floor").collect();
    let floor = floors.iter().find(|r| !r.is_external()).copied();
    let latest_run = records.iter().filter_map(|r| r.run.as_deref()).max();
    let reused = |r: &Record| latest_run.is_some() && r.run.as_deref() != latest_run;
    if !info.shards.is_empty() {
        b.extend(shards_section(info));
    }
    // A merged sweep timed on several devices: times are read per device, never across.
    let devices = distinct(records.iter().filter_map(|r| r.device.clone()));
    let mixed_devices = devices.len() > 1;
    if mixed_devices {
        b.extend(timings_by_device(&devices, records));
    }
    // A merged sweep's shards are separate runs by design (above).
    let earlier: Vec<&Record> = records
        .iter()
        .filter(|r| info.shards.is_empty() && reused(r))
        .collect();
    if !earlier.is_empty() {
        b.push(reused_paragraph(&earlier, records.len(), latest_run));
    }
    if !floors.is_empty() {
        b.push(Block::Heading(2, "Floor of the comparison".into()));
        match floor {
            Some(fl) if floors.len() == 1 => b.push(floor_paragraph(fl)),
            _ => b.extend(floors_table(&floors, floor)),
        }
    }
    // The experiments' own sections (the registry's), each empty for another's records.
    for section in sections {
        b.extend(section(info, records));
    }
    let variants = Variants::of(&points);
    // A sweep with a scene axis (lighting, tilt, IPD) draws its own charts in its section:
    // joining its points here would join unrelated settings.
    let has_scene_axis = points
        .iter()
        .any(|r| r.lights_depth().is_some() || r.tilt_deg().is_some() || r.stereo.is_some());
    // Errors at the floor are not resolved: a chart of them would rank noise.
    let all_at_floor = !points.is_empty()
        && floor.is_some_and(|fl| points.iter().all(|r| at_or_under_floor(r, fl)));
    if all_at_floor && let Some(fl) = floor {
        b.push(Block::Heading(2, "Error against time".into()));
        b.push(Block::Paragraph(format!(
            "Every point's error is at the comparison's floor (FLIP mean ≤ {FLOOR_FACTOR}× the \
             floor's {}): the methods are exact on this scene, and their errors are not \
             compared or charted. Their cost is.",
            sci(fl.metrics.flip_mean)
        )));
    }
    if !points.is_empty() && !has_scene_axis && !all_at_floor {
        if !mixed_devices {
            b.extend(error_against_time(&variants, floor, floors.len()));
        }
        b.extend(error_against_setting(&variants, floor));
    }
    b.extend(crate::split::split_section(records, &info.exact_methods));
    if !points.is_empty() {
        b.extend(all_points(&points, &reused));
        b.extend(image_rows(&variants));
    }
    b
}

/// The report's title and what it ran on; the adapters that left methods out.
fn header(info: &SweepInfo, records: &[Record]) -> Vec<Block> {
    // A score's devices are its clients' (the scoring machine only compared images), and
    // ours where a sweep is set beside them.
    let device = if info.is_score() {
        format!(
            "Devices: the clients' — {}{}; scored on {}{}; colour targets: {}",
            info.adapter,
            if info.driver.trim().is_empty() {
                String::new()
            } else {
                format!(" (driver {})", info.driver.trim())
            },
            info.cpu,
            ours_devices(records).map_or(String::new(), |o| format!("; our points on {o}")),
            color_formats(records)
        )
    } else {
        format!(
            "Device: {} — {}; colour targets: {}",
            info.cpu,
            info.adapter_description(),
            color_formats(records)
        )
    };
    let mut b = vec![
        Block::Heading(
            1,
            format!(
                "mirrorbox {}: {}",
                if info.is_score() { "score" } else { "sweep" },
                info.scene
            ),
        ),
        Block::Bullets(vec![
            format!("Resolution: {}", info.resolution),
            format!("Ground truth: {}", info.truth),
            device,
            format!("Versions: {}", info.versions),
            format!("Date: {}", info.date),
            format!("Command: `{}`", info.command),
        ]),
    ];
    if !info.unsupported.is_empty() {
        b.push(Block::Paragraph(format!(
            "Not measured on this adapter (left out of the sweep, not counted as errors): {}.",
            info.unsupported.join("; ")
        )));
    }
    b
}

/// The note on points reused from earlier runs (`earlier`, of `total`), marked † below.
fn reused_paragraph(earlier: &[&Record], total: usize, latest_run: Option<&str>) -> Block {
    let mut runs: Vec<&str> = earlier
        .iter()
        .map(|r| r.run.as_deref().unwrap_or("an unrecorded run"))
        .collect();
    runs.sort_unstable();
    runs.dedup();
    Block::Paragraph(format!(
        "† {} of {} points were reused from earlier runs of this sweep ({}) rather than measured \
         in the latest ({}): their frames were interleaved with that run's points, on the machine \
         of that day, so compare their times with this run's only with care; no paired ratio is \
         computed across runs. Run with `--fresh` to measure every point together.",
        earlier.len(),
        total,
        runs.join(", "),
        latest_run.unwrap_or_default()
    ))
}

/// A sweep's points by method variant and α, each group with its fixed style: what every
/// chart and the image rows of [`document`] draw from.
struct Variants<'a> {
    points: &'a [&'a Record],
    /// (variant, α) in the order of the points.
    groups: Vec<(String, f32)>,
    styles: Vec<crate::plot::Style>,
    /// The distinct α (bits).
    alphas: Vec<u32>,
}

impl<'a> Variants<'a> {
    fn of(points: &'a [&'a Record]) -> Self {
        let mut groups: Vec<(String, f32)> = Vec::new();
        for r in points {
            let group = (crate::document::variant(r), r.alpha);
            if !groups.contains(&group) {
                groups.push(group);
            }
        }
        // Each method its fixed style, each variant (its options, and its α where the chart
        // has several) the style its key gives it in every report; an outside renderer's
        // variant its equivalent's colour with hollow markers, so that it reads beside what it
        // is meant to match.
        let alphas = distinct(points.iter().map(|r| r.alpha.to_bits()));
        let largest_alpha = points.iter().map(|r| r.alpha).fold(f32::MIN, f32::max);
        let keys: Vec<(String, String, bool)> = groups
            .iter()
            .map(|(m, a)| {
                let r = points
                    .iter()
                    .find(|r| &crate::document::variant(r) == m && r.alpha == *a);
                // The largest α (the plain scene, α = 1 where it is swept) keeps the method's
                // style, whatever the records' order; each other α is a variant.
                let alpha = if *a == largest_alpha {
                    String::new()
                } else {
                    format!("α={a}")
                };
                match r {
                    Some(r) if r.is_external() => (
                        r.option("equivalent").unwrap_or(&r.method).to_string(),
                        format!("{} {alpha}", r.method).trim().to_string(),
                        true,
                    ),
                    _ => {
                        let (method, options) = m.split_once(' ').unwrap_or((m, ""));
                        (
                            method.to_string(),
                            format!("{options} {alpha}").trim().to_string(),
                            false,
                        )
                    }
                }
            })
            .collect();
        let styles = crate::plot::keyed_styles(
            &keys
                .iter()
                .map(|(method, variant, outside)| crate::plot::StyleKey {
                    method,
                    variant,
                    outside: *outside,
                })
                .collect::<Vec<_>>(),
        );
        Variants {
            points,
            groups,
            styles,
            alphas,
        }
    }

    /// The points of group (`m`, `a`), by their swept setting.
    fn of_group(&self, m: &str, a: f32) -> Vec<&'a Record> {
        let mut pts: Vec<&Record> = self
            .points
            .iter()
            .copied()
            .filter(|r| crate::document::variant(r) == m && r.alpha == a)
            .collect();
        pts.sort_by(|p, q| setting(p).total_cmp(&setting(q)));
        pts
    }

    /// ", α = …" for chart titles where every point has one α.
    fn alpha_note(&self) -> String {
        if self.alphas.len() == 1 {
            format!(
                ", α = {}",
                self.points.first().map_or("–".into(), |r| r.alpha_text())
            )
        } else {
            String::new()
        }
    }

    /// One series per method variant and α, joined along its one swept setting (n or depth):
    /// `keep`, which of a group's points the chart shows; `ms_on_x`, x is the median time,
    /// drawn with its bars ([`crate::ms_bars_for`]: the 95 % intervals, or the frames' range
    /// where a point has no interval); `x_log`, whether the x axis is
    /// logarithmic (a linear one shows x = 0: n = 0 auxiliary mirrors). The y axis is.
    fn series(
        &self,
        keep: &dyn Fn(&Record) -> bool,
        x: &dyn Fn(&Record) -> f64,
        y: &dyn Fn(&Record) -> Option<f64>,
        ms_on_x: bool,
        x_log: bool,
    ) -> Vec<Series> {
        // One legend name scheme and one kind of time bars for the whole chart.
        let variants: Vec<&str> = self.groups.iter().map(|(o, _)| o.as_str()).collect();
        let bars = crate::ms_bars_for(self.points.iter().copied());
        self.groups
            .iter()
            .zip(&self.styles)
            .filter_map(|((m, a), style)| {
                let pts: Vec<&Record> = self
                    .of_group(m, *a)
                    .into_iter()
                    .filter(|r| keep(r) && y(r).is_some())
                    .collect();
                if pts.is_empty() {
                    return None;
                }
                let m = crate::document::legend_name(m, &variants);
                let name = if self.alphas.len() > 1 {
                    format!("{m}, α={a}")
                } else {
                    m
                };
                // A value the log axes cannot show (an error of exactly 0) is named in the
                // legend, not drawn.
                let (pts, zero): (Vec<&Record>, Vec<&Record>) = pts.iter().partition(|r| {
                    let (px, py) = (x(r), y(r).unwrap_or(f64::NAN));
                    px.is_finite() && (px > 0.0 || !x_log) && py.is_finite() && py > 0.0
                });
                if pts.is_empty() {
                    return None;
                }
                let name = match zero.len() {
                    0 => name,
                    n => format!("{name} ({n} at 0, not drawn)"),
                };
                let mut s = Series::new(
                    name,
                    *style,
                    pts.iter()
                        .map(|r| (x(r), y(r).unwrap_or(f64::NAN)))
                        .collect(),
                );
                // Joined along its swept setting only where x grows with it and no scene axis
                // (a camera turn, a tilt) separates the points: else the line would zigzag
                // across another variable.
                s.joined = s.points.windows(2).all(|w| w[1].0 > w[0].0)
                    && pts.iter().all(|r| r.axes.is_empty());
                s.labels = crate::document::point_labels(&pts);
                if ms_on_x {
                    s.bars = bars;
                    s.x_intervals = pts.iter().map(|r| r.ms_bars(s.bars)).collect();
                }
                Some(s)
            })
            .collect()
    }
}

fn flip(r: &Record) -> Option<f64> {
    Some(r.metrics.flip_mean)
}

/// "Error against time": FLIP over the image and over the mirror pixels, and relMSE, against
/// ms/frame, the floor shaded (`floors`: how many the sweep has, to say whose is shaded).
fn error_against_time(v: &Variants, floor: Option<&Record>, floors: usize) -> Vec<Block> {
    let any = |_: &Record| true;
    let ms = |r: &Record| r.ms_median;
    let alpha_note = v.alpha_note();
    let chart = |file: &str, y: &dyn Fn(&Record) -> Option<f64>, band, title, y_label| {
        Block::Chart(
            file.into(),
            Box::new(Chart {
                x_log: true,
                y_log: true,
                series: v.series(&any, &ms, y, true, true),
                floor: band,
                ..Chart::new(
                    format!("{title} vs cost{alpha_note}"),
                    "ms/frame (median, 95 % CI bars)",
                    y_label,
                )
            }),
        )
    };
    vec![
        Block::Heading(2, "Error against time".into()),
        Block::Paragraph(format!(
            "Each method's points joined along its swept setting (n or the depth cap, labelled); \
             the shaded band is {} (raster vs trace without mirrors), where the y axis reaches \
             it; a note under a chart gives it where it lies below the axis.",
            match floor {
                Some(fl) if floors > 1 => format!("the floor of {}", floor_name(fl)),
                _ => "the comparison's floor".to_string(),
            }
        )),
        chart(
            "plot_flip_vs_ms.svg",
            &flip,
            floor.map(|fl| fl.metrics.flip_mean),
            "FLIP over the image",
            "FLIP mean over the image (lower is better)",
        ),
        chart(
            "plot_mirror_flip_vs_ms.svg",
            &|r| r.mirror_metrics.as_ref().map(|m| m.flip_mean),
            None,
            "FLIP over the mirror pixels",
            "FLIP mean over the mirror pixels",
        ),
        chart(
            "plot_relmse_vs_ms.svg",
            &|r| Some(r.metrics.relmse),
            floor.map(|fl| fl.metrics.relmse),
            "relMSE over the image (linear radiance)",
            "relMSE over the image",
        ),
    ]
}

/// "Error against the swept setting": FLIP against n and against the depth cap.
fn error_against_setting(v: &Variants, floor: Option<&Record>) -> Vec<Block> {
    let alpha_note = v.alpha_note();
    vec![
        Block::Heading(2, "Error against the swept setting".into()),
        Block::Chart(
            "plot_flip_vs_n.svg".into(),
            Box::new(Chart {
                y_log: true,
                series: v.series(
                    &|r| r.n.is_some(),
                    &|r| f64::from(r.n.unwrap_or(0)),
                    &flip,
                    false,
                    false,
                ),
                floor: floor.map(|fl| fl.metrics.flip_mean),
                x_ticks_at_data: true,
                ..Chart::new(
                    format!("FLIP over the image vs auxiliary mirrors n{alpha_note}"),
                    "n (auxiliary mirrors)",
                    "FLIP mean over the image",
                )
            }),
        ),
        Block::Chart(
            "plot_flip_vs_depth.svg".into(),
            Box::new(Chart {
                x_log: true,
                y_log: true,
                series: v.series(
                    &|r| r.depth.is_some(),
                    &|r| f64::from(r.depth.unwrap_or(0)),
                    &flip,
                    false,
                    true,
                ),
                floor: floor.map(|fl| fl.metrics.flip_mean),
                x_ticks_at_data: true,
                ..Chart::new(
                    format!("FLIP over the image vs depth cap{alpha_note}"),
                    crate::document::DEPTH_CAP_AXIS,
                    "FLIP mean over the image",
                )
            }),
        ),
    ]
}

/// "All points": one row per point, its times, memory, counts and errors; `reused` marks
/// with † a point from an earlier run.
fn all_points(points: &[&Record], reused: &dyn Fn(&Record) -> bool) -> Vec<Block> {
    // A stereo sweep's points differ by their IPD (or are mono), an uneven-mirror sweep's by
    // their tilt: said in the point's cell, where label() alone reads alike.
    let stereo = points
        .iter()
        .any(|r| r.axis(crate::axis::STEREO_IPD).is_some());
    let point_name = |r: &Record| {
        let mut name = label(r);
        match r.axis(crate::axis::STEREO_IPD) {
            Some(ipd) => name.push_str(&format!(", IPD {ipd}")),
            None if stereo => name.push_str(", mono"),
            None => {}
        }
        if let Some(t) = r.tilt_deg() {
            name.push_str(&format!(", tilt {t}°"));
        }
        // A scored variant of an export of several views: its view's name, from its key.
        if r.axis(crate::axis::VIEW).is_some()
            && let Some(view) = r.scored_view()
        {
            name.push_str(&format!(", view {view}"));
        }
        name
    };
    let ms_column = ms_heading("ms/frame median", points.iter().copied());
    let header = [
        "point",
        "α",
        ms_column.as_str(),
        "min",
        "CPU plan ms",
        "CPU encode ms",
        "GPU MiB (buffers + textures)",
        "peak RSS MiB",
        "timing",
        "passes",
        "draws",
        "RMSE",
        "relMSE",
        "SMAPE",
        "PSNR dB",
        "SSIM",
        "FLIP mean (image)",
        "p95",
        "p99",
        "mirror px %",
        "FLIP mean over mirror px",
        "its p95",
    ]
    .map(String::from)
    .to_vec();
    let rows = points
        .iter()
        .map(|r| {
            let m = &r.metrics;
            vec![
                if reused(r) {
                    format!("{} †", point_name(r))
                } else {
                    point_name(r)
                },
                r.alpha_text(),
                ms_cell(r, 2),
                ms(r.ms_min, 2),
                r.plan_ms.map_or("–".into(), |ms| f(ms, 2)),
                r.encode_ms.map_or("–".into(), |ms| f(ms, 2)),
                match (r.gpu_buffer_bytes, r.gpu_texture_bytes) {
                    (Some(b), Some(t)) => f((b + t) as f64 / MIB, 1),
                    _ => "–".into(),
                },
                r.peak_memory_bytes
                    .map_or("–".into(), |b| f(b as f64 / MIB, 0)),
                format!("{}, {}", r.timing_source, r.timing_order),
                unknown_outside(r, r.passes),
                unknown_outside(r, r.draws),
                sci(m.rmse),
                sci(m.relmse),
                sci(m.smape),
                m.psnr.map_or("∞".into(), |p| f(p, 2)),
                f(m.ssim, 5),
                sci(m.flip_mean),
                f(m.flip_p95, 4),
                f(m.flip_p99, 4),
                r.mirror_pixel_share.map_or("–".into(), |s| f(100.0 * s, 1)),
                r.mirror_metrics
                    .as_ref()
                    .map_or("–".into(), |m| sci(m.flip_mean)),
                r.mirror_metrics
                    .as_ref()
                    .map_or("–".into(), |m| f(m.flip_p95, 4)),
            ]
        })
        .collect();
    // Without intervals the time cell is "median (min …)" already: a "min" column beside it
    // said the same number twice.
    let (mut header, mut rows): (Vec<String>, Vec<Vec<String>>) = (header, rows);
    if points.iter().all(|r| r.ms_interval.is_none()) {
        let at = header
            .iter()
            .position(|h| h == "min")
            .expect("the min column");
        header.remove(at);
        for row in &mut rows {
            row.remove(at);
        }
    }
    vec![
        Block::Heading(2, "All points".into()),
        Block::Table(header, rows),
        Block::Paragraph(
            "The whole image's FLIP percentiles are 0 where fewer than 5 % of its pixels differ: \
             a method's error lives in the mirrors. The last three columns are over the mirror \
             pixels only (the pixels whose primary ray in the truth first meets a mirror's \
             front; – in records measured before they were)."
                .into(),
        ),
    ]
}

/// "Truth | raster | FLIP error": each variant's first and last point by its setting.
fn image_rows(v: &Variants) -> Vec<Block> {
    let mut b = vec![Block::Heading(2, "Truth | raster | FLIP error".into())];
    for (m, a) in &v.groups {
        let pts = v.of_group(m, *a);
        let chosen: Vec<&Record> = match pts.len() {
            0 => vec![],
            1 => vec![pts[0]],
            n => vec![pts[0], pts[n - 1]],
        };
        for r in chosen {
            b.push(Block::Paragraph(format!(
                "{}, α = {}: FLIP mean {} over the image{}",
                label(r),
                r.alpha_text(),
                sci(r.metrics.flip_mean),
                r.mirror_metrics.as_ref().map_or(String::new(), |m| format!(
                    ", {} over the mirror pixels",
                    sci(m.flip_mean)
                ))
            )));
            b.push(Block::Images(vec![
                (
                    format!("truth (α={})", r.alpha_text()),
                    r.truth_image.clone(),
                ),
                (label(r), r.raster_image.clone()),
                ("FLIP error".into(), r.heatmap_image.clone()),
            ]));
        }
    }
    b
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::document::fixtures::record;
    use crate::value;

    #[test]
    fn interrupted_lines_are_skipped_when_reading() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("results.jsonl");
        let good = serde_json::to_string(&record(0, 1.0, 3, 0.1)).unwrap();
        std::fs::write(&p, format!("{good}\n{{\"key\": \"trunc")).unwrap();
        assert_eq!(read_records(&p).unwrap().len(), 1);
        assert!(
            read_records(&dir.path().join("none.jsonl"))
                .unwrap()
                .is_empty()
        );
    }

    /// Only an interrupted last line is skipped: a broken line with its newline, or one
    /// followed by others, is refused naming the file, the line and why (they were dropped
    /// silently); a device or a FIFO is refused before a byte is read (`/dev/zero` grew
    /// without bound, a FIFO blocked).
    #[test]
    fn a_broken_line_or_a_file_that_is_no_file_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("results.jsonl");
        let good = serde_json::to_string(&record(0, 1.0, 3, 0.1)).unwrap();
        for text in [
            format!("{good}\n{{\"key\": \"trunc\n"),
            format!("{good}\nnot json\n{good}\n"),
        ] {
            std::fs::write(&p, text).unwrap();
            let e = read_records(&p).unwrap_err();
            assert!(e.refused);
            let e = e.to_string();
            assert!(
                e.contains("results.jsonl: line 2: not a sweep record"),
                "{e}"
            );
        }
        let fifo = dir.path().join("fifo.jsonl");
        assert!(
            std::process::Command::new("mkfifo")
                .arg(&fifo)
                .status()
                .unwrap()
                .success()
        );
        for special in [Path::new("/dev/zero"), &fifo] {
            let e = read_records(special).unwrap_err();
            assert!(e.refused && e.message.contains("regular file"), "{e}");
        }
    }

    /// A record's image outside its sweep folder (absolute, or up through `..`) is refused
    /// naming the line and the field: `report` had embedded `/etc/passwd` in its HTML and
    /// written an inset beside whatever a `..` path named. Inside, it reads.
    #[test]
    fn an_image_outside_the_sweep_folder_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("results.jsonl");
        let good = record(0, 1.0, 3, 0.1);
        for (field, image, refused) in [
            ("raster_image", "/etc/passwd", true),
            ("truth_image", "../../etc/passwd", true),
            ("heatmap_image", "images/../../x.png", true),
            ("raster_image", "images/naive.png", false),
            ("heatmap_image", "", false),
        ] {
            let mut r = good.clone();
            r.key = "second".into();
            match field {
                "raster_image" => r.raster_image = image.into(),
                "truth_image" => r.truth_image = image.into(),
                _ => r.heatmap_image = image.into(),
            }
            let line = serde_json::to_string(&r).unwrap();
            std::fs::write(
                &p,
                format!("{}\n{line}\n", serde_json::to_string(&good).unwrap()),
            )
            .unwrap();
            match read_records(&p) {
                Err(e) if refused => {
                    assert!(
                        e.refused
                            && e.to_string()
                                .contains(&format!("line 2: {field} {image:?}")),
                        "{e}"
                    );
                }
                Ok(records) if !refused => assert_eq!(records.len(), 2),
                other => panic!("{field} {image:?}: {other:?}"),
            }
        }
    }

    /// An image inside the folder is embedded in report.html; one that only links out of it
    /// (`images/r.png` → a file elsewhere) is not: `report` had embedded a link's target.
    #[test]
    fn an_image_linking_out_of_the_folder_is_not_embedded() {
        use base64::Engine;
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("sweep");
        std::fs::create_dir_all(dir.join("images")).unwrap();
        std::fs::write(root.path().join("secret.png"), b"SECRET-OUTSIDE").unwrap();
        std::os::unix::fs::symlink(root.path().join("secret.png"), dir.join("images/r.png"))
            .unwrap();
        std::fs::write(dir.join("images/t.png"), b"INSIDE-TRUTH").unwrap();
        let mut r = record(0, 1.0, 3, 0.1);
        (r.raster_image, r.truth_image) = ("images/r.png".into(), "images/t.png".into());
        write_report(&dir, &SweepInfo::default(), &[r], &[]).unwrap();
        let html = std::fs::read_to_string(dir.join("report.html")).unwrap();
        let b64 = |b: &[u8]| base64::engine::general_purpose::STANDARD.encode(b);
        assert!(html.contains(&b64(b"INSIDE-TRUTH")));
        assert!(!html.contains(&b64(b"SECRET-OUTSIDE")));
    }

    /// A number no measurement can be (a negative time, α 5, a negative error) is refused
    /// naming the line, the field and what is allowed; the record as written reads.
    #[test]
    fn a_record_out_of_range_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("results.jsonl");
        let good = record(0, 1.0, 3, 0.1);
        type Edit = fn(&mut Record);
        let edits: [(Edit, &str); 8] = [
            (
                |r| r.ms_median = -1.0,
                "line 1: ms_median -1 (allowed: [0, 86400000] ms)",
            ),
            (|r| r.alpha = 5.0, "line 1: alpha 5 (allowed: [0, 1])"),
            (
                |r| r.metrics.flip_mean = -1.0,
                "line 1: metrics.flip_mean -1 (allowed: ≥ 0)",
            ),
            (
                |r| r.frames_ms = vec![1.0, 1e300],
                "line 1: frames_ms 1e300",
            ),
            (|r| r.metrics.ssim = 2.0, "line 1: metrics.ssim 2"),
            (|r| r.width = 0, "line 1: width 0 (allowed: [1, 16384])"),
            (
                |r| r.height = 4_000_000_000,
                "line 1: height 4000000000 (allowed: [1, 16384])",
            ),
            (|r| r.kind = "zzz".into(), "line 1: kind \"zzz\""),
        ];
        for (edit, says) in edits {
            let mut r = good.clone();
            edit(&mut r);
            std::fs::write(&p, serde_json::to_string(&r).unwrap() + "\n").unwrap();
            let e = read_records(&p).unwrap_err();
            assert!(e.refused && e.to_string().contains(says), "{e}");
        }
        std::fs::write(&p, serde_json::to_string(&good).unwrap() + "\n").unwrap();
        assert_eq!(read_records(&p).unwrap().len(), 1);
    }

    /// A record older than the maps (issue 52) keeps its experiment's columns as fields of
    /// their own: read, they are in `axes` and `values`; written again, only the maps are, and
    /// they read back the same.
    #[test]
    fn older_columns_are_read_into_the_maps_and_written_only_there() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("results.jsonl");
        let mut old: serde_json::Value = serde_json::to_value(record(0, 1.0, 3, 0.1)).unwrap();
        for (k, v) in [
            ("symmetry_planes", serde_json::json!(3)),
            ("copies_drawn", serde_json::json!(6)),
            ("copies_total", serde_json::json!(8)),
            ("bake_ms", serde_json::json!(1.5)),
            ("reflection_offscreen_share", serde_json::json!(0.25)),
            ("mirrored_lights", serde_json::json!(2)),
            ("bump_amplitude_deg", serde_json::json!(7.5)),
        ] {
            old[k] = v;
        }
        std::fs::write(&p, format!("{old}\n")).unwrap();
        let read = read_records(&p).unwrap();
        let r = &read[0];
        assert_eq!(r.planes(), Some(3));
        assert_eq!(r.lights_depth(), Some(2));
        assert_eq!(r.tilt_deg(), Some(7.5));
        assert_eq!(r.value(value::COPIES_DRAWN), Some(6.0));
        assert_eq!(r.value(value::COPIES_TOTAL), Some(8.0));
        assert_eq!(r.value(value::BAKE_MS), Some(1.5));
        assert_eq!(r.value(value::REFLECTION_OFFSCREEN_SHARE), Some(0.25));
        let written = serde_json::to_value(r).unwrap();
        for k in [
            "symmetry_planes",
            "copies_drawn",
            "bake_ms",
            "reflection_offscreen_share",
        ] {
            assert!(written.get(k).is_none(), "{k} written: {written}");
        }
        assert_eq!(written["values"]["copies_drawn"], 6.0);
        std::fs::write(&p, format!("{written}\n")).unwrap();
        assert_eq!(&read_records(&p).unwrap()[0], r);
    }

    #[test]
    fn a_key_written_twice_is_read_once_as_its_last_record() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("results.jsonl");
        let (a, b) = (record(0, 1.0, 3, 0.1), record(1, 1.0, 7, 0.05));
        let mut a2 = a.clone();
        a2.ms_median = 42.0;
        let lines: Vec<String> = [&a, &b, &a2, &b]
            .iter()
            .map(|r| serde_json::to_string(r).unwrap())
            .collect();
        std::fs::write(&p, lines.join("\n") + "\n").unwrap();
        let read = read_records(&p).unwrap();
        assert_eq!(read.len(), 2, "two keys, each once");
        assert_eq!(
            (read[0].key.as_str(), read[0].ms_median),
            (a.key.as_str(), 42.0)
        );
        assert_eq!(read[1].key, b.key);
    }

    #[test]
    fn a_failed_report_write_names_the_file_and_leaves_no_partial_file() {
        let dir = tempfile::tempdir().unwrap();
        let records = vec![record(0, 1.0, 3, 0.1)];
        // A folder where the report file should go: the rename fails, like a full disk would.
        std::fs::create_dir(dir.path().join("report.md")).unwrap();
        std::fs::write(dir.path().join("report.md").join("x"), "").unwrap();
        let e = write_report(dir.path(), &SweepInfo::default(), &records, &[]).unwrap_err();
        assert!(e.to_string().contains("report.md"), "{e}");
        let leftovers: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
        // Refused before any file is written: no results.csv beside it (one had been
        // rewritten before the failure).
        assert!(e.refused, "{e}");
        assert!(!dir.path().join("results.csv").exists());
    }

    #[test]
    fn timings_of_several_devices_are_grouped_not_mixed() {
        let mut a = record(0, 20.0, 3, 0.1);
        a.device = Some("adapter A on CPU 1".into());
        let mut b = record(1, 30.0, 5, 0.05);
        b.device = Some("adapter B on CPU 2".into());
        let md = markdown(&document(
            &SweepInfo::default(),
            &[a.clone(), b.clone()],
            &[],
        ));
        assert!(md.contains("## Timings by device"), "{md}");
        assert!(
            md.contains("### On adapter A on CPU 1") && md.contains("### On adapter B on CPU 2")
        );
        assert!(
            !md.contains("Error against time"),
            "no plot mixes the devices"
        );
        b.device = a.device.clone();
        let md = markdown(&document(&SweepInfo::default(), &[a, b], &[]));
        assert!(!md.contains("Timings by device") && md.contains("Error against time"));
    }

    /// A client's own floor is no comparison floor: a client that drew no mirrors (its mirror
    /// point 0.33, its floor 0.44) had been told "the methods are exact on this scene". Ours,
    /// where the report has it, still is.
    #[test]
    fn a_clients_floor_never_calls_its_points_exact() {
        let external = |r: &mut Record| r.timing_order = crate::EXTERNAL_TIMING.into();
        let mut point = record(0, 20.0, 3, 0.33);
        point.key = "client/mirrors".into();
        external(&mut point);
        let mut client_floor = record(0, 20.0, 3, 0.44);
        client_floor.key = "client/floor".into();
        client_floor.kind = "floor".into();
        external(&mut client_floor);
        let md = markdown(&document(
            &SweepInfo::default(),
            &[point.clone(), client_floor.clone()],
            &[],
        ));
        assert!(!md.contains("exact on this scene"), "{md}");
        assert!(md.contains("No floor of mirrorbox's own"), "{md}");
        let mut ours = record(0, 1.0, 1, 0.5);
        ours.key = "floor".into();
        ours.kind = "floor".into();
        let md = markdown(&document(
            &SweepInfo::default(),
            &[point, client_floor, ours],
            &[],
        ));
        assert!(md.contains("exact on this scene"), "{md}");
    }

    /// Times without intervals (fewer than 6 frames) are "median (min …)" in their cell: no
    /// "min" column repeats the minimum beside them; with intervals it is there.
    #[test]
    fn the_min_column_is_there_only_beside_intervals() {
        let mut a = record(0, 20.0, 3, 0.1);
        let mut b = record(1, 30.0, 5, 0.05);
        (a.ms_interval, b.ms_interval) = (None, None);
        let md = markdown(&document(
            &SweepInfo::default(),
            &[a.clone(), b.clone()],
            &[],
        ));
        let head = |md: &str| {
            md.lines()
                .find(|l| l.starts_with("| point |"))
                .unwrap()
                .to_string()
        };
        assert!(
            head(&md).contains("ms/frame median (min) | CPU plan ms"),
            "{}",
            head(&md)
        );
        a.ms_interval = Some([19.0, 21.0]);
        b.ms_interval = Some([29.0, 31.0]);
        let md = markdown(&document(&SweepInfo::default(), &[a, b], &[]));
        assert!(head(&md).contains("[95 % CI] | min |"), "{}", head(&md));
    }

    #[test]
    fn points_reused_from_an_earlier_run_are_marked() {
        let dir = tempfile::tempdir().unwrap();
        let mut old = record(1, 45.0, 7, 0.05);
        old.run = Some("2026-11-20T10:00:00Z".into());
        let mut new = record(0, 20.0, 3, 0.1);
        new.run = Some("2026-11-22T10:00:00Z".into());
        write_report(dir.path(), &SweepInfo::default(), &[new.clone(), old], &[]).unwrap();
        let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
        assert!(md.contains("† 1 of 2 points were reused"), "{md}");
        assert!(md.contains("| auxiliary n=1 † |"), "{md}");
        assert!(!md.contains("auxiliary n=0 †"), "{md}");
        // All from one run: nothing marked.
        write_report(dir.path(), &SweepInfo::default(), &[new], &[]).unwrap();
        let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
        assert!(!md.contains('†'), "{md}");
    }

    /// A stereo sweep's points read apart in "All points": each names its IPD, or mono.
    #[test]
    fn all_points_name_a_stereo_points_ipd() {
        let dir = tempfile::tempdir().unwrap();
        let mono = record(2, 20.0, 3, 0.1);
        let mut pair = record(2, 30.0, 6, 0.1);
        pair.key = "pair".into();
        pair.axes.insert(crate::axis::STEREO_IPD.into(), 0.1);
        write_report(dir.path(), &SweepInfo::default(), &[mono, pair], &[]).unwrap();
        let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
        assert!(md.contains("| auxiliary n=2, mono |"), "{md}");
        assert!(md.contains("| auxiliary n=2, IPD 0.1 |"), "{md}");
    }

    /// A lent GPU's 1920×1080 images stay behind (issue 57): the report says they were not
    /// kept instead of linking files that are not there; kept images are linked.
    #[test]
    fn rows_whose_images_were_not_kept_say_so_instead_of_linking_them() {
        let dir = tempfile::tempdir().unwrap();
        let records = [record(0, 20.0, 3, 0.1)];
        write_report(dir.path(), &SweepInfo::default(), &records, &[]).unwrap();
        let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
        assert!(
            md.contains("(Images not kept with these records: `t.png`, `r.png`,"),
            "{md}"
        );
        assert!(!md.contains("](t.png)"), "{md}");
        for f in ["t.png", "r.png"] {
            std::fs::write(dir.path().join(f), b"").unwrap();
        }
        write_report(dir.path(), &SweepInfo::default(), &records, &[]).unwrap();
        let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
        assert!(md.contains("](t.png)") && !md.contains("not kept"), "{md}");
    }

    #[test]
    fn the_report_names_the_colour_formats_of_its_points() {
        let dir = tempfile::tempdir().unwrap();
        let mut half = record(1, 45.0, 7, 0.05);
        half.color_format = "rgba16float".into();
        write_report(
            dir.path(),
            &SweepInfo::default(),
            &[record(0, 20.0, 3, 0.1), half],
            &[],
        )
        .unwrap();
        let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
        assert!(
            md.contains("colour targets: rgba16float, rgba32float"),
            "{md}"
        );
        let csv = std::fs::read_to_string(dir.path().join("results.csv")).unwrap();
        assert!(csv.lines().next().unwrap().contains(
            ",color_format,peak_memory_bytes,plan_ms,encode_ms,gpu_buffer_bytes,gpu_texture_bytes,\
             method_options,marker_disparity_px,truth_marker_disparity_px,"
        ));
        assert!(
            csv.lines()
                .nth(2)
                .unwrap()
                .contains(",rgba16float,,,,,,\"\",,,,,,,,,")
        );
        // Every row has the header's number of columns (no value here holds a comma).
        let columns = |l: &str| l.split(',').count();
        let header = columns(csv.lines().next().unwrap());
        assert!(csv.lines().skip(1).all(|l| columns(l) == header), "{csv}");
    }

    /// n = 0 (no auxiliary mirror: the seed's Algorithm 1) is drawn on the linear n axis with
    /// the other n, not named as "not drawn" in the legend as a log axis would have to.
    #[test]
    fn n_zero_is_drawn_on_the_linear_n_axis() {
        let dir = tempfile::tempdir().unwrap();
        let records = [
            record(0, 1.0, 1, 0.2),
            record(1, 2.0, 3, 0.1),
            record(2, 3.0, 5, 0.05),
        ];
        write_report(dir.path(), &SweepInfo::default(), &records, &[]).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("plot_flip_vs_n.svg")).unwrap();
        assert!(!svg.contains("not drawn"), "{svg}");
        assert!(svg.contains(">0</text>"), "a tick at n = 0: {svg}");
        assert_eq!(
            svg.matches("<circle").count(),
            4,
            "three points and the legend's: {svg}"
        );
        // The log axis of time keeps its rule: nothing at 0 there to leave out.
        let ms = std::fs::read_to_string(dir.path().join("plot_flip_vs_ms.svg")).unwrap();
        assert!(!ms.contains("not drawn"), "{ms}");
    }

    /// The largest α keeps the method's own style whatever the records' order; another α
    /// keeps the method's marker, hollow.
    #[test]
    fn the_plain_alpha_keeps_the_method_style() {
        let mut low = record(1, 1.0, 1, 0.2);
        low.alpha = 0.7;
        let mut plain = record(1, 2.0, 1, 0.1);
        plain.alpha = 1.0;
        let points = [&low, &plain];
        let v = Variants::of(&points);
        let at = |a: f32| v.groups.iter().position(|g| g.1 == a).unwrap();
        assert_eq!(v.styles[at(1.0)], crate::plot::method_style("auxiliary"));
        let other = v.styles[at(0.7)];
        assert!(other.hollow && other.marker == crate::plot::method_style("auxiliary").marker);
    }

    /// Points timed on too few frames for a 95 % interval (five) are drawn with each one's
    /// fastest to slowest frame as its bar, and the axis says so; where every point has its
    /// interval, the intervals are the bars. Before, such charts showed bare medians.
    #[test]
    fn points_without_an_interval_show_their_range_of_frames() {
        let dir = tempfile::tempdir().unwrap();
        let mut records = [
            record(0, 1.0, 1, 0.2),
            record(1, 2.0, 3, 0.1),
            record(2, 3.0, 5, 0.05),
        ];
        for r in &mut records {
            r.frames_ms = [0.9, 1.0, 1.1, 1.2, 1.4].map(|f| f * r.ms_median).to_vec();
        }
        write_report(dir.path(), &SweepInfo::default(), &records, &[]).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("plot_flip_vs_ms.svg")).unwrap();
        assert!(
            svg.contains(">ms/frame (median, bars: fastest to slowest frame)<"),
            "{svg}"
        );
        assert_eq!(
            svg.matches("<path d=\"M").count(),
            3,
            "one bar a point: {svg}"
        );
        assert_eq!(
            records[1].ms_bars(crate::plot::Bars::FrameRange),
            Some([1.8, 2.8])
        );
        // Every point with its interval: the intervals, and the axis says 95 %.
        for r in &mut records {
            r.ms_interval = Some([0.95 * r.ms_median, 1.05 * r.ms_median]);
        }
        assert_eq!(crate::ms_bars_for(&records), crate::plot::Bars::Ci95);
        write_report(dir.path(), &SweepInfo::default(), &records, &[]).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("plot_flip_vs_ms.svg")).unwrap();
        assert!(svg.contains(">ms/frame (median, 95 % CI bars)<"), "{svg}");
        // One point without its frames or an interval (an outside renderer's) among points
        // with frames alone: the others keep their ranges; it draws none.
        for r in &mut records {
            r.ms_interval = None;
        }
        records[2].frames_ms.clear();
        assert_eq!(crate::ms_bars_for(&records), crate::plot::Bars::FrameRange);
        assert_eq!(records[2].ms_bars(crate::plot::Bars::FrameRange), None);
        // A point with an interval but without frames keeps the chart on intervals.
        records[2].ms_interval = Some([2.9, 3.1]);
        assert_eq!(crate::ms_bars_for(&records), crate::plot::Bars::Ci95);
        // One frame each and no interval: no bars, and the axis promises none.
        for r in &mut records {
            (r.ms_interval, r.frames_ms) = (None, vec![r.ms_median]);
        }
        write_report(dir.path(), &SweepInfo::default(), &records, &[]).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("plot_flip_vs_ms.svg")).unwrap();
        assert!(svg.contains(">ms/frame (median)<"), "{svg}");
        assert_eq!(svg.matches("<path d=\"M").count(), 0, "{svg}");
    }

    /// A score's several floors (each client's and view's, and ours) are each named in the
    /// floor section, and the figures say whose they shade: ours (before: the first floor
    /// found, unnamed).
    #[test]
    fn several_floors_are_each_named_and_the_shaded_one_is_said() {
        let dir = tempfile::tempdir().unwrap();
        let floor = |key: &str, flip: f64, external: bool| {
            let mut r = record(0, 1.0, 1, flip);
            r.kind = "floor".into();
            r.key = key.into();
            r.adapter = "our adapter".into();
            if external {
                r.timing_order = crate::EXTERNAL_TIMING.into();
            }
            r
        };
        let records = [
            floor("three/floor|camera|a0.9|16x16|ssaa1", 0.5, true),
            floor("floor|16x16", 0.001, false),
            record(1, 2.0, 3, 0.1),
            record(2, 3.0, 5, 0.05),
        ];
        write_report(dir.path(), &SweepInfo::default(), &records, &[]).unwrap();
        let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
        assert!(
            md.contains("| three, view camera |") && md.contains("| mirrorbox on our adapter |"),
            "{md}"
        );
        assert!(
            md.contains("the shaded band is the floor of mirrorbox on our adapter"),
            "{md}"
        );
    }

    /// A scored variant of an export of several views names its view in "All points" (two
    /// views' rows had read alike).
    #[test]
    fn a_scored_point_names_its_view() {
        let dir = tempfile::tempdir().unwrap();
        let mut r = record(0, 2.0, 1, 0.1);
        r.key = "three/reflector|left|a0.9|16x16|ssaa1".into();
        r.timing_order = crate::EXTERNAL_TIMING.into();
        r.axes.insert(crate::axis::VIEW.into(), 1.0);
        write_report(dir.path(), &SweepInfo::default(), &[r], &[]).unwrap();
        let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
        assert!(md.contains(", view left |"), "{md}");
    }

    /// A section of charts none of which can be drawn goes whole, heading and caption; one
    /// with a drawn chart, or with a table, stays.
    #[test]
    fn a_section_whose_charts_are_all_undrawn_goes_whole() {
        use crate::plot::{Chart, Series, method_style};
        let chart = |xs: &[f64]| {
            let mut c = Chart::new("t", "x", "y");
            c.series = vec![Series::new(
                "s",
                method_style("naive"),
                xs.iter().map(|&x| (x, 1.0)).collect(),
            )];
            Box::new(c)
        };
        let blocks = vec![
            Block::Heading(2, "empty".into()),
            Block::Paragraph("caption".into()),
            Block::Chart("a.svg".into(), chart(&[1.0])),
            Block::Heading(2, "drawn".into()),
            Block::Chart("b.svg".into(), chart(&[1.0, 2.0])),
            Block::Heading(2, "table".into()),
            Block::Table(vec!["h".into()], vec![]),
        ];
        let kept: Vec<String> = without_empty_chart_sections(blocks)
            .iter()
            .map(|b| match b {
                Block::Heading(_, h) => h.clone(),
                Block::Paragraph(p) => p.clone(),
                Block::Chart(f, _) => f.clone(),
                _ => "other".into(),
            })
            .collect();
        assert_eq!(kept, ["drawn", "b.svg", "table", "other"]);
    }

    /// RFC 4180's reading of a CSV text: rows of cells, a quoted cell's `""` one quote.
    fn parse_csv(text: &str) -> Vec<Vec<String>> {
        let (mut rows, mut row, mut cell) = (Vec::new(), Vec::new(), String::new());
        let (mut quoted, mut chars) = (false, text.chars().peekable());
        while let Some(c) = chars.next() {
            match (quoted, c) {
                (true, '"') if chars.peek() == Some(&'"') => {
                    chars.next();
                    cell.push('"');
                }
                (true, '"') => quoted = false,
                (true, c) => cell.push(c),
                (false, '"') => quoted = true,
                (false, ',') => row.push(std::mem::take(&mut cell)),
                (false, '\n') => {
                    row.push(std::mem::take(&mut cell));
                    rows.push(std::mem::take(&mut row));
                }
                (false, c) => cell.push(c),
            }
        }
        rows
    }

    /// The CSV has a column for every scene axis and extra value some point has, named by the
    /// records' key, in every row (empty where the point has none); none for what no point has.
    #[test]
    fn the_csv_has_a_column_per_axis_and_value_the_points_have() {
        let dir = tempfile::tempdir().unwrap();
        let mut a = record(0, 20.0, 3, 0.1);
        a.axes.insert("yaw_deg".into(), 15.0);
        a.values.insert(value::COPIES_DRAWN.into(), 4.0);
        let mut b = record(1, 45.0, 7, 0.05);
        b.axes.insert("planes".into(), 2.0);
        b.axes.insert("yaw_deg".into(), -30.0);
        write_report(dir.path(), &SweepInfo::default(), &[a, b], &[]).unwrap();
        let rows = parse_csv(&std::fs::read_to_string(dir.path().join("results.csv")).unwrap());
        let header = &rows[0];
        assert!(rows.iter().all(|row| row.len() == header.len()), "{rows:?}");
        let column = |name: &str| header.iter().position(|h| h == name);
        let (planes, yaw, copies) = (
            column("planes").unwrap(),
            column("yaw_deg").unwrap(),
            column("copies_drawn").unwrap(),
        );
        assert!(column("method_options").unwrap() < planes && planes < yaw && yaw < copies);
        assert_eq!(
            [&rows[1][planes], &rows[1][yaw], &rows[1][copies]],
            ["", "15", "4"]
        );
        assert_eq!(
            [&rows[2][planes], &rows[2][yaw], &rows[2][copies]],
            ["2", "-30", ""]
        );
        for absent in ["symmetry_planes", "bump_deg", "copies_total", "stereo_ipd"] {
            assert_eq!(column(absent), None, "{absent}: {header:?}");
        }
        // A key named as a fixed column, or a value named as an axis, keeps a column of its
        // own, named with its map.
        let mut c = record(2, 30.0, 5, 0.07);
        c.axes.insert("alpha".into(), 0.5);
        c.axes.insert("planes".into(), 1.0);
        c.values.insert("planes".into(), 3.0);
        write_report(dir.path(), &SweepInfo::default(), &[c], &[]).unwrap();
        let rows = parse_csv(&std::fs::read_to_string(dir.path().join("results.csv")).unwrap());
        let header = &rows[0];
        let at = |name: &str| header.iter().position(|h| h == name).unwrap();
        assert_eq!(
            header.iter().filter(|h| *h == "alpha").count(),
            1,
            "{header:?}"
        );
        assert_eq!(rows[1][at("axes.alpha")], "0.5");
        assert_eq!(rows[1][at("planes")], "1");
        assert_eq!(rows[1][at("values.planes")], "3");
    }

    /// Text a client wrote (its timing, its engine) comes back from results.csv cell for
    /// cell, commas, quotes and line breaks included: the web engines' timing text had split
    /// into four more cells than the header's.
    #[test]
    fn every_text_cell_of_the_csv_reads_back_as_written() {
        let dir = tempfile::tempdir().unwrap();
        let text = "a, \"b\"\nc";
        let mut r = record(1, 45.0, 7, 0.05);
        r.kind = text.into();
        r.method = text.into();
        r.timing_order = text.into();
        r.timing_source = text.into();
        r.adapter = text.into();
        r.backend = text.into();
        r.scene = text.into();
        r.scene_hash = text.into();
        r.color_format = text.into();
        r.method_options = text.into();
        write_report(dir.path(), &SweepInfo::default(), &[r], &[]).unwrap();
        let rows = parse_csv(&std::fs::read_to_string(dir.path().join("results.csv")).unwrap());
        assert_eq!(rows.len(), 2);
        let header = &rows[0];
        assert_eq!(rows[1].len(), header.len(), "{rows:?}");
        for column in [
            "kind",
            "method",
            "timing_order",
            "timing_source",
            "adapter",
            "backend",
            "scene",
            "scene_hash",
            "color_format",
            "method_options",
        ] {
            let i = header.iter().position(|h| h == column).unwrap();
            assert_eq!(rows[1][i], text, "{column}");
        }
    }
}
