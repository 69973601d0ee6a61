//! The live truth: the CPU tracer renders the current view in the background, coarse first,
//! then finer, and starts again whenever the view changes.
//!
//! Levels: the view at 1/8, 1/4 and 1/2 of its size with one centred sample per pixel, then
//! at full size on the method's `ssaa × ssaa` sub-pixel grid — the same grid the offline
//! comparisons give both renderers (`docs/shading.md`), so the last level is exactly
//! `mirrorbox trace --spp ssaa²` of this camera and the error view shows the method's error,
//! not a sampling mismatch. A coarse level is shown scaled up, and no error is computed
//! against it.
//!
//! One worker thread owns the BVH (built once: the camera does not change the geometry) and
//! traces with rayon; a new request bumps a generation counter that the running render
//! checks before every row, so a stale view is abandoned within one row per thread.
//!
//! On the GPU ([`TruthDevice::Gpu`], issue 39) the worker opens a device of its own and
//! traces each level with `ray-query --primary rays` (`trace --device gpu`: the same paths
//! in f32, equal to the CPU truth within float precision); a level is one frame, so a stale
//! view is abandoned between levels. Where no adapter has ray queries it says so and traces
//! on the CPU; so it does where a level fails on the GPU: the failure is kept and shown
//! ([`LiveTruth::device`], the panel, a screenshot's JSON), and that level and every later
//! one is traced on the CPU. The CPU truth stays the reference of every report.

use mirrorbox_image::RgbImage;
use mirrorbox_scene::{Camera, Scene};
use mirrorbox_trace::{SceneBvh, TraceSettings};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Downscale factors of the coarse levels, before the full-size level.
pub const COARSE_LEVELS: [u32; 3] = [8, 4, 2];

/// Where the live truth is traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TruthDevice {
    /// The CPU tracer (obvhs, rayon).
    Cpu,
    /// wgpu ray queries on a device of the worker's own.
    Gpu,
}

impl TruthDevice {
    /// `--truth auto`: the GPU where the viewer's adapter has ray queries and is a real GPU;
    /// on a CPU adapter (lavapipe) the GPU truth runs on the same cores as the CPU tracer and
    /// was measured slower than it (`reports/gpu_truth/report.md`), so the CPU traces.
    pub fn auto(report: &mirrorbox_raster::AdapterReport, features: wgpu::Features) -> Self {
        if features.contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY) && report.device_type != "Cpu"
        {
            TruthDevice::Gpu
        } else {
            TruthDevice::Cpu
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            TruthDevice::Cpu => "CPU tracer",
            TruthDevice::Gpu => "GPU ray queries",
        }
    }
}

/// What to trace: the camera (its size is the view's) and the sub-pixel grid side.
#[derive(Clone, Debug, PartialEq)]
pub struct TruthRequest {
    pub camera: Camera,
    pub grid_side: u32,
}

/// One finished level of the current request.
#[derive(Clone)]
pub struct TruthLevel {
    pub generation: u64,
    /// What was traced: the view's camera and grid. A level is the truth of a frame only if
    /// this is the frame's (with the truth off no new request is made, so a generation alone
    /// had called a moved camera's frame "complete" against the old view's image).
    pub request: TruthRequest,
    /// 0 … `level_count() - 1`; the last is the full-size image on the full grid.
    pub level: usize,
    pub complete: bool,
    pub image: Arc<RgbImage>,
    /// Wall time of this level's image loop.
    pub trace_time: Duration,
}

/// The levels a request of `grid_side` goes through: the coarse ones, then full size.
pub fn level_count() -> usize {
    COARSE_LEVELS.len() + 1
}

/// The camera and grid side of `level` for `request`.
pub fn level_setup(request: &TruthRequest, level: usize) -> (Camera, u32) {
    match COARSE_LEVELS.get(level) {
        Some(&factor) => {
            let mut camera = request.camera.clone();
            camera.width = request.camera.width.div_ceil(factor).max(1);
            camera.height = request.camera.height.div_ceil(factor).max(1);
            (camera, 1)
        }
        None => (request.camera.clone(), request.grid_side),
    }
}

struct Shared {
    /// The latest request and its generation.
    request: Mutex<Option<(u64, TruthRequest)>>,
    wake: Condvar,
    generation: AtomicU64,
    latest: Mutex<Option<TruthLevel>>,
    /// Set when the viewer closes.
    closing: std::sync::atomic::AtomicBool,
    /// Where the worker traces (the GPU asked for, and the CPU where that failed), and why
    /// not on the GPU.
    device: Mutex<(TruthDevice, Option<String>)>,
}

/// How a level is traced on the GPU: [`trace_on_gpu`] (the tests put a failing one in).
type GpuTracer = fn(&mirrorbox_raster::Gpu, &Scene, u32) -> Result<(RgbImage, Duration), String>;

/// The background tracer. Dropping it stops the worker (after its current row).
pub struct LiveTruth {
    shared: Arc<Shared>,
    worker: Option<JoinHandle<()>>,
    requested: Option<TruthRequest>,
}

impl LiveTruth {
    /// Starts the worker for `scene` (the camera of each request replaces the scene's),
    /// tracing on `device`.
    pub fn start(scene: Arc<Scene>, device: TruthDevice) -> Self {
        Self::start_with(scene, device, trace_on_gpu)
    }

    /// [`LiveTruth::start`], the GPU's levels traced by `gpu_tracer`.
    fn start_with(scene: Arc<Scene>, device: TruthDevice, gpu_tracer: GpuTracer) -> Self {
        let shared = Arc::new(Shared {
            request: Mutex::new(None),
            wake: Condvar::new(),
            generation: AtomicU64::new(0),
            latest: Mutex::new(None),
            closing: Default::default(),
            device: Mutex::new((device, None)),
        });
        let for_worker = shared.clone();
        let worker = std::thread::Builder::new()
            .name("live truth".into())
            .spawn(move || work(&scene, &for_worker, gpu_tracer))
            .expect("spawning the live-truth thread");
        LiveTruth {
            shared,
            worker: Some(worker),
            requested: None,
        }
    }

    /// Asks for `request`; a request equal to the current one changes nothing.
    pub fn request(&mut self, request: TruthRequest) {
        if self.requested.as_ref() == Some(&request) {
            return;
        }
        self.requested = Some(request.clone());
        let generation = self.shared.generation.fetch_add(1, Ordering::SeqCst) + 1;
        *self.shared.request.lock().expect("truth request") = Some((generation, request));
        self.shared.wake.notify_all();
    }

    /// Where the truth is traced, and why not on the GPU where that was asked for and failed
    /// (no device with ray queries, or a level that failed on it).
    pub fn device(&self) -> (TruthDevice, Option<String>) {
        self.shared.device.lock().expect("truth device").clone()
    }

    /// The generation of the current request.
    pub fn generation(&self) -> u64 {
        self.shared.generation.load(Ordering::SeqCst)
    }

    /// The newest finished level of the current request, if any.
    pub fn latest(&self) -> Option<TruthLevel> {
        let latest = self.shared.latest.lock().expect("truth level").clone()?;
        (latest.generation == self.generation()).then_some(latest)
    }

    /// Waits up to `timeout` for the current request's full-size level.
    pub fn wait_complete(&self, timeout: Duration) -> Option<TruthLevel> {
        let start = Instant::now();
        loop {
            if let Some(level) = self.latest().filter(|l| l.complete) {
                return Some(level);
            }
            if start.elapsed() > timeout {
                return None;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

impl Drop for LiveTruth {
    fn drop(&mut self) {
        self.shared.closing.store(true, Ordering::SeqCst);
        self.shared.generation.fetch_add(1, Ordering::SeqCst);
        self.shared.wake.notify_all();
        if let Some(worker) = self.worker.take() {
            let _ = worker.join();
        }
    }
}

/// The GPU of the worker, where it traces on one: a device of its own with ray queries, or
/// why not (then it traces on the CPU).
fn open_gpu(shared: &Shared) -> Option<mirrorbox_raster::Gpu> {
    if shared.device.lock().expect("truth device").0 != TruthDevice::Gpu {
        return None;
    }
    let failed = |why: String| {
        *shared.device.lock().expect("truth device") = (TruthDevice::Cpu, Some(why));
        None
    };
    match mirrorbox_raster::Gpu::new() {
        Ok(gpu)
            if gpu
                .features
                .contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY) =>
        {
            Some(gpu)
        }
        Ok(gpu) => failed(format!("{} has no ray queries", gpu.report.name)),
        Err(e) => failed(e.to_string()),
    }
}

fn work(scene: &Scene, shared: &Shared, gpu_tracer: GpuTracer) {
    let mut gpu = open_gpu(shared);
    let bvh = SceneBvh::build(&scene.geometry);
    // One mono copy whose camera each level replaces.
    let mut view = scene.clone();
    view.stereo = None;
    view.head = None;
    let mut done_generation = 0;
    loop {
        let (generation, request) = {
            let mut slot = shared.request.lock().expect("truth request");
            loop {
                if shared.closing.load(Ordering::SeqCst) {
                    return;
                }
                match &*slot {
                    Some((g, r)) if *g != done_generation => break (*g, r.clone()),
                    _ => slot = shared.wake.wait(slot).expect("truth request"),
                }
            }
        };
        let current = || shared.generation.load(Ordering::SeqCst) == generation;
        for level in 0..level_count() {
            let (camera, grid_side) = level_setup(&request, level);
            view.camera = camera;
            let traced = match gpu.as_ref().map(|g| gpu_tracer(g, &view, grid_side)) {
                Some(Ok(traced)) => Some(traced),
                on_cpu => {
                    // A failed GPU level is shown, not dropped: the failure is kept for the
                    // panel and the screenshot, and the CPU traces this level and the rest.
                    if let Some(Err(why)) = on_cpu {
                        let (w, h) = (view.camera.width, view.camera.height);
                        *shared.device.lock().expect("truth device") = (
                            TruthDevice::Cpu,
                            Some(format!("the GPU trace of a {w}×{h} level failed: {why}")),
                        );
                        gpu = None;
                    }
                    let settings = TraceSettings::whitted(grid_side);
                    mirrorbox_trace::render_while(&view, &bvh, &settings, &|_| {}, &current)
                        .map(|out| (out.image, out.wall))
                }
            };
            let Some((image, trace_time)) = traced else {
                break;
            };
            let finished = TruthLevel {
                generation,
                request: request.clone(),
                level,
                complete: level + 1 == level_count(),
                image: Arc::new(image),
                trace_time,
            };
            if !current() {
                break;
            }
            *shared.latest.lock().expect("truth level") = Some(finished);
        }
        done_generation = generation;
    }
}

/// One level on the GPU: `trace --device gpu` of `view` on the `grid_side²` grid, to the
/// CPU truth's depth and throughput cut (the depth capped at the GPU's 4096), or why the
/// device could not.
fn trace_on_gpu(
    gpu: &mirrorbox_raster::Gpu,
    view: &Scene,
    grid_side: u32,
) -> Result<(RgbImage, Duration), String> {
    let truth = mirrorbox_trace::WhittedSettings::default();
    let settings = mirrorbox_raster::methods::ray_query::gpu_truth_settings(
        grid_side,
        truth.max_depth,
        truth.min_throughput,
    )
    .map_err(|e| e.to_string())?;
    let start = Instant::now();
    let out = mirrorbox_raster::render(gpu, view, &settings).map_err(|e| e.to_string())?;
    Ok((out.image, start.elapsed()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small_scene() -> Scene {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mirror_box.json");
        let mut scene = mirrorbox_scene::load_scene(&path).expect("bundled scene");
        scene.camera.width = 64;
        scene.camera.height = 36;
        scene
    }

    #[test]
    fn the_last_level_is_the_offline_trace_bit_for_bit() {
        let scene = small_scene();
        let mut truth = LiveTruth::start(Arc::new(scene.clone()), TruthDevice::Cpu);
        truth.request(TruthRequest {
            camera: scene.camera.clone(),
            grid_side: 2,
        });
        let level = truth
            .wait_complete(Duration::from_secs(120))
            .expect("the truth completes");
        assert_eq!(level.level, level_count() - 1);
        let bvh = SceneBvh::build(&scene.geometry);
        let offline =
            mirrorbox_trace::render(&scene, &bvh, &TraceSettings::whitted(2), &|_| {}).image;
        assert_eq!(level.image.pixels, offline.pixels);
    }

    /// `--truth gpu` (issue 39): the last level is `trace --device gpu` of the view bit for
    /// bit, and within float precision of the CPU truth; the worker says it traces on the GPU.
    /// Whether this machine's adapter has ray queries; where not, a failure, or `false`
    /// where `MIRRORBOX_TEST_SKIP` names `raytracing`.
    fn ray_queries() -> bool {
        let gpu = mirrorbox_raster::Gpu::new().expect("a wgpu adapter");
        mirrorbox_testing::require(
            mirrorbox_testing::RAYTRACING,
            gpu.features
                .contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY),
            &format!("{} has no ray queries", gpu.report.name),
        )
    }

    #[test]
    fn the_gpu_last_level_is_trace_on_the_gpu() {
        if !ray_queries() {
            return;
        }
        let scene = small_scene();
        let mut truth = LiveTruth::start(Arc::new(scene.clone()), TruthDevice::Gpu);
        truth.request(TruthRequest {
            camera: scene.camera.clone(),
            grid_side: 2,
        });
        let level = truth
            .wait_complete(Duration::from_secs(120))
            .expect("the truth completes");
        assert_eq!(truth.device(), (TruthDevice::Gpu, None));
        let gpu = mirrorbox_raster::Gpu::new().unwrap();
        let d = mirrorbox_trace::WhittedSettings::default();
        let settings = mirrorbox_raster::methods::ray_query::gpu_truth_settings(
            2,
            d.max_depth,
            d.min_throughput,
        )
        .unwrap();
        let offline = mirrorbox_raster::render(&gpu, &scene, &settings)
            .unwrap()
            .image;
        assert_eq!(level.image.pixels, offline.pixels);
        let bvh = SceneBvh::build(&scene.geometry);
        let cpu = mirrorbox_trace::render(&scene, &bvh, &TraceSettings::whitted(2), &|_| {}).image;
        let worst = cpu
            .pixels
            .iter()
            .zip(&level.image.pixels)
            .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
            .fold(0.0f32, f32::max);
        assert!(worst <= 1e-4, "GPU and CPU truth differ by {worst}");
    }

    /// A GPU level that fails is shown, not dropped (issue 50): the worker says where the
    /// truth is traced now and why, and the CPU traces that level and the rest, so the truth
    /// still completes — as the offline CPU trace.
    #[test]
    fn a_failed_gpu_level_is_shown_and_traced_on_the_cpu() {
        if !ray_queries() {
            return;
        }
        fn failing(
            _: &mirrorbox_raster::Gpu,
            _: &Scene,
            _: u32,
        ) -> Result<(RgbImage, Duration), String> {
            Err("device lost (injected)".into())
        }
        let scene = small_scene();
        let mut truth = LiveTruth::start_with(Arc::new(scene.clone()), TruthDevice::Gpu, failing);
        truth.request(TruthRequest {
            camera: scene.camera.clone(),
            grid_side: 2,
        });
        let level = truth
            .wait_complete(Duration::from_secs(120))
            .expect("the truth completes on the CPU");
        let (device, why) = truth.device();
        assert_eq!(device, TruthDevice::Cpu);
        assert_eq!(
            why.as_deref(),
            Some("the GPU trace of a 8×5 level failed: device lost (injected)")
        );
        let bvh = SceneBvh::build(&scene.geometry);
        let offline =
            mirrorbox_trace::render(&scene, &bvh, &TraceSettings::whitted(2), &|_| {}).image;
        assert_eq!(level.image.pixels, offline.pixels);
    }

    #[test]
    fn a_new_view_replaces_the_old_one_and_levels_grow() {
        let scene = small_scene();
        let mut truth = LiveTruth::start(Arc::new(scene.clone()), TruthDevice::Cpu);
        let first = TruthRequest {
            camera: scene.camera.clone(),
            grid_side: 1,
        };
        truth.request(first.clone());
        let g1 = truth.generation();
        let mut moved = first.clone();
        moved.camera.position.x += 0.3;
        truth.request(moved.clone());
        assert_eq!(truth.generation(), g1 + 1);
        // The same request again is not a new view.
        truth.request(moved);
        assert_eq!(truth.generation(), g1 + 1);
        let done = truth.wait_complete(Duration::from_secs(120)).expect("done");
        assert_eq!(done.generation, g1 + 1);
        assert_eq!((done.image.width, done.image.height), (64, 36));
        let (coarse, grid) = level_setup(&first, 0);
        assert_eq!((coarse.width, coarse.height, grid), (8, 5, 1));
    }

    #[test]
    fn a_cancelled_render_returns_nothing() {
        let scene = small_scene();
        let bvh = SceneBvh::build(&scene.geometry);
        let out = mirrorbox_trace::render_while(
            &scene,
            &bvh,
            &TraceSettings::whitted(1),
            &|_| {},
            &|| false,
        );
        assert!(out.is_none());
    }
}
