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
    /// Per mirror: its plane where it is flat (what [`MirrorPlanes::flat_plane`] answers;
    /// a copy of `planes` and `bumps` together, kept apart from the large bump records so
    /// that a bounce reads one small entry).
    flat: Vec<Option<(DVec3, f64)>>,
}

impl MirrorPlanes {
    pub fn new(scene: &Scene) -> Self {
        let planes = scene
            .mirrors
            .iter()
            .map(mirrorbox_scene::Mirror::plane_f64)
            .collect::<Vec<_>>();
        let bumps = scene
            .mirrors
            .iter()
            .zip(&scene.bumps)
            .map(|(m, b)| b.clone().map(|b| (m.clone(), b)))
            .collect::<Vec<_>>();
        let flat = planes
            .iter()
            .zip(&bumps)
            .map(|(&plane, bump)| bump.is_none().then_some(plane))
            .collect();
        MirrorPlanes {
            planes,
            bumps,
            flat,
        }
    }

    /// The ray `origin + t·dir` reflected at mirror `mirror`: (hit point, reflected
    /// direction), or `None` where an uneven mirror absorbs it (radiance 0 from there).
    /// Inline, with the bump's normal ([`bump::world_normal`]): compiled into the walks for
    /// their CPU features (out of line it was a quarter of `bumpy_pair`'s time, compiled for
    /// the baseline; inlined, the uneven scenes ×0.72, the same bits).
    #[inline(always)]
    pub fn reflect(&self, mirror: usize, origin: DVec3, dir: DVec3) -> Option<(DVec3, DVec3)> {
        let (n, offset) = self.planes[mirror];
        match &self.bumps[mirror] {
            None => {
                let (hit, r) =
                    reflect_on_plane(n.to_array(), offset, origin.to_array(), dir.to_array());
                Some((DVec3::from(hit), DVec3::from(r)))
            }
            Some((m, b)) => {
                let t = (offset - n.dot(origin)) / n.dot(dir);
                let hit = origin + dir * t;
                let shading = bump::world_normal(m, b, hit);
                bump::reflect(dir, n, shading).map(|r| (hit, r))
            }
        }
    }

    /// The plane (unit normal, offset) of mirror `mirror` when it is flat; `None` when it
    /// is uneven (its bounce needs [`MirrorPlanes::reflect`]).
    #[inline(always)]
    pub fn flat_plane(&self, mirror: usize) -> Option<(DVec3, f64)> {
        self.flat[mirror]
    }
}

/// The plane-exact bounce of `o + t·d` off the plane `n·x = offset`: the hit
/// `o + t·d` with `t = (offset − n·o)/(n·d)`, and `normalize(d − 2(d·n)n)`. Written on
/// arrays with glam's order of operations (its `dot`, `normalize` = `v · (1/√(v·v))`), so
/// that a loop over the lanes of a packet vectorises and gives the same bits as one ray.
#[inline(always)]
pub fn reflect_on_plane(
    n: [f64; 3],
    offset: f64,
    o: [f64; 3],
    d: [f64; 3],
) -> ([f64; 3], [f64; 3]) {
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let t = (offset - dot(n, o)) / dot(n, d);
    let hit = [o[0] + d[0] * t, o[1] + d[1] * t, o[2] + d[2] * t];
    let s = 2.0 * dot(d, n);
    let r = [d[0] - s * n[0], d[1] - s * n[1], d[2] - s * n[2]];
    let inv_length = 1.0 / dot(r, r).sqrt();
    (
        hit,
        [r[0] * inv_length, r[1] * inv_length, r[2] * inv_length],
    )
}

/// A packet's bounces off flat mirrors, side by side: every lane with `flat[i]` has its ray
/// `(origin, dir)` (f64 lanes) replaced by the bounce off the plane `(normal, offset)`
/// ([`reflect_on_plane`]), rounded to f32 when `ROUND_TO_F32` (the `path` integrator holds
/// its rays in f32); other lanes keep their ray. Branch free over all lanes: it vectorises
/// (inline: compiled for the caller's CPU features).
#[inline(always)]
pub fn bounce_flat_lanes<const L: usize, const ROUND_TO_F32: bool>(
    flat: &[bool; L],
    normal: &[[f64; L]; 3],
    offset: &[f64; L],
    origin: &mut [[f64; L]; 3],
    dir: &mut [[f64; L]; 3],
) {
    for i in 0..L {
        let n = [normal[0][i], normal[1][i], normal[2][i]];
        let o = [origin[0][i], origin[1][i], origin[2][i]];
        let d = [dir[0][i], dir[1][i], dir[2][i]];
        let (hit, r) = reflect_on_plane(n, offset[i], o, d);
        for k in 0..3 {
            let (h, r) = if ROUND_TO_F32 {
                (hit[k] as f32 as f64, r[k] as f32 as f64)
            } else {
                (hit[k], r[k])
            };
            origin[k][i] = if flat[i] { h } else { origin[k][i] };
            dir[k][i] = if flat[i] { r } else { dir[k][i] };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The array form gives glam's bits (the form the truth was rendered with before the
    /// packet walks vectorised it), over random planes, origins and directions.
    #[test]
    fn plane_bounce_is_glams_arithmetic() {
        let mut rng = crate::sampler::SplitMix64::for_pixel(11, 0);
        let mut unit = || {
            let v = DVec3::new(
                rng.next_unit() as f64,
                rng.next_unit() as f64,
                rng.next_unit() as f64,
            ) - 0.5;
            v.normalize()
        };
        for _ in 0..10_000 {
            let (n, d) = (unit(), unit());
            let o = unit() * 3.0;
            let offset = n.dot(unit());
            let t = (offset - n.dot(o)) / n.dot(d);
            let hit = o + d * t;
            let r = (d - 2.0 * d.dot(n) * n).normalize();
            let (h, s) = reflect_on_plane(n.to_array(), offset, o.to_array(), d.to_array());
            assert_eq!(h.map(f64::to_bits), hit.to_array().map(f64::to_bits));
            assert_eq!(s.map(f64::to_bits), r.to_array().map(f64::to_bits));
        }
    }
}
