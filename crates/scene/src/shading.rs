//! The shading contract (`docs/shading.md`), implemented once on the CPU. The tracer calls
//! it directly and the WGSL shaders are tested against it.
//!
//! Radiance is linear RGB. A diffuse surface seen from direction `ω_o` returns
//!
//! `L = E·[front] + ρ/π · Σᵢ Iᵢ·max(0, n·lᵢ)/rᵢ² + ρ·A`
//!
//! with `n` the face normal turned towards the viewer (diffuse is two-sided), `E` the
//! emission (front side only), `ρ` the albedo, `Iᵢ` the point lights' intensities (W/sr) at
//! distance `rᵢ` in unit direction `lᵢ`, and `A` the ambient term. A mirror's front returns its
//! reflectance times the radiance along the reflected ray.
//!
//! Opt-in (`lighting` in the scene file): with `mirrored_lights = k` the sum also runs over
//! the lights' images through chains of at most k mirrors ([`crate::light_images`]), each
//! where its chain is valid; with `shadows`, each straight leg of a light's path must be
//! unoccluded (the caller decides, [`Lighting::diffuse_radiance_with`]).

use crate::geometry::Surface;
use crate::light_images::{LightImages, for_each_leg};
use glam::Vec3;

/// An isotropic point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    pub position: Vec3,
    /// Radiant intensity per channel, W/sr.
    pub intensity: Vec3,
}

/// Everything that lights a diffuse surface.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lighting {
    pub lights: Vec<PointLight>,
    pub ambient: Vec3,
    /// `lighting.shadows`: every straight leg from a surface to a light (or through mirrors to
    /// it) must be unoccluded.
    pub shadows: bool,
    /// `lighting.mirrored_lights`: most mirrors between a light and a surface (0: none).
    pub mirrored_lights: u32,
    /// The lights' images through chains of at most `mirrored_lights` mirrors.
    pub images: LightImages,
}

/// Squared distance below which a light is considered to touch the surface and ignored
/// (its 1/r² would be unbounded).
pub const MIN_LIGHT_DISTANCE_SQUARED: f32 = 1e-8;

impl Lighting {
    /// One line for outputs' provenance: `direct, no shadows` (the default contract), or the
    /// shadows and the light images with what pruning left out.
    pub fn describe(&self) -> String {
        let shadows = if self.shadows {
            "shadows"
        } else {
            "no shadows"
        };
        if self.mirrored_lights == 0 {
            return format!("direct, {shadows}");
        }
        let i = &self.images;
        format!(
            "mirrored lights through <= {} mirrors ({} light images; {} dim chains pruned below {}, \
             changing no pixel by more than {:.3e}), {shadows}",
            self.mirrored_lights,
            i.images.len(),
            i.pruned_dim,
            i.min_throughput,
            i.pruned_bound
        )
    }

    /// Radiance leaving a diffuse point `p` towards the viewer, every light reaching it
    /// (no occlusion test: what a renderer without shadows computes).
    ///
    /// `face_normal` is the triangle's front normal, `to_viewer` the unit direction from `p`
    /// back towards the viewer (−ray direction).
    pub fn diffuse_radiance(
        &self,
        p: Vec3,
        face_normal: Vec3,
        to_viewer: Vec3,
        albedo: Vec3,
        emission: Vec3,
    ) -> Vec3 {
        self.diffuse_radiance_with(p, face_normal, to_viewer, albedo, emission, |_, _, _, _| {
            true
        })
    }

    /// [`Lighting::diffuse_radiance`], with shadows when [`Lighting::shadows`] is set:
    /// `unoccluded(a, a_mirror, b, b_mirror)` says whether the straight leg from `a` to `b`
    /// is clear (`a_mirror`, `b_mirror`: the mirror an end lies on, if any; the first leg
    /// starts at `p`). It is asked only for lights that would add something.
    pub fn diffuse_radiance_with(
        &self,
        p: Vec3,
        face_normal: Vec3,
        to_viewer: Vec3,
        albedo: Vec3,
        emission: Vec3,
        mut unoccluded: impl FnMut(Vec3, Option<usize>, Vec3, Option<usize>) -> bool,
    ) -> Vec3 {
        let front = face_normal.dot(to_viewer) >= 0.0;
        let n = if front { face_normal } else { -face_normal };
        let mut irradiance = Vec3::ZERO;
        for light in &self.lights {
            let e = point_irradiance(p, n, light.position, light.intensity);
            if e != Vec3::ZERO && (!self.shadows || unoccluded(p, None, light.position, None)) {
                irradiance += e;
            }
        }
        for (i, image) in self.images.images.iter().enumerate() {
            if !image.lights(p) {
                continue;
            }
            let e = point_irradiance(p, n, image.position, image.intensity);
            if e != Vec3::ZERO
                && (!self.shadows
                    || for_each_leg(&self.images.images, &self.lights, i, p, &mut unoccluded))
            {
                irradiance += e;
            }
        }
        let emitted = if front { emission } else { Vec3::ZERO };
        emitted + albedo * (irradiance * std::f32::consts::FRAC_1_PI + self.ambient)
    }

    /// [`Lighting::diffuse_radiance_with`] at the points of the lanes of `shaded` at once,
    /// each light's (and each light image's) legs asked together: `unoccluded(legs, clear)`
    /// sets `clear[j]` for each of `legs` — at most one per lane, each the leg the one-point
    /// form asks of that lane at that moment — so that a caller can trace them as one
    /// packet. Per lane the same operations in the same order as the one-point form (the
    /// same bits), the same legs asked (a chain stops at its first blocked leg), each counted
    /// in `asked[lane]`. Arguments are `[component][lane]`, as
    /// [`Lighting::direct_radiance_lanes`]'s; inline, so compiled for the caller's CPU
    /// features (measured: not inlined, a change of its body cost the lit scenes 18 %).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn diffuse_radiance_lanes_with<const L: usize>(
        &self,
        shaded: &[bool; L],
        p: &[[f32; L]; 3],
        face_normal: &[[f32; L]; 3],
        to_viewer: &[[f32; L]; 3],
        albedo: &[[f32; L]; 3],
        emission: &[[f32; L]; 3],
        asked: &mut [u32; L],
        mut unoccluded: impl LegsClear,
    ) -> [[f32; L]; 3] {
        let lane = |a: &[[f32; L]; 3], i: usize| Vec3::new(a[0][i], a[1][i], a[2][i]);
        let shaded_lanes = || (0..L).filter(|&i| shaded[i]);
        let mut n = [Vec3::ZERO; L];
        let mut front = [false; L];
        for i in shaded_lanes() {
            let face = lane(face_normal, i);
            front[i] = face.dot(lane(to_viewer, i)) >= 0.0;
            n[i] = if front[i] { face } else { -face };
        }
        let mut irradiance = [Vec3::ZERO; L];
        let mut e = [Vec3::ZERO; L];
        let mut legs = [Leg::NONE; L];
        let mut clear = [false; L];
        // Asks `legs` (at most one per lane), then keeps alive only the lanes whose leg is
        // clear. (A function, not a closure: a closure is compiled on its own, without the
        // caller's CPU features, and the legs' tracing inside it with them.)
        #[inline(always)]
        fn ask<const L: usize>(
            unoccluded: &mut impl LegsClear,
            legs: &[Leg],
            alive: &mut [bool; L],
            asked: &mut [u32; L],
            clear: &mut [bool; L],
        ) {
            for leg in legs {
                asked[leg.lane] += 1;
            }
            unoccluded.clear(legs, &mut clear[..legs.len()]);
            for (leg, &clear) in legs.iter().zip(clear.iter()) {
                alive[leg.lane] &= clear;
            }
        }
        for light in &self.lights {
            let mut alive = [false; L];
            let mut count = 0;
            for i in shaded_lanes() {
                let (x, source) = (lane(p, i), (light.position, light.intensity));
                if self.reaches(x, n[i], source, &mut e[i], &mut irradiance[i]) {
                    alive[i] = true;
                    legs[count] = Leg::new(i, x, None, light.position, None);
                    count += 1;
                }
            }
            if count > 0 {
                ask(
                    &mut unoccluded,
                    &legs[..count],
                    &mut alive,
                    asked,
                    &mut clear,
                );
                for i in (0..L).filter(|&i| alive[i]) {
                    irradiance[i] += e[i];
                }
            }
        }
        let images = &self.images.images;
        // Each lane's point on its chain (written before it is read, for the lanes alive).
        let mut from = [Vec3::ZERO; L];
        for (index, image) in images.iter().enumerate() {
            let mut alive = [false; L];
            let mut any = false;
            let lit = image.lights_lanes(shaded, p);
            for i in (0..L).filter(|&i| lit[i]) {
                let (x, source) = (lane(p, i), (image.position, image.intensity));
                if self.reaches(x, n[i], source, &mut e[i], &mut irradiance[i]) {
                    alive[i] = true;
                    from[i] = x;
                    any = true;
                }
            }
            if !any {
                continue;
            }
            // The chain's legs (`for_each_leg`'s), one per lane at a time: the mirrors and
            // images are the same for every lane, the points the lane's own.
            let mut from_mirror = None;
            let mut current = Some(index);
            while let Some(c) = current {
                let image = &images[c];
                let mut count = 0;
                for i in (0..L).filter(|&i| alive[i]) {
                    let hit = image.mirror_point(from[i]);
                    legs[count] = Leg::new(i, from[i], from_mirror, hit, Some(image.mirror));
                    count += 1;
                    from[i] = hit;
                }
                if count == 0 {
                    break;
                }
                ask(
                    &mut unoccluded,
                    &legs[..count],
                    &mut alive,
                    asked,
                    &mut clear,
                );
                from_mirror = Some(image.mirror);
                current = image.parent;
                if current.is_none() {
                    let light = self.lights[image.light].position;
                    let mut count = 0;
                    for i in (0..L).filter(|&i| alive[i]) {
                        legs[count] = Leg::new(i, from[i], from_mirror, light, None);
                        count += 1;
                    }
                    if count > 0 {
                        ask(
                            &mut unoccluded,
                            &legs[..count],
                            &mut alive,
                            asked,
                            &mut clear,
                        );
                    }
                }
            }
            for i in (0..L).filter(|&i| alive[i]) {
                irradiance[i] += e[i];
            }
        }
        let mut out = [[0.0; L]; 3];
        for i in shaded_lanes() {
            let emitted = if front[i] {
                lane(emission, i)
            } else {
                Vec3::ZERO
            };
            let l = emitted
                + lane(albedo, i) * (irradiance[i] * std::f32::consts::FRAC_1_PI + self.ambient);
            for k in 0..3 {
                out[k][i] = l[k];
            }
        }
        out
    }

    /// [`Lighting::diffuse_radiance_lanes_with`]'s start for one lane and one source (a light
    /// or a light image at `position` with `intensity`): its irradiance at `x` into `e`,
    /// added to `irradiance` at once without shadows; true where it adds something and its
    /// legs are to be asked.
    #[inline(always)]
    fn reaches(
        &self,
        x: Vec3,
        n: Vec3,
        (position, intensity): (Vec3, Vec3),
        e: &mut Vec3,
        irradiance: &mut Vec3,
    ) -> bool {
        *e = point_irradiance(x, n, position, intensity);
        if *e == Vec3::ZERO {
            return false;
        }
        if !self.shadows {
            *irradiance += *e;
            return false;
        }
        true
    }

    /// Whether [`Lighting::direct_radiance_lanes`] computes this lighting: no shadows and no
    /// light images (the default contract).
    pub fn lanes_apply(&self) -> bool {
        !self.shadows && self.images.images.is_empty()
    }

    /// [`Lighting::diffuse_radiance`] at `L` points at once, where
    /// [`Lighting::lanes_apply`]: each argument is `[component][lane]`. Per lane the same
    /// operations in the same order (the same bits); written as loops over the lanes, innermost
    /// and branch free, so that they vectorise (inline: compiled for the caller's CPU).
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // lane loops index several arrays by lane
    pub fn direct_radiance_lanes<const L: usize>(
        &self,
        p: &[[f32; L]; 3],
        face_normal: &[[f32; L]; 3],
        to_viewer: &[[f32; L]; 3],
        albedo: &[[f32; L]; 3],
        emission: &[[f32; L]; 3],
    ) -> [[f32; L]; 3] {
        debug_assert!(self.lanes_apply());
        let lane = |a: &[[f32; L]; 3], i: usize| Vec3::new(a[0][i], a[1][i], a[2][i]);
        let mut n = [[0.0; L]; 3];
        let mut front = [false; L];
        for i in 0..L {
            let face = lane(face_normal, i);
            front[i] = face.dot(lane(to_viewer, i)) >= 0.0;
            let turned = if front[i] { face } else { -face };
            for k in 0..3 {
                n[k][i] = turned[k];
            }
        }
        let mut irradiance = [[0.0; L]; 3];
        for light in &self.lights {
            let mut e = [[0.0; L]; 3];
            for i in 0..L {
                let e_i =
                    point_irradiance(lane(p, i), lane(&n, i), light.position, light.intensity);
                for k in 0..3 {
                    e[k][i] = e_i[k];
                }
            }
            // Stored whole (`store_unmasked`): a select written back in place becomes a masked
            // store, slow on AMD's AVX2 CPUs.
            let mut sums = [[0.0; L]; 3];
            for i in 0..L {
                let adds = lane(&e, i) != Vec3::ZERO;
                for k in 0..3 {
                    let sum = irradiance[k][i] + e[k][i];
                    sums[k][i] = if adds { sum } else { irradiance[k][i] };
                }
            }
            for (a, s) in irradiance.iter_mut().zip(sums) {
                crate::lanes::store_unmasked(a, s);
            }
        }
        let mut out = [[0.0; L]; 3];
        for i in 0..L {
            let emitted = if front[i] {
                lane(emission, i)
            } else {
                Vec3::ZERO
            };
            let l = emitted
                + lane(albedo, i)
                    * (lane(&irradiance, i) * std::f32::consts::FRAC_1_PI + self.ambient);
            for k in 0..3 {
                out[k][i] = l[k];
            }
        }
        out
    }
}

/// What answers [`Lighting::diffuse_radiance_lanes_with`]'s legs: `clear[j]` for each of
/// `legs`, whether nothing blocks it. A trait, so that a tracer's `#[inline(always)]`
/// implementation is compiled into its caller for the caller's CPU features (a closure is a
/// function of its own, compiled for the baseline: the lit scenes' leg packets ran there,
/// three quarters of `mirror_room_lit`'s time in one closure). Closures implement it too.
pub trait LegsClear {
    fn clear(&mut self, legs: &[Leg], clear: &mut [bool]);
}

impl<F: FnMut(&[Leg], &mut [bool])> LegsClear for F {
    #[inline(always)]
    fn clear(&mut self, legs: &[Leg], clear: &mut [bool]) {
        self(legs, clear)
    }
}

/// A straight leg of a light's path that [`Lighting::diffuse_radiance_lanes_with`] asks
/// about: lane `lane`'s, from `a` (on mirror `a_mirror`, if any) to `b` (on `b_mirror`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Leg {
    pub lane: usize,
    pub a: Vec3,
    pub a_mirror: Option<usize>,
    pub b: Vec3,
    pub b_mirror: Option<usize>,
}

impl Leg {
    const NONE: Leg = Leg::new(0, Vec3::ZERO, None, Vec3::ZERO, None);

    const fn new(
        lane: usize,
        a: Vec3,
        a_mirror: Option<usize>,
        b: Vec3,
        b_mirror: Option<usize>,
    ) -> Self {
        Leg {
            lane,
            a,
            a_mirror,
            b,
            b_mirror,
        }
    }
}

/// `I·max(0, n·l)/r²` from a point source at `source` (zero closer than
/// [`MIN_LIGHT_DISTANCE_SQUARED`]). Branch free (selects), so that
/// [`Lighting::direct_radiance_lanes`] vectorises it with these very operations.
#[inline(always)]
fn point_irradiance(p: Vec3, n: Vec3, source: Vec3, intensity: Vec3) -> Vec3 {
    let to_light = source - p;
    let r2 = to_light.length_squared();
    let cos = n.dot(to_light) / r2.sqrt();
    // As the early return it replaces: only `r2 < min` is dropped (a NaN is not).
    let touching = r2 < MIN_LIGHT_DISTANCE_SQUARED;
    let lit = !touching & (cos > 0.0);
    let e = intensity * (cos / r2);
    if lit { e } else { Vec3::ZERO }
}

/// What happens where a ray meets a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Interaction {
    /// Shade with [`Lighting::diffuse_radiance`].
    Diffuse { albedo: Vec3, emission: Vec3 },
    /// Follow the perfect reflection, multiplying by `reflectance`.
    Reflect { reflectance: Vec3 },
}

/// The contract's rule for each surface: a mirror reflects on its front side only and is a
/// plain diffuse surface (no emission) on its back side.
/// A textured surface's factors only: [`interaction_at`] evaluates its textures.
#[inline]
pub fn interaction(surface: &Surface, front_facing: bool) -> Interaction {
    match *surface {
        Surface::Diffuse {
            albedo, emission, ..
        } => Interaction::Diffuse { albedo, emission },
        Surface::Mirror { reflectance, .. } if front_facing => Interaction::Reflect { reflectance },
        Surface::Mirror { back_albedo, .. } => Interaction::Diffuse {
            albedo: back_albedo,
            emission: Vec3::ZERO,
        },
    }
}

/// [`interaction`] at point `p` of triangle `triangle` of `g`: a diffuse surface's albedo
/// and emission there, textures included.
#[inline(always)]
pub fn interaction_at(
    g: &crate::Geometry,
    triangle: usize,
    p: Vec3,
    front_facing: bool,
) -> Interaction {
    match g.diffuse_at(triangle, p) {
        Some((albedo, emission)) => Interaction::Diffuse { albedo, emission },
        None => interaction(g.surface(triangle), front_facing),
    }
}

/// [`interaction_at`] with the point asked for only where it matters: not at a mirror's
/// front, which reflects whatever the point (most hits in a mirror scene), so that the
/// tracers compute it (an f64 solve with a division, `hit_point`) only for the surfaces
/// shaded there; `point` is called at most once, and its point returned with the
/// interaction.
#[inline(always)]
pub fn interaction_with_point(
    g: &crate::Geometry,
    triangle: usize,
    front_facing: bool,
    point: impl FnOnce() -> Vec3,
) -> (Interaction, Option<Vec3>) {
    let reflects = interaction(g.surface(triangle), front_facing);
    if let Interaction::Reflect { .. } = reflects {
        return (reflects, None);
    }
    let p = point();
    (interaction_at(g, triangle, p, front_facing), Some(p))
}

/// Perfect specular reflection of direction `d` about unit normal `n`: `d − 2(d·n)n`.
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * d.dot(n) * n
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    fn one_light(position: Vec3, intensity: f32) -> Lighting {
        Lighting {
            lights: vec![PointLight {
                position,
                intensity: Vec3::splat(intensity),
            }],
            ..Default::default()
        }
    }

    /// The lane form with legs is the one-point form bit for bit, and asks each lane the same
    /// legs in the same order (a chain stops at its first blocked leg): `mirror_room_lit`'s
    /// light and its images through up to 8 mirrors, with and without shadows, points in the
    /// room facing every way, some lanes not shaded; a leg is blocked by a fixed function of
    /// its ends, so both forms see the same occluders.
    #[test]
    fn diffuse_radiance_lanes_with_legs_is_the_one_point_form() {
        const L: usize = 16;
        let scene = crate::load::bundled_scene("mirror_room_lit.json");
        let mut next = crate::test_support::unit_floats(0x9e37_79b9_7f4a_7c15);
        let blocked = |a: Vec3, b: Vec3| {
            let h = [a, b]
                .iter()
                .flat_map(|v| v.to_array())
                .fold(0xcbf2_9ce4_8422_2325u64, |h, x| {
                    (h ^ u64::from(x.to_bits())).wrapping_mul(0x100_0000_01b3)
                });
            h % 3 == 0
        };
        let mut legs_total = 0;
        for shadows in [true, false] {
            let mut lighting = scene.lighting.clone();
            lighting.shadows = shadows;
            assert!(lighting.images.images.len() > 20 && !lighting.lanes_apply());
            for _ in 0..20 {
                let mut args = [[[0.0f32; L]; 3]; 5];
                let mut shaded = [false; L];
                for i in 0..L {
                    shaded[i] = next() < 0.85;
                    let room = [4.0 * next() - 2.0, 3.0 * next(), 4.0 * next() - 2.0];
                    let normal = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
                    let view = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
                    let values = [
                        Vec3::from(room),
                        normal,
                        view,
                        Vec3::splat(next()),
                        Vec3::ZERO,
                    ];
                    for (a, v) in args.iter_mut().zip(values) {
                        for k in 0..3 {
                            a[k][i] = v[k];
                        }
                    }
                }
                let [p, n, v, albedo, emission] = &args;
                let mut asked = [0u32; L];
                let mut lane_legs: Vec<Vec<Leg>> = vec![Vec::new(); L];
                let out = lighting.diffuse_radiance_lanes_with(
                    &shaded,
                    p,
                    n,
                    v,
                    albedo,
                    emission,
                    &mut asked,
                    |legs: &[Leg], clear: &mut [bool]| {
                        let mut seen = [false; L];
                        for (leg, clear) in legs.iter().zip(clear.iter_mut()) {
                            assert!(!seen[leg.lane], "two legs of one lane in a batch");
                            seen[leg.lane] = true;
                            lane_legs[leg.lane].push(*leg);
                            *clear = !blocked(leg.a, leg.b);
                        }
                    },
                );
                let at = |a: &[[f32; L]; 3], i: usize| Vec3::new(a[0][i], a[1][i], a[2][i]);
                for i in (0..L).filter(|&i| shaded[i]) {
                    let mut one_legs = Vec::new();
                    let one = lighting.diffuse_radiance_with(
                        at(p, i),
                        at(n, i),
                        at(v, i),
                        at(albedo, i),
                        at(emission, i),
                        |a, a_mirror, b, b_mirror| {
                            one_legs.push(Leg::new(i, a, a_mirror, b, b_mirror));
                            !blocked(a, b)
                        },
                    );
                    assert_eq!(
                        at(&out, i).to_array().map(f32::to_bits),
                        one.to_array().map(f32::to_bits),
                        "lane {i}, shadows {shadows}"
                    );
                    assert_eq!(lane_legs[i], one_legs, "lane {i}");
                    assert_eq!(asked[i] as usize, one_legs.len(), "lane {i}");
                    legs_total += one_legs.len();
                }
                for i in (0..L).filter(|&i| !shaded[i]) {
                    assert!(lane_legs[i].is_empty() && asked[i] == 0);
                }
            }
        }
        assert!(legs_total > 1000, "{legs_total} legs asked");
    }

    /// The lane form is the scalar contract bit for bit: lights in front, behind, at the
    /// shading point itself; back faces; emission; 16 lanes and a short tail.
    #[test]
    fn direct_radiance_lanes_is_the_scalar_contract() {
        let mut unit = crate::test_support::unit_floats(0x2545_f491_4f6c_dd1d);
        let mut next = move || unit() * 2.0 - 1.0;
        let mut v = || Vec3::new(next(), next(), next());
        let lighting = Lighting {
            lights: vec![
                PointLight {
                    position: Vec3::new(0.0, 2.0, 0.0),
                    intensity: Vec3::new(10.0, 8.0, 6.0),
                },
                PointLight {
                    position: Vec3::new(0.25, -0.5, 0.125),
                    intensity: Vec3::new(0.0, 3.0, 1.0),
                },
            ],
            ambient: Vec3::new(0.05, 0.04, 0.03),
            ..Default::default()
        };
        assert!(lighting.lanes_apply());
        for round in 0..500 {
            const L: usize = 16;
            let mut lanes = [[[0.0f32; L]; 3]; 5];
            let mut points = Vec::new();
            for i in 0..L {
                let mut p = v() * 3.0;
                if round % 7 == 0 && i == 3 {
                    p = lighting.lights[1].position; // a light touching the surface
                }
                let point = [
                    p,
                    v().normalize(),
                    v().normalize(),
                    v().abs(),
                    v().abs() * (i % 2) as f32,
                ];
                for (a, value) in lanes.iter_mut().zip(point) {
                    for k in 0..3 {
                        a[k][i] = value[k];
                    }
                }
                points.push(point);
            }
            let [p, n, to_viewer, albedo, emission] = &lanes;
            let out = lighting.direct_radiance_lanes(p, n, to_viewer, albedo, emission);
            for (i, &[p, n, to_viewer, albedo, emission]) in points.iter().enumerate() {
                let one = lighting.diffuse_radiance(p, n, to_viewer, albedo, emission);
                let lane = [out[0][i], out[1][i], out[2][i]];
                assert_eq!(
                    lane.map(f32::to_bits),
                    one.to_array().map(f32::to_bits),
                    "lane {i}"
                );
            }
        }
    }

    /// The point is asked for only off a mirror's front: once on a diffuse triangle and on
    /// a mirror's back (given back with the interaction), never on a mirror's front.
    #[test]
    fn the_point_is_asked_for_only_where_a_surface_is_shaded() {
        let mut g = crate::Geometry::default();
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        g.push_part(
            "floor".into(),
            Surface::diffuse(Vec3::ONE, Vec3::ZERO),
            vec![tri],
        );
        let mirror = Surface::Mirror {
            mirror: 0,
            reflectance: Vec3::splat(0.9),
            back_albedo: Vec3::splat(0.5),
        };
        g.push_part("mirror".into(), mirror, vec![tri]);
        let p = Vec3::new(0.25, 0.25, 0.0);
        for (triangle, front, asked) in [
            (0, true, true),
            (0, false, true),
            (1, false, true),
            (1, true, false),
        ] {
            let mut calls = 0;
            let (interaction, point) = interaction_with_point(&g, triangle, front, || {
                calls += 1;
                p
            });
            assert_eq!(calls, asked as usize, "triangle {triangle}, front {front}");
            assert_eq!(point, asked.then_some(p));
            assert_eq!(interaction, interaction_at(&g, triangle, p, front));
        }
    }

    #[test]
    fn lambert_with_inverse_square_falloff() {
        // Light 2 units straight above: E = I/r² = 10/4; L = ρ/π·E.
        let l = one_light(Vec3::new(0.0, 2.0, 0.0), 10.0);
        let rho = Vec3::new(0.5, 0.25, 1.0);
        let out = l.diffuse_radiance(Vec3::ZERO, Vec3::Y, Vec3::Y, rho, Vec3::ZERO);
        assert!(out.abs_diff_eq(rho * (2.5 / PI), 1e-6));
        // At 60° incidence the cosine halves it.
        let p = Vec3::new(-2.0 * 3f32.sqrt(), 0.0, 0.0); // light at distance 4, 60° off normal
        let out = l.diffuse_radiance(p, Vec3::Y, Vec3::Y, rho, Vec3::ZERO);
        assert!(
            out.abs_diff_eq(rho * (10.0 * 0.5 / 16.0 / PI), 1e-6),
            "{out}"
        );
    }

    #[test]
    fn two_sided_diffuse_but_one_sided_emission() {
        let mut l = one_light(Vec3::new(0.0, -1.0, 0.0), 1.0);
        l.ambient = Vec3::splat(0.1);
        let e = Vec3::splat(3.0);
        let rho = Vec3::splat(0.5);
        // Viewer and light below a surface whose front faces up: lit as the back, no emission.
        let below = l.diffuse_radiance(Vec3::ZERO, Vec3::Y, -Vec3::Y, rho, e);
        assert!(below.abs_diff_eq(rho * (1.0 / PI + 0.1), 1e-6));
        // Viewer above, light below: only emission and ambient.
        let above = l.diffuse_radiance(Vec3::ZERO, Vec3::Y, Vec3::Y, rho, e);
        assert!(above.abs_diff_eq(e + rho * 0.1, 1e-6));
    }

    #[test]
    fn mirror_back_is_diffuse() {
        let s = Surface::Mirror {
            mirror: 0,
            reflectance: Vec3::splat(0.9),
            back_albedo: Vec3::splat(0.2),
        };
        assert_eq!(
            interaction(&s, true),
            Interaction::Reflect {
                reflectance: Vec3::splat(0.9)
            }
        );
        assert_eq!(
            interaction(&s, false),
            Interaction::Diffuse {
                albedo: Vec3::splat(0.2),
                emission: Vec3::ZERO
            }
        );
    }

    #[test]
    fn reflection_of_a_direction() {
        let d = Vec3::new(1.0, -1.0, 0.0).normalize();
        assert!(reflect(d, Vec3::Y).abs_diff_eq(Vec3::new(1.0, 1.0, 0.0).normalize(), 1e-6));
    }
}
