//! `mirrorbox trace SCENE -o OUT.exr`: the ground truth, rendered on the CPU with obvhs.

use super::{check_outputs, grid_side, load, output_path, progress_bar, setting, unit_interval};
use crate::Failure;
use mirrorbox_image::{RgbImage, StagedFiles, colormap, stage_exr, stage_png, stage_png_bytes};
use mirrorbox_scene::SubpixelGrid;
use mirrorbox_trace::{
    BvhKind, Sampling, SceneBvh, TraceOutput, TraceSettings, WhittedSettings, render,
};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Bvh {
    Cwbvh,
    Bvh2,
    Wide,
}

/// How `whitted` asks the BVH for closest hits (the same answers either way).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Kernel {
    /// A pixel's samples traced together through a binary BVH, SIMD across rays (docs/tracer-performance.md).
    Packet,
    /// One ray at a time through the --bvh hierarchy.
    Single,
}

/// Which vector build runs the tracer's lane loops (`mirrorbox_trace::cpu_features`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Simd {
    /// The CPU's widest: AVX-512 (F, VL, BW, DQ), else AVX2, else the baseline; `path` takes
    /// AVX2 on Intel's AVX-512 CPUs, whose clock 512-bit vectors slow.
    Widest,
    /// AVX-512 (an error on a CPU without it), for every integrator.
    Avx512,
    /// AVX2 (an error on a CPU without it).
    Avx2,
    /// The x86-64 baseline, SSE2.
    Baseline,
}

/// A form of the change behind the tracer's A/B switch (`mirrorbox_trace::ab_switch`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AbForm {
    /// The switch off.
    A,
    /// The switch on.
    B,
}

impl AbForm {
    fn name(self) -> &'static str {
        match self {
            AbForm::A => "a",
            AbForm::B => "b",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Device {
    /// The CPU tracer (obvhs BVH, rayon threads).
    Cpu,
    /// wgpu ray queries (`whitted` only).
    Gpu,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Integrator {
    /// Perfect mirror chains, the contract's lighting at the first diffuse hit.
    Whitted,
    /// Physically based path tracing (shadows, interreflection), to compare with Mitsuba's `path`.
    Path,
}

#[derive(clap::Args, Clone)]
pub struct Args {
    /// Scene file (JSON).
    scene: PathBuf,
    /// Output EXR (linear float32 RGB); an sRGB PNG is written beside it.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    size: super::SizeArgs,
    #[command(flatten)]
    time: super::TimeArgs,
    /// Samples per pixel: a perfect square s², taken as the s×s sub-pixel grid the
    /// rasterizer reproduces with --ssaa s. The default, 1, is the pixel centre, as
    /// `render`'s default --ssaa 1: at their defaults the two commands sample the same points
    /// (a 4×4 box average differs from the centre value by the image's curvature: up to
    /// 1.8e-4 relative at the steep edges of a mirrored light's falloff).
    #[arg(long, default_value_t = 1)]
    spp: u32,
    /// α: override every mirror's reflectance (the attenuation per reflection being measured),
    /// in [0, 1]. `--reflectance` is the same flag.
    #[arg(
        long = "alpha",
        visible_alias = "reflectance",
        allow_negative_numbers = true
    )]
    reflectance: Option<f32>,
    /// Light surfaces through chains of up to this many mirrors, 0..=64 (overrides the
    /// scene's `lighting.mirrored_lights`; docs/shading.md). Whitted only: `path` finds light
    /// through mirrors by its own sampling, and never from point lights.
    #[arg(long)]
    mirrored_lights: Option<u32>,
    /// whitted: most mirror reflections a path follows (depth, as everywhere in mirrorbox)
    /// [default: 10000]. `path` counts its length in segments instead: --max-segments.
    #[arg(long)]
    max_depth: Option<u32>,
    /// path: longest path in segments, diffuse bounces included (Mitsuba's max_depth: N
    /// visible reflections need N + 2) [default: 10000].
    #[arg(long)]
    max_segments: Option<u32>,
    /// path: the segment count from which Russian roulette may end paths (Mitsuba's
    /// rr_depth) [default: 5].
    #[arg(long)]
    rr_from: Option<u32>,
    /// whitted: stop a path when its throughput's largest channel would fall below this, in
    /// [0, 1) (`path` ends its paths by --max-segments and Russian roulette instead).
    #[arg(long, default_value_t = WhittedSettings::default().min_throughput, allow_negative_numbers = true)]
    min_throughput: f32,
    /// Stratified random sub-pixel positions instead of the fixed grid.
    #[arg(long)]
    jitter: bool,
    /// Seed of --jitter and of the path integrator's random numbers.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Also write the mean number of mirror bounces per pixel (EXR, with a heat-map PNG beside it).
    #[arg(long, value_name = "FILE.exr")]
    bounces: Option<PathBuf>,
    /// How paths are followed: the contract's Whitted chains, or physically based paths.
    #[arg(long, value_enum, default_value_t = Integrator::Whitted)]
    integrator: Integrator,
    /// Hierarchy of the single-ray queries (shadow legs, `path` after a diffuse bounce, --kernel single): obvhs's cwbvh is faster than its bvh2, bvh2 does not miss some hits at mirror corners that cwbvh does; wide is our own 8-wide one (bvh2's answers, docs/tracer-performance.md).
    #[arg(long, value_enum, default_value_t = Bvh::Wide)]
    bvh: Bvh,
    /// Closest-hit kernel: packets (`whitted`'s paths, and the mirror chains that start `path`'s, traced as 32-ray packets through a BVH2) or single (one ray at a time).
    #[arg(long, value_enum, default_value_t = Kernel::Packet)]
    kernel: Kernel,
    /// Vector build of the tracer's lane loops: the CPU's widest (detected), or a narrower
    /// one, to time the AVX2 or baseline (SSE2) code on a wider CPU; every build gives the
    /// same bits (docs/tracer-performance.md). A build the CPU lacks is an error.
    #[arg(long, value_enum, default_value_t = Simd::Widest)]
    simd: Simd,
    /// Untimed renders of each view before the timed one, 0..=10: the timed render then runs
    /// in a process that has rendered (its threads awake, its memory and caches warm), as
    /// Mitsuba's compiled-kernel time is its second render (scripts/bench-tracer.sh). The
    /// same image; --json gives each warm-up render's seconds (warm_up_seconds; total_seconds
    /// includes them). CPU only.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=10))]
    warm_up: u32,
    /// For timing a change to the tracer (hidden: developers' use, scripts/ab-inprocess.sh):
    /// the --warm-up renders alternate the tracer's A/B switch (`mirrorbox_trace::ab_switch`),
    /// the first in the form named; --json lists each one's form (warm_up_forms). The timed
    /// render runs in form A.
    #[arg(long, value_enum, hide = true, requires = "warm_up")]
    ab_switch: Option<AbForm>,
    /// Print the summary as one JSON object (one per eye with --stereo).
    #[arg(long)]
    json: bool,
    /// Where to trace: cpu (obvhs, rayon; the reference of every report) or gpu (`whitted`
    /// by wgpu ray queries, `ray-query --primary rays`: the same paths in f32 on an adapter
    /// with EXPERIMENTAL_RAY_QUERY; grid sampling only, at most 64 spp and 4096 reflections).
    #[arg(long, value_enum, default_value_t = Device::Cpu)]
    device: Device,
    #[command(flatten)]
    stereo: super::stereo::StereoArgs,
}

/// `--max-depth` when none is given (whitted), and `--max-segments` (path).
const DEFAULT_MAX_DEPTH: u32 = 10_000;
const DEFAULT_MAX_SEGMENTS: u32 = 10_000;
const DEFAULT_RR_FROM: u32 = 5;

impl Args {
    /// The integrator's cut of a path's length, as (flag, record key, value): whitted's
    /// reflections (`--max-depth`), path's segments (`--max-segments`).
    fn length_cut(&self) -> (&'static str, &'static str, u32) {
        match self.integrator {
            Integrator::Whitted => (
                "--max-depth",
                "max_depth",
                self.max_depth.unwrap_or(DEFAULT_MAX_DEPTH),
            ),
            Integrator::Path => (
                "--max-segments",
                "max_segments",
                self.max_segments.unwrap_or(DEFAULT_MAX_SEGMENTS),
            ),
        }
    }
}

fn check_args(args: &Args) -> Result<(SubpixelGrid, WhittedSettings), Failure> {
    use mirrorbox_trace::cpu_features::{Build, narrow_to};
    let build = match args.simd {
        Simd::Widest => None,
        Simd::Avx512 => Some(Build::Avx512),
        Simd::Avx2 => Some(Build::Avx2),
        Simd::Baseline => Some(Build::Baseline),
    };
    if let Some(build) = build {
        narrow_to(build).map_err(|e| Failure::BadInput(format!("--simd: {e}")))?;
    }
    let s = grid_side(args.spp)?;
    unit_interval("--alpha", args.reflectance)?;
    // "Depth" is mirror reflections everywhere (docs/shading.md); a physically based path's
    // length, diffuse bounces included, is counted in segments under its own flag.
    match args.integrator {
        Integrator::Path if args.max_depth.is_some() => {
            return Err(Failure::BadInput(
                "--max-depth counts mirror reflections (whitted); `path` counts its length in \
                 segments, diffuse bounces included: use --max-segments (N visible reflections \
                 need N + 2)"
                    .into(),
            ));
        }
        Integrator::Path if args.mirrored_lights.is_some() => {
            return Err(Failure::BadInput(
                "--mirrored-lights is the `whitted` integrator's: `path` finds light through \
                 mirrors by its own sampling, and never from point lights"
                    .into(),
            ));
        }
        // The path integrator ends paths by its length and Russian roulette, not by a
        // throughput cut: the flag had been taken, recorded, and done nothing.
        Integrator::Path if args.min_throughput != WhittedSettings::default().min_throughput => {
            return Err(Failure::BadInput(
                "--min-throughput is the `whitted` integrator's cut: `path` ends paths by \
                 --max-segments and Russian roulette (--rr-from)"
                    .into(),
            ));
        }
        Integrator::Path if args.max_segments == Some(0) => {
            return Err(Failure::BadInput(
                "--max-segments must be at least 1 (a path's first segment is the camera ray)"
                    .into(),
            ));
        }
        Integrator::Whitted if args.max_segments.is_some() || args.rr_from.is_some() => {
            return Err(Failure::BadInput(
                "--max-segments and --rr-from are the `path` integrator's (--integrator path); \
                 whitted follows at most --max-depth mirror reflections"
                    .into(),
            ));
        }
        _ => {}
    }
    let whitted = WhittedSettings {
        max_depth: args.max_depth.unwrap_or(DEFAULT_MAX_DEPTH),
        min_throughput: args.min_throughput,
    };
    whitted.check().map_err(setting)?;
    Ok((SubpixelGrid::new(s), whitted))
}

/// A stereo pair's side-by-side and red–cyan PNGs (`OUT_sbs.png`, `OUT_anaglyph.png`), from
/// the two eyes' linear images at `left`'s camera exposure: the CPU's trace and the GPU's both.
fn stage_stereo_pngs(
    staged: &mut StagedFiles,
    exr_path: &Path,
    left: &mirrorbox_scene::Scene,
    left_image: &mirrorbox_image::RgbImage,
    right_image: &mirrorbox_image::RgbImage,
) -> Result<(), Failure> {
    use mirrorbox_files::with_stem_suffix;
    let e = left.camera.exposure;
    let (a, b) = (left_image.to_srgb8(e), right_image.to_srgb8(e));
    let (w, h) = (left.camera.width, left.camera.height);
    let sbs = mirrorbox_image::stereo::side_by_side(&a, &b, w, h);
    let sbs_path = with_stem_suffix(exr_path, "sbs").with_extension("png");
    stage_png_bytes(staged, &sbs_path, 2 * w, h, &sbs).map_err(write_failed)?;
    let ana = mirrorbox_image::stereo::anaglyph(&a, &b);
    let ana_path = with_stem_suffix(exr_path, "anaglyph").with_extension("png");
    stage_png_bytes(staged, &ana_path, w, h, &ana).map_err(write_failed)
}

fn write_failed(e: impl ToString) -> Failure {
    Failure::Other(e.to_string())
}

/// One frame, or with `--sequence` one frame per time step (each written whole before the
/// next starts; frame k into OUT_k).
pub fn run(args: &Args) -> Result<(), Failure> {
    let scene = std::cell::OnceCell::new();
    args.time.run(
        args,
        |args, time, suffix| Args {
            time,
            output: mirrorbox_files::with_stem_suffix(&args.output, suffix),
            // Each frame's own bounce map (one file had been overwritten frame after frame).
            bounces: args
                .bounces
                .as_ref()
                .map(|b| mirrorbox_files::with_stem_suffix(b, suffix)),
            ..args.clone()
        },
        |frame| {
            check_args(frame)?;
            check_frame_outputs(frame)?;
            super::check_frame_time(frame.time, &frame.scene, &scene)
        },
        run_frame,
    )
}

/// Checks a frame's outputs (`-o`, `--bounces`, their PNGs and a stereo pair's pictures):
/// their folders exist, none is a folder, no two are one file. Returns `-o` and `--bounces`.
fn check_frame_outputs(args: &Args) -> Result<(PathBuf, Option<PathBuf>), Failure> {
    use super::stereo::eye_path;
    use mirrorbox_files::with_stem_suffix;
    let exr_path = output_path("-o", &args.output, "exr")?;
    let bounces_path = args
        .bounces
        .as_deref()
        .map(|p| output_path("--bounces", p, "exr"))
        .transpose()?;
    let eyes: Vec<Option<mirrorbox_scene::stereo::Eye>> = if args.stereo.asked() {
        mirrorbox_scene::stereo::Eye::BOTH.map(Some).to_vec()
    } else {
        vec![None]
    };
    let mut outputs = Vec::new();
    for &eye in &eyes {
        let exr = eye_path(&exr_path, eye);
        outputs.push(("-o", exr.clone()));
        outputs.push(("-o (its PNG)", exr.with_extension("png")));
        if let Some(b) = &bounces_path {
            let b = eye_path(b, eye);
            outputs.push(("--bounces", b.clone()));
            outputs.push(("--bounces (its PNG)", b.with_extension("png")));
        }
    }
    if args.stereo.asked() {
        outputs.push((
            "-o (side by side)",
            with_stem_suffix(&exr_path, "sbs").with_extension("png"),
        ));
        outputs.push((
            "-o (anaglyph)",
            with_stem_suffix(&exr_path, "anaglyph").with_extension("png"),
        ));
    }
    check_outputs(&outputs)?;
    Ok((exr_path, bounces_path))
}

fn run_frame(args: &Args) -> Result<(), Failure> {
    use super::stereo::{eye_path, views};
    let (grid, whitted) = check_args(args)?;
    let (exr_path, bounces_path) = check_frame_outputs(args)?;
    let mut scene = args.time.apply(load(&args.scene)?)?;
    let rig = args.stereo.rig(&scene)?;
    args.size.apply(&mut scene)?;
    if let Some(r) = args.reflectance {
        scene
            .set_reflectance(glam::Vec3::splat(r))
            .map_err(|e| super::light_budget(&scene, "--reflectance", e))?;
    }
    if let Some(k) = args.mirrored_lights {
        let max = mirrorbox_scene::light_images::MAX_MIRRORED_LIGHTS;
        if k > max {
            return Err(Failure::BadInput(format!(
                "--mirrored-lights must be in [0, {max}], got {k}"
            )));
        }
        // As the scene file's own field (docs/shading.md): uneven mirrors keep no light
        // images; the override had been taken and had changed the truth.
        if k > 0 && scene.has_bumps() {
            return Err(Failure::BadInput(format!(
                "--mirrored-lights must be 0: {} has uneven mirrors (a bump), which keep no \
                 mirrored light sources (docs/shading.md)",
                args.scene.display()
            )));
        }
        scene.lighting.mirrored_lights = k;
    }
    if args.mirrored_lights.is_some() || scene.lighting.mirrored_lights > 0 {
        // The light images are pruned at the tracer's own threshold, as its eye paths are.
        scene
            .enumerate_light_images(whitted.min_throughput)
            .map_err(|e| super::light_budget(&scene, "--min-throughput", e))?;
    }
    if args.device == Device::Gpu {
        return trace_on_gpu(args, &scene, rig, grid, whitted, &exr_path);
    }
    let sampling = if args.jitter {
        Sampling::Jittered {
            grid,
            seed: args.seed,
        }
    } else {
        Sampling::Grid(grid)
    };
    let kind = match args.bvh {
        Bvh::Cwbvh => BvhKind::Cwbvh,
        Bvh::Bvh2 => BvhKind::Bvh2,
        Bvh::Wide => BvhKind::Wide,
    };
    let started = Instant::now();
    let bvh =
        SceneBvh::build_with(&scene.geometry, kind).with_packets(args.kernel == Kernel::Packet);
    let integrator: mirrorbox_trace::IntegratorSettings = match args.integrator {
        Integrator::Path => mirrorbox_trace::PathSettings {
            max_segments: args.max_segments.unwrap_or(DEFAULT_MAX_SEGMENTS),
            rr_from: args.rr_from.unwrap_or(DEFAULT_RR_FROM),
            seed: args.seed,
        }
        .into(),
        Integrator::Whitted => whitted.into(),
    };
    let settings = TraceSettings::default()
        .with_sampling(sampling)
        .with_integrator(integrator);
    // Every output appears together, or none does (a failing --bounces leaves no image).
    let mut staged = StagedFiles::new();
    let forms = warm_up_forms(args);
    let mut traced = Vec::new();
    for (eye, view) in views(&scene, rig) {
        // Rendered in full and dropped: only their times are kept (--warm-up).
        let warm_up: Vec<f64> = forms
            .iter()
            .map(|form| {
                mirrorbox_trace::ab_switch::set(*form == Some(AbForm::B));
                render(&view, &bvh, &settings, &|_| {}).wall.as_secs_f64()
            })
            .collect();
        mirrorbox_trace::ab_switch::set(false);
        let bar = progress_bar(view.camera.height as u64, "tracing rows");
        let out = render(&view, &bvh, &settings, &|rows| {
            bar.set_position(rows as u64)
        });
        bar.finish_and_clear();
        let exr = eye_path(&exr_path, eye);
        let bounces = bounces_path.as_deref().map(|b| eye_path(b, eye));
        stage_view(
            args,
            &view,
            &out,
            grid,
            sampling,
            whitted,
            eye,
            &exr,
            bounces.as_deref(),
            &mut staged,
        )?;
        traced.push((eye, view, out, warm_up));
    }
    if let [(_, l, left, _), (_, _, right, _)] = &traced[..] {
        stage_stereo_pngs(&mut staged, &exr_path, l, &left.image, &right.image)?;
    }
    let written = staged.commit().map_err(write_failed)?;
    let total = started.elapsed();
    for (i, (eye, view, out, warm_up)) in traced.iter().enumerate() {
        if let Some(e) = eye
            && !args.json
        {
            println!("{} eye:", e.name());
        }
        let timing = Timing {
            total,
            warm_up_seconds: warm_up,
            warm_up_forms: &forms,
        };
        // The files, written together, are said once, after the last eye (the JSON of each
        // eye lists them all).
        let last = i + 1 == traced.len();
        report(args, view, &bvh, out, grid, &timing, (&written, last), *eye);
    }
    Ok(())
}

/// Stages one view's EXR, PNG and bounce outputs with their provenance.
#[allow(clippy::too_many_arguments)]
fn stage_view(
    args: &Args,
    scene: &mirrorbox_scene::Scene,
    out: &TraceOutput,
    grid: SubpixelGrid,
    sampling: Sampling,
    whitted: WhittedSettings,
    eye: Option<mirrorbox_scene::stereo::Eye>,
    exr_path: &Path,
    bounces_path: Option<&Path>,
    staged: &mut StagedFiles,
) -> Result<(), Failure> {
    let reflectance = args
        .reflectance
        .map_or("as in scene".to_string(), |r| r.to_string());
    let mut attributes = vec![
        ("mirrorbox.version", env!("CARGO_PKG_VERSION").to_string()),
        ("mirrorbox.scene", args.scene.display().to_string()),
        (
            "mirrorbox.scene_hash",
            format!("{:016x}", scene.content_hash()),
        ),
        ("mirrorbox.exposure", scene.camera.exposure.to_string()),
        (
            "mirrorbox.integrator",
            format!("{:?}", args.integrator).to_lowercase(),
        ),
        ("mirrorbox.spp", grid.samples_per_pixel().to_string()),
        ("mirrorbox.sampling", sampling.describe()),
        (
            match args.length_cut().1 {
                "max_depth" => "mirrorbox.max_depth",
                _ => "mirrorbox.max_segments",
            },
            args.length_cut().2.to_string(),
        ),
        ("mirrorbox.reflectance", reflectance),
        (
            "mirrorbox.render_seconds",
            format!("{:.3}", out.wall.as_secs_f64()),
        ),
        ("mirrorbox.rays", out.stats.rays.to_string()),
        ("mirrorbox.deepest_path", out.stats.deepest.to_string()),
        ("mirrorbox.lighting", scene.lighting.describe()),
    ];
    // The cut each integrator applies, and what else its image depends on.
    match args.integrator {
        Integrator::Whitted => attributes.push((
            "mirrorbox.min_throughput",
            whitted.min_throughput.to_string(),
        )),
        Integrator::Path => {
            attributes.push(("mirrorbox.seed", args.seed.to_string()));
            attributes.push((
                "mirrorbox.rr_from",
                args.rr_from.unwrap_or(DEFAULT_RR_FROM).to_string(),
            ));
        }
    }
    attributes.extend(args.time.attribute());
    if let Some(e) = eye {
        let c = &scene.camera;
        attributes.push((
            "mirrorbox.eye",
            format!(
                "{} (position {:?}, look_at {:?}, shift_x {})",
                e.name(),
                c.position,
                c.look_at,
                c.shift_x
            ),
        ));
    }
    stage_exr(staged, exr_path, &out.image, &attributes).map_err(write_failed)?;
    let png_path = exr_path.with_extension("png");
    stage_png(staged, &png_path, &out.image, scene.camera.exposure).map_err(write_failed)?;
    if let Some(path) = bounces_path {
        stage_bounces(staged, path, &out.bounces, out.stats.deepest, &attributes)?;
    }
    Ok(())
}

/// The bounce AOV: EXR of the mean count, and a heat map (log scale up to the deepest path).
fn stage_bounces(
    staged: &mut StagedFiles,
    path: &Path,
    image: &RgbImage,
    deepest: u32,
    attributes: &[(&str, String)],
) -> Result<(), Failure> {
    // Said to be counts, not radiance: `compare` refuses it as an image of the scene.
    let mut attributes = attributes.to_vec();
    attributes.push(("mirrorbox.aov", "bounces".to_string()));
    stage_exr(staged, path, image, &attributes).map_err(write_failed)?;
    let scale = (1.0 + deepest.max(1) as f32).ln();
    let bytes: Vec<u8> = image
        .pixels
        .iter()
        .flat_map(|p| colormap::heat((1.0 + p[0]).ln() / scale))
        .collect();
    let png = path.with_extension("png");
    stage_png_bytes(staged, &png, image.width, image.height, &bytes).map_err(write_failed)
}

/// A traced view's times besides its timed render: the whole command's, and the untimed
/// --warm-up renders' before it.
struct Timing<'a> {
    total: std::time::Duration,
    warm_up_seconds: &'a [f64],
    /// Each warm-up render's form of the A/B switch, with --ab-switch.
    warm_up_forms: &'a [Option<AbForm>],
}

/// The form of the A/B switch each --warm-up render runs in: alternating from --ab-switch's,
/// or none without it.
fn warm_up_forms(args: &Args) -> Vec<Option<AbForm>> {
    (0..args.warm_up)
        .map(|i| {
            args.ab_switch.map(|first| match (first, i % 2) {
                (form, 0) => form,
                (AbForm::A, _) => AbForm::B,
                (AbForm::B, _) => AbForm::A,
            })
        })
        .collect()
}

#[allow(clippy::too_many_arguments)]
fn report(
    args: &Args,
    scene: &mirrorbox_scene::Scene,
    bvh: &SceneBvh,
    out: &TraceOutput,
    grid: SubpixelGrid,
    timing: &Timing,
    (written, said): (&[PathBuf], bool),
    eye: Option<mirrorbox_scene::stereo::Eye>,
) {
    let total = timing.total;
    let s = &out.stats;
    let secs = out.wall.as_secs_f64();
    let mrays = s.rays as f64 / secs / 1e6;
    let (w, h) = (scene.camera.width, scene.camera.height);
    if args.json {
        let mut v = serde_json::json!({
            "scene": args.scene.display().to_string(),
            // The camera path's time of this view (`--time`, or this frame's), if given.
            "time": args.time.time,
            "eye": eye.map(|e| e.name()),
            "scene_hash": format!("{:016x}", scene.content_hash()),
            "width": w, "height": h, "spp": grid.samples_per_pixel(),
            "paths": s.paths, "rays": s.rays, "mrays_per_s": mrays,
            "deepest_path": s.deepest, "render_seconds": secs, "total_seconds": total.as_secs_f64(),
            "warm_up_seconds": timing.warm_up_seconds,
            "warm_up_forms": args.ab_switch.map(|_| {
                timing.warm_up_forms.iter().flatten().map(|f| f.name()).collect::<Vec<_>>()
            }),
            "bvh": format!("{:?}", bvh.kind).to_lowercase(), "bvh_build_seconds": bvh.build_time.as_secs_f64(),
            "kernel": format!("{:?}", args.kernel).to_lowercase(),
            "packet_bvh_build_seconds": bvh.packet_build_time().map(|t| t.as_secs_f64()),
            "simd": out.vectors.name(),
            "threads": out.threads,
            "ended": { "diffuse": s.diffuse, "escaped": s.escaped,
                       "min_throughput": s.cut_by_throughput, "roulette": s.cut_by_roulette,
                       "absorbed_by_uneven_mirrors": s.absorbed },
            "outputs": written.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            "lighting": { "shadows": scene.lighting.shadows,
                          "mirrored_lights": scene.lighting.mirrored_lights,
                          "light_images": scene.lighting.images.images.len(),
                          "pruned_dim": scene.lighting.images.pruned_dim,
                          "pruned_bound": scene.lighting.images.pruned_bound },
        });
        // Cut by `max_depth` (whitted's reflections) or `max_segments` (path's length).
        v["ended"][args.length_cut().1] = s.cut_by_depth.into();
        // What was traced and with which cuts, beside the counts ("ended" counts paths).
        v["device"] = "cpu".into();
        v["integrator"] = format!("{:?}", args.integrator).to_lowercase().into();
        v["jitter"] = args.jitter.into();
        v["reflectance"] = args.reflectance.map_or("as in scene".into(), Into::into);
        v["settings"] = match args.integrator {
            Integrator::Whitted => serde_json::json!({
                "max_depth": args.length_cut().2,
                "min_throughput": args.min_throughput,
            }),
            Integrator::Path => serde_json::json!({
                "max_segments": args.length_cut().2,
                "rr_from": args.rr_from.unwrap_or(DEFAULT_RR_FROM),
                "seed": args.seed,
            }),
        };
        println!("{v}");
        return;
    }
    println!(
        "traced {}: {w}x{h}, {} spp ({}x{} grid{}), {} rays, {mrays:.2} Mrays/s, deepest path {} bounces, {} on {}",
        args.scene.display(),
        grid.samples_per_pixel(),
        grid.per_axis,
        grid.per_axis,
        if args.jitter { ", jittered" } else { "" },
        s.rays,
        s.deepest,
        // A small render takes milliseconds: "0.00 s" beside its rate said nothing.
        if secs < 1.0 {
            format!("{:.1} ms", secs * 1e3)
        } else {
            format!("{secs:.2} s")
        },
        crate::count(out.threads, "thread"),
    );
    println!(
        "  {} paths ended: {} at diffuse surfaces, {} escaped, {} cut by {} {}, {}",
        s.paths,
        s.diffuse,
        s.escaped,
        s.cut_by_depth,
        args.length_cut().0,
        args.length_cut().2,
        // Each integrator's own second cut (path has no throughput cut).
        if args.integrator == Integrator::Path {
            format!(
                "{} by Russian roulette from --rr-from {}",
                s.cut_by_roulette,
                args.rr_from.unwrap_or(DEFAULT_RR_FROM)
            )
        } else {
            format!(
                "{} cut by --min-throughput {}",
                s.cut_by_throughput, args.min_throughput
            )
        }
    );
    if scene.has_bumps() {
        println!(
            "  {} paths absorbed by uneven mirrors (a reflection that would leave behind the mirror: docs/shading.md)",
            s.absorbed
        );
    }
    println!("  lighting: {}", scene.lighting.describe());
    let packet_build = match bvh.packet_build_time() {
        Some(t) => format!(
            " (+ {:.1} ms for the packet kernel's BVH2)",
            t.as_secs_f64() * 1e3
        ),
        None => String::new(),
    };
    println!(
        "  {:?} over {} triangles built in {:.1} ms{packet_build}; {} vectors{}",
        bvh.kind,
        scene.geometry.triangles.len(),
        bvh.build_time.as_secs_f64() * 1e3,
        out.vectors.name(),
        if said {
            format!(
                "; wrote {}",
                written
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        } else {
            String::new()
        }
    );
}

/// `trace --device gpu`: every view traced by `ray-query --primary rays` (the tracer's
/// `whitted` in WGSL), written as the CPU truth is.
fn trace_on_gpu(
    args: &Args,
    scene: &mirrorbox_scene::Scene,
    rig: Option<mirrorbox_scene::stereo::Stereo>,
    grid: SubpixelGrid,
    whitted: WhittedSettings,
    exr_path: &Path,
) -> Result<(), Failure> {
    use super::stereo::{eye_path, views};
    let refuse = |flag: &str, why: &str| Failure::BadInput(format!("--device gpu: {flag} {why}"));
    if args.integrator != Integrator::Whitted {
        return Err(refuse(
            "--integrator path",
            "is CPU only (the GPU traces whitted)",
        ));
    }
    if args.jitter {
        return Err(refuse(
            "--jitter",
            "is CPU only (the GPU samples the fixed grid)",
        ));
    }
    if args.bounces.is_some() {
        return Err(refuse("--bounces", "is CPU only"));
    }
    if args.warm_up > 0 {
        return Err(refuse(
            "--warm-up",
            "is CPU only (the GPU trace times one frame of its own)",
        ));
    }
    // The CPU tracer's hierarchy, kernel and vector build: the GPU has its own (they had been
    // taken and ignored, unlike --jitter and --warm-up).
    if args.bvh != Bvh::Wide || args.kernel != Kernel::Packet || args.simd != Simd::Widest {
        return Err(refuse(
            "--bvh, --kernel and --simd",
            "are the CPU tracer's (the GPU traces through its own acceleration structures)",
        ));
    }
    let per_axis = (grid.samples_per_pixel() as f64).sqrt().round() as u32;
    if per_axis > mirrorbox_raster::MAX_SSAA {
        let max = mirrorbox_raster::MAX_SSAA;
        return Err(refuse(
            "--spp",
            &format!(
                "must be at most {} (a {max}×{max} grid), got {}",
                max * max,
                args.spp
            ),
        ));
    }
    let depth_cap = mirrorbox_raster::methods::ray_query::MAX_GPU_TRUTH_DEPTH;
    let settings = mirrorbox_raster::methods::ray_query::gpu_truth_settings(
        per_axis,
        whitted.max_depth,
        whitted.min_throughput,
    )?;
    let gpu = mirrorbox_raster::Gpu::new()?;
    let started = Instant::now();
    let mut staged = StagedFiles::new();
    let mut done = Vec::new();
    for (eye, view) in views(scene, rig) {
        let out = mirrorbox_raster::render(&gpu, &view, &settings)?;
        let exr = eye_path(exr_path, eye);
        let mut attributes = vec![
            ("mirrorbox.version", env!("CARGO_PKG_VERSION").to_string()),
            ("mirrorbox.scene", args.scene.display().to_string()),
            (
                "mirrorbox.scene_hash",
                format!("{:016x}", view.content_hash()),
            ),
            ("mirrorbox.exposure", view.camera.exposure.to_string()),
            (
                "mirrorbox.integrator",
                "whitted (gpu ray queries)".to_string(),
            ),
            ("mirrorbox.spp", grid.samples_per_pixel().to_string()),
            (
                "mirrorbox.max_depth",
                whitted.max_depth.min(depth_cap).to_string(),
            ),
            (
                "mirrorbox.min_throughput",
                whitted.min_throughput.to_string(),
            ),
            ("mirrorbox.adapter", gpu.report.name.clone()),
            ("mirrorbox.lighting", view.lighting.describe()),
            // As the CPU trace records them: the grid, the reflectance asked for, the time
            // and the eye (the GPU's EXRs had lacked them).
            ("mirrorbox.sampling", Sampling::Grid(grid).describe()),
            (
                "mirrorbox.reflectance",
                args.reflectance
                    .map_or("as in scene".to_string(), |r| r.to_string()),
            ),
        ];
        attributes.extend(args.time.attribute());
        if let Some(e) = eye {
            attributes.push(("mirrorbox.eye", e.name().to_string()));
        }
        stage_exr(&mut staged, &exr, &out.image, &attributes).map_err(write_failed)?;
        stage_png(
            &mut staged,
            &exr.with_extension("png"),
            &out.image,
            view.camera.exposure,
        )
        .map_err(write_failed)?;
        done.push((eye, view, out));
    }
    // The pair's side-by-side and anaglyph, as the CPU trace writes them (the GPU had not).
    if let [(_, l, left), (_, _, right)] = &done[..] {
        stage_stereo_pngs(&mut staged, exr_path, l, &left.image, &right.image)?;
    }
    let written = staged.commit().map_err(write_failed)?;
    let total = started.elapsed().as_secs_f64();
    for (eye, view, out) in &done {
        let (w, h) = (view.camera.width, view.camera.height);
        let gpu_ms = out.timing.median_ms();
        let build_ms = out.bake_ms.unwrap_or(0.0);
        if args.json {
            let v = serde_json::json!({
                "scene": args.scene.display().to_string(),
                "time": args.time.time,
                "eye": eye.map(|e| e.name()),
                "scene_hash": format!("{:016x}", view.content_hash()),
                "device": "gpu", "adapter": gpu.report.name, "backend": gpu.report.backend,
                "integrator": "whitted",
                "width": w, "height": h, "spp": grid.samples_per_pixel(),
                "max_depth": whitted.max_depth.min(depth_cap),
                "trace_ms": gpu_ms, "timing": out.timing.source.name(),
                "acceleration_build_ms": build_ms, "total_seconds": total,
                "outputs": written.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            });
            println!("{v}");
            continue;
        }
        if let Some(e) = eye {
            println!("{} eye:", e.name());
        }
        println!(
            "traced {} on the GPU ({}, {}): {w}x{h}, {} spp (the {per_axis}×{per_axis} grid), \
             whitted to {} reflections, min throughput {}",
            args.scene.display(),
            gpu.report.name,
            gpu.report.backend,
            grid.samples_per_pixel(),
            whitted.max_depth.min(depth_cap),
            whitted.min_throughput,
        );
        if whitted.max_depth > depth_cap {
            // Named as the user gave it: the flag, or the default they did not change.
            let asked = match args.max_depth {
                Some(d) => format!("--max-depth {d} was capped"),
                None => format!("the default depth {} was capped", whitted.max_depth),
            };
            println!("  (the GPU follows at most {depth_cap} reflections; {asked})");
        }
        println!(
            "  lighting: {}\n  trace {gpu_ms:.2} ms ({}); acceleration structures {build_ms:.2} ms; \
             {total:.2} s in all; wrote {}",
            view.lighting.describe(),
            out.timing.source.name(),
            written
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(())
}
