//! One timed render of a sweep point: in the sweep's own process (the default), or in a child
//! process (`mirrorbox render-worker`, `sweep --isolate-renders`), one per point and round.
//!
//! Why children existed: on lavapipe (Mesa 22.3, Vulkan) every executed frame leaves memory behind in the
//! process — a few hundred MB per frame of `portal` at depth 512, freed neither when the
//! frame's resources nor when the device are dropped (measured: `render --frames 16` peaked
//! at 5.2 GB where one frame peaks at 0.47 GB; wgpu's GL backend does not grow). A sweep that
//! renders thousands of frames in one process piled that up to 12.7 GB. A child per render
//! returns it all to the system when it exits, and its peak resident memory is the point's
//! own, recorded beside its timing.
//!
//! The job names the scene by file and the changes the sweep makes to it (size, α, mirrors
//! removed for the floor); the worker checks that it built the same scene (content hash).

use crate::HarnessError;
use glam::Vec3;
use mirrorbox_image::{RgbImage, write_exr};
use mirrorbox_raster::{Gpu, Method, RasterError, RenderSettings};
use mirrorbox_scene::limits::SettingError;
use mirrorbox_scene::{Scene, load_scene};
use serde::{Deserialize, Serialize};
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// One timed render, as the sweep describes it to a worker.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RenderJob {
    pub scene: PathBuf,
    pub width: u32,
    pub height: u32,
    /// The floor point: the scene without its mirrors.
    pub floor: bool,
    pub alpha: f32,
    /// The method with every option not at its default (`auxiliary n=2 max-passes=100`).
    pub method: String,
    pub ssaa: u32,
    pub frames: u32,
    pub warmup: u32,
    /// The content hash the worker's scene must have (the sweep's, after its changes).
    pub scene_hash: u64,
    /// Where the worker writes the rendered image (linear EXR).
    pub image: PathBuf,
    /// The point's scene axes (`crate::axes`), by name: `[["planes", 3]]`.
    #[serde(default)]
    pub axes: Vec<(String, f64)>,
    /// The sweep's view in place of the scene's camera ([`crate::SweepConfig::camera`]).
    #[serde(default)]
    pub camera: Option<crate::exchange::ViewSpec>,
}

/// Where a stereo job's right eye goes, beside `image`.
pub fn right_eye_image(image: &Path) -> PathBuf {
    image.with_extension("right.exr")
}

/// What a worker measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RenderReport {
    pub frames_ms: Vec<f64>,
    pub timing_source: String,
    pub passes: usize,
    pub texture_renders: usize,
    pub draws: usize,
    pub depth: usize,
    pub triangles: usize,
    pub paths_kept: Option<usize>,
    pub paths_pruned: Option<usize>,
    pub color_format: String,
    pub adapter: String,
    pub backend: String,
    /// The worker's peak resident memory (Linux `VmHWM`), bytes.
    pub peak_memory_bytes: Option<u64>,
    /// Wall time of planning the frame on the CPU, ms.
    pub plan_ms: f64,
    /// CPU time of encoding and submitting each timed frame, ms, in order.
    pub encode_ms: Vec<f64>,
    /// GPU memory held by buffers and by textures while the frame's resources were alive,
    /// bytes (`mirrorbox_raster::GpuMemory`).
    pub gpu_buffer_bytes: u64,
    pub gpu_texture_bytes: u64,
    /// Symmetry methods: the copies drawn and 2^p.
    #[serde(default)]
    pub copies: Option<CopyReport>,
    /// `symmetry-baked`: CPU time of the bake, ms (outside the frame time).
    #[serde(default)]
    pub bake_ms: Option<f64>,
}

/// [`mirrorbox_raster::method::CopyCounts`] as a worker reports it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CopyReport {
    pub drawn: usize,
    pub total: usize,
}

/// A rendered point: the image and what was measured.
pub struct Rendered {
    /// The view (a stereo pair's left eye).
    pub image: RgbImage,
    /// A stereo pair's right eye.
    pub right_eye: Option<RgbImage>,
    pub report: RenderReport,
}

/// `method` with every option not at its default, in a form [`Method::parse`] reads back.
pub fn method_text(method: &Method) -> String {
    let entry = method.entry();
    let mut text = entry.name.to_string();
    for (o, v) in entry.options.iter().zip(method.params().values()) {
        if *v != o.default {
            text.push_str(&format!(" {}={v}", o.name));
        }
    }
    text
}

/// The scene a job describes.
fn job_scene(job: &RenderJob) -> Result<Scene, HarnessError> {
    let mut scene = load_scene(&job.scene)?;
    if let Some(view) = &job.camera {
        scene = crate::exchange::view_scene(&scene, view)?;
    }
    scene.resize(Some(job.width), Some(job.height))?;
    let axes = job
        .axes
        .iter()
        .map(|(name, v)| {
            crate::axes::axis(name).map(|a| (a, *v)).ok_or_else(|| {
                HarnessError::Setting(SettingError::new(
                    "a render job's axes",
                    "the names of crate::axes::AXES",
                    name,
                ))
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    point_scene(&scene, job.floor, &axes, job.alpha)
}

/// A point's scene made from the sweep's scene, the one derivation the sweep and its workers
/// share (the worker's scene hash must equal the sweep's): the floor drops the mirrors, a
/// symmetry-planes point keeps the first p planes, a mirrored-lights point lights through
/// chains of at most k mirrors, and every mirror reflects α (the light images follow). A
/// stereo point's scene carries its rig at the point's IPD ([`Scene::stereo_rig`]); every
/// other point's carries none (a mono frame, whatever the file's camera says).
pub(crate) fn point_scene(
    base: &Scene,
    floor: bool,
    axes: &[(&'static crate::axes::AxisSpec, f64)],
    alpha: f32,
) -> Result<Scene, HarnessError> {
    let mut scene = crate::axes::apply_axes(base, floor, axes)?;
    let budget = |source| HarnessError::LightImages {
        scene: base.source.clone(),
        source,
    };
    scene.set_reflectance(Vec3::splat(alpha)).map_err(budget)?;
    let threshold = scene.lighting.images.min_throughput;
    scene.enumerate_light_images(threshold).map_err(budget)?;
    Ok(scene)
}

/// The eyes of a stereo point's scene (left, right), or `None` for a mono point.
pub fn eye_scenes(scene: &Scene) -> Option<[Scene; 2]> {
    let rig = scene.stereo?;
    Some(mirrorbox_scene::stereo::Eye::BOTH.map(|e| scene.eye(&rig, e)))
}

/// Plans a point's frame (a stereo point: its pair) on the CPU, refusing what is over budget.
pub(crate) fn plan_point(
    scene: &Scene,
    settings: &RenderSettings,
) -> Result<PlannedPoint, mirrorbox_raster::PlanError> {
    Ok(match eye_scenes(scene) {
        Some(eyes) => PlannedPoint::Pair(
            mirrorbox_raster::stereo_pair::plan_pair([&eyes[0], &eyes[1]], settings)?,
            Box::new(eyes),
        ),
        None => PlannedPoint::Mono(mirrorbox_raster::plan_frame(scene, settings)?),
    })
}

/// A planned point: one frame, or a stereo pair with its eyes' scenes.
pub(crate) enum PlannedPoint {
    Mono(mirrorbox_raster::Planned),
    Pair(mirrorbox_raster::stereo_pair::Planned, Box<[Scene; 2]>),
}

impl PlannedPoint {
    /// Refuses the point when its frame's estimated memory is above `budget` bytes.
    pub(crate) fn check_memory(
        &self,
        scene: &Scene,
        settings: &RenderSettings,
        budget: u64,
    ) -> Result<(), mirrorbox_raster::PlanError> {
        match self {
            PlannedPoint::Mono(p) => p.check_memory(scene, settings, budget).map(|_| ()),
            PlannedPoint::Pair(p, eyes) => p
                .check_memory([&eyes[0], &eyes[1]], settings, budget)
                .map(|_| ()),
        }
    }
}

/// Runs `job` in a worker process: builds its scene from the file and checks that it is the
/// sweep's (content hash), then [`render_scene`].
pub fn run_job(job: &RenderJob, gpu: &Gpu) -> Result<Rendered, HarnessError> {
    let scene = job_scene(job)?;
    if scene.content_hash() != job.scene_hash {
        return Err(HarnessError::Worker(format!(
            "{}: the worker built another scene than the sweep (hash {:016x}, expected {:016x}); was the file changed during the sweep?",
            job.scene.display(),
            scene.content_hash(),
            job.scene_hash
        )));
    }
    render_scene(job, &scene, gpu)
}

/// Renders `job` on `scene` (the point's scene, made once by the sweep or by the worker).
pub fn render_scene(job: &RenderJob, scene: &Scene, gpu: &Gpu) -> Result<Rendered, HarnessError> {
    let method = Method::parse(&job.method)
        .map_err(|e| HarnessError::Worker(format!("{}: {e}", job.method)))?;
    let settings = RenderSettings {
        method,
        ssaa: job.ssaa,
        frames: job.frames,
        warmup: job.warmup,
    };
    // The point's own peak, when several points render in one process (the sweep's default).
    // Where the kernel refuses the reset, the peak read later would be the process's so far,
    // growing point by point: none is recorded then.
    let own_peak = reset_peak_memory();
    // Planning is the CPU's share of a frame (reflection paths, the paper's recursion):
    // timed on its own, since GPU timestamps do not see it.
    let started = std::time::Instant::now();
    let planned = plan_point(scene, &settings).map_err(RasterError::from)?;
    let plan_ms = started.elapsed().as_secs_f64() * 1e3;
    let out = match planned {
        PlannedPoint::Mono(planned) => {
            mirrorbox_raster::render_planned(gpu, scene, planned, &settings)?
        }
        PlannedPoint::Pair(planned, eyes) => mirrorbox_raster::stereo_pair::render_pair(
            gpu,
            [&eyes[0], &eyes[1]],
            planned,
            &settings,
        )?,
    };
    let s = &out.stats;
    Ok(Rendered {
        report: RenderReport {
            frames_ms: out.timing.frames_ms.clone(),
            timing_source: out.timing.source.name().into(),
            passes: s.passes,
            texture_renders: s.texture_renders,
            draws: s.draws,
            depth: s.depth,
            triangles: s.triangles,
            paths_kept: s.paths.map(|c| c.kept),
            paths_pruned: s.paths.map(|c| c.pruned()),
            color_format: out.color_format.name().into(),
            adapter: gpu.report.name.clone(),
            backend: gpu.report.backend.clone(),
            peak_memory_bytes: own_peak.then(peak_memory_bytes).flatten(),
            plan_ms,
            encode_ms: out.timing.encode_ms.clone(),
            gpu_buffer_bytes: out.gpu_memory.buffer_bytes,
            gpu_texture_bytes: out.gpu_memory.texture_bytes,
            copies: s.copies.map(|c| CopyReport {
                drawn: c.drawn,
                total: c.total,
            }),
            bake_ms: out.bake_ms,
        },
        image: out.image,
        right_eye: out.right_eye,
    })
}

/// Runs `job` in this process and writes its image to `job.image`, as a worker would.
pub fn run_job_to_file(job: &RenderJob, gpu: &Gpu) -> Result<RenderReport, HarnessError> {
    write_images(job, run_job(job, gpu)?)
}

/// Writes a render's image (and a stereo pair's right eye) where `job` says; returns its
/// report.
pub fn write_images(job: &RenderJob, rendered: Rendered) -> Result<RenderReport, HarnessError> {
    write_exr(&job.image, &rendered.image, &[])?;
    if let Some(right) = &rendered.right_eye {
        write_exr(&right_eye_image(&job.image), right, &[])?;
    }
    Ok(rendered.report)
}

/// The worker's main: a job as JSON on stdin, the image to `job.image`, the report as JSON
/// on stdout.
pub fn serve(
    stdin: impl std::io::Read,
    mut stdout: impl std::io::Write,
) -> Result<(), HarnessError> {
    let job: RenderJob = serde_json::from_reader(stdin)?;
    let gpu = Gpu::new()?;
    let report = run_job_to_file(&job, &gpu)?;
    serde_json::to_writer(&mut stdout, &report)?;
    stdout
        .flush()
        .map_err(|e| HarnessError::Worker(format!("cannot answer the sweep: {e}")))
}

/// Runs `job` (the point `label`) in a child process `exe render-worker` and reads its
/// answer; the image stays in `job.image`. A worker's refusal (exit 2) stays a refusal.
pub fn render_in_worker(
    exe: &Path,
    job: &RenderJob,
    label: &str,
) -> Result<RenderReport, HarnessError> {
    let mut child = std::process::Command::new(exe)
        .arg("render-worker")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .map_err(|e| HarnessError::Worker(format!("cannot start {}: {e}", exe.display())))?;
    let input = serde_json::to_vec(job)?;
    child
        .stdin
        .take()
        .expect("piped stdin")
        .write_all(&input)
        .map_err(|e| HarnessError::Worker(format!("{label}: cannot send the job: {e}")))?;
    let out = child
        .wait_with_output()
        .map_err(|e| HarnessError::Worker(format!("{label}: {e}")))?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        // The worker's own message, not a driver's chatter before it.
        let message = stderr
            .lines()
            .rev()
            .find_map(|l| l.strip_prefix("error: "))
            .map_or_else(|| stderr.trim().to_string(), str::to_string);
        return Err(match out.status.code() {
            Some(2) => HarnessError::WorkerRefused(format!("{label}: {message}")),
            Some(code) => HarnessError::Worker(format!("{label} (exit {code}): {message}")),
            None => HarnessError::Worker(format!(
                "{label}: the worker was killed ({}; out of memory?)",
                out.status
            )),
        });
    }
    Ok(serde_json::from_slice(&out.stdout)?)
}

/// Starts this process's peak resident memory afresh (Linux: `5` written to
/// `/proc/self/clear_refs` sets `VmHWM` to the current resident size), so that the peak read
/// after a render is that render's, the sweep's own resident memory included. Returns
/// whether the kernel took it; elsewhere the peak stays the process's so far.
pub fn reset_peak_memory() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// This process's peak resident memory so far (Linux `VmHWM`), bytes.
pub fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kb * 1024)
}
