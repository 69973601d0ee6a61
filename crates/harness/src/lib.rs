//! The sweep: for each method, n and α, render and time with the rasterizer, compare with
//! the ground truth traced at reflectance α on the same sub-pixel grid, and append one
//! [`Record`] per point to `results.jsonl` once its timing rounds are done. Then write the
//! reports.
//!
//! - **Truth cache**: `cache/truth-<key>.exr`, the key an FNV-1a hash of everything that
//!   affects the traced image (scene content hash after α and size, spp, depth limits,
//!   integrator, tracer version). A re-run reuses it.
//! - **Interleaved timing**: the points still to do are timed round-robin — `frames` rounds,
//!   each rendering every point's warm-up frames and one timed frame, in an order shuffled
//!   per round with a fixed seed — so drift of a shared machine hits every point alike. Each
//!   record holds every frame, the median, its 95 % bootstrap interval and the minimum. A
//!   [settling round](SETTLING_ROUNDS) renders every point's frame once, untimed, before them.
//! - **Resume**: points whose key is already in `results.jsonl` are skipped. Points are
//!   written once all rounds are done: an interrupted sweep keeps every point written
//!   before, and measures the interrupted batch again.
//! - **Floor**: raster vs trace on the scene without its mirrors, the error that is left
//!   when there is no mirror effect to truncate.

pub mod advise;
pub mod axes;
pub mod exchange;
pub mod merge;
pub mod score;
pub mod sequence;
mod worker;

pub use axes::{AxisSpec, AxisValues, PointAxes};
pub use worker::{RenderJob, RenderReport, Rendered, peak_memory_bytes, reset_peak_memory, serve};

use mirrorbox_files::{FileError, FolderLock, with_stem_suffix, write_atomically};
use mirrorbox_image::metrics::{MetricsError, compare_detailed};
use mirrorbox_image::{
    ImageError, RgbImage, StagedFiles, colormap, read_image, stage_exr, stage_png, write_png,
    write_png_bytes,
};
use mirrorbox_raster::{Gpu, METHODS, Method, PlanError, RasterError, RenderSettings};
use mirrorbox_report::{
    ErrorSplit, MetricValues, Record, SweepInfo, read_records, value, write_report,
};
use mirrorbox_scene::limits::{SettingError, unit_interval};
use mirrorbox_scene::{Scene, SceneError, load_scene};
use mirrorbox_trace::{SceneBvh, TraceSettings, WhittedSettings};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// An axis along `values` (each applied; see [`AxisValues`] for `None`).
pub fn along(axis: &'static AxisSpec, values: impl IntoIterator<Item = f64>) -> AxisValues {
    AxisValues {
        axis,
        values: values.into_iter().map(Some).collect(),
    }
}

#[derive(Clone, Debug)]
pub struct SweepConfig {
    pub scene: PathBuf,
    pub out: PathBuf,
    /// Every configured method to measure at each α (one point each), e.g. `auxiliary n=0`
    /// … `auxiliary n=4`, `portal depth=64`.
    pub methods: Vec<Method>,
    pub alphas: Vec<f32>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub ssaa: u32,
    pub frames: u32,
    pub warmup: u32,
    pub truth: WhittedSettings,
    /// The command line, for the report.
    pub command: String,
    /// Where the timed renders run: in a child process of this executable
    /// (`EXE render-worker`, [`worker`]), so that the driver's per-frame memory is returned
    /// after each and every point's peak memory is its own; `None` renders in this process.
    pub worker: Option<PathBuf>,
    /// A point whose frame's estimated GPU + host memory
    /// (`mirrorbox_raster::Planned::memory_estimate`) exceeds this many bytes is refused
    /// before any work (`--memory-budget`, default 2 GiB).
    pub memory_budget: u64,
    /// The scene axes the sweep varies beside the methods and α ([`axes::AXES`]: symmetry
    /// planes, mirrored-light depth, uneven-mirror tilt, stereo IPD), each with its values;
    /// every combination is a point (of every method, at every α). Empty: the scene as it is.
    pub axes: Vec<AxisValues>,
    /// The experiments' report sections the report offers its records (the registry's, from
    /// `mirrorbox-experiments`); none: the sections every sweep report has.
    pub sections: Vec<mirrorbox_report::Section>,
    /// The object whose first reflection a stereo point locates in each eye, truth and raster
    /// alike, to measure its disparity (`--marker NAME`, a diffuse object of the scene; its
    /// albedo's chromaticity finds it: `mirrorbox_image::stereo::marker_blob`).
    pub marker: Option<String>,
    /// This run's share of the sweep (`--shard I/N`, issue 20): only the points [`Shard::owns`]
    /// are measured and reported; `mirrorbox merge` joins the shards. `None`: every point.
    pub shard: Option<Shard>,
    /// Where traced truths are cached (`--truth-cache DIR`; default `OUT/cache`): several
    /// shards may share one, as every truth is written atomically under a content hash.
    pub truth_cache: Option<PathBuf>,
    /// The scene's camera replaced by this view (`advise --views`, [`exchange::ViewSpec`]):
    /// every point, its truth and its worker see the scene from here. `None`: the scene's own.
    pub camera: Option<exchange::ViewSpec>,
    /// A point refused — by its plan's limits or memory estimate before any work, or by its
    /// method as it builds the frame (`unrolled`'s triangles per frame) — is left out and said
    /// ([`Event::Refused`]) instead of ending the sweep: what `mirrorbox advise` wants of its
    /// rounds. Off: the refusal ends the sweep (exit 2), as a sweep's settings are wrong.
    pub drop_refused: bool,
}

/// One of `count` disjoint shares of a sweep's points (`--shard index/count`, index from 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

/// Most shards of one sweep.
pub const MAX_SHARDS: u32 = 100_000;

impl Shard {
    /// Whether the point of resume key `key` belongs to this shard: FNV-1a of the key modulo
    /// the count — stable across runs, machines and the order points are listed in, and
    /// spread evenly over the shards.
    pub fn owns(&self, key: &str) -> bool {
        let mut h = mirrorbox_scene::hash::Fnv1a::new();
        let _ = h.write_str(key);
        h.finish() % u64::from(self.count) == u64::from(self.index)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// The methods `name` at each value of its swept option (`"auxiliary"`, `[0, 1, 2]`), every
/// other option at its default.
pub fn swept(name: &str, values: impl IntoIterator<Item = u32>) -> Vec<Method> {
    let base = Method::named(name).unwrap_or_else(|e| panic!("preset: {e}"));
    let option = base.entry().swept.expect("preset methods are swept");
    values
        .into_iter()
        .map(|v| {
            base.clone()
                .with(option, mirrorbox_raster::ParamValue::Count(v))
                .unwrap_or_else(|e| panic!("preset: {e}"))
        })
        .collect()
}

/// `base` with the options of `words` (`"lights=direct shadow-map=1024"`, or empty) set.
pub fn with_options(base: &Method, words: &str) -> Method {
    Method::parse(&format!("{} {words}", base.key())).unwrap_or_else(|e| panic!("preset: {e}"))
}

impl SweepConfig {
    /// A sweep of `scene` into `out` with the defaults of the presets: native resolution,
    /// no SSAA, 5 timed frames each after one warm-up frame (the first frame after a build
    /// runs 1.2–2.2× slower on lavapipe, the second is at the steady state: docs/budgets.md),
    /// the default truth.
    pub fn new(scene: PathBuf, out: PathBuf, methods: Vec<Method>, alphas: Vec<f32>) -> Self {
        SweepConfig {
            scene,
            out,
            methods,
            alphas,
            width: None,
            height: None,
            ssaa: 1,
            frames: 5,
            warmup: 1,
            truth: WhittedSettings::default(),
            command: String::new(),
            worker: None,
            memory_budget: mirrorbox_raster::DEFAULT_MEMORY_BUDGET,
            axes: Vec::new(),
            sections: Vec::new(),
            marker: None,
            shard: None,
            truth_cache: None,
            camera: None,
            drop_refused: false,
        }
    }

    /// A preset on the paper's scene (mirror_box) with 9 timed frames: enough for a 95 %
    /// interval of each median (the experiments' presets start from it).
    pub fn preset(out: PathBuf, methods: Vec<Method>, alphas: Vec<f32>) -> Self {
        SweepConfig {
            frames: 9,
            ..SweepConfig::new(
                PathBuf::from("scenes/mirror_box.json"),
                out,
                methods,
                alphas,
            )
        }
    }
}

/// Most points in one sweep (methods × α, plus the floor): each renders, times and compares
/// one image, and keeps one record; a longer list is a typo, not an experiment.
pub const MAX_POINTS: usize = 10_000;

impl SweepConfig {
    /// The one check of a sweep's settings, before anything is loaded or written: α each in
    /// `[0, 1]`, the truth's settings as `trace` checks them, and at most [`MAX_POINTS`]
    /// points. SSAA, frames and warm-up are checked as `render` checks them
    /// ([`RenderSettings::check`]), and the image size as everywhere ([`Scene::resize`]),
    /// once the scene is loaded.
    pub fn validate(&self) -> Result<(), HarnessError> {
        if self.alphas.is_empty() {
            return Err(
                SettingError::new("--alpha", "at least one value in [0, 1]", "none").into(),
            );
        }
        for &a in &self.alphas {
            unit_interval("--alpha", a)?;
        }
        self.truth.check()?;
        for (i, a) in self.axes.iter().enumerate() {
            a.axis.check(&a.values)?;
            if self.axes[..i].iter().any(|o| o.axis.name == a.axis.name) {
                return Err(SettingError::new(a.axis.flag, "one list", "two").into());
            }
        }
        if let Some(sh) = self.shard
            && !(sh.count >= 1 && sh.count <= MAX_SHARDS && sh.index < sh.count)
        {
            return Err(SettingError::new(
                "--shard",
                format!("I/N with N in [1, {MAX_SHARDS}] and I in [0, N)"),
                sh,
            )
            .into());
        }
        let points = 1 + self.axes.iter().fold(
            self.methods.len().saturating_mul(self.alphas.len()),
            |n, a| n.saturating_mul(a.values.len()),
        );
        if points > MAX_POINTS {
            let flags: String = self
                .axes
                .iter()
                .map(|a| format!(" × {}", a.axis.flag))
                .collect();
            let counts: String = self
                .axes
                .iter()
                .map(|a| format!(" × {} {}", a.values.len(), a.axis.what))
                .collect();
            return Err(SettingError::new(
                &format!("--methods × their axes × --alpha{flags}"),
                format!("at most {MAX_POINTS} points"),
                format!(
                    "{} configured methods × {} α{counts} = {points} points",
                    self.methods.len(),
                    self.alphas.len()
                ),
            )
            .into());
        }
        Ok(())
    }
}

/// Why a sweep failed. [`HarnessError::is_refusal`] tells the user's input (exit 2) from
/// everything else (exit 1).
#[derive(Debug, thiserror::Error)]
pub enum HarnessError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A point's configuration is refused before any work (too many passes, …).
    #[error("{point}: {source}")]
    Refused { point: String, source: PlanError },
    #[error(transparent)]
    Raster(#[from] RasterError),
    #[error("{}: {source}", .path.display())]
    OutputFolder {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {source}", .path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(transparent)]
    Image(#[from] ImageError),
    #[error(transparent)]
    Metrics(#[from] MetricsError),
    #[error("a result could not be encoded: {0}")]
    Encode(#[from] serde_json::Error),
    /// A sweep setting out of range, worded as `trace` and `render` word it.
    #[error(transparent)]
    Setting(#[from] SettingError),
    /// An output file could not be written, or the output folder is in use.
    #[error(transparent)]
    File(#[from] FileError),
    /// A sequence sweep's setting out of range.
    #[error("{0}")]
    Sequence(String),
    /// A render worker could not be run or failed.
    #[error("render worker: {0}")]
    Worker(String),
    /// A render worker refused its point (exit 2: a resource beyond the device or a budget).
    #[error("{0}")]
    WorkerRefused(String),
    /// `--symmetry-planes` asks for more planes than the scene has, or the bake is refused.
    #[error("--symmetry-planes: {0}")]
    SymmetryPlanes(#[from] mirrorbox_scene::symmetry::SymmetryError),
    /// A file of the exchange (`export-views`, `score`) refused: the file or field, and why.
    #[error("{0}")]
    Exchange(String),
    /// At a swept reflectance (or the truth's threshold) the scene's light images exceed
    /// their budget.
    #[error("{}: {source}", .scene.display())]
    LightImages {
        scene: PathBuf,
        source: mirrorbox_scene::light_images::TooManyLightImages,
    },
}

impl HarnessError {
    pub fn is_refusal(&self) -> bool {
        match self {
            HarnessError::Scene(_)
            | HarnessError::Refused { .. }
            | HarnessError::Setting(_)
            | HarnessError::WorkerRefused(_)
            | HarnessError::SymmetryPlanes(_)
            | HarnessError::LightImages { .. }
            | HarnessError::OutputFolder { .. }
            | HarnessError::Exchange(_)
            | HarnessError::Sequence(_) => true,
            HarnessError::Raster(e) => e.is_refusal(),
            HarnessError::File(e) => e.refused,
            _ => false,
        }
    }
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> HarnessError + '_ {
    move |source| HarnessError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Untimed rounds before the timed ones: every point renders one frame (no warm-up before
/// it), and none of it is kept. The first round after a sweep's shaders are compiled ran
/// slower for some methods than for others — on lavapipe the paper's `auxiliary` n = 2 took
/// 21–26 ms in the first round and about 15 ms after it while `portal` did not change (the
/// `table1-runs` records of issue 54, frames kept in round order) — which biased the paired
/// ratios. One frame per point settles it as well as its warm-up and timed frames did
/// (table1, three runs each way interleaved on the 2-core Intel Xeon: per-point medians
/// ×0.98, 0.94–1.04, within the runs' own spread; docs/budgets.md).
pub const SETTLING_ROUNDS: u32 = 1;

/// The seed of the per-round shuffles of interleaved timing.
pub const INTERLEAVE_SEED: u64 = 2026;

/// Progress of a sweep.
pub enum Event<'a> {
    /// `todo` points will be computed, `reused` were already in results.jsonl.
    Planned {
        todo: usize,
        reused: usize,
    },
    /// A point's truth is being traced or read from the cache.
    Started {
        label: &'a str,
    },
    /// A point renders in the untimed settling round ([`SETTLING_ROUNDS`]).
    Settling {
        label: &'a str,
    },
    /// A point renders its frame of timing round `round` (1-based) of `rounds`.
    Timing {
        label: &'a str,
        round: u32,
        rounds: u32,
    },
    Finished {
        record: &'a Record,
    },
    /// A point is left out: this adapter lacks a feature its method needs (`reason`).
    Unsupported {
        label: &'a str,
        reason: &'a str,
    },
    /// A point is left out: its plan or its method refused it (`reason`), with
    /// [`SweepConfig::drop_refused`].
    Refused {
        label: &'a str,
        method: &'a Method,
        reason: &'a str,
    },
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Summary {
    pub computed: usize,
    pub reused: usize,
    pub truths_traced: usize,
    pub truths_cached: usize,
    /// Points left out because the adapter lacks a feature their method needs.
    pub unsupported: usize,
    /// Points left out because their plan or method refused them
    /// ([`SweepConfig::drop_refused`]).
    pub refused: usize,
}

struct Point {
    method: Option<Method>,
    alpha: f32,
    /// The point's setting of the sweep's scene axes (none for the floor, nor for the
    /// stereo axis' `mono`).
    axes: PointAxes,
    key: String,
    label: String,
    slug: String,
}

/// The resume key of a point: the method's stable [`Method::key`], then the α, size, SSAA,
/// frames and scene. Frozen: earlier `results.jsonl` files resume by it.
/// A symmetry-planes sweep adds `|planes=p` after the method, a mirrored-lights sweep
/// `|mirrored_lights=k`, a tilt `|bump_deg=a`, a stereo pair `|stereo_ipd=d` (keys without
/// them are as before; a mono point of an `--ipd` sweep has a plain key).
fn point_key(method: Option<&Method>, alpha: f32, axes: &PointAxes, common: &str) -> String {
    let fragments: String = axes
        .iter()
        .map(|(a, v)| format!("|{}={}", a.name, a.text(*v)))
        .collect();
    match method {
        Some(m) => format!("{}{fragments}|alpha={alpha}|{common}", m.key()),
        None => format!("floor|{common}"),
    }
}

fn points(config: &SweepConfig, base_hash: u64, w: u32, h: u32) -> Vec<Point> {
    let common = format!(
        "{w}x{h}|ssaa={}|frames={}|scene={base_hash:016x}",
        config.ssaa, config.frames
    );
    let mut out = vec![Point {
        method: None,
        alpha: 1.0,
        axes: Vec::new(),
        key: point_key(None, 1.0, &Vec::new(), &common),
        label: "floor (no mirrors)".into(),
        slug: "floor".into(),
    }];
    // Every combination of the axes' values, the first axis (in AXES order) outermost.
    let mut settings: Vec<PointAxes> = vec![Vec::new()];
    for spec in axes::AXES {
        let Some(a) = config.axes.iter().find(|a| a.axis.name == spec.name) else {
            continue;
        };
        settings = settings
            .iter()
            .flat_map(|s| {
                a.values.iter().map(move |v| {
                    let mut s = s.clone();
                    if let Some(v) = v {
                        s.push((spec, *v));
                    }
                    s
                })
            })
            .collect();
    }
    for &alpha in &config.alphas {
        for setting in &settings {
            for method in &config.methods {
                let key = point_key(Some(method), alpha, setting, &common);
                // A value listed twice (`--depth 1,1`, `--alpha 0.7,0.7`) is one point.
                if out.iter().any(|p| p.key == key) {
                    continue;
                }
                let label: String = setting
                    .iter()
                    .map(|(a, v)| format!("{}{}{}", a.label, a.text(*v), a.unit))
                    .collect();
                let slug: String = setting
                    .iter()
                    .map(|(a, v)| format!("_{}{}", a.slug, a.text(*v)))
                    .collect();
                out.push(Point {
                    key,
                    label: format!("{method}{label} α={alpha}"),
                    slug: format!("{}{slug}_a{alpha}", method.slug()),
                    method: Some(method.clone()),
                    alpha,
                    axes: setting.clone(),
                });
            }
        }
    }
    out
}

pub(crate) fn cpu_description() -> String {
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
    // A hit needs both files (a sweep killed between them once left an EXR alone).
    if path.is_file()
        && path.with_extension("png").is_file()
        && let Ok(img) = read_image(&path)
    {
        summary.truths_cached += 1;
        if !mask_path(&path).is_file() {
            // A truth cached before masks were kept.
            let bvh = SceneBvh::build(&scene.geometry);
            write_mask(scene, &bvh, config, &path)?;
        }
        return Ok((img, path));
    }
    // Light images are pruned at the truth's own threshold, as its eye paths are.
    let relit;
    let scene = if scene.lighting.mirrored_lights > 0
        && scene.lighting.images.min_throughput != t.min_throughput
    {
        let mut s = scene.clone();
        s.enumerate_light_images(t.min_throughput)
            .map_err(|source| HarnessError::LightImages {
                scene: scene.source.clone(),
                source,
            })?;
        relit = s;
        &relit
    } else {
        scene
    };
    let bvh = SceneBvh::build(&scene.geometry);
    let settings = TraceSettings::whitted(config.ssaa).with_integrator(*t);
    let out = mirrorbox_trace::render(scene, &bvh, &settings, &|_| {});
    // Both files or neither.
    let mut staged = StagedFiles::new();
    stage_exr(
        &mut staged,
        &path,
        &out.image,
        &[("mirrorbox.cache_key", format!("{:016x}", key.finish()))],
    )?;
    stage_png(
        &mut staged,
        &path.with_extension("png"),
        &out.image,
        scene.camera.exposure,
    )?;
    staged.commit()?;
    write_mask(scene, &bvh, config, &path)?;
    summary.truths_traced += 1;
    Ok((out.image, path))
}

/// The truth of `scene` with at most `reflections` reflections (the terminal radiance
/// beyond, as `trace --max-depth`), from the cache when present; the full truth's own file
/// when `reflections` reaches its depth.
fn truth_at_depth(
    scene: &Scene,
    config: &SweepConfig,
    reflections: usize,
    cache: &Path,
    summary: &mut Summary,
) -> Result<PathBuf, HarnessError> {
    let depth = u32::try_from(reflections).unwrap_or(u32::MAX);
    let mut truncated = config.clone();
    truncated.truth.max_depth = depth.min(config.truth.max_depth);
    Ok(truth(scene, &truncated, cache, summary)?.1)
}

/// A point's [`ErrorSplit`]: the truncated truth against the full one, the raster against
/// the truncated one, over the whole image and over the full truth's mirror pixels.
fn error_split(
    full: &Path,
    truncated: &Path,
    raster: &Path,
    exposure: f32,
    reflections: usize,
) -> Result<ErrorSplit, HarnessError> {
    let (full_image, truncated_image) = (read_image(full)?, read_image(truncated)?);
    let raster_image = read_image(raster)?;
    let mask = read_mask(full)
        .map(|(m, _)| m)
        .filter(|m| m.len() == raster_image.pixels.len());
    let part = |reference: &RgbImage, test: &RgbImage| -> Result<_, HarnessError> {
        let c = compare_detailed(reference, test, exposure)?;
        let mirror = mask
            .as_ref()
            .and_then(|m| c.masked(reference, test, m))
            .map(|m| metric_values(&m));
        Ok((metric_values(&c.metrics), mirror))
    };
    let (truncation, truncation_mirror) = part(&full_image, &truncated_image)?;
    let (approximation, approximation_mirror) = part(&truncated_image, &raster_image)?;
    Ok(ErrorSplit {
        reflections,
        truncation,
        truncation_mirror,
        approximation,
        approximation_mirror,
    })
}

/// Where the mirror masks of the cached truth `truth` are kept: red where a pixel shows a
/// mirror ([`mirrorbox_trace::mirror_mask`]), green where most of its mirror samples reflect
/// something off screen ([`mirrorbox_trace::reflections_off_screen`]). (`.mask.png`, red only,
/// was the name before the green channel: a cache holding only that one gets the new file.)
fn mask_path(truth: &Path) -> PathBuf {
    truth.with_extension("mirrors.png")
}

/// Writes the mirror masks of `scene`'s truth on the sweep's sub-pixel grid beside `truth`.
fn write_mask(
    scene: &Scene,
    bvh: &SceneBvh,
    config: &SweepConfig,
    truth: &Path,
) -> Result<(), HarnessError> {
    let grid = mirrorbox_scene::camera::SubpixelGrid::new(config.ssaa);
    let mask = mirrorbox_trace::mirror_mask(scene, bvh, grid);
    let off = mirrorbox_trace::reflections_off_screen(scene, bvh, grid);
    let bytes: Vec<u8> = mask
        .iter()
        .zip(&off)
        .flat_map(|(&m, &o)| [if m { 255 } else { 0 }, if o { 255 } else { 0 }, 0])
        .collect();
    write_png_bytes(
        &mask_path(truth),
        scene.camera.width,
        scene.camera.height,
        &bytes,
    )?;
    Ok(())
}

/// The mirror masks beside a cached truth (mirror pixels, reflections off screen), if kept.
fn read_mask(truth: &Path) -> Option<(Vec<bool>, Vec<bool>)> {
    let img = read_image(&mask_path(truth)).ok()?;
    Some(img.pixels.iter().map(|p| (p[0] > 0.5, p[1] > 0.5)).unzip())
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
        clean.push_str(&serde_json::to_string(r)?);
        clean.push('\n');
    }
    Ok(write_atomically(results, clean.as_bytes())?)
}

/// Where point `i`'s last render waits between the timing rounds and the reports (in the
/// sweep's `cache/`, which is not kept in git), named per process.
fn rendered_image(cache: &Path, i: usize) -> PathBuf {
    cache.join(format!(".render-{}-{i}.exr", std::process::id()))
}

/// The albedo of the sweep's `--marker` object, checked against the scene.
fn marker_albedo(config: &SweepConfig, scene: &Scene) -> Result<Option<[f32; 3]>, HarnessError> {
    let Some(name) = &config.marker else {
        return Ok(None);
    };
    match scene.albedo_of(name) {
        Some(a) => Ok(Some(a.to_array())),
        None => Err(SettingError::new(
            "--marker",
            format!(
                "the name of a diffuse object of {} (its `name`)",
                config.scene.display()
            ),
            format!("{name:?}"),
        )
        .into()),
    }
}

/// Where a point's pictures go: the raster, its FLIP map and its truth (a stereo point: side
/// by side, with the raster's and the truth's anaglyphs beside them, `_anaglyph`).
struct ViewFiles {
    raster: PathBuf,
    heat: PathBuf,
    truth: PathBuf,
}

/// A point's comparison: its metrics (a stereo pair: the mean of both eyes') and, for a pair,
/// each eye's.
struct Compared {
    metrics: MetricValues,
    /// Over the mirror pixels (mono points with a mask that has any).
    mirror_metrics: Option<MetricValues>,
    mirror_pixel_share: Option<f64>,
    reflection_offscreen_share: Option<f64>,
    eyes: Option<Vec<mirrorbox_report::EyeRecord>>,
}

/// Compares each view's raster (EXR, `rasters`) with its truth (`truths`: one, or a stereo
/// pair's two, left first) and writes the pictures of `files`; with `marker` (an albedo),
/// finds the marker's first reflection in each eye of a pair.
fn compare_views(
    truths: &[PathBuf],
    rasters: &[PathBuf],
    exposure: f32,
    marker: Option<[f32; 3]>,
    files: &ViewFiles,
) -> Result<Compared, HarnessError> {
    let mut metrics = Vec::new();
    let mut pictures: Vec<[Vec<u8>; 3]> = Vec::new();
    let mut eyes = Vec::new();
    let (mut w, mut h) = (0, 0);
    for (eye, (truth_path, raster_path)) in truths.iter().zip(rasters).enumerate() {
        let truth = read_image(truth_path)?;
        let raster = read_image(raster_path)?;
        (w, h) = (raster.width, raster.height);
        let comparison = compare_detailed(&truth, &raster, exposure)?;
        let m = metric_values(&comparison.metrics);
        let heat: Vec<u8> = comparison
            .flip_map
            .iter()
            .flat_map(|&v| colormap::heat(v))
            .collect();
        if truths.len() == 1 {
            let masks = read_mask(truth_path).filter(|(m, _)| m.len() == raster.pixels.len());
            let mask = masks.as_ref().map(|(m, _)| m.clone());
            let reflection_offscreen_share = masks.as_ref().and_then(|(m, off)| {
                let mirrors = m.iter().filter(|v| **v).count();
                (mirrors > 0).then(|| off.iter().filter(|v| **v).count() as f64 / mirrors as f64)
            });
            let mirror_metrics = mask
                .as_ref()
                .and_then(|mask| comparison.masked(&truth, &raster, mask))
                .map(|m| metric_values(&m));
            let mirror_pixel_share = mask
                .as_ref()
                .map(|m| m.iter().filter(|v| **v).count() as f64 / m.len().max(1) as f64);
            // Mono: the raster's PNG from its linear image, the truth's copied from the cache.
            write_png(&files.raster, &raster, exposure)?;
            write_png_bytes(&files.heat, w, h, &heat)?;
            let source = truth_path.with_extension("png");
            mirrorbox_files::write_atomically_with(&files.truth, |tmp| {
                std::fs::copy(&source, tmp)
                    .map(|_| ())
                    .map_err(|e| format!("cannot copy {}: {e}", source.display()))
            })?;
            return Ok(Compared {
                metrics: m,
                mirror_metrics,
                mirror_pixel_share,
                reflection_offscreen_share,
                eyes: None,
            });
        }
        let blob = |img: &RgbImage| {
            marker.and_then(|a| {
                mirrorbox_image::stereo::marker_blob(&img.pixels, img.width, a).map(|b| {
                    mirrorbox_report::MarkerRecord {
                        x: b.x,
                        y: b.y,
                        pixels: b.pixels,
                    }
                })
            })
        };
        eyes.push(mirrorbox_report::EyeRecord {
            eye: mirrorbox_scene::stereo::Eye::BOTH[eye].name().into(),
            metrics: m.clone(),
            marker: blob(&raster),
            truth_marker: blob(&truth),
        });
        metrics.push(m);
        pictures.push([comparison.reference_srgb8, comparison.test_srgb8, heat]);
    }
    let [[t_l, r_l, h_l], [t_r, r_r, h_r]] = &pictures[..] else {
        unreachable!("a stereo point has two eyes");
    };
    let sbs = |a: &[u8], b: &[u8]| mirrorbox_image::stereo::side_by_side(a, b, w, h);
    write_png_bytes(&files.raster, 2 * w, h, &sbs(r_l, r_r))?;
    write_png_bytes(&files.heat, 2 * w, h, &sbs(h_l, h_r))?;
    write_png_bytes(&files.truth, 2 * w, h, &sbs(t_l, t_r))?;
    for (file, l, r) in [(&files.raster, r_l, r_r), (&files.truth, t_l, t_r)] {
        let anaglyph = mirrorbox_image::stereo::anaglyph(l, r);
        write_png_bytes(&with_stem_suffix(file, "anaglyph"), w, h, &anaglyph)?;
    }
    Ok(Compared {
        metrics: MetricValues::mean(&metrics),
        mirror_metrics: None,
        mirror_pixel_share: None,
        reflection_offscreen_share: None,
        eyes: Some(eyes),
    })
}

/// A sweep (or a merge) creates its own folder `out`, inside one that must exist (as every
/// command's outputs): a mistyped path is refused, not created.
pub(crate) fn check_output_parent(out: &Path) -> Result<(), HarnessError> {
    let parent = mirrorbox_files::folder_of(out);
    if parent.is_dir() {
        return Ok(());
    }
    Err(HarnessError::OutputFolder {
        path: out.to_path_buf(),
        source: std::io::Error::new(
            std::io::ErrorKind::NotFound,
            format!("folder {} does not exist", parent.display()),
        ),
    })
}

/// An output folder refused, and why (exit 2, the folder named first).
pub(crate) fn folder_refused(dir: &Path, why: String) -> HarnessError {
    HarnessError::OutputFolder {
        path: dir.to_path_buf(),
        source: std::io::Error::other(why),
    }
}

/// Checks a folder the sweep writes into (`flag`: `--out`, `--truth-cache`), before any
/// work: its parent exists (a mistyped folder is refused, not created with its parents) and
/// it is not a file. Before, a file was read as a folder (exit 1, "Not a directory").
pub(crate) fn check_output_folder(flag: &str, dir: &Path) -> Result<(), HarnessError> {
    let refuse = |why: String| folder_refused(dir, why);
    if dir.exists() && !dir.is_dir() {
        return Err(refuse(format!(
            "{flag} names a file; name a folder (created if missing)"
        )));
    }
    let parent = mirrorbox_files::folder_of(dir);
    if !parent.is_dir() {
        return Err(refuse(format!(
            "{flag}: folder {} does not exist (only the last folder is created)",
            parent.display()
        )));
    }
    Ok(())
}

/// The files by which a folder holds a report, by kind: a sweep's (`sweep`, `merge`,
/// `score`), a sequence sweep's (`sweep --path`), an advice's. The checks that refuse a
/// folder of another kind ([`merge`], [`sequence`]) name them from here.
pub(crate) const SWEEP_FILES: [&str; 2] = ["results.jsonl", "sweep.json"];
pub(crate) const SEQUENCE_FILES: [&str; 2] = ["frames.jsonl", "motion.json"];
pub(crate) const ADVICE_FILES: [&str; 1] = ["advice.json"];

/// Refuses a sweep into a folder whose records were measured on another scene, size,
/// sub-pixel grid or number of frames: a folder holds one scene at one size (its report's
/// heading names one, and its pictures are named by method and axes alone, so a second
/// scene's would replace the first's under the first's numbers). Before, such a sweep was
/// accepted and `report` then mixed the two. More methods, values or α into the same folder
/// are the resumable sweep's purpose, and stay accepted (`--fresh` starts the folder anew).
fn check_same_sweep(
    out: &Path,
    records: &[Record],
    base_hash: u64,
    (width, height): (u32, u32),
    config: &SweepConfig,
) -> Result<(), HarnessError> {
    let hash = format!("{base_hash:016x}");
    let Some(r) = records.iter().find(|r| {
        r.scene_hash != hash
            || (r.width, r.height) != (width, height)
            || r.ssaa != config.ssaa
            || r.frames != config.frames
    }) else {
        return Ok(());
    };
    let described = |scene: &str, hash: &str, w: u32, h: u32, ssaa: u32, frames: u32| {
        let frames = if frames == 1 {
            "1 frame".to_string()
        } else {
            format!("{frames} frames")
        };
        format!("{scene} (content {hash}) at {w}×{h}, ssaa {ssaa}, {frames}")
    };
    Err(folder_refused(
        out,
        format!(
            "holds points of {} (results.jsonl, point {:?}); this sweep is of {}: one folder \
             holds one scene at one size, grid and frame count — name another --out, or pass \
             --fresh to discard its points",
            described(&r.scene, &r.scene_hash, r.width, r.height, r.ssaa, r.frames),
            r.key,
            described(
                &config.scene.display().to_string(),
                &hash,
                width,
                height,
                config.ssaa,
                config.frames
            ),
        ),
    ))
}

/// Whether `path`, as a file we read names it (views.json's truths, a record's pictures),
/// stays inside the folder it is relative to: not empty, relative, no `..` — so that joined
/// to that folder it can neither read nor write outside it.
pub(crate) fn is_inner_path(path: &str) -> bool {
    use std::path::Component;
    let p = Path::new(path);
    p.components().any(|c| matches!(c, Component::Normal(_)))
        && p.components()
            .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
}

/// Every picture a record names, relative to its sweep folder.
pub(crate) fn record_pictures(r: &Record) -> Vec<&str> {
    let mut out = vec![
        r.truth_image.as_str(),
        r.raster_image.as_str(),
        r.heatmap_image.as_str(),
    ];
    if let Some(s) = &r.stereo {
        out.extend([s.anaglyph_image.as_str(), s.truth_anaglyph_image.as_str()]);
    }
    out.retain(|p| !p.is_empty());
    out
}

/// Checks the pictures a record of the sweep folder `dir` names before they are copied
/// (`merge`, `score --with`): each is a file inside `dir/images/` — a record is an input, and
/// `../x.txt` joined to the output folder wrote outside it.
pub(crate) fn check_record_pictures(dir: &Path, r: &Record) -> Result<(), String> {
    for picture in record_pictures(r) {
        let path = Path::new(picture);
        if !is_inner_path(picture) || !path.starts_with("images") || path.iter().count() < 2 {
            return Err(format!(
                "{}: point {:?} names the picture {picture:?}; a sweep's pictures are in its \
                 images/ folder (a relative path without ..)",
                dir.join("results.jsonl").display(),
                r.key
            ));
        }
        // A regular file, not a link: a link in images/ could name any file to be copied.
        let regular = std::fs::symlink_metadata(dir.join(path)).is_ok_and(|m| m.is_file());
        if !regular {
            return Err(format!(
                "{}: point {:?} names the picture {picture:?}, which is not a file there (a \
                 regular file, not a link)",
                dir.display(),
                r.key
            ));
        }
    }
    Ok(())
}

/// The method every floor point renders the mirror-free scene with: one scene pass.
pub const FLOOR_METHOD: &str = "naive";

/// A point's comparison with its truth, done after the timing rounds: what its record needs.
struct PointImages {
    views: Compared,
    split: Option<ErrorSplit>,
    files: ViewFiles,
    /// A stereo point's IPD.
    ipd: Option<f32>,
}

/// Compares point `p`'s last raster (`raster`, and its right eye's beside it for a stereo
/// point) with its truths, writes its pictures into `images`, splits a mono point's error
/// at `depth` against `truncated` (its truth cut there), and removes the rasters.
#[allow(clippy::too_many_arguments)]
fn compare_point(
    p: &Point,
    raster: &Path,
    truths: &[PathBuf],
    truncated: Option<&Path>,
    depth: usize,
    exposure: f32,
    marker: Option<[f32; 3]>,
    images: &Path,
) -> Result<PointImages, HarnessError> {
    let mut rasters = vec![raster.to_path_buf()];
    let ipd = p
        .axes
        .iter()
        .find(|(a, _)| a.name == axes::STEREO_IPD.name)
        .map(|(_, d)| *d as f32);
    if ipd.is_some() {
        rasters.push(worker::right_eye_image(raster));
    }
    let truth_name = match &p.method {
        None => "floor".into(),
        Some(_) => {
            let axes: String = p
                .axes
                .iter()
                .map(|(a, v)| format!("{}{}_", a.slug, a.text(*v)))
                .collect();
            format!("{axes}a{}", p.alpha)
        }
    };
    let files = ViewFiles {
        raster: images.join(format!("{}.png", p.slug)),
        heat: images.join(format!("{}_flip.png", p.slug)),
        // One truth per α (and per plane count, light depth, tilt, IPD).
        truth: images.join(format!("truth_{truth_name}.png")),
    };
    let views = compare_views(truths, &rasters, exposure, marker, &files)?;
    let split = match (truncated, truths) {
        (Some(truncated), [full]) => {
            Some(error_split(full, truncated, &rasters[0], exposure, depth)?)
        }
        _ => None,
    };
    for r in &rasters {
        let _ = std::fs::remove_file(r);
    }
    Ok(PointImages {
        views,
        split,
        files,
        ipd,
    })
}

/// A point's scene (mirrors removed for the floor, reflectance α) and render settings.
fn point_setup(
    base: &Scene,
    p: &Point,
    config: &SweepConfig,
) -> Result<(Scene, RenderSettings), HarnessError> {
    let scene = worker::point_scene(base, p.method.is_none(), &p.axes, p.alpha)?;
    let method = p
        .method
        .clone()
        .unwrap_or_else(|| Method::named(FLOOR_METHOD).expect("the floor method is registered"));
    let settings = RenderSettings {
        method,
        ssaa: config.ssaa,
        frames: config.frames,
        warmup: config.warmup,
    };
    Ok((scene, settings))
}

/// The sweep's scene at its size (`--width/--height` over the camera's), and that size.
fn base_scene(config: &SweepConfig) -> Result<(Scene, u32, u32), HarnessError> {
    config.validate()?;
    let mut base = load_scene(&config.scene)?;
    if let Some(view) = &config.camera {
        base = exchange::view_scene(&base, view)?;
    }
    check_compared_scene(
        &mut base,
        (config.width, config.height),
        RenderSettings {
            method: Method::named(FLOOR_METHOD).expect("the floor method is registered"),
            ssaa: config.ssaa,
            frames: config.frames,
            warmup: config.warmup,
        },
    )?;
    marker_albedo(config, &base)?;
    let (w, h) = (base.camera.width, base.camera.height);
    Ok((base, w, h))
}

/// Sizes `scene` by `--width` / `--height` and checks what a sweep compares with its truth:
/// each side at least SSIM's window, and `settings` (the floor method's, with the sweep's
/// `--ssaa`, `--frames` and `--warmup`) in range. Shared by `sweep` and `sweep --path`, so
/// both refuse the same input before any work.
pub(crate) fn check_compared_scene(
    base: &mut Scene,
    (width, height): (Option<u32>, Option<u32>),
    settings: RenderSettings,
) -> Result<(), HarnessError> {
    let min = mirrorbox_image::metrics::MIN_SIDE;
    // A side given as a flag is held to the range of these commands (their help's), not the
    // general one a renderer would name.
    for (flag, side) in [("--width", width), ("--height", height)] {
        if let Some(side) =
            side.filter(|s| !(min..=mirrorbox_scene::limits::MAX_IMAGE_SIDE).contains(s))
        {
            return Err(SettingError::new(
                flag,
                format!(
                    "in [{min}, {}] pixels where an image is compared with its truth (SSIM's \
                     window)",
                    mirrorbox_scene::limits::MAX_IMAGE_SIDE
                ),
                side,
            )
            .into());
        }
    }
    base.resize(width, height)?;
    for (flag, side) in [
        (
            "the image width (--width or camera.width)",
            base.camera.width,
        ),
        (
            "the image height (--height or camera.height)",
            base.camera.height,
        ),
    ] {
        if side < min {
            return Err(SettingError::new(
                flag,
                format!(
                    "at least {min} pixels where an image is compared with its truth \
                     (SSIM's window)"
                ),
                side,
            )
            .into());
        }
    }
    settings.check(base)?;
    Ok(())
}

/// The resume keys of every point of `config` (the floor first), in sweep order, without
/// rendering anything.
pub fn point_keys(config: &SweepConfig) -> Result<Vec<String>, HarnessError> {
    let (base, w, h) = base_scene(config)?;
    Ok(points(config, base.content_hash(), w, h)
        .into_iter()
        .map(|p| p.key)
        .collect())
}

/// Whether `e` is a method's refusal to render a point (its plan's limits), not a failure of
/// the device, the files or the settings.
fn refused_by_method(e: &HarnessError) -> bool {
    match e {
        HarnessError::Raster(r) => r.is_refusal(),
        HarnessError::WorkerRefused(_) => true,
        _ => false,
    }
}

/// Whether point `p`'s frame fits the sweep's memory budget by the plan's estimate (planned
/// on the CPU, the plan dropped): [`run_sweep`]'s check before any work.
fn fits_memory(
    base: &Scene,
    p: &Point,
    config: &SweepConfig,
) -> Result<Result<(), PlanError>, HarnessError> {
    let (scene, settings) = point_setup(base, p, config)?;
    Ok(worker::plan_point(&scene, &settings)
        .and_then(|planned| planned.check_memory(&scene, &settings, config.memory_budget)))
}

/// The current UTC time, RFC 3339 to the second.
pub(crate) fn now_rfc3339() -> String {
    humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string()
}

/// Runs (or resumes) the sweep and writes its reports; `fresh` discards the points already
/// in `results.jsonl` first (cached truths stay). The output folder is locked for the whole
/// run: a second sweep into it is refused at once, naming the process that holds it.
pub fn run_sweep(
    config: &SweepConfig,
    fresh: bool,
    progress: &mut dyn FnMut(Event),
) -> Result<Summary, HarnessError> {
    // Points are timed together only within one run (and one shard: shards may start in the
    // same second on several machines).
    let run_started = match config.shard {
        Some(sh) => format!("{} shard {sh}", now_rfc3339()),
        None => now_rfc3339(),
    };
    let (base, w, h) = base_scene(config)?;
    let base_hash = base.content_hash();
    let every_point = points(config, base_hash, w, h);
    let point_keys: Vec<String> = match config.shard {
        Some(_) => every_point.iter().map(|p| p.key.clone()).collect(),
        None => Vec::new(),
    };
    let all: Vec<Point> = every_point
        .into_iter()
        .filter(|p| config.shard.is_none_or(|s| s.owns(&p.key)))
        .collect();
    let out = &config.out;
    check_output_folder("--out", out)?;
    if let Some(cache) = &config.truth_cache {
        check_output_folder("--truth-cache", cache)?;
    }
    let results = out.join("results.jsonl");
    let still_to_do = |done: &[Record]| -> Vec<&Point> {
        all.iter()
            .filter(|p| !done.iter().any(|r| r.key == p.key))
            .collect()
    };
    // Refuse over-budget points before any work: plan every point still to do on the CPU
    // (and drop the plan; it is made again when the point is rendered, so memory stays one
    // point's). Nothing is written before this.
    let done_before = if fresh {
        Vec::new()
    } else {
        read_records(&results)?
    };
    check_same_sweep(out, &done_before, base_hash, (w, h), config)?;
    // With `drop_refused`, a refused point is left out and said instead.
    let mut refused: Vec<&str> = Vec::new();
    for p in still_to_do(&done_before) {
        if let Err(source) = fits_memory(&base, p, config)? {
            match &p.method {
                Some(method) if config.drop_refused => {
                    progress(Event::Refused {
                        label: &p.label,
                        method,
                        reason: &source.to_string(),
                    });
                    refused.push(&p.key);
                }
                _ => {
                    return Err(HarnessError::Refused {
                        point: p.label.clone(),
                        source,
                    });
                }
            }
        }
    }
    let (images, cache) = (out.join("images"), out.join("cache"));
    let truth_cache = config.truth_cache.clone().unwrap_or_else(|| cache.clone());
    for d in [out, &images, &cache, &truth_cache] {
        std::fs::create_dir_all(d).map_err(|source| HarnessError::OutputFolder {
            path: d.to_path_buf(),
            source,
        })?;
    }
    let _lock = FolderLock::try_acquire(out)?;
    if fresh && results.exists() {
        std::fs::remove_file(&results).map_err(io(&results))?;
    }
    // Read again under the lock: the points done now (a subset of what was planned).
    let existing = read_records(&results)?;
    salvage(&results, &existing)?;
    let todo = still_to_do(&existing);
    let reused = all.len() - todo.len();
    let todo: Vec<&Point> = todo
        .into_iter()
        .filter(|p| !refused.contains(&p.key.as_str()))
        .collect();
    let gpu = Gpu::new()?;
    // A method this adapter cannot run (ray queries on a GPU without them) is left out and
    // said, not fatal to the other methods: its points stay to do, for a run on an adapter
    // that has the feature.
    let mut unsupported: Vec<String> = Vec::new();
    let todo: Vec<&Point> = todo
        .into_iter()
        .filter(|p| {
            let Some(Err(why)) = p.method.as_ref().map(|m| m.entry().check_features(&gpu)) else {
                return true;
            };
            let why = why.to_string();
            progress(Event::Unsupported {
                label: &p.label,
                reason: &why,
            });
            if !unsupported.contains(&why) {
                unsupported.push(why);
            }
            false
        })
        .collect();
    let mut summary = Summary {
        reused,
        unsupported: all.len() - reused - refused.len() - todo.len(),
        refused: refused.len(),
        ..Default::default()
    };
    progress(Event::Planned {
        todo: todo.len(),
        reused: summary.reused,
    });
    // Truths first (traced or from the cache), so that timing rounds run back to back; and
    // each point's render job, the same in every round. Only paths are kept: a sweep may
    // have thousands of points.
    let mut truths = Vec::with_capacity(todo.len());
    let mut jobs = Vec::with_capacity(todo.len());
    // Rendering in this process, each point's scene is made once and kept for its rounds
    // (a few thousand triangles each); a worker makes it again from the file.
    let mut scenes = Vec::with_capacity(todo.len());
    for (i, p) in todo.iter().enumerate() {
        progress(Event::Started { label: &p.label });
        let (scene, settings) = point_setup(&base, p, config)?;
        // A stereo point: each eye's truth.
        let mut paths = Vec::new();
        match worker::eye_scenes(&scene) {
            Some(eyes) => {
                for eye in &eyes {
                    paths.push(truth(eye, config, &truth_cache, &mut summary)?.1);
                }
            }
            None => paths.push(truth(&scene, config, &truth_cache, &mut summary)?.1),
        }
        truths.push(paths);
        jobs.push(RenderJob {
            scene: config.scene.clone(),
            width: w,
            height: h,
            floor: p.method.is_none(),
            alpha: p.alpha,
            method: worker::method_text(&settings.method),
            ssaa: config.ssaa,
            frames: 1,
            warmup: config.warmup,
            scene_hash: scene.content_hash(),
            image: rendered_image(&cache, i),
            camera: config.camera.clone(),
            axes: p
                .axes
                .iter()
                .map(|(a, v)| (a.name.to_string(), *v))
                .collect(),
        });
        if config.worker.is_none() {
            scenes.push(scene);
        }
    }
    let Rounds {
        mut timing,
        mut last,
        dropped,
    } = time_in_rounds(&todo, &jobs, &scenes, &gpu, config, &mut summary, progress)?;
    // Every point shares the base scene's camera, hence its exposure.
    let exposure = base.camera.exposure;
    let marker = marker_albedo(config, &base)?;
    // Each mono point's truth cut at the depth its method reached (the error split), traced
    // one after another (each trace runs on every core) or read from the cache.
    let mut truncated: Vec<Option<PathBuf>> = Vec::with_capacity(todo.len());
    for (i, p) in todo.iter().enumerate() {
        truncated.push(match (&p.method, truths[i].as_slice(), &last[i]) {
            (Some(_), [_], Some(report)) if !dropped[i] => {
                let (scene, _) = point_setup(&base, p, config)?;
                let at = report.depth;
                Some(truth_at_depth(
                    &scene,
                    config,
                    at,
                    &truth_cache,
                    &mut summary,
                )?)
            }
            _ => None,
        });
    }
    // Then every point's images compared and their pictures written, the points spread over
    // the cores (each comparison runs on one): the rounds above are over, nothing is timed.
    let compared: Vec<Option<Result<PointImages, HarnessError>>> = (0..todo.len())
        .into_par_iter()
        .map(|i| {
            if dropped[i] {
                return None;
            }
            let report = last[i]
                .as_ref()
                .expect("every point renders in every round");
            Some(compare_point(
                todo[i],
                &jobs[i].image,
                &truths[i],
                truncated[i].as_deref(),
                report.depth,
                exposure,
                marker,
                &images,
            ))
        })
        .collect();
    let point_run = PointRun {
        scene_hash: base_hash,
        size: (w, h),
        run: &run_started,
    };
    for ((i, p), compared) in todo.iter().enumerate().zip(compared) {
        let Some(compared) = compared else {
            continue;
        };
        let report = last[i].take().expect("every point renders in every round");
        let record = point_record(
            p,
            config,
            &point_run,
            &report,
            std::mem::take(&mut timing[i]),
            compared?,
        );
        let line = serde_json::to_string(&record)?;
        let mut f = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&results)
            .map_err(io(&results))?;
        f.write_all(format!("{line}\n").as_bytes())
            .and_then(|()| f.sync_data())
            .map_err(io(&results))?;
        summary.computed += 1;
        progress(Event::Finished { record: &record });
    }
    // Every record of the folder, as `mirrorbox report` writes it: the sweep's report had
    // shown this configuration's points only, and `report` then all of them (the points of
    // an earlier configuration are marked as reused from an earlier run).
    let records = read_records(&results)?;
    // This run's description; where it measured nothing, with the date, commit and machine
    // of the run that measured the points — its CPU, adapter, driver, Mesa's shader cache
    // (which moves lavapipe's timings: issue 54) and versions — not this run's (a resumed
    // sweep had stamped them with its own). The rest is this run's: its command, shard and
    // the methods its adapter left out.
    let mut info = sweep_info(config, &gpu, (w, h), point_keys, unsupported);
    if summary.computed == 0
        && let Ok(before) = mirrorbox_report::folder::read_sweep_info(out)
    {
        (info.date, info.commit) = (before.date, before.commit);
        (info.cpu, info.adapter, info.backend) = (before.cpu, before.adapter, before.backend);
        (info.device_type, info.driver) = (before.device_type, before.driver);
        (info.shader_cache, info.versions) = (before.shader_cache, before.versions);
    }
    write_atomically(
        &out.join("sweep.json"),
        serde_json::to_string_pretty(&info)?.as_bytes(),
    )?;
    write_report(out, &info, &records, &config.sections)?;
    Ok(summary)
}

/// Each point's timing over the rounds, its last round's report (its image waits on disk,
/// not in memory), and whether its method refused to render it
/// ([`SweepConfig::drop_refused`]).
struct Rounds {
    timing: Vec<PointTiming>,
    last: Vec<Option<RenderReport>>,
    dropped: Vec<bool>,
}

/// Times the points `todo` (their render `jobs`, and their `scenes` where rendered in this
/// process) interleaved: `frames` rounds after the settling ones; in each, every point renders
/// its warm-up frames and one timed frame, the points in an order shuffled per round (fixed
/// seed). Drift of a shared machine then spreads over every point alike instead of landing
/// on a few.
fn time_in_rounds(
    todo: &[&Point],
    jobs: &[RenderJob],
    scenes: &[Scene],
    gpu: &Gpu,
    config: &SweepConfig,
    summary: &mut Summary,
    progress: &mut dyn FnMut(Event),
) -> Result<Rounds, HarnessError> {
    let mut timing: Vec<PointTiming> = todo.iter().map(|_| PointTiming::default()).collect();
    let mut last: Vec<Option<RenderReport>> = todo.iter().map(|_| None).collect();
    let mut dropped = vec![false; todo.len()];
    let mut order: Vec<usize> = (0..todo.len()).collect();
    let mut rng = mirrorbox_report::stats::Rng::new(INTERLEAVE_SEED);
    for round in 0..SETTLING_ROUNDS + config.frames {
        let settling = round < SETTLING_ROUNDS;
        let round = round.saturating_sub(SETTLING_ROUNDS);
        rng.shuffle(&mut order);
        for &i in &order {
            let p = todo[i];
            if dropped[i] {
                continue;
            }
            progress(if settling {
                Event::Settling { label: &p.label }
            } else {
                Event::Timing {
                    label: &p.label,
                    round: round + 1,
                    rounds: config.frames,
                }
            });
            // The settling round draws one frame per point (no warm-up before it): what it
            // settles is each point's first draw after its shaders are compiled.
            let settling_job;
            let job = if settling {
                settling_job = RenderJob {
                    warmup: 0,
                    ..jobs[i].clone()
                };
                &settling_job
            } else {
                &jobs[i]
            };
            let rendered = match &config.worker {
                Some(exe) => worker::render_in_worker(exe, job, &p.label),
                None => worker::render_scene(job, &scenes[i], gpu).and_then(|rendered| {
                    // Only the last round's image is compared; the others are not written.
                    if !settling && round + 1 == config.frames {
                        worker::write_images(job, rendered)
                    } else {
                        Ok(rendered.report)
                    }
                }),
            };
            let report = match (rendered, &p.method) {
                (Ok(report), _) => report,
                (Err(e), Some(method)) if config.drop_refused && refused_by_method(&e) => {
                    progress(Event::Refused {
                        label: &p.label,
                        method,
                        reason: &e.to_string(),
                    });
                    dropped[i] = true;
                    summary.refused += 1;
                    continue;
                }
                (Err(e), _) => return Err(e),
            };
            timing[i].peak = timing[i].peak.max(report.peak_memory_bytes);
            if settling {
                continue;
            }
            timing[i].frames_ms.extend(&report.frames_ms);
            timing[i].plans_ms.push(report.plan_ms);
            timing[i].encodes_ms.extend(&report.encode_ms);
            last[i] = Some(report);
        }
    }
    Ok(Rounds {
        timing,
        last,
        dropped,
    })
}

/// A point's timing over the rounds: its timed frames, peak memory, and CPU plan and encode
/// times.
#[derive(Default)]
struct PointTiming {
    frames_ms: Vec<f64>,
    peak: Option<u64>,
    plans_ms: Vec<f64>,
    encodes_ms: Vec<f64>,
}

/// What every point of one run shares in its record.
struct PointRun<'a> {
    scene_hash: u64,
    size: (u32, u32),
    /// When the run started (and its shard): points are timed together only within one.
    run: &'a str,
}

/// Point `p`'s record: its last round's `report`, its `timing` over the rounds and its
/// images as compared.
fn point_record(
    p: &Point,
    config: &SweepConfig,
    run: &PointRun,
    report: &RenderReport,
    timing: PointTiming,
    compared: PointImages,
) -> Record {
    let PointImages {
        views,
        split,
        files,
        ipd,
    } = compared;
    let PointTiming {
        frames_ms,
        peak,
        plans_ms,
        encodes_ms,
    } = timing;
    let rel = |q: &Path| {
        q.strip_prefix(&config.out)
            .unwrap_or(q)
            .to_string_lossy()
            .into_owned()
    };
    let s = report;
    let interval = mirrorbox_report::stats::median_interval(&frames_ms);
    Record {
        key: p.key.clone(),
        kind: if p.method.is_some() { "point" } else { "floor" }.into(),
        scene: config.scene.display().to_string(),
        scene_hash: format!("{:016x}", run.scene_hash),
        method: p.method.as_ref().map_or("floor", |m| m.name()).into(),
        method_options: p
            .method
            .as_ref()
            .map_or(String::new(), Method::variant_options),
        axes: p
            .axes
            .iter()
            .map(|(a, v)| (a.name.to_string(), *v))
            .collect(),
        values: [
            (value::COPIES_DRAWN, s.copies.map(|c| c.drawn as f64)),
            (value::COPIES_TOTAL, s.copies.map(|c| c.total as f64)),
            (value::BAKE_MS, s.bake_ms),
            (
                value::REFLECTION_OFFSCREEN_SHARE,
                views.reflection_offscreen_share,
            ),
        ]
        .into_iter()
        .filter_map(|(name, v)| Some((name.to_string(), v?)))
        .collect(),
        legacy: Default::default(),
        n: p.method.as_ref().and_then(|m| m.count_of("n")),
        depth: p.method.as_ref().and_then(|m| m.count_of("depth")),
        alpha: p.alpha,
        width: run.size.0,
        height: run.size.1,
        ssaa: config.ssaa,
        ms_median: mirrorbox_report::stats::median(&frames_ms),
        ms_min: frames_ms.iter().copied().fold(f64::INFINITY, f64::min),
        ms_interval: interval.map(|i| [i.low, i.high]),
        frames_ms,
        timing_order: "interleaved".into(),
        run: Some(run.run.to_string()),
        peak_memory_bytes: peak,
        plan_ms: Some(mirrorbox_report::stats::median(&plans_ms)),
        encode_ms: Some(mirrorbox_report::stats::median(&encodes_ms)),
        gpu_buffer_bytes: Some(s.gpu_buffer_bytes),
        gpu_texture_bytes: Some(s.gpu_texture_bytes),
        timing_source: s.timing_source.clone(),
        frames: config.frames,
        passes: s.passes,
        draws: s.draws,
        texture_renders: s.texture_renders,
        reflections: s.depth,
        triangles: Some(s.triangles),
        paths: s.paths_kept,
        paths_pruned: s.paths_pruned,
        metrics: views.metrics,
        mirror_metrics: views.mirror_metrics,
        mirror_pixel_share: views.mirror_pixel_share,
        split,
        adapter: s.adapter.clone(),
        backend: s.backend.clone(),
        color_format: s.color_format.clone(),
        truth_image: rel(&files.truth),
        raster_image: rel(&files.raster),
        heatmap_image: rel(&files.heat),
        device: None,
        stereo: views.eyes.map(|eyes| mirrorbox_report::StereoRecord {
            ipd: ipd.unwrap_or(0.0),
            eyes,
            anaglyph_image: rel(&with_stem_suffix(&files.raster, "anaglyph")),
            truth_anaglyph_image: rel(&with_stem_suffix(&files.truth, "anaglyph")),
        }),
    }
}

/// The description of a sweep's run ([`SweepInfo`], `sweep.json`): its command, machine,
/// adapter, versions, scene, size and truth; `point_keys`, every point's key where the run is
/// a shard; `unsupported`, why this adapter left methods out.
fn sweep_info(
    config: &SweepConfig,
    gpu: &Gpu,
    (w, h): (u32, u32),
    point_keys: Vec<String>,
    unsupported: Vec<String>,
) -> SweepInfo {
    SweepInfo {
        command: config.command.clone(),
        date: now_rfc3339(),
        cpu: cpu_description(),
        adapter: gpu.report.name.clone(),
        backend: gpu.report.backend.clone(),
        device_type: gpu.report.device_type.clone(),
        driver: format!("{} {}", gpu.report.driver, gpu.report.driver_info)
            .trim()
            .to_string(),
        shader_cache: gpu.report.shader_cache().unwrap_or_default().to_string(),
        commit: source_commit(),
        records_commit: String::new(),
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
        exact_methods: METHODS
            .iter()
            .filter(|e| e.exact)
            .map(|e| e.name.to_string())
            .collect(),
        bump_methods: METHODS
            .iter()
            .filter(|e| {
                e.options
                    .iter()
                    .any(|o| std::ptr::eq(*o, &mirrorbox_raster::uneven::BUMP))
            })
            .map(|e| e.name.to_string())
            .collect(),
        shard: config.shard.map(|s| s.to_string()),
        point_keys,
        shards: Vec::new(),
        unsupported,
    }
}

/// The commit of the checkout the running binary was built in (`git describe --always`, run
/// beside the executable), with `-dirty` when its code differs from that commit — the sources,
/// shaders, scenes, scripts and tools, not `reports/`, which a main job rewrites as it goes:
/// what a report's figures name as the code that measured them. Empty outside a git checkout,
/// unless `MIRRORBOX_SOURCE_COMMIT` says it: a binary carried to a machine without the
/// repository's history (the lent GPU, `scripts/gpu-prepare.sh`) names its commit so.
pub fn source_commit() -> String {
    if let Some(commit) = std::env::var("MIRRORBOX_SOURCE_COMMIT")
        .ok()
        .filter(|c| !c.trim().is_empty())
    {
        return commit.trim().to_string();
    }
    let Some(dir) = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().map(Path::to_path_buf))
    else {
        return String::new();
    };
    let git = |args: &[&str]| git_output(&dir, args);
    let Some(commit) = git(&["describe", "--always", "--abbrev=10"]) else {
        return String::new();
    };
    let code = [
        ":/crates",
        ":/shaders",
        ":/scenes",
        ":/scripts",
        ":/tools",
        ":/Cargo.toml",
        ":/Cargo.lock",
    ];
    let mut status = vec!["status", "--porcelain", "--"];
    status.extend(code);
    match git(&status) {
        Some(changes) if !changes.is_empty() => format!("{commit}-dirty"),
        _ => commit,
    }
}

/// The trimmed standard output of `git -C dir ARGS`, or `None` where git fails (not a
/// checkout, no git): what the reports' commits are read with.
pub fn git_output(dir: &Path, args: &[&str]) -> Option<String> {
    std::process::Command::new("git")
        .arg("-C")
        .arg(dir)
        .args(args)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A compared image's side: a flag is held to [11, 16384] under its own name, the scene
    /// camera's (no flag) under the camera's field; both before any work.
    #[test]
    fn a_compared_side_is_refused_under_the_name_it_was_given() {
        let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mirror_box.json");
        let settings = RenderSettings {
            method: Method::named(FLOOR_METHOD).unwrap(),
            ssaa: 1,
            frames: 1,
            warmup: 0,
        };
        let check = |base: &mut Scene, size| {
            check_compared_scene(base, size, settings.clone()).map_err(|e| e.to_string())
        };
        let base = load_scene(&scene).unwrap();
        for (size, expected) in [
            (
                (Some(0), None),
                "--width must be in [11, 16384] pixels where an image is compared",
            ),
            ((None, Some(10)), "--height must be in [11, 16384]"),
            ((Some(16385), None), "--width must be in [11, 16384]"),
        ] {
            let e = check(&mut base.clone(), size).unwrap_err();
            assert!(e.contains(expected), "{size:?}: {e}");
        }
        let mut small = base.clone();
        small.camera.width = 8;
        let e = check(&mut small, (None, None)).unwrap_err();
        assert!(
            e.contains("camera.width) must be at least 11 pixels"),
            "{e}"
        );
        assert_eq!(check(&mut small, (Some(11), Some(11))), Ok(()));
    }

    /// A point its method refuses to render (`unrolled` at depth 256 in the four-mirror room
    /// at α = 1: 83 M triangles per frame, above the limit that `Unrolled::new` checks once the
    /// frame's instances are built; its plan passes) ends the sweep, as wrong settings do; with
    /// `drop_refused` (advise's rounds) it is left out and said, and the other points are
    /// measured.
    #[test]
    fn a_point_its_method_refuses_is_left_out_when_asked() {
        let out = tempfile::tempdir().unwrap();
        let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mirror_room.json");
        let refused = Method::parse("unrolled depth=256").unwrap();
        let mut config = SweepConfig::new(
            scene,
            out.path().join("sweep"),
            vec![Method::parse("naive").unwrap(), refused.clone()],
            vec![1.0],
        );
        (config.width, config.height, config.frames, config.warmup) = (Some(320), Some(180), 1, 0);
        let err = run_sweep(&config, true, &mut |_| {}).unwrap_err();
        assert!(refused_by_method(&err), "{err}");
        config.drop_refused = true;
        let mut said = Vec::new();
        let summary = run_sweep(&config, true, &mut |e| {
            if let Event::Refused { method, reason, .. } = e {
                said.push((method.clone(), reason.to_string()));
            }
        })
        .unwrap();
        assert_eq!(summary.refused, 1);
        assert_eq!(said.len(), 1);
        assert_eq!(said[0].0, refused);
        assert!(said[0].1.contains("triangles"), "{}", said[0].1);
        let records = read_records(&out.path().join("sweep/results.jsonl")).unwrap();
        let keys: Vec<&str> = records.iter().map(|r| r.method_key()).collect();
        assert_eq!(keys, ["floor", "naive"]);
    }

    /// A folder holds one scene at one size: a second sweep into it at another size, frame
    /// count or of another scene is refused before any work, its records untouched; one
    /// that adds an α to the same scene and size is a resumed sweep, accepted.
    #[test]
    fn a_sweep_into_a_folder_of_another_scene_or_size_is_refused() {
        let out = tempfile::tempdir().unwrap();
        let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let config = |scene: &str, width: u32, frames: u32, alpha: f32| {
            let mut c = SweepConfig::new(
                scenes.join(scene),
                out.path().join("sweep"),
                vec![Method::parse("naive").unwrap()],
                vec![alpha],
            );
            (c.width, c.height, c.frames, c.warmup) = (Some(width), Some(18), frames, 0);
            c
        };
        run_sweep(&config("mirror_box.json", 32, 1, 0.5), false, &mut |_| {}).unwrap();
        let results = out.path().join("sweep/results.jsonl");
        let before = std::fs::read(&results).unwrap();
        // The same sweep again measures nothing, and keeps the date, commit and machine of
        // the run that measured its points (marked here as another machine's, with Mesa's
        // shader cache in another state, to tell them from this run's).
        let info = out.path().join("sweep/sweep.json");
        let mut described =
            mirrorbox_report::folder::read_sweep_info(&info.with_file_name("")).unwrap();
        described.cpu = "the measuring CPU".into();
        described.adapter = "the measuring adapter".into();
        described.driver = "the measuring driver".into();
        described.shader_cache = "the measuring run's shader cache".into();
        described.versions = "the measuring versions".into();
        std::fs::write(&info, serde_json::to_string_pretty(&described).unwrap()).unwrap();
        std::thread::sleep(std::time::Duration::from_millis(1100));
        let again = run_sweep(&config("mirror_box.json", 32, 1, 0.5), false, &mut |_| {}).unwrap();
        assert_eq!(again.computed, 0);
        let now = mirrorbox_report::folder::read_sweep_info(&info.with_file_name("")).unwrap();
        let machine = |i: &SweepInfo| {
            let fields = [&i.cpu, &i.adapter, &i.driver, &i.shader_cache, &i.versions];
            (i.date.clone(), i.commit.clone(), fields.map(String::clone))
        };
        assert_eq!(machine(&now), machine(&described));
        let mut taller = config("mirror_box.json", 32, 1, 0.5);
        taller.height = Some(20);
        let mut finer = config("mirror_box.json", 32, 1, 0.5);
        finer.ssaa = 2;
        for (c, other) in [
            (config("mirror_box.json", 40, 1, 0.5), "at 40×18"),
            (taller, "at 32×20"),
            (finer, "ssaa 2"),
            (config("mirror_box.json", 32, 2, 0.5), "2 frames"),
            (
                config("mirror_room.json", 32, 1, 0.5),
                "scenes/mirror_room.json",
            ),
        ] {
            let e = run_sweep(&c, false, &mut |_| {}).unwrap_err();
            let text = e.to_string();
            assert!(e.is_refusal(), "{text}");
            assert!(
                text.contains("holds points of") && text.contains("at 32×18, ssaa 1, 1 frame"),
                "{text}"
            );
            assert!(
                text.contains(other) && text.contains("one folder holds one scene"),
                "{text}"
            );
            assert_eq!(std::fs::read(&results).unwrap(), before, "{text}");
        }
        let summary =
            run_sweep(&config("mirror_box.json", 32, 1, 0.9), false, &mut |_| {}).unwrap();
        assert_eq!(read_records(&results).unwrap().len(), 3, "{summary:?}");
        // Its report holds every point of the folder, α 0.5's too, as `report` writes it.
        let csv = std::fs::read_to_string(out.path().join("sweep/results.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + 3, "{csv}");
        // `--fresh` (the main job's) discards the folder's points first: accepted.
        run_sweep(&config("mirror_box.json", 40, 1, 0.5), true, &mut |_| {}).unwrap();
        assert_eq!(read_records(&results).unwrap().len(), 2);
    }

    /// Every point renders once in the settling round before its timed rounds, and only the
    /// timed rounds' frames are kept.
    #[test]
    fn a_settling_round_renders_every_point_before_the_timed_rounds_and_is_not_kept() {
        let out = tempfile::tempdir().unwrap();
        let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mirror_box.json");
        let mut config = SweepConfig::new(
            scene,
            out.path().join("sweep"),
            vec![Method::parse("naive").unwrap()],
            vec![0.5],
        );
        (config.width, config.height, config.frames, config.warmup) = (Some(32), Some(18), 2, 0);
        let mut events = Vec::new();
        run_sweep(&config, true, &mut |e| match e {
            Event::Settling { label } => events.push(format!("settle {label}")),
            Event::Timing { label, round, .. } => events.push(format!("time {round} {label}")),
            _ => {}
        })
        .unwrap();
        // The floor and one point: both settle before either is timed.
        assert_eq!(
            events.len(),
            2 * (SETTLING_ROUNDS as usize + 2),
            "{events:?}"
        );
        assert!(
            events[..2].iter().all(|e| e.starts_with("settle")),
            "{events:?}"
        );
        assert!(
            events[2..].iter().all(|e| e.starts_with("time")),
            "{events:?}"
        );
        let records = read_records(&out.path().join("sweep/results.jsonl")).unwrap();
        assert_eq!(records.len(), 2);
        assert!(
            records.iter().all(|r| r.frames_ms.len() == 2),
            "{records:?}"
        );
    }
}
