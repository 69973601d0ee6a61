//! The `whitted` integrator: the shading contract (`docs/shading.md`) followed exactly.
//!
//! From the camera, follow perfect mirror reflections (throughput × reflectance at each
//! bounce) until a diffuse surface (shaded by [`mirrorbox_scene::Lighting`], with its shadow
//! legs traced through the BVH when the scene asks for shadows), the background,
//! or termination: `max_depth` reflections followed, or a throughput whose largest channel
//! would fall below `min_throughput`. A terminated path shows the scene's `terminal`
//! radiance on the mirror it could not follow, times the throughput so far.
//!
//! **Deep paths without drift**: mirror bounces are plane-exact in f64 and skip the mirror
//! they leave ([`crate::mirror_bounce`]).

use super::{Integrator, PathResult, Termination, face_normals};
use crate::bvh::packet::{LANES, LaneMask, RayPacket, lanes};
use crate::bvh::{Hit, SceneBvh};
use crate::mirror_bounce::MirrorPlanes;
use crate::sampler::SplitMix64;
use glam::{DVec3, Vec3};
use mirrorbox_scene::shading::{Interaction, interaction};
use mirrorbox_scene::{Ray, Scene};

/// Fewest rays of a pixel traced as a packet; fewer go one at a time.
const MIN_PACKET: usize = 4;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WhittedSettings {
    /// Most mirror reflections a path follows (the `--max-depth`).
    pub max_depth: u32,
    /// A path stops when the largest channel of its throughput would drop below this.
    pub min_throughput: f32,
}

impl Default for WhittedSettings {
    fn default() -> Self {
        WhittedSettings {
            max_depth: 10_000,
            min_throughput: 1e-4,
        }
    }
}

impl WhittedSettings {
    /// The one check of these settings (`trace` and `sweep` alike): `min_throughput` in
    /// `[0, 1)`; any depth is fine (paths are followed iteratively, nothing per bounce is kept).
    pub fn check(&self) -> Result<(), mirrorbox_scene::limits::SettingError> {
        if !(0.0..1.0).contains(&self.min_throughput) {
            return Err(mirrorbox_scene::limits::SettingError::new(
                "--min-throughput",
                "in [0, 1)",
                self.min_throughput,
            ));
        }
        Ok(())
    }
}

pub struct Whitted<'a> {
    scene: &'a Scene,
    bvh: &'a SceneBvh,
    settings: WhittedSettings,
    face_normals: Vec<Vec3>,
    mirror_planes: MirrorPlanes,
}

impl<'a> Whitted<'a> {
    pub fn new(scene: &'a Scene, bvh: &'a SceneBvh, settings: WhittedSettings) -> Self {
        let face_normals = face_normals(&scene.geometry);
        let mirror_planes = MirrorPlanes::new(scene);
        Whitted {
            scene,
            bvh,
            settings,
            face_normals,
            mirror_planes,
        }
    }

    pub fn settings(&self) -> WhittedSettings {
        self.settings
    }

    /// Whether the straight leg from `a` to `b` is unoccluded (`lighting.shadows`). It
    /// starts on mirror `a_mirror`, or else on triangle `from` (the shaded point); either is
    /// skipped, being planar. The leg ends at a light or on a mirror: hits within 10⁻⁴ of
    /// its length from `b` are not counted, as the `path` integrator's shadow rays do.
    fn leg_unoccluded(&self, a: Vec3, a_mirror: Option<usize>, from: usize, b: Vec3) -> bool {
        let d = b - a;
        let length = d.length();
        if length == 0.0 {
            return true;
        }
        let ray = Ray {
            origin: a,
            dir: d / length,
        };
        let skip_triangle = if a_mirror.is_none() { Some(from) } else { None };
        !self
            .bvh
            .occluded(&ray, 0.0, length * (1.0 - 1e-4), a_mirror, skip_triangle)
    }

    /// Radiance along `ray` (what [`Integrator::radiance`] returns; no random numbers).
    pub fn radiance(&self, ray: Ray) -> PathResult {
        self.trace(ray, |_, _, _| {})
    }

    /// Radiance along `ray`, calling `on_mirror(k, point, mirror)` at the k-th reflection
    /// (k from 1) with the exact hit point (tests and diagnostics; the closure inlines away).
    pub fn trace(&self, ray: Ray, mut on_mirror: impl FnMut(u32, DVec3, usize)) -> PathResult {
        let mut walk = Walk::new(ray);
        loop {
            let query = walk.query();
            let hit = self
                .bvh
                .closest_hit(&query, 0.0, f32::INFINITY, walk.leaving);
            if let Some(end) = self.step(&mut walk, &query, hit, &mut on_mirror) {
                return walk.result(end);
            }
        }
    }

    /// [`Whitted::radiance`] of each of `rays`, in order, into `out`: the rays walk their
    /// paths side by side, and each round's closest-hit queries go to the BVH together as
    /// one packet ([`SceneBvh::closest_hits`]). Every path takes the same steps as alone, so
    /// the results are the same.
    pub fn radiance_packet(&self, rays: &[Ray], out: &mut Vec<PathResult>) {
        for chunk in rays.chunks(LANES) {
            // Lanes past the chunk's end repeat its last ray and are never active.
            let mut walks: [Walk; LANES] =
                std::array::from_fn(|lane| Walk::new(chunk[lane.min(chunk.len() - 1)]));
            let mut ends = [Termination::Escaped; LANES];
            let mut active: LaneMask = (1 << chunk.len()) - 1;
            let mut packet = RayPacket::default();
            let mut queries = [chunk[0]; LANES];
            let mut hits = [None; LANES];
            while active != 0 {
                for lane in lanes(active) {
                    queries[lane] = walks[lane].query();
                    packet.set(lane, &queries[lane], walks[lane].leaving);
                }
                self.bvh.closest_hits(&packet, active, &mut hits);
                for lane in lanes(active) {
                    let walk = &mut walks[lane];
                    if let Some(end) =
                        self.step(walk, &queries[lane], hits[lane], &mut |_, _, _| {})
                    {
                        ends[lane] = end;
                        active &= !(1 << lane);
                    }
                }
            }
            out.extend((0..chunk.len()).map(|lane| walks[lane].result(ends[lane])));
        }
    }

    /// One step of a path: `hit` is the closest hit of `query` (the walk's current ray);
    /// shades it or reflects the walk there. `Some` when the path ends.
    #[inline(always)]
    fn step(
        &self,
        walk: &mut Walk,
        query: &Ray,
        hit: Option<Hit>,
        on_mirror: &mut impl FnMut(u32, DVec3, usize),
    ) -> Option<Termination> {
        let scene = self.scene;
        walk.rays += 1;
        let Some(hit) = hit else {
            walk.radiance += walk.throughput * scene.background;
            return Some(Termination::Escaped);
        };
        let normal = self.face_normals[hit.triangle];
        let front = normal.dot(query.dir) < 0.0;
        let surface = scene.geometry.surface(hit.triangle);
        match interaction(surface, front) {
            Interaction::Diffuse { albedo, emission } => {
                let p = query.at(hit.t);
                let mut legs = 0;
                let shaded = scene.lighting.diffuse_radiance_with(
                    p,
                    normal,
                    -query.dir,
                    albedo,
                    emission,
                    |a, a_mirror, b, _| {
                        legs += 1;
                        self.leg_unoccluded(a, a_mirror, hit.triangle, b)
                    },
                );
                walk.rays += legs;
                walk.radiance += walk.throughput * shaded;
                Some(Termination::Diffuse)
            }
            Interaction::Reflect { reflectance } => {
                let mirrorbox_scene::Surface::Mirror { mirror, .. } = *surface else {
                    unreachable!("only mirrors reflect")
                };
                let next = walk.throughput * reflectance;
                let cut = if walk.bounces >= self.settings.max_depth {
                    Some(Termination::Depth)
                } else if next.max_element() < self.settings.min_throughput {
                    Some(Termination::Throughput)
                } else {
                    None
                };
                if let Some(reason) = cut {
                    walk.radiance += walk.throughput * scene.terminal;
                    return Some(reason);
                }
                walk.throughput = next;
                walk.bounces += 1;
                let Some(next_ray) = self.mirror_planes.reflect(mirror, walk.origin, walk.dir)
                else {
                    return Some(Termination::Absorbed);
                };
                (walk.origin, walk.dir) = next_ray;
                walk.leaving = Some(mirror);
                on_mirror(walk.bounces, walk.origin, mirror);
                None
            }
        }
    }
}

/// A path in progress: its ray (in f64, for plane-exact bounces), what it carries so far
/// and the mirror it leaves.
#[derive(Clone, Copy)]
struct Walk {
    origin: DVec3,
    dir: DVec3,
    throughput: Vec3,
    radiance: Vec3,
    bounces: u32,
    rays: u32,
    leaving: Option<usize>,
}

impl Walk {
    fn new(ray: Ray) -> Self {
        Walk {
            origin: ray.origin.as_dvec3(),
            dir: ray.dir.as_dvec3(),
            throughput: Vec3::ONE,
            radiance: Vec3::ZERO,
            bounces: 0,
            rays: 0,
            leaving: None,
        }
    }

    /// The ray the BVH is asked about next.
    fn query(&self) -> Ray {
        Ray {
            origin: self.origin.as_vec3(),
            dir: self.dir.as_vec3(),
        }
    }

    fn result(&self, termination: Termination) -> PathResult {
        PathResult {
            radiance: self.radiance,
            bounces: self.bounces,
            termination,
            rays: self.rays,
        }
    }
}

impl Integrator for Whitted<'_> {
    fn radiance(&self, ray: Ray, _rng: &mut SplitMix64) -> PathResult {
        Whitted::radiance(self, ray)
    }

    /// As packets when the BVH traces them and there are enough rays to fill some lanes.
    fn radiance_all(&self, rays: &[Ray], _rng: &mut SplitMix64, out: &mut Vec<PathResult>) {
        out.clear();
        if self.bvh.packets() && rays.len() >= MIN_PACKET {
            self.radiance_packet(rays, out);
        } else {
            out.extend(rays.iter().map(|&ray| Whitted::radiance(self, ray)));
        }
    }
}
