//! Integrators: the radiance of one camera sample.
//!
//! - [`whitted`]: the shading contract followed to deep bounce counts (the ground truth).
//! - [`path`]: physically based, for comparison with Mitsuba's `path`.
//!
//! Every integrator implements [`Integrator`]; [`IntegratorSettings`] has one variant per
//! integrator and builds it for a scene, once per render. Adding one:
//! `docs/adding-an-integrator.md`.

pub mod path;
pub mod whitted;

use crate::bvh::SceneBvh;
use crate::cpu_features::{Vectorised, build_for, run_on};
use crate::sampler::SplitMix64;
use glam::{Vec2, Vec3};
use mirrorbox_scene::camera::RayGenerator;
use mirrorbox_scene::{Geometry, Ray, Scene};
use path::{PathSettings, PathTracer};
use whitted::{Whitted, WhittedSettings};

/// The radiance of one camera sample. `Sync`: the image loop shares one integrator across
/// its threads.
pub trait Integrator: Sync {
    /// Radiance along the camera ray `ray`. Random numbers come from `rng`, the pixel's own
    /// stream (seeded by [`IntegratorSettings::seed`] and the pixel index, shared by the
    /// pixel's samples in order); a deterministic integrator ignores it.
    fn radiance(&self, ray: Ray, rng: &mut SplitMix64) -> PathResult;

    /// The radiance of each of `rngs.len()` pixels' camera rays `rays` (pixel after pixel,
    /// equally many each), in order, into `out` (cleared first): exactly what
    /// [`Integrator::radiance`] returns for each in turn, the rays of the call's p-th pixel
    /// sharing that pixel's stream `rngs[p]` in order. An integrator may trace them together (`whitted`
    /// and `path` trace packets).
    fn radiance_all(&self, rays: &[Ray], rngs: &mut [SplitMix64], out: &mut Vec<PathResult>) {
        out.clear();
        for (pixel, rng) in rays.chunks(rays_per_pixel(rays, rngs)).zip(rngs) {
            out.extend(pixel.iter().map(|&ray| self.radiance(ray, rng)));
        }
    }

    /// [`Integrator::radiance_all`] of the camera rays `camera` makes through the image
    /// positions `positions` (pixel after pixel, as there), made into `rays` first (a buffer
    /// kept by the caller). An integrator may make them itself, in the form it walks them
    /// (`whitted`'s packets: in lanes, no buffer of rays), with the same bits.
    fn radiance_at(
        &self,
        camera: &RayGenerator,
        positions: &[Vec2],
        rays: &mut Vec<Ray>,
        rngs: &mut [SplitMix64],
        out: &mut Vec<PathResult>,
    ) {
        rays.clear();
        camera_rays(camera, positions, rays, self.gains_from_512_bits());
        self.radiance_all(rays, rngs, out);
    }

    /// Whether the AVX-512 build of a render's work (the image row, the camera rays, the
    /// walks) pays where 512-bit vectors slow the CPU's clock
    /// ([`crate::cpu_features::build_for`]): default yes; `path` says no.
    fn gains_from_512_bits(&self) -> bool {
        true
    }

    /// How many neighbouring pixels of a row the image loop may hand to one
    /// [`Integrator::radiance_all`] call, their rays pixel after pixel, given
    /// `samples_per_pixel` (each with its own random stream). Default 1; 0 is taken as 1.
    fn pixels_per_call(&self, samples_per_pixel: usize) -> usize {
        let _ = samples_per_pixel;
        1
    }
}

/// The camera rays `camera` makes through the image positions `positions`, appended to
/// `rays`: [`RayGenerator::rays_at_positions`] compiled for the CPU's widest vectors, or the
/// integrator's build where 512-bit ones do not pay for it ([`build_for`]).
pub fn camera_rays(
    camera: &RayGenerator,
    positions: &[Vec2],
    rays: &mut Vec<Ray>,
    gains_from_512_bits: bool,
) {
    struct MakeRays<'w> {
        camera: &'w RayGenerator,
        positions: &'w [Vec2],
        rays: &'w mut Vec<Ray>,
    }
    impl Vectorised for MakeRays<'_> {
        type Output = ();
        #[inline(always)]
        fn run(self) {
            self.camera.rays_at_positions(self.positions, self.rays);
        }
    }
    run_on(
        build_for(gains_from_512_bits),
        MakeRays {
            camera,
            positions,
            rays,
        },
    );
}

/// Packets per [`Integrator::radiance_all`] call: a call's fixed work (its walks' buffers
/// set up, the vector build chosen, the row's per-call bookkeeping) shared by this many
/// packets. Against one (issue 56, plain builds, one thread, this project's AVX2 AMD EPYC,
/// paired): `whitted` `mirror_box` ×0.910 [0.831–0.956] (40 rounds) and ×0.877 (30),
/// `mirror_room` ×0.955, `path` ×0.958 / ×0.955; the instructions of `whitted` (160×90,
/// cachegrind) −15.7 % / −5.6 % (most of it a 3 KB `memset` per call, which valgrind counts
/// by the byte); docs/tracer-performance.md.
const PACKETS_PER_CALL: usize = 8;

/// Pixels per [`Integrator::radiance_all`] call for an integrator that traces packets:
/// as many as fill [`PACKETS_PER_CALL`] packets' lanes, at least one, when `bvh` traces
/// packets; else one. (A pixel that fills that many by itself goes alone: more pixels would
/// only make the call's buffers larger — `path` at 9 216 samples a pixel measured ×1.2
/// slower with eight pixels a call.) Lanes are grouped into packets within a call, so this
/// changes which rays share a packet, never an answer: the packets give the single-ray
/// answers, bit for bit.
fn packet_pixels(bvh: &SceneBvh, samples_per_pixel: usize) -> usize {
    if bvh.packets() && samples_per_pixel >= 1 {
        (crate::bvh::packet::LANES * PACKETS_PER_CALL / samples_per_pixel).max(1)
    } else {
        1
    }
}

/// How many rays each pixel has in a [`Integrator::radiance_all`] call: `rays` must hold
/// `rngs.len()` pixels' rays, equally many each (the image loop's contract; a mismatch
/// would pair rays with the wrong streams, so it is checked).
fn rays_per_pixel(rays: &[Ray], rngs: &[SplitMix64]) -> usize {
    assert!(
        !rngs.is_empty() && rays.len().is_multiple_of(rngs.len()),
        "{} rays for {} pixels",
        rays.len(),
        rngs.len()
    );
    (rays.len() / rngs.len()).max(1)
}

/// How a path ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Termination {
    /// Shaded at a diffuse surface.
    Diffuse,
    /// Left the scene (background).
    Escaped,
    /// Cut at `max_depth`.
    Depth,
    /// Cut because its throughput fell below `min_throughput`.
    Throughput,
    /// Ended by Russian roulette.
    Roulette,
    /// Absorbed by an uneven mirror (`docs/shading.md`, "Uneven mirrors").
    Absorbed,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathResult {
    pub radiance: Vec3,
    /// Mirror reflections followed.
    pub bounces: u32,
    pub termination: Termination,
    /// Rays cast (closest-hit and shadow queries).
    pub rays: u32,
}

/// Which integrator renders, with its settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IntegratorSettings {
    Whitted(WhittedSettings),
    Path(PathSettings),
}

impl Default for IntegratorSettings {
    fn default() -> Self {
        IntegratorSettings::Whitted(WhittedSettings::default())
    }
}

impl From<WhittedSettings> for IntegratorSettings {
    fn from(s: WhittedSettings) -> Self {
        IntegratorSettings::Whitted(s)
    }
}

impl From<PathSettings> for IntegratorSettings {
    fn from(s: PathSettings) -> Self {
        IntegratorSettings::Path(s)
    }
}

impl IntegratorSettings {
    /// The integrator for `scene` and its `bvh`.
    pub fn build<'a>(&self, scene: &'a Scene, bvh: &'a SceneBvh) -> Box<dyn Integrator + 'a> {
        match *self {
            IntegratorSettings::Whitted(s) => Box::new(Whitted::new(scene, bvh, s)),
            IntegratorSettings::Path(s) => Box::new(PathTracer::new(scene, bvh, s)),
        }
    }

    /// The name on the command line and in image metadata.
    pub fn name(&self) -> &'static str {
        match self {
            IntegratorSettings::Whitted(_) => "whitted",
            IntegratorSettings::Path(_) => "path",
        }
    }

    /// Seed of the per-pixel random streams; 0 for integrators that draw no random numbers.
    pub fn seed(&self) -> u64 {
        match self {
            IntegratorSettings::Whitted(_) => 0,
            IntegratorSettings::Path(p) => p.seed,
        }
    }
}

/// Unit face normal of every triangle of `geometry`, by index (front side).
pub fn face_normals(geometry: &Geometry) -> Vec<Vec3> {
    (0..geometry.triangles.len())
        .map(|i| geometry.face_normal(i))
        .collect()
}
