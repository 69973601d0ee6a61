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

use mirrorbox_image::RgbImage;
use mirrorbox_scene::{Camera, Scene};
use mirrorbox_trace::{SceneBvh, TraceSettings};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Downscale factors of the coarse levels, before the full-size level.
pub const COARSE_LEVELS: [u32; 3] = [8, 4, 2];

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
}

/// The background tracer. Dropping it stops the worker (after its current row).
pub struct LiveTruth {
    shared: Arc<Shared>,
    worker: Option<JoinHandle<()>>,
    requested: Option<TruthRequest>,
}

impl LiveTruth {
    /// Starts the worker for `scene` (the camera of each request replaces the scene's).
    pub fn start(scene: Arc<Scene>) -> Self {
        let shared = Arc::new(Shared {
            request: Mutex::new(None),
            wake: Condvar::new(),
            generation: AtomicU64::new(0),
            latest: Mutex::new(None),
            closing: Default::default(),
        });
        let for_worker = shared.clone();
        let worker = std::thread::Builder::new()
            .name("live truth".into())
            .spawn(move || work(&scene, &for_worker))
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

fn work(scene: &Scene, shared: &Shared) {
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
            let settings = TraceSettings::whitted(grid_side);
            let Some(out) =
                mirrorbox_trace::render_while(&view, &bvh, &settings, &|_| {}, &current)
            else {
                break;
            };
            let finished = TruthLevel {
                generation,
                level,
                complete: level + 1 == level_count(),
                image: Arc::new(out.image),
                trace_time: out.wall,
            };
            if !current() {
                break;
            }
            *shared.latest.lock().expect("truth level") = Some(finished);
        }
        done_generation = generation;
    }
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
        let mut truth = LiveTruth::start(Arc::new(scene.clone()));
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

    #[test]
    fn a_new_view_replaces_the_old_one_and_levels_grow() {
        let scene = small_scene();
        let mut truth = LiveTruth::start(Arc::new(scene.clone()));
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
