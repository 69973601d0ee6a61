//! The sweep: for each method, n and α, render and time with the rasterizer, compare with
//! the ground truth traced at reflectance α on the same sub-pixel grid, and append one
//! [`Record`] per point to `results.jsonl` as it completes. Then write the reports.
//!
//! - **Truth cache**: `cache/truth-<key>.exr`, the key an FNV-1a hash of everything that
//!   affects the traced image (scene content hash after α and size, spp, depth limits,
//!   integrator, tracer version). A re-run reuses it.
//! - **Resume**: points whose key is already in `results.jsonl` are skipped; a point is
//!   written only when complete, so an interrupted sweep loses no finished point.
//! - **Floor**: raster vs trace on the scene without its mirrors, the error that is left
//!   when there is no mirror effect to truncate.

use glam::Vec3;
use mirrorbox_image::metrics::{compare, flip_map};
use mirrorbox_image::{RgbImage, colormap, read_image, write_exr, write_png, write_png_bytes};
use mirrorbox_raster::{Gpu, Method, RasterError, RenderSettings, plan};
use mirrorbox_report::{MetricValues, Record, SweepInfo, read_records, write_report};
use mirrorbox_scene::{Scene, SubpixelGrid, load_scene};
use mirrorbox_trace::{Sampling, SceneBvh, TraceSettings, WhittedSettings};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// The exact methods' path pruning in sweeps (the `render` command's defaults): portals
/// holding no pixel centre (always; exact) and attenuations under 1e-4 (the truth's
/// `--min-throughput`); no lossy area threshold.
pub const EXACT_MIN_PORTAL_AREA: f32 = 0.0;
pub const EXACT_MIN_ATTENUATION: f32 = 1e-4;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodKind {
    Naive,
    Auxiliary,
    /// Exact stencil recursion, swept over `depths`.
    Portal,
    /// Exact instanced unrolling, swept over `depths`.
    Unrolled,
}

#[derive(Clone, Debug)]
pub struct SweepConfig {
    pub scene: PathBuf,
    pub out: PathBuf,
    pub methods: Vec<MethodKind>,
    /// Auxiliary mirror counts (auxiliary method).
    pub ns: Vec<u32>,
    /// Reflection depths (exact methods: portal, unrolled).
    pub depths: Vec<u32>,
    pub alphas: Vec<f32>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub ssaa: u32,
    pub frames: u32,
    pub warmup: u32,
    pub max_passes: usize,
    pub truth: WhittedSettings,
    /// The command line, for the report.
    pub command: String,
}

#[derive(Debug, thiserror::Error)]
pub enum HarnessError {
    #[error("{0}")]
    BadInput(String),
    #[error("{0}")]
    Other(String),
}

fn other(e: impl ToString) -> HarnessError {
    HarnessError::Other(e.to_string())
}

/// Progress of a sweep.
pub enum Event<'a> {
    /// `todo` points will be computed, `reused` were already in results.jsonl.
    Planned {
        todo: usize,
        reused: usize,
    },
    Started {
        label: &'a str,
    },
    Finished {
        record: &'a Record,
    },
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Summary {
    pub computed: usize,
    pub reused: usize,
    pub truths_traced: usize,
    pub truths_cached: usize,
}

struct Point {
    method: Option<Method>,
    alpha: f32,
    key: String,
    label: String,
    slug: String,
}

fn points(config: &SweepConfig, base_hash: u64, w: u32, h: u32) -> Vec<Point> {
    let common = format!(
        "{w}x{h}|ssaa={}|frames={}|scene={base_hash:016x}",
        config.ssaa, config.frames
    );
    let mut out = vec![Point {
        method: None,
        alpha: 1.0,
        key: format!("floor|{common}"),
        label: "floor (no mirrors)".into(),
        slug: "floor".into(),
    }];
    for &alpha in &config.alphas {
        for &m in &config.methods {
            let methods: Vec<Method> = match m {
                MethodKind::Naive => vec![Method::Naive],
                MethodKind::Auxiliary => {
                    config.ns.iter().map(|&n| Method::Auxiliary { n }).collect()
                }
                MethodKind::Portal => config
                    .depths
                    .iter()
                    .map(|&depth| Method::Portal { depth })
                    .collect(),
                MethodKind::Unrolled => config
                    .depths
                    .iter()
                    .map(|&depth| Method::Unrolled { depth })
                    .collect(),
            };
            for method in methods {
                let name = method.name();
                let n = method.to_string()[name.len()..].to_string();
                out.push(Point {
                    method: Some(method),
                    alpha,
                    key: format!("{name}{n}|alpha={alpha}|{common}"),
                    label: format!("{name}{n} α={alpha}"),
                    slug: format!(
                        "{name}{}_a{alpha}",
                        n.replace(" n=", "_n").replace(" depth=", "_d")
                    ),
                });
            }
        }
    }
    out
}

fn cpu_description() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!("{model}, {cores} cores available")
}

/// The traced truth for `scene`, from the cache when present.
fn truth(
    scene: &Scene,
    config: &SweepConfig,
    cache: &Path,
    summary: &mut Summary,
) -> Result<(RgbImage, PathBuf), HarnessError> {
    let mut key = mirrorbox_scene::hash::Fnv1a::new();
    let t = &config.truth;
    let _ = write!(
        key,
        "{:016x}|spp={}|depth={}|min_t={}|whitted|trace {}",
        scene.content_hash(),
        config.ssaa * config.ssaa,
        t.max_depth,
        t.min_throughput,
        env!("CARGO_PKG_VERSION")
    );
    let path = cache.join(format!("truth-{:016x}.exr", key.finish()));
    if path.is_file()
        && let Ok(img) = read_image(&path)
    {
        summary.truths_cached += 1;
        return Ok((img, path));
    }
    let bvh = SceneBvh::build(&scene.geometry);
    let settings = TraceSettings {
        sampling: Sampling::Grid(SubpixelGrid::new(config.ssaa)),
        whitted: *t,
        path: None,
    };
    let out = mirrorbox_trace::render(scene, &bvh, &settings, &|_| {});
    write_exr(
        &path,
        &out.image,
        &[("mirrorbox.cache_key", format!("{:016x}", key.finish()))],
    )
    .map_err(other)?;
    write_png(
        &path.with_extension("png"),
        &out.image,
        scene.camera.exposure,
    )
    .map_err(other)?;
    summary.truths_traced += 1;
    Ok((out.image, path))
}

fn metric_values(m: &mirrorbox_image::metrics::Metrics) -> MetricValues {
    MetricValues {
        rmse: m.rmse,
        relmse: m.relmse,
        smape: m.smape,
        max_abs: m.max_abs,
        psnr: m.psnr.is_finite().then_some(m.psnr),
        ssim: m.ssim,
        flip_mean: m.flip_mean,
        flip_p95: m.flip_p95,
        flip_p99: m.flip_p99,
    }
}

/// An interrupted write can leave a partial last line; appending to it would glue the next
/// record onto it. Rewrite the file (atomically) with only its complete records when any
/// line is broken.
fn salvage(results: &Path, records: &[Record]) -> Result<(), HarnessError> {
    let Ok(text) = std::fs::read_to_string(results) else {
        return Ok(());
    };
    if text.lines().count() == records.len() && (text.is_empty() || text.ends_with('\n')) {
        return Ok(());
    }
    let mut clean = String::new();
    for r in records {
        clean.push_str(&serde_json::to_string(r).map_err(other)?);
        clean.push('\n');
    }
    let tmp = results.with_extension("jsonl.tmp");
    std::fs::write(&tmp, clean)
        .and_then(|()| std::fs::rename(&tmp, results))
        .map_err(other)
}

/// Runs (or resumes) the sweep and writes its reports.
pub fn run_sweep(
    config: &SweepConfig,
    progress: &mut dyn FnMut(Event),
) -> Result<Summary, HarnessError> {
    let mut base = load_scene(&config.scene).map_err(|e| HarnessError::BadInput(e.to_string()))?;
    let (w, h) = (
        config.width.unwrap_or(base.camera.width),
        config.height.unwrap_or(base.camera.height),
    );
    base.camera = base.camera.with_size(w, h);
    let base_hash = base.content_hash();
    let all = points(config, base_hash, w, h);
    // Refuse over-budget points before any work.
    for p in &all {
        if let Some(method @ (Method::Naive | Method::Auxiliary { .. })) = p.method {
            plan::plan(
                &base,
                method,
                w * config.ssaa,
                h * config.ssaa,
                config.max_passes,
            )
            .map_err(|e| HarnessError::BadInput(format!("{}: {e}", p.label)))?;
        }
    }
    let out = &config.out;
    let (images, cache) = (out.join("images"), out.join("cache"));
    for d in [out, &images, &cache] {
        std::fs::create_dir_all(d)
            .map_err(|e| HarnessError::BadInput(format!("{}: {e}", d.display())))?;
    }
    let results = out.join("results.jsonl");
    let existing = read_records(&results).map_err(other)?;
    salvage(&results, &existing)?;
    let done: Vec<String> = existing.into_iter().map(|r| r.key).collect();
    let todo: Vec<&Point> = all.iter().filter(|p| !done.contains(&p.key)).collect();
    let mut summary = Summary {
        reused: all.len() - todo.len(),
        ..Default::default()
    };
    progress(Event::Planned {
        todo: todo.len(),
        reused: summary.reused,
    });
    let gpu = Gpu::new().map_err(|e| match e {
        RasterError::Adapter(mirrorbox_raster::AdapterError::BadOverride { .. }) => {
            HarnessError::BadInput(e.to_string())
        }
        e => other(e),
    })?;
    for p in todo {
        progress(Event::Started { label: &p.label });
        let mut scene = if p.method.is_some() {
            base.clone()
        } else {
            base.without_mirrors()
        };
        scene.set_reflectance(Vec3::splat(p.alpha));
        let (truth_image, truth_path) = truth(&scene, config, &cache, &mut summary)?;
        let settings = RenderSettings {
            method: p.method.unwrap_or(Method::Naive),
            ssaa: config.ssaa,
            frames: config.frames,
            warmup: config.warmup,
            max_passes: config.max_passes,
            texture_scale: 1.0,
            min_portal_area: EXACT_MIN_PORTAL_AREA,
            min_attenuation: EXACT_MIN_ATTENUATION,
            fragment_clipping: false,
        };
        let rendered = mirrorbox_raster::render(&gpu, &scene, &settings).map_err(other)?;
        let m = compare(&truth_image, &rendered.image, scene.camera.exposure).map_err(other)?;
        let raster_png = images.join(format!("{}.png", p.slug));
        write_png(&raster_png, &rendered.image, scene.camera.exposure).map_err(other)?;
        let exposure = scene.camera.exposure;
        let map = flip_map(
            &truth_image.to_srgb8(exposure),
            &rendered.image.to_srgb8(exposure),
            w,
            h,
        );
        let heat: Vec<u8> = map.iter().flat_map(|&v| colormap::heat(v)).collect();
        let heat_png = images.join(format!("{}_flip.png", p.slug));
        write_png_bytes(&heat_png, w, h, &heat).map_err(other)?;
        let truth_png = images.join(format!(
            "truth_{}.png",
            if p.method.is_some() {
                format!("a{}", p.alpha)
            } else {
                "floor".into()
            }
        ));
        std::fs::copy(truth_path.with_extension("png"), &truth_png).map_err(other)?;
        let rel = |q: &Path| {
            q.strip_prefix(out)
                .unwrap_or(q)
                .to_string_lossy()
                .into_owned()
        };
        let t = &rendered.timing;
        let s = &rendered.stats;
        let record = Record {
            key: p.key.clone(),
            kind: if p.method.is_some() { "point" } else { "floor" }.into(),
            scene: config.scene.display().to_string(),
            scene_hash: format!("{base_hash:016x}"),
            method: p.method.map_or("floor", |m| m.name()).into(),
            n: p.method.and_then(|m| m.n()),
            depth: p.method.and_then(|m| m.depth_limit()),
            alpha: p.alpha,
            width: w,
            height: h,
            ssaa: config.ssaa,
            ms_median: t.median_ms(),
            ms_min: t.min_ms(),
            timing_source: t.source.name().into(),
            frames: config.frames,
            passes: s.passes,
            draws: s.draws,
            texture_renders: s.texture_renders,
            reflections: s.depth,
            triangles: Some(s.triangles),
            paths: s.paths.map(|c| c.kept),
            paths_pruned: s.paths.map(|c| c.pruned()),
            metrics: metric_values(&m),
            adapter: gpu.report.name.clone(),
            backend: gpu.report.backend.clone(),
            truth_image: rel(&truth_png),
            raster_image: rel(&raster_png),
            heatmap_image: rel(&heat_png),
        };
        let line = serde_json::to_string(&record).map_err(other)?;
        let mut f = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&results)
            .map_err(other)?;
        f.write_all(format!("{line}\n").as_bytes())
            .and_then(|()| f.sync_data())
            .map_err(other)?;
        summary.computed += 1;
        progress(Event::Finished { record: &record });
    }
    let records = read_records(&results).map_err(other)?;
    // Report the points of this configuration only (results.jsonl may hold others).
    let keys: Vec<&String> = all.iter().map(|p| &p.key).collect();
    let records: Vec<Record> = records
        .into_iter()
        .filter(|r| keys.contains(&&r.key))
        .collect();
    let info = SweepInfo {
        command: config.command.clone(),
        date: humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string(),
        cpu: cpu_description(),
        adapter: gpu.report.name.clone(),
        backend: gpu.report.backend.clone(),
        device_type: gpu.report.device_type.clone(),
        versions: format!(
            "mirrorbox {}, wgpu 30.0.1, obvhs 0.4.0",
            env!("CARGO_PKG_VERSION")
        ),
        scene: config.scene.display().to_string(),
        resolution: format!(
            "{w}x{h}, ssaa {} (truth: the same {}x{} sub-pixel grid)",
            config.ssaa, config.ssaa, config.ssaa
        ),
        truth: format!(
            "whitted, max depth {}, min throughput {}, traced at reflectance α",
            config.truth.max_depth, config.truth.min_throughput
        ),
    };
    std::fs::write(
        out.join("sweep.json"),
        serde_json::json!({ "command": info.command, "date": info.date }).to_string(),
    )
    .map_err(other)?;
    write_report(out, &info, &records).map_err(other)?;
    Ok(summary)
}
