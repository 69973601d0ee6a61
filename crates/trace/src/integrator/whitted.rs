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
use crate::bvh::SceneBvh;
use crate::mirror_bounce::MirrorPlanes;
use crate::sampler::SplitMix64;
use glam::{DVec3, Vec3};
use mirrorbox_scene::shading::{Interaction, interaction};
use mirrorbox_scene::{Ray, Scene};

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
        let scene = self.scene;
        let mut origin = ray.origin.as_dvec3();
        let mut dir = ray.dir.as_dvec3();
        let mut throughput = Vec3::ONE;
        let mut radiance = Vec3::ZERO;
        let mut bounces = 0u32;
        let mut rays = 0u32;
        let mut leaving: Option<usize> = None;
        let termination = loop {
            rays += 1;
            let query = Ray {
                origin: origin.as_vec3(),
                dir: dir.as_vec3(),
            };
            let Some(hit) = self.bvh.closest_hit(&query, 0.0, f32::INFINITY, leaving) else {
                radiance += throughput * scene.background;
                break Termination::Escaped;
            };
            let normal = self.face_normals[hit.triangle];
            let front = normal.dot(query.dir) < 0.0;
            let surface = scene.geometry.surface(hit.triangle);
            match interaction(surface, front) {
                Interaction::Diffuse { albedo, emission } => {
                    let p = query.at(hit.t);
                    let shaded = scene.lighting.diffuse_radiance_with(
                        p,
                        normal,
                        -query.dir,
                        albedo,
                        emission,
                        |a, a_mirror, b, _| {
                            rays += 1;
                            self.leg_unoccluded(a, a_mirror, hit.triangle, b)
                        },
                    );
                    radiance += throughput * shaded;
                    break Termination::Diffuse;
                }
                Interaction::Reflect { reflectance } => {
                    let mirrorbox_scene::Surface::Mirror { mirror, .. } = *surface else {
                        unreachable!("only mirrors reflect")
                    };
                    let next = throughput * reflectance;
                    let cut = if bounces >= self.settings.max_depth {
                        Some(Termination::Depth)
                    } else if next.max_element() < self.settings.min_throughput {
                        Some(Termination::Throughput)
                    } else {
                        None
                    };
                    if let Some(reason) = cut {
                        radiance += throughput * scene.terminal;
                        break reason;
                    }
                    throughput = next;
                    bounces += 1;
                    let Some(next_ray) = self.mirror_planes.reflect(mirror, origin, dir) else {
                        break Termination::Absorbed;
                    };
                    (origin, dir) = next_ray;
                    leaving = Some(mirror);
                    on_mirror(bounces, origin, mirror);
                }
            }
        };
        PathResult {
            radiance,
            bounces,
            termination,
            rays,
        }
    }
}

impl Integrator for Whitted<'_> {
    fn radiance(&self, ray: Ray, _rng: &mut SplitMix64) -> PathResult {
        Whitted::radiance(self, ray)
    }
}
