//! Plane-exact mirror bounces, shared by every integrator.
//!
//! A mirror hit is re-solved against the mirror's exact plane (`t = (offset − n·o)/(n·d)`)
//! and reflected there (`d − 2(d·n)n`); the BVH only decides *which* mirror is hit. The next
//! ray skips the mirror it leaves (a planar mirror cannot be hit again by its own
//! reflection), so no offset epsilon is needed. `whitted` bounces in f64, so that error after
//! k bounces stays at f64 rounding (tested against the closed form at k = 10 000); `path`,
//! whose rays are f32 and whose paths are at most a few dozen segments (as Mitsuba's, which
//! bounces in f32), bounces in f32 — the same formula ([`reflect_on_plane`] on [`PlaneReal`]),
//! the plane rounded to f32 ([`MirrorPlanes::flat_plane_f32`]): measured ×0.975 / ×0.971 on
//! `path` `mirror_box` / `mirror_room` (issue 56, docs/tracer-performance.md).
//!
//! An uneven mirror (`mirrorbox_scene::bump`) reflects about its perturbed normal at the hit
//! point instead, or absorbs the ray by the contract's rule (`docs/shading.md`); a flat bump
//! reflects bit for bit as a plain mirror. The reflected ray still leaves the mirror's plane
//! forwards, so it cannot hit that mirror again either.

use std::mem::MaybeUninit;

use glam::DVec3;
use mirrorbox_scene::Scene;
use mirrorbox_scene::bump::{self, MirrorBump};
use mirrorbox_scene::lanes::store_unmasked;

pub struct MirrorPlanes {
    /// Per mirror: unit normal and offset, in f64.
    planes: Vec<(DVec3, f64)>,
    /// Per mirror: the mirror and its bump, where it has one.
    bumps: Vec<Option<(mirrorbox_scene::Mirror, MirrorBump)>>,
    /// Per mirror: its plane where it is flat (what [`MirrorPlanes::flat_plane`] answers;
    /// a copy of `planes` and `bumps` together, kept apart from the large bump records so
    /// that a bounce reads one small entry).
    flat: Vec<Option<(DVec3, f64)>>,
    /// `flat` rounded to f32 ([`MirrorPlanes::flat_plane_f32`]).
    flat_f32: Vec<Option<([f32; 3], f32)>>,
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
            .collect::<Vec<_>>();
        let flat_f32 = flat
            .iter()
            .map(|p| p.map(|(n, offset)| (n.as_vec3().to_array(), offset as f32)))
            .collect();
        MirrorPlanes {
            planes,
            bumps,
            flat,
            flat_f32,
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

    /// [`MirrorPlanes::flat_plane`] rounded to f32: the `path` integrator's bounces
    /// ([`reflect_on_plane`] on f32).
    #[inline(always)]
    pub fn flat_plane_f32(&self, mirror: usize) -> Option<([f32; 3], f32)> {
        self.flat_f32[mirror]
    }
}

/// The arithmetic [`reflect_on_plane`] needs, for f64 (`whitted`: plane-exact chains of
/// thousands of bounces) and f32 (`path`, whose rays and hit points are f32, as Mitsuba's).
pub trait PlaneReal:
    Copy
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
{
    const ONE: Self;
    const TWO: Self;
    fn sqrt(self) -> Self;
}

macro_rules! plane_real {
    ($($t:ty),*) => {$(
        impl PlaneReal for $t {
            const ONE: $t = 1.0;
            const TWO: $t = 2.0;
            #[inline(always)]
            fn sqrt(self) -> $t {
                <$t>::sqrt(self)
            }
        }
    )*};
}

plane_real!(f64, f32);

/// The plane-exact bounce of `o + t·d` off the plane `n·x = offset`: the hit
/// `o + t·d` with `t = (offset − n·o)/(n·d)`, and `normalize(d − 2(d·n)n)`. Written on
/// arrays with glam's order of operations (its `dot`, `normalize` = `v · (1/√(v·v))`), so
/// that a loop over the lanes of a packet vectorises and gives the same bits as one ray.
/// In f64 for `whitted`, in f32 for `path`.
#[inline(always)]
pub fn reflect_on_plane<T: PlaneReal>(
    n: [T; 3],
    offset: T,
    o: [T; 3],
    d: [T; 3],
) -> ([T; 3], [T; 3]) {
    let dot = |a: [T; 3], b: [T; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let t = (offset - dot(n, o)) / dot(n, d);
    let hit = [o[0] + d[0] * t, o[1] + d[1] * t, o[2] + d[2] * t];
    let s = T::TWO * dot(d, n);
    let r = [d[0] - s * n[0], d[1] - s * n[1], d[2] - s * n[2]];
    let inv_length = T::ONE / dot(r, r).sqrt();
    (
        hit,
        [r[0] * inv_length, r[1] * inv_length, r[2] * inv_length],
    )
}

/// A packet's bounces off flat mirrors, side by side: every lane with `flat[i]` has its ray
/// `(origin, dir)` replaced by the bounce off the plane `(normal, offset)`
/// ([`reflect_on_plane`], f64 or f32 lanes); other lanes keep their ray. Branch free over
/// all lanes: it vectorises (inline: compiled for the caller's CPU features).
#[inline(always)]
pub fn bounce_flat_lanes<T: PlaneReal, const L: usize>(
    flat: &[bool; L],
    normal: &[[T; L]; 3],
    offset: &[T; L],
    origin: &mut [[T; L]; 3],
    dir: &mut [[T; L]; 3],
) {
    // The new lanes start uninitialised: the loop writes every one of them (a copy of the
    // old lanes first, or zeros, is 48 vector stores a round for nothing: ×0.988 / ×0.986 on
    // `whitted` `mirror_room` / `mirror_box` without it, issue 56's ninth session).
    let mut new_origin = MaybeUninit::<[[T; L]; 3]>::uninit();
    let mut new_dir = MaybeUninit::<[[T; L]; 3]>::uninit();
    let (o_out, d_out) = (new_origin.as_mut_ptr(), new_dir.as_mut_ptr());
    for i in 0..L {
        let n = [normal[0][i], normal[1][i], normal[2][i]];
        let o = [origin[0][i], origin[1][i], origin[2][i]];
        let d = [dir[0][i], dir[1][i], dir[2][i]];
        let (hit, r) = reflect_on_plane(n, offset[i], o, d);
        for k in 0..3 {
            // SAFETY: in bounds of the arrays the pointers point to; `T: Copy`, so
            // assigning to an uninitialised place drops nothing.
            unsafe {
                (*o_out)[k][i] = if flat[i] { hit[k] } else { o[k] };
                (*d_out)[k][i] = if flat[i] { r[k] } else { d[k] };
            }
        }
    }
    // SAFETY: the loop above wrote every lane of every component of both.
    let (new_origin, new_dir) = unsafe { (new_origin.assume_init(), new_dir.assume_init()) };
    for k in 0..3 {
        store_unmasked(&mut origin[k], new_origin[k]);
        store_unmasked(&mut dir[k], new_dir[k]);
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

    /// The f32 form (`path`'s) is glam's f32 arithmetic too, and its lane form gives the
    /// same bits as one ray: the lanes with `flat` bounce, the others keep their ray.
    #[test]
    fn plane_bounce_in_f32_is_glams_arithmetic_and_its_lanes_agree() {
        use glam::Vec3;
        let mut rng = crate::sampler::SplitMix64::for_pixel(12, 0);
        let mut unit = || Vec3::new(rng.next_unit(), rng.next_unit(), rng.next_unit()) - 0.5;
        const L: usize = 8;
        for round in 0..1_000 {
            let (mut normal, mut offset) = ([[0.0f32; L]; 3], [0.0f32; L]);
            let (mut origin, mut dir) = ([[0.0f32; L]; 3], [[0.0f32; L]; 3]);
            let mut flat = [false; L];
            let mut expected = Vec::new();
            for i in 0..L {
                let (n, d) = (unit().normalize(), unit().normalize());
                let o = unit() * 6.0;
                let off = n.dot(unit() * 2.0);
                let t = (off - n.dot(o)) / n.dot(d);
                let hit = o + d * t;
                let r = (d - 2.0 * d.dot(n) * n).normalize();
                let (h, s) = reflect_on_plane(n.to_array(), off, o.to_array(), d.to_array());
                assert_eq!(h.map(f32::to_bits), hit.to_array().map(f32::to_bits));
                assert_eq!(s.map(f32::to_bits), r.to_array().map(f32::to_bits));
                flat[i] = (round + i) % 3 != 0;
                for k in 0..3 {
                    normal[k][i] = n[k];
                    origin[k][i] = o[k];
                    dir[k][i] = d[k];
                }
                offset[i] = off;
                expected.push(if flat[i] { (hit, r) } else { (o, d) });
            }
            bounce_flat_lanes(&flat, &normal, &offset, &mut origin, &mut dir);
            for (i, (o, d)) in expected.into_iter().enumerate() {
                let at = |a: &[[f32; L]; 3]| Vec3::new(a[0][i], a[1][i], a[2][i]);
                assert_eq!(
                    at(&origin).to_array().map(f32::to_bits),
                    o.to_array().map(f32::to_bits)
                );
                assert_eq!(
                    at(&dir).to_array().map(f32::to_bits),
                    d.to_array().map(f32::to_bits)
                );
            }
        }
    }
}
