//! Plane-exact mirror bounces, shared by every integrator.
//!
//! A mirror hit is re-solved in f64 against the mirror's exact plane
//! (`t = (offset − n·o)/(n·d)`) and reflected there (`d − 2(d·n)n`); the BVH only decides
//! *which* mirror is hit. The next ray skips the mirror it leaves (a planar mirror cannot be
//! hit again by its own reflection), so no offset epsilon is needed and error after k bounces
//! stays at f64 rounding (tested against the closed form at k = 10 000).
//!
//! An uneven mirror (`mirrorbox_scene::bump`) reflects about its perturbed normal at the hit
//! point instead, or absorbs the ray by the contract's rule (`docs/shading.md`); a flat bump
//! reflects bit for bit as a plain mirror. The reflected ray still leaves the mirror's plane
//! forwards, so it cannot hit that mirror again either.

use glam::DVec3;
use mirrorbox_scene::Scene;
use mirrorbox_scene::bump::{self, MirrorBump};

pub struct MirrorPlanes {
    /// Per mirror: unit normal and offset, in f64.
    planes: Vec<(DVec3, f64)>,
    /// Per mirror: the mirror and its bump, where it has one.
    bumps: Vec<Option<(mirrorbox_scene::Mirror, MirrorBump)>>,
}

impl MirrorPlanes {
    pub fn new(scene: &Scene) -> Self {
        let planes = scene
            .mirrors
            .iter()
            .map(mirrorbox_scene::Mirror::plane_f64)
            .collect();
        let bumps = scene
            .mirrors
            .iter()
            .zip(&scene.bumps)
            .map(|(m, b)| b.clone().map(|b| (m.clone(), b)))
            .collect();
        MirrorPlanes { planes, bumps }
    }

    /// The ray `origin + t·dir` reflected at mirror `mirror`: (hit point, reflected
    /// direction), or `None` where an uneven mirror absorbs it (radiance 0 from there).
    pub fn reflect(&self, mirror: usize, origin: DVec3, dir: DVec3) -> Option<(DVec3, DVec3)> {
        let (n, offset) = self.planes[mirror];
        let t = (offset - n.dot(origin)) / n.dot(dir);
        let hit = origin + dir * t;
        match &self.bumps[mirror] {
            None => Some((hit, (dir - 2.0 * dir.dot(n) * n).normalize())),
            Some((m, b)) => {
                let shading = bump::world_normal(m, b, hit);
                bump::reflect(dir, n, shading).map(|r| (hit, r))
            }
        }
    }
}
