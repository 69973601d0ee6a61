//! The image loop: every pixel's samples through the integrator, rows in parallel (rayon).
//!
//! Each pixel depends only on the scene, the settings and its own index, and its samples are
//! summed in a fixed order, so the image is bit-identical whatever the thread count.

use crate::bvh::SceneBvh;
use crate::cpu_features::{self, Vectorised};
use crate::integrator::{Integrator, IntegratorSettings, Termination};
use crate::path::PathSettings;
use crate::sampler::{Sampling, SplitMix64};
use mirrorbox_image::RgbImage;
use mirrorbox_scene::camera::RayGenerator;
use mirrorbox_scene::{Scene, SubpixelGrid};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// What to render with: sub-pixel sampling and the integrator. The default is the
/// command line's: the 4×4 grid (16 spp) and `whitted` at its defaults. Change only what
/// differs: `TraceSettings::whitted(2).with_integrator(WhittedSettings { .. })`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceSettings {
    pub sampling: Sampling,
    pub integrator: IntegratorSettings,
}

impl Default for TraceSettings {
    fn default() -> Self {
        TraceSettings::whitted(4)
    }
}

impl TraceSettings {
    /// `whitted` at its defaults on the `grid_side × grid_side` sub-pixel grid.
    pub fn whitted(grid_side: u32) -> Self {
        TraceSettings {
            sampling: Sampling::Grid(SubpixelGrid::new(grid_side)),
            integrator: IntegratorSettings::default(),
        }
    }

    /// `path` with `settings` on the `grid_side × grid_side` sub-pixel grid.
    pub fn path(grid_side: u32, settings: PathSettings) -> Self {
        TraceSettings::whitted(grid_side).with_integrator(settings)
    }

    pub fn with_sampling(self, sampling: Sampling) -> Self {
        TraceSettings { sampling, ..self }
    }

    /// Takes [`IntegratorSettings`], or a `WhittedSettings` / `PathSettings` directly.
    pub fn with_integrator(self, integrator: impl Into<IntegratorSettings>) -> Self {
        TraceSettings {
            integrator: integrator.into(),
            ..self
        }
    }
}

/// Counters over all paths of a render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraceStats {
    pub paths: u64,
    pub rays: u64,
    pub diffuse: u64,
    pub escaped: u64,
    /// Cut at `max_depth`.
    pub cut_by_depth: u64,
    /// Cut at `min_throughput` (`whitted`).
    pub cut_by_throughput: u64,
    /// Ended by Russian roulette (`path`).
    pub cut_by_roulette: u64,
    /// Absorbed by an uneven mirror (its reflection would leave behind it).
    pub absorbed: u64,
    /// Most mirror reflections followed by any path.
    pub deepest: u32,
}

impl TraceStats {
    fn record(&mut self, bounces: u32, termination: Termination, rays: u32) {
        self.paths += 1;
        self.rays += rays as u64;
        self.deepest = self.deepest.max(bounces);
        match termination {
            Termination::Diffuse => self.diffuse += 1,
            Termination::Escaped => self.escaped += 1,
            Termination::Depth => self.cut_by_depth += 1,
            Termination::Throughput => self.cut_by_throughput += 1,
            Termination::Roulette => self.cut_by_roulette += 1,
            Termination::Absorbed => self.absorbed += 1,
        }
    }
    fn merge(mut self, o: TraceStats) -> TraceStats {
        self.paths += o.paths;
        self.rays += o.rays;
        self.diffuse += o.diffuse;
        self.escaped += o.escaped;
        self.cut_by_depth += o.cut_by_depth;
        self.cut_by_throughput += o.cut_by_throughput;
        self.cut_by_roulette += o.cut_by_roulette;
        self.absorbed += o.absorbed;
        self.deepest = self.deepest.max(o.deepest);
        self
    }
}

pub struct TraceOutput {
    /// Linear radiance, the mean over each pixel's samples.
    pub image: RgbImage,
    /// Mean number of mirror reflections per pixel (the same value in all three channels).
    pub bounces: RgbImage,
    pub stats: TraceStats,
    /// Wall time of the image loop (BVH build excluded; see [`SceneBvh::build_time`]).
    pub wall: Duration,
    pub threads: usize,
    /// The vector build the image loop ran ([`cpu_features::build_for`]).
    pub vectors: cpu_features::Build,
}

/// One finished image row: radiance, mean bounces, statistics.
type Row = (Vec<[f32; 3]>, Vec<[f32; 3]>, TraceStats);

/// One image row: every pixel's camera rays (generated sixteen at a time) through the
/// integrator, as many pixels per call as it takes ([`Integrator::pixels_per_call`]), each
/// pixel's results summed in order. Compiled for the CPU's widest vectors.
struct RowWork<'a> {
    y: u32,
    width: u32,
    rays: &'a RayGenerator,
    sampling: &'a Sampling,
    integrator: &'a dyn Integrator,
    seed: u64,
}

impl Vectorised for RowWork<'_> {
    type Output = Row;

    #[inline(always)]
    fn run(self) -> Row {
        let RowWork {
            y,
            width: w,
            rays,
            sampling,
            integrator,
            seed,
        } = self;
        let samples = sampling.grid().samples_per_pixel() as usize;
        let spp = samples as f32;
        let batch = integrator.pixels_per_call(samples).max(1) as u32;
        let mut offsets = Vec::new();
        let mut positions = Vec::new();
        let mut camera_rays = Vec::new();
        let mut results = Vec::new();
        let mut rngs = Vec::new();
        let mut stats = TraceStats::default();
        let mut colour = Vec::with_capacity(w as usize);
        let mut depth = Vec::with_capacity(w as usize);
        // The grid's offsets are the same in every pixel.
        let per_pixel = matches!(sampling, Sampling::Jittered { .. });
        sampling.offsets(y as u64 * w as u64, &mut offsets);
        let pixel_index = |x: u32| y as u64 * w as u64 + x as u64;
        for first in (0..w).step_by(batch as usize) {
            // The camera rays of pixels first.. (as many as the integrator takes per call),
            // pixel after pixel, and each pixel's random stream.
            positions.clear();
            rngs.clear();
            for x in first..(first + batch).min(w) {
                if per_pixel {
                    sampling.offsets(pixel_index(x), &mut offsets);
                }
                let (x_f, y_f) = (x as f32, y as f32);
                positions.extend(
                    offsets
                        .iter()
                        .map(|o| glam::Vec2::new(x_f + o.x, y_f + o.y)),
                );
                rngs.push(SplitMix64::for_pixel(seed, pixel_index(x)));
            }
            integrator.radiance_at(rays, &positions, &mut camera_rays, &mut rngs, &mut results);
            for pixel in results.chunks(samples) {
                let mut sum = glam::Vec3::ZERO;
                let mut bounces = 0u64;
                for r in pixel {
                    sum += r.radiance;
                    bounces += r.bounces as u64;
                    stats.record(r.bounces, r.termination, r.rays);
                }
                colour.push((sum / spp).to_array());
                depth.push([bounces as f32 / spp; 3]);
            }
        }
        (colour, depth, stats)
    }
}

/// Renders `scene` (its camera's size) with `bvh`. `progress(rows_done)` is called as rows
/// finish, from worker threads.
pub fn render(
    scene: &Scene,
    bvh: &SceneBvh,
    settings: &TraceSettings,
    progress: &(dyn Fn(u32) + Sync),
) -> TraceOutput {
    render_while(scene, bvh, settings, progress, &|| true)
        .expect("a render that is never cancelled finishes")
}

/// [`render`], abandoned (`None`) as soon as `go_on()` is false before a row starts: the
/// viewer's live truth cancels a view the camera has left. A finished render is the same
/// image as [`render`]'s, bit for bit.
pub fn render_while(
    scene: &Scene,
    bvh: &SceneBvh,
    settings: &TraceSettings,
    progress: &(dyn Fn(u32) + Sync),
    go_on: &(dyn Fn() -> bool + Sync),
) -> Option<TraceOutput> {
    let cam = &scene.camera;
    let (w, h) = (cam.width, cam.height);
    let rays = cam.ray_generator();
    let integrator = settings.integrator.build(scene, bvh);
    let seed = settings.integrator.seed();
    let vectors = cpu_features::build_for(integrator.gains_from_512_bits());
    let done = AtomicU32::new(0);
    let start = Instant::now();
    let rows: Option<Vec<Row>> = (0..h)
        .into_par_iter()
        .map(|y| {
            if !go_on() {
                return None;
            }
            let row = cpu_features::run_on(
                vectors,
                RowWork {
                    y,
                    width: w,
                    rays: &rays,
                    sampling: &settings.sampling,
                    integrator: integrator.as_ref(),
                    seed,
                },
            );
            progress(done.fetch_add(1, Ordering::Relaxed) + 1);
            Some(row)
        })
        .collect();
    let rows = rows?;
    let wall = start.elapsed();
    let mut image = RgbImage::new(w, h);
    let mut bounces = RgbImage::new(w, h);
    let mut stats = TraceStats::default();
    image.pixels.clear();
    bounces.pixels.clear();
    for (c, d, s) in rows {
        image.pixels.extend(c);
        bounces.pixels.extend(d);
        stats = stats.merge(s);
    }
    Some(TraceOutput {
        image,
        bounces,
        stats,
        wall,
        threads: rayon::current_num_threads(),
        vectors,
    })
}
