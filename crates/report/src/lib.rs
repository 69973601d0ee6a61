//! Sweep results and the reports made from them. This crate knows records, files and text —
//! nothing about renderers or GPUs.
//!
//! - [`Record`]: one measured point (one JSON line of `results.jsonl`).
//! - [`write_report`]: `results.csv`, `report.md`, a self-contained `report.html` and the SVG
//!   plots, with the sections the caller offers (each experiment's own, from the registry of
//!   `mirrorbox-experiments`, which also holds every experiment's regions).
//! - [`readme`]: the README's figures, generated from the committed reports.

pub mod book_figures;
pub mod document;
mod error;
pub mod folder;
mod image_rows;
pub mod overview;
pub mod plot;
pub mod readme;
pub mod sequence;
pub mod split;
pub mod stats;
mod write;

pub use document::{Block, Section};

pub use folder::{MAX_SWEEP_JSON_BYTES, Sweep, load_sweep, read_sweep_info, rewrite_report};
pub use readme::read_lines;
pub use write::{floor_paragraph, read_records, write_report};

use serde::{Deserialize, Serialize};

/// Error metrics of one comparison (see `mirrorbox_image::metrics`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MetricValues {
    pub rmse: f64,
    pub relmse: f64,
    pub smape: f64,
    pub max_abs: f64,
    /// `None` when the images are identical (infinite PSNR).
    pub psnr: Option<f64>,
    pub ssim: f64,
    pub flip_mean: f64,
    pub flip_p95: f64,
    pub flip_p99: f64,
}

impl MetricValues {
    /// The mean of each metric over `views` (a stereo pair's eyes); PSNR only where every view
    /// has one.
    pub fn mean(views: &[MetricValues]) -> MetricValues {
        let n = views.len().max(1) as f64;
        let mean = |f: fn(&MetricValues) -> f64| views.iter().map(f).sum::<f64>() / n;
        MetricValues {
            rmse: mean(|m| m.rmse),
            relmse: mean(|m| m.relmse),
            smape: mean(|m| m.smape),
            max_abs: views.iter().map(|m| m.max_abs).fold(0.0, f64::max),
            psnr: views
                .iter()
                .map(|m| m.psnr)
                .sum::<Option<f64>>()
                .map(|s| s / n),
            ssim: mean(|m| m.ssim),
            flip_mean: mean(|m| m.flip_mean),
            flip_p95: mean(|m| m.flip_p95),
            flip_p99: mean(|m| m.flip_p99),
        }
    }
}

/// A stereo point (issue 17): both eyes rendered as one frame, each against its own truth.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StereoRecord {
    /// Interpupillary distance, scene units.
    pub ipd: f32,
    /// Left, then right.
    pub eyes: Vec<EyeRecord>,
    /// The raster's and the truth's red–cyan anaglyphs.
    pub anaglyph_image: String,
    pub truth_anaglyph_image: String,
}

impl StereoRecord {
    /// The marker's disparity in the pair, pixels (`x_right − x_left`, positive behind the
    /// convergence plane): of the raster's pictures, or with `truth` of the truth's.
    pub fn disparity(&self, truth: bool) -> Option<f64> {
        let at = |k: usize| -> Option<MarkerRecord> {
            let e = self.eyes.get(k)?;
            if truth { e.truth_marker } else { e.marker }
        };
        Some(at(1)?.x - at(0)?.x)
    }
}

/// One eye of a stereo point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EyeRecord {
    pub eye: String,
    /// Against this eye's truth.
    pub metrics: MetricValues,
    /// The sweep's marker (`--marker`) in the raster's and in the truth's picture of this eye:
    /// its first reflection's centroid, `None` where it is not seen.
    pub marker: Option<MarkerRecord>,
    pub truth_marker: Option<MarkerRecord>,
}

/// Where a marker appears: centroid in pixels (x right, y down) and its size in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MarkerRecord {
    pub x: f64,
    pub y: f64,
    pub pixels: usize,
}

fn back_to_back() -> String {
    "back-to-back".into()
}

/// Most milliseconds one frame may take: a day. Any larger is a unit slip, not a frame; a
/// record's or an outside client's (`score`) is refused beyond it.
pub const MAX_FRAME_MS: f64 = 86_400_000.0;

/// One point of a sweep: a method at one setting, timed and compared with the truth.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// Identifies the point; a resumed sweep skips keys it already has.
    pub key: String,
    /// `"point"`, or `"floor"`: raster vs trace on the scene without mirrors.
    pub kind: String,
    pub scene: String,
    pub scene_hash: String,
    pub method: String,
    /// The method's options that are neither swept nor at their default, as
    /// `name=value` words (e.g. `symmetry-draws=per-copy`): a variant of the method with its
    /// own series in the report. Empty in older records.
    #[serde(default)]
    pub method_options: String,
    /// The point's scene axes (the harness's `axes::AXES`), by name: `planes` (symmetry
    /// planes p kept, seed 001), `mirrored_lights` (k, issue 15), `bump_deg` (the uneven
    /// mirrors' steepest tilt, issue 16), `stereo_ipd` (issue 17). Records older than the map
    /// kept them in fields of their own; [`read_records`] moves those here.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub axes: std::collections::BTreeMap<String, f64>,
    /// Numbers a method or an experiment reports of a point beyond the common columns, by
    /// name ([`value`] names them): `copies_drawn` and `copies_total` (the symmetry methods'
    /// copies drawn, and 2^p), `bake_ms` (`symmetry-baked`'s CPU bake, outside the frame
    /// time), `reflection_offscreen_share` (the share of the mirror pixels whose first
    /// reflection is off screen, in [0, 1]: what screen-space reflections cannot show, issue
    /// 39). Records older than the map kept them in fields of their own; [`read_records`]
    /// moves those here.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub values: std::collections::BTreeMap<String, f64>,
    /// The fields of older records that now live in [`Record::axes`] and [`Record::values`]:
    /// read, moved into the maps by [`Record::migrate`], never written.
    #[serde(flatten, skip_serializing)]
    pub legacy: LegacyColumns,
    /// A stereo point (an `--ipd` sweep): the IPD and each eye's comparison; `metrics` is then
    /// the mean of both eyes', the images are side by side, the time is the pair's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stereo: Option<StereoRecord>,
    /// In a merged sweep (`mirrorbox merge`): the device its shard ran on (the shard's
    /// adapter and CPU), so that timings are read per device.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub device: Option<String>,
    /// Auxiliary mirrors (auxiliary method).
    pub n: Option<u32>,
    /// Reflection depth (depth-limited methods).
    pub depth: Option<u32>,
    pub alpha: f32,
    pub width: u32,
    pub height: u32,
    pub ssaa: u32,
    pub ms_median: f64,
    pub ms_min: f64,
    /// The 95 % bootstrap interval of the median, ms ([`stats::median_interval`]); absent in
    /// records older than it.
    #[serde(default)]
    pub ms_interval: Option<[f64; 2]>,
    /// Every timed frame, ms, in the order measured (empty in older records).
    #[serde(default)]
    pub frames_ms: Vec<f64>,
    /// How the frames were timed: `interleaved` (one frame per point per round, round-robin
    /// over the sweep's points in an order shuffled per round, so drift of the machine hits
    /// every point alike) or `back-to-back` (all of a point's frames in a row: older records).
    #[serde(default = "back_to_back")]
    pub timing_order: String,
    /// When the sweep run that measured this point started (UTC, RFC 3339). Frames are
    /// interleaved only among the points of one run: a point reused from an earlier run (a
    /// resumed sweep) was timed beside other points, on the machine of that day, and its frames
    /// pair with no one else's. Absent in older records.
    #[serde(default)]
    pub run: Option<String>,
    /// Peak resident memory of the process that rendered the point (its render worker),
    /// bytes; absent in older records.
    #[serde(default)]
    pub peak_memory_bytes: Option<u64>,
    /// CPU wall time of planning one frame (reflection paths, the paper's recursion), ms,
    /// median over the rounds; GPU timestamps do not include it. Absent in older records.
    #[serde(default)]
    pub plan_ms: Option<f64>,
    /// CPU wall time of encoding and submitting one frame's command buffer (recording every
    /// pass and draw, until `submit` returns), ms, median over the timed frames. Absent in
    /// older records.
    #[serde(default)]
    pub encode_ms: Option<f64>,
    /// GPU memory held by buffers, and by textures, while the point's frame was alive
    /// (wgpu's allocation counters, device-wide in the point's render worker), bytes.
    /// Absent in older records.
    #[serde(default)]
    pub gpu_buffer_bytes: Option<u64>,
    #[serde(default)]
    pub gpu_texture_bytes: Option<u64>,
    pub timing_source: String,
    pub frames: u32,
    pub passes: usize,
    pub draws: usize,
    pub texture_renders: usize,
    /// Reflections the method can show.
    pub reflections: usize,
    /// Triangles submitted per frame (absent in records older than this field).
    #[serde(default)]
    pub triangles: Option<usize>,
    /// Exact methods: reflection paths drawn.
    #[serde(default)]
    pub paths: Option<usize>,
    /// Exact methods: reflection paths pruned (empty or sample-free portal, attenuation,
    /// depth cap).
    #[serde(default)]
    pub paths_pruned: Option<usize>,
    pub metrics: MetricValues,
    /// The same metrics over the mirror pixels only (the pixels whose primary hit in the truth
    /// is a mirror, from the tracer's own object ids): where a method's error lives, undiluted
    /// by the pixels every method gets right. Absent in older records and for stereo points.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mirror_metrics: Option<MetricValues>,
    /// The share of the image's pixels that are mirror pixels, in [0, 1].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mirror_pixel_share: Option<f64>,
    /// The point's error split into what stopping at its reflection count leaves out and what
    /// the method gets wrong of what it shows (issue 50). Absent for the floor, stereo points
    /// and older records.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub split: Option<ErrorSplit>,
    pub adapter: String,
    pub backend: String,
    /// The colour format of the raster targets (`rgba32float`, or `rgba16float` where the
    /// adapter has no float colour buffers). Records older than this field were all rendered
    /// into RGBA32F, the only format then.
    #[serde(default = "rgba32float")]
    pub color_format: String,
    /// Images relative to the sweep folder.
    pub truth_image: String,
    pub raster_image: String,
    pub heatmap_image: String,
}

/// The columns of older records that moved into [`Record::axes`] and [`Record::values`].
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
pub struct LegacyColumns {
    /// Now `axes["planes"]`.
    #[serde(default)]
    symmetry_planes: Option<u32>,
    /// Now `axes["mirrored_lights"]`.
    #[serde(default)]
    mirrored_lights: Option<u32>,
    /// Now `axes["bump_deg"]`.
    #[serde(default)]
    bump_amplitude_deg: Option<f32>,
    /// Now `values["copies_drawn"]`, `values["copies_total"]`, `values["bake_ms"]`.
    #[serde(default)]
    copies_drawn: Option<usize>,
    #[serde(default)]
    copies_total: Option<usize>,
    #[serde(default)]
    bake_ms: Option<f64>,
    /// Now `values["reflection_offscreen_share"]`.
    #[serde(default)]
    reflection_offscreen_share: Option<f64>,
}

/// The names of [`Record::values`].
pub mod value {
    /// Copies of the objects a symmetry method drew, of [`COPIES_TOTAL`].
    pub const COPIES_DRAWN: &str = "copies_drawn";
    /// 2^p: the copies the seed's method draws.
    pub const COPIES_TOTAL: &str = "copies_total";
    /// `symmetry-baked`'s CPU bake, ms, outside the frame time.
    pub const BAKE_MS: &str = "bake_ms";
    /// The share of the mirror pixels whose first reflection is off screen, in [0, 1].
    pub const REFLECTION_OFFSCREEN_SHARE: &str = "reflection_offscreen_share";
    /// 1 for a scored variant's view at the scene's own camera, the one our sweeps show
    /// (`mirrorbox score`; absent in scores made before it was kept).
    pub const SCENE_CAMERA: &str = "scene_camera";
    /// 1 for a scored variant of an export whose mirrors share no one grey reflectance (they
    /// differ, or are tinted): no one α stands for them, so the record's `alpha` (1) is none,
    /// and reports say "per mirror" ([`crate::Record::alpha_text`]).
    pub const ALPHA_PER_MIRROR: &str = "alpha_per_mirror";
    /// Which `score --with` sweep a record of ours came from (0 the first): each sweep has
    /// its own floor, timed in its own rounds, and a time is set against that one.
    pub const WITH_SWEEP: &str = "with_sweep";
}

/// The time bars one chart draws for all of its `points`: their 95 % intervals where every
/// point has one; else each point's fastest to slowest frame where that draws more bars —
/// some point has frames but no interval (sweeps of five frames have no 95 % interval; a chart
/// showed their medians bare) and no point with an interval lacks frames. A point with
/// neither (one frame, or an outside renderer's record without its frames) draws no bar
/// either way, so it no longer holds a chart of ranged points on intervals. One kind per
/// chart: the axis label says which ([`plot::Chart`]).
pub fn ms_bars_for<'a>(points: impl IntoIterator<Item = &'a Record> + Clone) -> plot::Bars {
    let any = |f: &dyn Fn(&Record) -> bool| points.clone().into_iter().any(f);
    let ranged = |r: &Record| r.ms_bars(plot::Bars::FrameRange).is_some();
    let gains = any(&|r| r.ms_interval.is_none() && ranged(r));
    let loses = any(&|r| r.ms_interval.is_some() && !ranged(r));
    if gains && !loses {
        plot::Bars::FrameRange
    } else {
        plot::Bars::Ci95
    }
}

/// A point's error against the truth, split at the reflection count `reflections` it shows
/// (the method's `FrameStats::depth`): **truncation**, the truth traced with at most that
/// many reflections (the terminal radiance beyond, as `trace --max-depth`) against the full
/// truth — what any method stopping there leaves out; and **approximation**, the method
/// against that truncated truth — what it gets wrong of what it claims to show (for an exact
/// method, edge samples within the rasterizer's sub-pixel grid; for the paper's auxiliary
/// mirrors, what they distort). Over the whole image and over the full truth's mirror pixels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ErrorSplit {
    pub reflections: usize,
    pub truncation: MetricValues,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truncation_mirror: Option<MetricValues>,
    pub approximation: MetricValues,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub approximation_mirror: Option<MetricValues>,
}

/// The names of the scene axes in [`Record::axes`].
pub mod axis {
    pub const PLANES: &str = "planes";
    pub const MIRRORED_LIGHTS: &str = "mirrored_lights";
    pub const BUMP_DEG: &str = "bump_deg";
    pub const STEREO_IPD: &str = "stereo_ipd";
    /// A scored variant's view, by its index in the export's views.json (`mirrorbox score`,
    /// exports of several views); its name is the record key's second field.
    pub const VIEW: &str = "view";
    /// The camera's turn about the vertical, degrees (a `--camera-yaw` sweep, issue 39).
    pub const YAW_DEG: &str = "yaw_deg";

    /// A point's value of axis `name` as a chart labels it: `p=3`, `k=2`, `tilt 5°`,
    /// `yaw 22.5°`, `IPD 0.064`, `view 1`; `name=value` for an axis added later.
    pub fn label(name: &str, value: f64) -> String {
        match name {
            PLANES => format!("p={value}"),
            MIRRORED_LIGHTS => format!("k={value}"),
            BUMP_DEG => format!("tilt {value}°"),
            YAW_DEG => format!("yaw {value}°"),
            STEREO_IPD => format!("IPD {value}"),
            VIEW => format!("view {value}"),
            other => format!("{other}={value}"),
        }
    }
}

impl Record {
    /// The first image field that is not a path inside the sweep folder (relative, every part
    /// a plain name: no root, no `..`), with its name: a report reads, embeds and writes
    /// beside these, so one naming `/etc/passwd` or `../..` must be refused, not followed.
    /// An empty path (no image) is inside.
    pub fn image_outside_folder(&self) -> Option<(&'static str, &str)> {
        let inside = |p: &str| {
            std::path::Path::new(p)
                .components()
                .all(|c| matches!(c, std::path::Component::Normal(_)))
        };
        let mut fields = vec![
            ("truth_image", self.truth_image.as_str()),
            ("raster_image", self.raster_image.as_str()),
            ("heatmap_image", self.heatmap_image.as_str()),
        ];
        if let Some(s) = &self.stereo {
            fields.push(("stereo.anaglyph_image", &s.anaglyph_image));
            fields.push(("stereo.truth_anaglyph_image", &s.truth_anaglyph_image));
        }
        fields.into_iter().find(|(_, p)| !inside(p))
    }

    /// The first number outside what a measurement can be, as `field value (allowed)`: α in
    /// [0, 1]; the median, fastest and every frame's ms in [0, a day]; the image's and the
    /// mirror pixels' errors ≥ 0 (SSIM in [−1, 1]); the mirror pixels' share in [0, 1]. (The
    /// CPU times, the interval and the error split are not checked.) A report drawn from a
    /// hand-edited `results.jsonl` had taken them all.
    pub fn out_of_range(&self) -> Option<String> {
        let ms = |x: f64| (0.0..=MAX_FRAME_MS).contains(&x);
        let ms_range = format!("[0, {MAX_FRAME_MS}] ms");
        let ms_range = ms_range.as_str();
        use mirrorbox_image::MAX_IMAGE_SIDE;
        let sides = format!("[1, {MAX_IMAGE_SIDE}]");
        let sides = sides.as_str();
        let mut checks: Vec<(String, f64, bool, &str)> = vec![
            (
                "alpha".into(),
                f64::from(self.alpha),
                (0.0..=1.0).contains(&self.alpha),
                "[0, 1]",
            ),
            (
                "ms_median".into(),
                self.ms_median,
                ms(self.ms_median),
                ms_range,
            ),
            ("ms_min".into(), self.ms_min, ms(self.ms_min), ms_range),
            // An image's sides (the images' limit).
            (
                "width".into(),
                f64::from(self.width),
                (1..=MAX_IMAGE_SIDE).contains(&self.width),
                sides,
            ),
            (
                "height".into(),
                f64::from(self.height),
                (1..=MAX_IMAGE_SIDE).contains(&self.height),
                sides,
            ),
        ];
        if !["point", "floor"].contains(&self.kind.as_str()) {
            return Some(format!(
                "kind {:?} (allowed: \"point\" or \"floor\")",
                self.kind
            ));
        }
        if let Some(&f) = self.frames_ms.iter().find(|&&f| !ms(f)) {
            checks.push(("frames_ms".into(), f, false, ms_range));
        }
        if let Some(share) = self.mirror_pixel_share {
            checks.push((
                "mirror_pixel_share".into(),
                share,
                (0.0..=1.0).contains(&share),
                "[0, 1]",
            ));
        }
        for (name, m) in [
            ("metrics", Some(&self.metrics)),
            ("mirror_metrics", self.mirror_metrics.as_ref()),
        ] {
            let Some(m) = m else { continue };
            for (metric, v) in [
                ("rmse", m.rmse),
                ("relmse", m.relmse),
                ("smape", m.smape),
                ("max_abs", m.max_abs),
                ("flip_mean", m.flip_mean),
                ("flip_p95", m.flip_p95),
                ("flip_p99", m.flip_p99),
            ] {
                checks.push((format!("{name}.{metric}"), v, v >= 0.0, "≥ 0"));
            }
            checks.push((
                format!("{name}.ssim"),
                m.ssim,
                (-1.0..=1.0).contains(&m.ssim),
                "[−1, 1]",
            ));
        }
        checks
            .into_iter()
            .find(|(_, _, ok, _)| !ok)
            .map(|(field, v, _, allowed)| {
                // 1e300 in full would be three hundred digits.
                let v = if v.abs() < 1e15 {
                    v.to_string()
                } else {
                    format!("{v:e}")
                };
                format!("{field} {v} (allowed: {allowed})")
            })
    }

    /// The value of scene axis `name` ([`axis`]) at this point.
    pub fn axis(&self, name: &str) -> Option<f64> {
        self.axes.get(name).copied()
    }

    /// Symmetry planes p the point's scene kept (a `--symmetry-planes` sweep, seed 001).
    pub fn planes(&self) -> Option<u32> {
        self.axis(axis::PLANES).map(|v| v as u32)
    }

    /// `lighting.mirrored_lights` of the point's scene (a `--mirrored-lights` sweep).
    pub fn lights_depth(&self) -> Option<u32> {
        self.axis(axis::MIRRORED_LIGHTS).map(|v| v as u32)
    }

    /// The steepest tilt of the point's uneven mirrors, degrees (a `--bump-amplitude` sweep).
    pub fn tilt_deg(&self) -> Option<f32> {
        self.axis(axis::BUMP_DEG).map(|v| v as f32)
    }

    /// The point's α as reports print it: the number, or "per mirror" where the mirrors'
    /// reflectances differ ([`value::ALPHA_PER_MIRROR`]).
    pub fn alpha_text(&self) -> String {
        if self.value(value::ALPHA_PER_MIRROR) == Some(1.0) {
            "per mirror".into()
        } else {
            self.alpha.to_string()
        }
    }

    /// The value `name` of [`Record::values`], if the point has it.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.values.get(name).copied()
    }

    /// Moves the columns of a record older than [`Record::axes`] and [`Record::values`] into
    /// the maps.
    pub fn migrate(&mut self) {
        let old = std::mem::take(&mut self.legacy);
        let values = [
            (value::COPIES_DRAWN, old.copies_drawn.map(|c| c as f64)),
            (value::COPIES_TOTAL, old.copies_total.map(|c| c as f64)),
            (value::BAKE_MS, old.bake_ms),
            (
                value::REFLECTION_OFFSCREEN_SHARE,
                old.reflection_offscreen_share,
            ),
        ];
        for (name, v) in values {
            if let Some(v) = v {
                self.values.entry(name.to_string()).or_insert(v);
            }
        }
        let legacy = [
            (axis::PLANES, old.symmetry_planes.map(f64::from)),
            (axis::MIRRORED_LIGHTS, old.mirrored_lights.map(f64::from)),
            // The f32 as its shortest decimal, as the key wrote it.
            (
                axis::BUMP_DEG,
                old.bump_amplitude_deg
                    .map(|a| a.to_string().parse().unwrap_or(f64::from(a))),
            ),
            (
                axis::STEREO_IPD,
                self.stereo
                    .as_ref()
                    .map(|s| s.ipd.to_string().parse().unwrap_or(f64::from(s.ipd))),
            ),
        ];
        for (name, value) in legacy {
            if let Some(v) = value {
                self.axes.entry(name.to_string()).or_insert(v);
            }
        }
    }

    /// The bars of this point's time in a chart drawn with `bars` ([`ms_bars_for`]).
    pub fn ms_bars(&self, bars: plot::Bars) -> Option<[f64; 2]> {
        match bars {
            plot::Bars::Ci95 => self.ms_interval,
            plot::Bars::FrameRange => {
                let lo = self.frames_ms.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = self
                    .frames_ms
                    .iter()
                    .copied()
                    .fold(f64::NEG_INFINITY, f64::max);
                (self.frames_ms.len() >= 2 && lo.is_finite() && hi.is_finite()).then_some([lo, hi])
            }
        }
    }

    /// The 95 % interval of the median time, if the record has one.
    pub fn ms_ci(&self) -> Option<stats::Interval> {
        self.ms_interval
            .map(|[low, high]| stats::Interval { low, high })
    }

    /// The method part of the point's resume key (`portal depth=8`, `ssr ssr-fallback=none`):
    /// what `Method::parse` reads back.
    pub fn method_key(&self) -> &str {
        self.key.split('|').next().unwrap_or_default()
    }

    /// The error a point is judged by: its FLIP mean over the mirror pixels where the mask
    /// was kept, else over the image.
    pub fn mirror_flip(&self) -> f64 {
        self.mirror_metrics
            .as_ref()
            .map_or(self.metrics.flip_mean, |m| m.flip_mean)
    }

    /// Our own floor among `records` (the scene without mirrors, rendered by us): a scored
    /// folder holds the clients' floors too, and the first floor found had been a client's
    /// (a web report's "one full-scene pass" was Babylon's wall-clock time).
    pub fn our_floor(records: &[Record]) -> Option<&Record> {
        records
            .iter()
            .find(|r| r.kind == "floor" && !r.is_external())
    }

    /// The floor `self` is timed beside: a client's own of the same view for its variants,
    /// else ours of the same `score --with` sweep ([`value::WITH_SWEEP`]), at the same size.
    /// Two sweeps' floors are two timings (14 % apart on the web report's box): a time over
    /// another sweep's floor had mixed them.
    pub fn floor_beside<'a>(&self, records: &'a [Record]) -> Option<&'a Record> {
        let size = (self.width, self.height, self.ssaa);
        records.iter().find(|f| {
            f.kind == "floor"
                && (f.width, f.height, f.ssaa) == size
                && f.is_external() == self.is_external()
                && f.scored_client() == self.scored_client()
                && f.scored_view() == self.scored_view()
                && f.value(value::WITH_SWEEP) == self.value(value::WITH_SWEEP)
        })
    }

    /// A variant an outside renderer drew, scored through the exchange (`mirrorbox score`).
    pub fn is_external(&self) -> bool {
        self.timing_order == EXTERNAL_TIMING
    }

    /// A scored variant's client, from its key (`client/variant|view|…`, `mirrorbox score`);
    /// `None` for our own records. Not its method cut at a `-`: a client's name may hold one.
    pub fn scored_client(&self) -> Option<&str> {
        let first = self.key.split('|').next()?;
        self.is_external()
            .then(|| first.split('/').next().unwrap_or(first))
    }

    /// A scored variant's view, from its key's second field; `None` for our own records.
    pub fn scored_view(&self) -> Option<&str> {
        self.key
            .split('|')
            .nth(1)
            .filter(|v| self.is_external() && !v.is_empty())
    }

    /// The value of raster option `name` among the record's non-default options.
    pub fn option(&self, name: &str) -> Option<&str> {
        self.method_options.split_whitespace().find_map(|w| {
            w.split_once('=')
                .filter(|(n, _)| *n == name)
                .map(|(_, v)| v)
        })
    }

    /// The method the point measured, with its swept count and its options except those
    /// named in `omit`: `auxiliary n=2`, `unrolled depth=64`.
    pub fn method_without(&self, omit: &[&str]) -> String {
        let mut words = vec![self.method.clone()];
        if let Some(n) = self.n {
            words.push(format!("n={n}"));
        }
        if let Some(d) = self.depth {
            words.push(format!("depth={d}"));
        }
        words.extend(
            self.method_options
                .split_whitespace()
                .filter(|w| {
                    !w.split_once('=')
                        .is_some_and(|(name, _)| omit.contains(&name))
                })
                .map(String::from),
        );
        words.join(" ")
    }
}

/// The colour format of records written before [`Record::color_format`] existed.
fn rgba32float() -> String {
    "rgba32float".into()
}

/// The `timing_order` of a variant an outside renderer drew (its own clock and rounds,
/// `mirrorbox score`).
pub const EXTERNAL_TIMING: &str = "external";

/// Facts about the whole sweep, printed at the top of every report and kept in the sweep
/// folder's `sweep.json` (which the README's generated regions read).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SweepInfo {
    pub command: String,
    /// UTC, RFC 3339.
    pub date: String,
    pub cpu: String,
    pub adapter: String,
    pub backend: String,
    pub device_type: String,
    /// The adapter's driver and its version (`wgpu::AdapterInfo::driver` and `driver_info`);
    /// empty in sweeps written before it was recorded.
    pub driver: String,
    /// For a Mesa driver, whether its on-disk shader cache was on (lavapipe runs shaders it
    /// loads from there slower than those it compiles: issue 54); empty for other drivers and
    /// in sweeps written before it was recorded.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub shader_cache: String,
    pub versions: String,
    pub scene: String,
    pub resolution: String,
    pub truth: String,
    /// The commit of the mirrorbox that measured the sweep (`git describe`-style, `-dirty`
    /// when the tree had changes); empty in sweeps written before it was recorded, where the
    /// report names the commit that committed the records instead (`records_commit`).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub commit: String,
    /// For a sweep without [`SweepInfo::commit`]: the commit that last committed its records,
    /// found by `mirrorbox report` (not stored).
    #[serde(skip)]
    pub records_commit: String,
    /// The exact methods' names, from the raster registry (the report groups them by depth
    /// and sets them beside the paper's method).
    #[serde(default)]
    pub exact_methods: Vec<String>,
    /// The methods that read uneven mirrors with a trick (their `bump` option), from the
    /// raster registry; the others show an uneven mirror flat (issue 16).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bump_methods: Vec<String>,
    /// A shard of a sweep (`--shard I/N`, issue 20): `"I/N"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<String>,
    /// A shard's whole sweep: every point's resume key, the floor first (what `merge` checks
    /// the shards against: the same configuration, every point once).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub point_keys: Vec<String>,
    /// A merged sweep: where each shard ran and how many points it measured.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shards: Vec<ShardInfo>,
    /// The methods this run's adapter cannot run, each with why (a feature it lacks, e.g.
    /// ray queries on a GPU without them): their points were left out, not measured, and stay
    /// to do for a run on an adapter that has it (issue 57).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub unsupported: Vec<String>,
}

/// One shard of a merged sweep (`mirrorbox merge`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ShardInfo {
    /// `"I/N"`.
    pub shard: String,
    /// The shard's folder, as given to `merge`.
    pub folder: String,
    pub date: String,
    pub cpu: String,
    /// [`SweepInfo::adapter_description`] of the shard.
    pub device: String,
    pub points: usize,
}

impl SweepInfo {
    /// Whether these are a score's records (`mirrorbox score`: outside renderers' images
    /// compared here), not a sweep's.
    pub fn is_score(&self) -> bool {
        self.device_type == "external"
    }

    /// The commit that measured, its hash cut to `digits` with a changed tree's `-dirty` kept
    /// (not that commit's code); `None` where the sweep recorded none.
    pub fn measured_by(&self, digits: usize) -> Option<String> {
        let full = &self.commit;
        let cut = |hash: &str| hash.get(..digits).unwrap_or(hash).to_string();
        match full.split_once('-') {
            _ if full.is_empty() => None,
            Some((hash, rest)) => Some(format!("{}-{rest}", cut(hash))),
            None => Some(cut(full)),
        }
    }

    /// The footer of every chart: scene, size, device, date, commit — what a figure printed
    /// alone must say about where its numbers come from. (A score's writer adds our points'
    /// device, which its description does not hold.)
    pub fn footer(&self) -> String {
        let size = self.resolution.split(',').next().unwrap_or_default().trim();
        let date = self.date.get(..10).unwrap_or(&self.date);
        let commit = if !self.commit.is_empty() {
            format!("commit {}", self.commit)
        } else if !self.records_commit.is_empty() {
            format!("records committed in {}", self.records_commit)
        } else {
            "commit not recorded".to_string()
        };
        let device = if self.is_score() {
            format!("{} (the clients'), scored on {}", self.adapter, self.cpu)
        } else {
            format!("{} ({}) on {}", self.adapter, self.backend, self.cpu)
        };
        format!("{} · {size} · {device} · {date} · {commit}", self.scene)
    }

    /// "adapter NAME (backend, type[, driver D])": the device a sweep's timings belong to.
    pub fn adapter_description(&self) -> String {
        let driver = if self.driver.trim().is_empty() {
            String::new()
        } else {
            format!(", driver {}", self.driver.trim())
        };
        let driver = if self.shader_cache.is_empty() {
            driver
        } else {
            format!("{driver}, {}", self.shader_cache)
        };
        format!(
            "adapter {} ({}, {}{driver})",
            self.adapter, self.backend, self.device_type
        )
    }
}

/// Least-squares line `y = a + b·x`: returns `(a, b)`, or None with fewer than two distinct x.
pub fn linear_fit(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    if points.len() < 2 {
        return None;
    }
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| (my - sxy / sxx * mx, sxy / sxx))
}

#[cfg(test)]
mod structure {
    /// The modules of this crate and the sibling modules each one names (`crate::x`).
    fn imports() -> Vec<(String, Vec<String>)> {
        let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let modules: Vec<String> = std::fs::read_dir(&src)
            .unwrap()
            .flatten()
            .filter_map(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                name.strip_suffix(".rs")
                    .filter(|n| *n != "lib")
                    .map(String::from)
            })
            .collect();
        modules
            .iter()
            .map(|m| {
                let text = std::fs::read_to_string(src.join(format!("{m}.rs"))).unwrap();
                let mut used: Vec<String> = text
                    .split("crate::")
                    .skip(1)
                    .filter_map(|rest| {
                        let name: String = rest
                            .chars()
                            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                            .collect();
                        // `crate::{a, b}` names root items and modules alike.
                        (modules.contains(&name) && name != *m).then_some(name)
                    })
                    .collect();
                used.sort();
                used.dedup();
                (m.clone(), used)
            })
            .collect()
    }

    #[test]
    fn the_report_modules_import_each_other_without_a_circle() {
        let graph = imports();
        // Depth-first search for a back edge; the path to it is the circle.
        fn visit(
            m: &str,
            graph: &[(String, Vec<String>)],
            path: &mut Vec<String>,
            done: &mut Vec<String>,
        ) -> Option<Vec<String>> {
            if let Some(i) = path.iter().position(|p| p == m) {
                let mut circle = path[i..].to_vec();
                circle.push(m.to_string());
                return Some(circle);
            }
            if done.iter().any(|d| d == m) {
                return None;
            }
            path.push(m.to_string());
            let next = graph.iter().find(|(n, _)| n == m).map(|(_, u)| u.clone());
            for u in next.unwrap_or_default() {
                if let Some(c) = visit(&u, graph, path, done) {
                    return Some(c);
                }
            }
            path.pop();
            done.push(m.to_string());
            None
        }
        let (mut path, mut done) = (Vec::new(), Vec::new());
        for (m, _) in &graph {
            if let Some(circle) = visit(m, &graph, &mut path, &mut done) {
                panic!("import circle in crates/report/src: {}", circle.join(" → "));
            }
        }
        // The README's regions use the document model; the document model imports neither
        // them nor the writer.
        let uses = |m: &str| graph.iter().find(|(n, _)| n == m).unwrap().1.clone();
        assert!(uses("readme").contains(&"document".to_string()));
        assert!(!uses("document").contains(&"write".to_string()));
    }
}

#[cfg(test)]
mod floors {
    use super::*;
    use crate::document::fixtures::record;

    /// A point's floor is its own `score --with` sweep's (two sweeps' floors are two timings),
    /// a client's variant its client's, never another size's.
    #[test]
    fn a_point_is_timed_beside_its_own_sweeps_floor() {
        let floor = |ms: f64, with: f64| {
            let mut r = record(0, ms, 1, 0.0);
            r.kind = "floor".into();
            r.values.insert(value::WITH_SWEEP.into(), with);
            r
        };
        let mut point = record(0, 20.0, 1, 0.1);
        point.values.insert(value::WITH_SWEEP.into(), 1.0);
        let mut small = floor(1.0, 1.0);
        small.width /= 2;
        let records = [floor(5.0, 0.0), small, floor(7.0, 1.0)];
        assert_eq!(point.floor_beside(&records).map(|f| f.ms_median), Some(7.0));
        point.values.remove(value::WITH_SWEEP);
        assert_eq!(point.floor_beside(&records), None);
    }
}

#[cfg(test)]
mod commits {
    use super::SweepInfo;

    /// A measuring commit is cut to its digits with `-dirty` kept, and is none where the
    /// sweep recorded none.
    #[test]
    fn a_dirty_commit_keeps_its_mark() {
        let info = |commit: &str| SweepInfo {
            commit: commit.into(),
            ..Default::default()
        };
        assert_eq!(
            info("245f368d8b-dirty").measured_by(7).as_deref(),
            Some("245f368-dirty")
        );
        assert_eq!(
            info("245f368d8b").measured_by(7).as_deref(),
            Some("245f368")
        );
        assert_eq!(info("").measured_by(7), None);
    }
}
