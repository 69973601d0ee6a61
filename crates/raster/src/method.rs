//! The one registry of raster methods.
//!
//! The interface of the raster methods: their implementations are in [`crate::methods`],
//! the table and configured methods in [`crate::registry`].
//!
//! A raster method is one file that implements [`RasterMethod`] and declares one
//! [`MethodEntry`] — its name, one-line help, whether it is exact, the options it accepts
//! (with bounds and defaults), the option a sweep varies, the adapter features it needs, and
//! the function that turns validated [`Params`] into the method's own typed settings — plus
//! one line in [`METHODS`]. Everything else follows from that table: `render --method` and
//! its flags (and the "this flag does not apply to that method" errors), `sweep --methods`
//! and its axes, resume keys, the harness's records and the report's exact-method sections.
//! See `CONTRIBUTING.md`.
//!
//! A configured method is a [`Method`](crate::registry::Method): an entry and a complete, validated set of parameter
//! values. Its `Method::key` is the stable identity sweeps resume by.

use crate::gpu::{Gpu, RasterError};
use crate::memory::MemoryEstimate;
use crate::plan::PlanError;
use mirrorbox_scene::Scene;
use std::fmt;

/// One raster method's row of the table.
pub struct MethodEntry {
    /// The CLI, key and report name.
    pub name: &'static str,
    /// One line for `render --help`.
    pub help: &'static str,
    /// Whether the method claims to match the traced truth (up to its depth cap and edge
    /// samples); reports group exact methods by depth.
    pub exact: bool,
    /// Whether its error (beyond the exact methods' floor) is the reflections it stops short
    /// of: the registry test then holds it nearer the truth at its depth than one shallower.
    /// False for `cubemap`, whose error is parallax at every depth, and `ssr`, whose error is
    /// what the screen does not hold (that test instead holds them to the truth wherever no
    /// mirror is seen).
    pub depth_limited: bool,
    /// The options it accepts, in key order.
    pub options: &'static [&'static OptionSpec],
    /// The option a sweep varies for this method (named in every resume key), if any.
    pub swept: Option<&'static OptionSpec>,
    /// Adapter features used where the adapter has them (the method works without).
    pub optional_features: wgpu::Features,
    /// Adapter features the method cannot run without.
    pub required_features: wgpu::Features,
    /// Its WGSL variants (see [`crate::wgsl`]); all are validated by naga in the tests.
    pub shaders: &'static [&'static crate::wgsl::WgslSource],
    /// Its `#[repr(C)]` GPU structs, checked against their WGSL twins in the tests.
    pub gpu_structs: fn() -> Vec<crate::wgsl::HostLayout>,
    /// The method's typed settings from validated parameters.
    pub configure: fn(&Params) -> Box<dyn RasterMethod>,
    /// How `mirrorbox advise` searches it (issue 55).
    pub advise: Advise,
}

/// How `mirrorbox advise` searches a method for a scene and a frame budget (issue 55): the
/// candidates it is offered, declared in the method's row rather than in the advisor.
#[derive(Clone, Copy, Debug)]
pub enum Advise {
    /// Not a candidate for mirrors (the symmetry-plane methods draw a scene's symmetry
    /// copies, not its mirrors).
    Skip,
    /// One candidate per variant (options as `render` words, `""` for the defaults).
    Fixed(&'static [&'static str]),
    /// Per variant, `option` over its values: the cost rises with the value and the error
    /// does not (more reflections, finer textures). The advisor times `coarse` first (in
    /// ascending order, stopping where a value is over budget), then bisects between the
    /// last value within budget and the first over it.
    Knob {
        option: &'static OptionSpec,
        coarse: &'static [u32],
        variants: &'static [&'static str],
    },
}

impl MethodEntry {
    pub fn accepts(&self, option: &OptionSpec) -> bool {
        self.options.iter().any(|o| o.name == option.name)
    }

    /// Fails unless `gpu` has every feature this method cannot run without (exit 1).
    pub fn check_features(&self, gpu: &Gpu) -> Result<(), RasterError> {
        let missing = self.required_features - gpu.features;
        if missing.is_empty() {
            Ok(())
        } else {
            Err(RasterError::MissingFeature {
                method: self.name,
                feature: crate::gpu::feature_names(missing),
                adapter: format!("{} ({})", gpu.report.name, gpu.report.backend),
            })
        }
    }
}

impl fmt::Debug for MethodEntry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name)
    }
}

impl PartialEq for MethodEntry {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

/// A configured raster method. Its work is split so that anything that may refuse the
/// configuration (too many passes, paths or triangles) happens on the CPU, before any GPU
/// resource exists.
pub trait RasterMethod {
    /// Plans a frame at render resolution `width × height` (output × SSAA).
    fn plan(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
    ) -> Result<Box<dyn PlannedFrame>, PlanError>;

    /// Plans a stereo pair's frame ([`crate::stereo_pair`]); `eyes` differ only in their
    /// cameras. By default each eye is planned as its own frame (seed 002's per-eye mirror
    /// cameras); a method that shares work between the eyes plans them jointly.
    fn plan_pair(
        &self,
        eyes: [&Scene; 2],
        width: u32,
        height: u32,
    ) -> Result<PlannedPair, PlanError> {
        plan_each_eye(self, eyes, width, height)
    }
}

// ---------------------------------------------------------------------------------------
// Stereo pairs (rendered by crate::stereo_pair)

/// A frame that draws both eyes' views, each into its own target.
pub trait PairEncoder {
    /// `first_pass` carries the timestamp write the frame's first pass must attach.
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: [&crate::targets::RenderTarget; 2],
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    );
}

/// A pair planned jointly: one set of GPU resources drawing both eyes.
pub trait PlannedJointPair {
    /// The pair's memory, as [`PlannedFrame::memory`] (both eyes' main passes).
    fn memory(&self, eyes: [&Scene; 2], color_bytes_per_texel: u64) -> MemoryEstimate;

    fn build(
        self: Box<Self>,
        gpu: &Gpu,
        eyes: [&Scene; 2],
        shadows: &crate::shadow_maps::ShadowMaps,
    ) -> Result<BuiltPair, RasterError>;
}

/// A jointly planned pair's resources and counts (passes of both eyes).
pub struct BuiltPair {
    pub encoder: Box<dyn PairEncoder>,
    pub stats: FrameStats,
}

/// How a method plans a stereo pair ([`RasterMethod::plan_pair`]).
pub enum PlannedPair {
    /// Each eye its own frame (left, right).
    Separate([Box<dyn PlannedFrame>; 2]),
    /// One frame drawing both eyes, sharing what the eyes share.
    Joint(Box<dyn PlannedJointPair>),
}

/// Each eye planned as its own frame (the default [`RasterMethod::plan_pair`]).
pub fn plan_each_eye<M: RasterMethod + ?Sized>(
    method: &M,
    eyes: [&Scene; 2],
    width: u32,
    height: u32,
) -> Result<PlannedPair, PlanError> {
    Ok(PlannedPair::Separate([
        method.plan(eyes[0], width, height)?,
        method.plan(eyes[1], width, height)?,
    ]))
}

/// A planned frame, ready to become GPU resources.
pub trait PlannedFrame {
    /// A stateful method (`feedback`) continues from `history`, the state the previous frame
    /// of a sequence left ([`crate::timing::FrameEncoder::history`]), instead of starting
    /// afresh. Stateless methods ignore it.
    fn continue_from(&mut self, _history: crate::timing::FrameHistory) {}

    /// The memory the method's own resources will take when built for `scene`, from the
    /// plan alone (no GPU): its scene buffers, mirror textures and depth targets, uniform
    /// and instance buffers (GPU), and what it keeps on the CPU (host), with colour texels of
    /// `color_bytes_per_texel`. The frame's render target, resolve, readback, shadow maps
    /// and the driver are added by [`crate::Planned::memory_estimate`]. An upper bound of
    /// what `build` creates (wgpu's counters are checked against it in the tests).
    fn memory(&self, scene: &Scene, color_bytes_per_texel: u64) -> MemoryEstimate;

    fn build(
        self: Box<Self>,
        gpu: &Gpu,
        scene: &Scene,
        shadows: &crate::shadow_maps::ShadowMaps,
    ) -> Result<BuiltFrame, RasterError>;
}

/// A method's GPU resources for one frame, what it draws, and what it cannot promise.
pub struct BuiltFrame {
    pub encoder: Box<dyn crate::timing::FrameEncoder>,
    pub stats: FrameStats,
    /// Conditions under which the image may not be what the method promises.
    pub warnings: Vec<String>,
    /// CPU milliseconds spent in planning on baking geometry (`symmetry-baked`'s
    /// split-and-mirror, seed 001): work a real-time renderer redoes only when the planes
    /// change, so it is reported apart from the frame time. Not in [`FrameStats`], whose
    /// counts are the same on every run.
    pub bake_ms: Option<f64>,
}

/// Per-frame counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameStats {
    /// Scene passes: the main view plus one per texture render.
    pub passes: usize,
    pub texture_renders: usize,
    /// Draw calls, including the SSAA resolve's one.
    pub draws: usize,
    /// Deepest chain of textures or reflection path: the reflections the method can show.
    pub depth: usize,
    /// Triangles submitted per frame (each instance counted), before any clipping.
    pub triangles: usize,
    /// Exact methods: the reflection paths drawn and pruned.
    pub paths: Option<PathCounts>,
    /// How a mirror's world is clipped to the mirror's front (and, in `unrolled`, to its
    /// cell).
    pub clipping: Clipping,
    /// The depth (or depth-stencil) format: 32-bit float, except `portal`'s 24-bit fallback on
    /// an adapter without `DEPTH32FLOAT_STENCIL8`.
    pub depth_format: wgpu::TextureFormat,
    /// The symmetry methods (seed 001): the copies of the objects drawn and pruned.
    pub copies: Option<CopyCounts>,
}

/// What a symmetry method (seed 001) drew of the 2^p copies of the objects that p symmetry
/// planes make.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CopyCounts {
    /// Symmetry planes p.
    pub planes: usize,
    /// 2^p.
    pub total: usize,
    /// Copies drawn (instances, or draws with `--symmetry-draws per-copy`).
    pub drawn: usize,
    /// Copies whose cell holds no part of the objects' bounds (`symmetry-pruned`).
    pub pruned_empty: usize,
    /// Copies wholly outside the view frustum (`symmetry-pruned`).
    pub pruned_outside_view: usize,
    /// Object parts drawn with back-face culling: closed, and the eye outside them in every
    /// copy drawn, so culling removes no surface the eye can see first.
    pub culled_parts: usize,
    /// Object parts drawn.
    pub parts: usize,
}

/// How a method clips a mirror's world to the mirror's front (and to its cell).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clipping {
    /// Hardware clip distances (plus, in `unrolled`, the per-fragment guard where a part
    /// needs it).
    ClipDistances,
    /// Every test per fragment, with discard (an adapter without clip distances, or
    /// `unrolled --fragment-clipping`).
    FragmentDiscard,
    /// Nothing is clipped: the method draws a mesh as it is (`symmetry-baked`).
    None,
}

impl Clipping {
    /// Hardware clip distances where the device has them.
    pub fn for_features(features: wgpu::Features) -> Clipping {
        if features.contains(wgpu::Features::CLIP_DISTANCES) {
            Clipping::ClipDistances
        } else {
            Clipping::FragmentDiscard
        }
    }
}

impl Clipping {
    pub fn name(&self) -> &'static str {
        match self {
            Clipping::ClipDistances => "clip distances",
            Clipping::FragmentDiscard => "fragment discard",
            Clipping::None => "none",
        }
    }
}

/// How many reflection paths an exact method kept and why it dropped the others
/// (see `mirrorbox_scene::reflection_paths`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathCounts {
    /// Paths through at least one mirror that are drawn (the camera itself not counted).
    pub kept: usize,
    pub pruned_empty: usize,
    /// Portals holding no sample (exact pruning).
    pub pruned_no_sample: usize,
    /// Portals under `--min-portal-area` (lossy).
    pub pruned_small: usize,
    pub pruned_attenuation: usize,
    /// Paths cut by the depth cap.
    pub capped: usize,
    /// Portals holding pixel centres only where nearer sibling mirrors hide them.
    pub pruned_hidden: usize,
    /// Kept paths part of whose portal a nearer sibling mirror hides (drawn as the rest).
    pub partly_hidden: usize,
}

impl PathCounts {
    pub fn of(set: &mirrorbox_scene::reflection_paths::PathSet) -> Self {
        PathCounts {
            kept: set.paths.len().saturating_sub(1),
            pruned_empty: set.pruned_empty,
            pruned_no_sample: set.pruned_no_sample,
            pruned_small: set.pruned_small,
            pruned_attenuation: set.pruned_attenuation,
            capped: set.capped,
            pruned_hidden: set.pruned_hidden,
            partly_hidden: set.partly_hidden,
        }
    }

    pub fn pruned(&self) -> usize {
        self.pruned_empty
            + self.pruned_no_sample
            + self.pruned_small
            + self.pruned_attenuation
            + self.capped
            + self.pruned_hidden
    }
}

// ---------------------------------------------------------------------------------------
// Options and parameters

/// One option a method accepts: `--NAME VALUE` on `render` and `sweep`.
#[derive(Debug)]
pub struct OptionSpec {
    /// The flag without dashes, and the name in resume keys: `n`, `depth`, `texture-scale`.
    pub name: &'static str,
    pub help: &'static str,
    pub kind: OptionKind,
    pub default: ParamValue,
    /// How a sweep varies it, if it is some method's swept option.
    pub sweep: Option<SweepAxis>,
    /// Whether a non-default value names a different point (resume keys). False for
    /// options that change neither the image nor its timing, such as a refusal limit.
    pub in_key: bool,
}

/// A sweep axis: the values a sweep takes by default and how its error message shows them.
#[derive(Debug)]
pub struct SweepAxis {
    /// Default axis: a range `A..B` (counts only) or a list `a,b,c`.
    pub default: &'static str,
    pub range_example: &'static str,
    pub list_example: &'static str,
    /// What the values are, plural ("counts", "depths").
    pub noun: &'static str,
}

/// The type and bounds of an option's values.
#[derive(Clone, Copy, Debug)]
pub enum OptionKind {
    /// An integer in `[min, max]`.
    Count { min: u32, max: u32 },
    /// A finite real above `min` (`min_open`: strictly above) and at most `max`, if any.
    Real {
        min: f32,
        min_open: bool,
        max: Option<f32>,
    },
    /// A switch: present means true.
    Switch,
    /// One of a few named values.
    Choice { values: &'static [&'static str] },
}

/// One option's value.
#[derive(Clone, Copy, Debug)]
pub enum ParamValue {
    Count(u32),
    Real(f32),
    Switch(bool),
    /// One of an [`OptionKind::Choice`]'s values.
    Choice(&'static str),
}

impl PartialEq for ParamValue {
    /// Reals compare bit for bit, so a key never depends on rounding.
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (ParamValue::Count(a), ParamValue::Count(b)) => a == b,
            (ParamValue::Real(a), ParamValue::Real(b)) => a.to_bits() == b.to_bits(),
            (ParamValue::Switch(a), ParamValue::Switch(b)) => a == b,
            (ParamValue::Choice(a), ParamValue::Choice(b)) => a == b,
            _ => false,
        }
    }
}

impl fmt::Display for ParamValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ParamValue::Count(v) => write!(f, "{v}"),
            ParamValue::Real(v) => write!(f, "{v}"),
            ParamValue::Switch(v) => write!(f, "{v}"),
            ParamValue::Choice(v) => f.write_str(v),
        }
    }
}

/// A parameter that cannot be used; the message names the flag and what is allowed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ParamError {
    #[error("unknown method {name:?} (known: {known})")]
    UnknownMethod { name: String, known: String },
    #[error("--{option} applies to --method {methods} only")]
    NotAccepted { option: String, methods: String },
    #[error("--{option} must be {allowed}, got {got}")]
    OutOfRange {
        option: String,
        allowed: String,
        got: String,
    },
}

impl OptionSpec {
    /// What values are allowed, in words: `in [1, 4096]`, `in (0, 4]`, `≥ 0`, `a switch`.
    pub fn allowed(&self) -> String {
        match self.kind {
            OptionKind::Count { min, max } => format!("in [{min}, {max}]"),
            OptionKind::Real {
                min,
                min_open,
                max: Some(max),
            } => format!("in {}{min}, {max}]", if min_open { "(" } else { "[" }),
            OptionKind::Real {
                min,
                min_open,
                max: None,
            } => format!("{} {min}", if min_open { ">" } else { "≥" }),
            OptionKind::Switch => "a switch (no value)".into(),
            OptionKind::Choice { values } => format!("one of {}", values.join(", ")),
        }
    }

    fn out_of_range(&self, got: impl fmt::Display) -> ParamError {
        ParamError::OutOfRange {
            option: self.name.into(),
            allowed: self.allowed(),
            got: got.to_string(),
        }
    }

    /// Checks a value's type and bounds.
    pub fn check(&self, value: ParamValue) -> Result<ParamValue, ParamError> {
        let ok = match (self.kind, value) {
            (OptionKind::Count { min, max }, ParamValue::Count(v)) => (min..=max).contains(&v),
            (OptionKind::Real { min, min_open, max }, ParamValue::Real(v)) => {
                v.is_finite()
                    && (if min_open { v > min } else { v >= min })
                    && max.is_none_or(|m| v <= m)
            }
            (OptionKind::Switch, ParamValue::Switch(_)) => true,
            (OptionKind::Choice { values }, ParamValue::Choice(v)) => values.contains(&v),
            _ => false,
        };
        if ok {
            Ok(value)
        } else {
            Err(self.out_of_range(value))
        }
    }

    /// Parses and checks one value given on a command line.
    pub fn parse(&self, text: &str) -> Result<ParamValue, ParamError> {
        let t = text.trim();
        let value = match self.kind {
            OptionKind::Count { .. } => t.parse().map(ParamValue::Count).ok(),
            OptionKind::Real { .. } => t.parse().map(ParamValue::Real).ok(),
            OptionKind::Switch => t.parse().map(ParamValue::Switch).ok(),
            OptionKind::Choice { values } => values
                .iter()
                .find(|v| **v == t)
                .map(|v| ParamValue::Choice(v)),
        };
        self.check(value.ok_or_else(|| self.out_of_range(format!("{text:?}")))?)
    }

    /// Parses a sweep axis: a range `A..B` or `A..=B` (both ends included; counts only) or a
    /// list `a,b,c`.
    pub fn parse_axis(&self, text: &str) -> Result<Vec<ParamValue>, String> {
        let axis = self.sweep.as_ref();
        let err = || match axis {
            Some(a) => format!(
                "--{} {text:?}: expected a range like {} or a list like {} of {} {}",
                self.name,
                a.range_example,
                a.list_example,
                a.noun,
                match self.kind {
                    OptionKind::Count { min, max } => format!("{min}..={max}"),
                    _ => self.allowed(),
                }
            ),
            None => format!(
                "--{} {text:?}: expected a list of values {}",
                self.name,
                self.allowed()
            ),
        };
        let values: Vec<ParamValue> = match (self.kind, text.split_once("..")) {
            (OptionKind::Count { .. }, Some((a, b))) => {
                let b = b.strip_prefix('=').unwrap_or(b);
                let a: u32 = a.trim().parse().map_err(|_| err())?;
                let b: u32 = b.trim().parse().map_err(|_| err())?;
                if a > b || b - a > 100_000 {
                    return Err(err());
                }
                (a..=b)
                    .map(|v| self.check(ParamValue::Count(v)).map_err(|_| err()))
                    .collect::<Result<_, _>>()?
            }
            _ => text
                .split(',')
                .map(|x| self.parse(x).map_err(|_| err()))
                .collect::<Result<_, _>>()?,
        };
        if values.is_empty() {
            return Err(err());
        }
        Ok(values)
    }
}

/// A method's complete, validated parameter values, in its entry's option order.
#[derive(Clone, Debug, PartialEq)]
pub struct Params {
    entry: &'static MethodEntry,
    values: Vec<ParamValue>,
}

impl Params {
    /// Every option of `entry` at its default.
    pub(crate) fn defaults(entry: &'static MethodEntry) -> Params {
        Params {
            entry,
            values: entry.options.iter().map(|o| o.default).collect(),
        }
    }

    pub fn entry(&self) -> &'static MethodEntry {
        self.entry
    }

    /// The values, in the entry's option order.
    pub fn values(&self) -> &[ParamValue] {
        &self.values
    }

    /// Sets option `i` of the entry (already checked).
    pub(crate) fn set(&mut self, i: usize, value: ParamValue) {
        self.values[i] = value;
    }

    fn value(&self, option: &OptionSpec) -> ParamValue {
        let i = self
            .entry
            .options
            .iter()
            .position(|o| o.name == option.name)
            .unwrap_or_else(|| {
                panic!(
                    "method {} reads option --{}, which its entry does not declare",
                    self.entry.name, option.name
                )
            });
        self.values[i]
    }

    pub fn get(&self, option: &OptionSpec) -> Option<ParamValue> {
        self.entry.accepts(option).then(|| self.value(option))
    }

    /// The value of a count option the method declares.
    pub fn count(&self, option: &OptionSpec) -> u32 {
        match self.value(option) {
            ParamValue::Count(v) => v,
            v => panic!("--{} is declared a count, holds {v:?}", option.name),
        }
    }

    pub fn real(&self, option: &OptionSpec) -> f32 {
        match self.value(option) {
            ParamValue::Real(v) => v,
            v => panic!("--{} is declared a real, holds {v:?}", option.name),
        }
    }

    pub fn switch(&self, option: &OptionSpec) -> bool {
        match self.value(option) {
            ParamValue::Switch(v) => v,
            v => panic!("--{} is declared a switch, holds {v:?}", option.name),
        }
    }

    /// The value of a choice option the method declares.
    pub fn choice(&self, option: &OptionSpec) -> &'static str {
        match self.value(option) {
            ParamValue::Choice(v) => v,
            v => panic!("--{} is declared a choice, holds {v:?}", option.name),
        }
    }
}
