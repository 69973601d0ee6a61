//! Mirrored light sources (seed 002's listed limit): the images of each point light through
//! chains of planar mirrors, and the beam of points each image lights (`docs/shading.md`).
//!
//! **Image-source method.** Light from `L` that reflects off mirrors `m₁ … m_j` (in that
//! order) and reaches a point `x` travels the straight line from the image
//! `L′ = R_j⋯R₁·L` to `x` unfolded; its length is `|x − L′|`, so the point is lit with
//! `I·∏R·max(0, n·l′)/|x − L′|²`. The chain is valid for `x` only where that line, folded
//! back, crosses each mirror's front face inside its rectangle, in order.
//!
//! **Beams.** Where a chain is valid is a convex cone, built once per chain (beam tracing):
//! the light reaching mirror `m_{j+1}` via `m₁ … m_j` is the part of `m_{j+1}`'s rectangle
//! inside the previous beam — the cone from the image `L′_j` through the previous window, on
//! the front side of `m_j` — and `L′_j` in front of `m_{j+1}`. That part, the **window**, is a
//! convex polygon; the new beam is the cone from `L′_{j+1}` through it, in front of
//! `m_{j+1}`. A point `x` is lit through the chain exactly when it lies in the beam: one
//! plane test per window edge, the test both renderers run per shading point.
//!
//! **Pruning** (enumeration of chains, breadth first):
//! - *never valid* (exact): a chain whose next mirror is the last one (a plane cannot
//!   reflect its own reflection), whose image lies on or behind the next mirror's plane, or
//!   whose window is empty or thinner than [`MIN_WINDOW_AREA`] — a beam through no area lights
//!   no point of positive measure;
//! - *dim*: a chain whose attenuation `∏R` (largest channel) falls below the threshold (the
//!   tracer's `--min-throughput`), with its every extension up to `mirrored_lights`. What it
//!   would have added at any point is bounded (module test `pruning_bound_holds`): an
//!   extension's unfolded path is at least as long as `d`, the distance from the pruned
//!   image's pre-image to the pruned mirror's plane, and each further mirror multiplies by at
//!   most `R_max` with at most `M − 1` choices, so the pruned chain and its extensions add at
//!   most `ρ_max/π · I_max · t · Σ_{i<k−j} ((M−1)·R_max)^i / d²` (t its attenuation, j its
//!   length, k = `mirrored_lights`). [`LightImages::pruned_bound`] is the sum of these: no
//!   pixel changes by more (eye paths only attenuate it further).

use crate::Scene;
use crate::polygon::clip_by;
use glam::{DVec3, Vec3, Vec4};

/// Windows thinner than this (scene units²) light nothing of positive measure and are pruned.
pub const MIN_WINDOW_AREA: f64 = 1e-10;
/// Most mirrors between a light and a surface (`lighting.mirrored_lights`).
pub const MAX_MIRRORED_LIGHTS: u32 = 64;
/// Most light images a scene may hold (both renderers loop over them per shading point).
pub const MAX_LIGHT_IMAGES: usize = 1 << 16;
/// The attenuation below which chains are pruned when a scene is loaded (the tracer's default
/// `--min-throughput`; the raster methods use this one).
pub const DEFAULT_MIN_THROUGHPUT: f32 = 1e-4;

/// One image of a point light through a chain of mirrors.
#[derive(Clone, Debug, PartialEq)]
pub struct LightImage {
    /// Index of the real light in [`crate::Lighting::lights`].
    pub light: usize,
    /// The image position `R_j⋯R₁·L`.
    pub position: Vec3,
    /// `I·∏R`: the light's intensity times the reflectances along the chain.
    pub intensity: Vec3,
    /// The chain's last mirror (index into `Scene::mirrors`).
    pub mirror: usize,
    /// The image this one reflects (`None`: the real light), index into [`LightImages::images`].
    pub parent: Option<usize>,
    /// Chain length j ≥ 1.
    pub depth: u32,
    /// The beam: `x` is lit through this chain iff `n·x + w ≥ 0` for every plane `(n, w)`;
    /// the first is the last mirror's plane (front), the others pass through `position` and
    /// each edge of the window. Normals are unit length.
    pub beam: Vec<Vec4>,
}

impl LightImage {
    /// Whether `x` lies in this image's beam (the chain is valid for `x`). A point on the
    /// mirror plane itself is not lit through it.
    pub fn lights(&self, x: Vec3) -> bool {
        beam_side(self.beam[0], x) > 0.0 && self.beam[1..].iter().all(|&p| beam_side(p, x) >= 0.0)
    }

    /// [`LightImage::lights`] for the points `p` (`[axis][lane]`) of the lanes of `shaded`
    /// at once (false for the others): the same comparisons, in lane loops that vectorise.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // lane loops index several arrays by lane
    pub fn lights_lanes<const L: usize>(&self, shaded: &[bool; L], p: &[[f32; L]; 3]) -> [bool; L] {
        let at = |i: usize| Vec3::new(p[0][i], p[1][i], p[2][i]);
        let mut lit = [false; L];
        for i in 0..L {
            lit[i] = shaded[i] & (beam_side(self.beam[0], at(i)) > 0.0);
        }
        for &plane in &self.beam[1..] {
            for i in 0..L {
                lit[i] &= beam_side(plane, at(i)) >= 0.0;
            }
        }
        lit
    }

    /// Where the line from `from` to this image's position crosses its last mirror's plane:
    /// the mirror point of the leg from `from` ([`for_each_leg`]).
    #[inline]
    pub fn mirror_point(&self, from: Vec3) -> Vec3 {
        let plane = self.beam[0];
        let (da, db) = (
            plane.dot(from.extend(1.0)),
            plane.dot(self.position.extend(1.0)),
        );
        from + (self.position - from) * (da / (da - db))
    }
}

/// `plane · (x, 1)` for a beam plane `(n, w)`, summed as `(nx·x + nz·z) + (ny·y + w)`: glam's
/// SSE2 `Vec4::dot` grouping, written out so that [`LightImage::lights_lanes`] computes the
/// very same bits in lane loops.
#[inline(always)]
fn beam_side(plane: Vec4, x: Vec3) -> f32 {
    (plane.x * x.x + plane.z * x.z) + (plane.y * x.y + plane.w)
}

/// Every light image of a scene, with what enumeration pruned.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightImages {
    /// Parents before children, shallow chains first.
    pub images: Vec<LightImage>,
    /// The attenuation threshold they were enumerated with.
    pub min_throughput: f32,
    /// Chains that can never be valid (same mirror twice in a row, image behind the next
    /// mirror, empty window).
    pub pruned_invalid: usize,
    /// Chains pruned as dim (with their extensions, not counted).
    pub pruned_dim: usize,
    /// Upper bound on the radiance the dim chains would add to any pixel (module docs).
    pub pruned_bound: f32,
}

/// A chain too many images: the scene's `lighting.mirrored_lights` must be lower.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "lighting.mirrored_lights = {mirrored_lights} gives more than {MAX_LIGHT_IMAGES} light images \
     (at attenuation threshold {min_throughput}); allowed: a smaller mirrored_lights, or a \
     larger threshold"
)]
pub struct TooManyLightImages {
    pub mirrored_lights: u32,
    pub min_throughput: f32,
}

/// The images of `scene`'s lights through chains of at most `mirrored_lights` mirrors,
/// pruning chains whose attenuation falls below `min_throughput` (module docs).
pub fn light_images(
    scene: &Scene,
    lights: &[crate::PointLight],
    mirrored_lights: u32,
    min_throughput: f32,
) -> Result<LightImages, TooManyLightImages> {
    let mut out = LightImages {
        min_throughput,
        ..Default::default()
    };
    if mirrored_lights == 0 || scene.mirrors.is_empty() {
        return Ok(out);
    }
    let planes: Vec<(DVec3, f64)> = scene.mirrors.iter().map(crate::Mirror::plane_f64).collect();
    let rectangles: Vec<Vec<DVec3>> = scene
        .mirrors
        .iter()
        .map(|m| m.corners().iter().map(|c| c.as_dvec3()).collect())
        .collect();
    let reflectance_max = scene
        .mirrors
        .iter()
        .map(|m| m.reflectance.max_element())
        .fold(0.0f32, f32::max) as f64;
    let albedo_max = scene.geometry.surfaces.iter().fold(0.0f32, |a, s| match s {
        crate::Surface::Diffuse { albedo, .. } => a.max(albedo.max_element()),
        crate::Surface::Mirror { back_albedo, .. } => a.max(back_albedo.max_element()),
    }) as f64;
    let branching = (scene.mirrors.len() - 1) as f64 * reflectance_max;
    // Σ_{i<n} branching^i: what a pruned chain with n levels left may add, per unit.
    let extensions = |levels: u32| (0..levels).map(|i| branching.powi(i as i32)).sum::<f64>();
    let mut bound = 0.0f64;

    /// A chain under construction: its image (f64), window and attenuation.
    struct Node {
        position: DVec3,
        window: Vec<DVec3>,
        attenuation: Vec3,
        mirror: Option<usize>,
        image: Option<usize>,
        depth: u32,
        light: usize,
    }
    let mut frontier: Vec<Node> = lights
        .iter()
        .enumerate()
        .map(|(i, l)| Node {
            position: l.position.as_dvec3(),
            window: Vec::new(),
            attenuation: Vec3::ONE,
            mirror: None,
            image: None,
            depth: 0,
            light: i,
        })
        .collect();
    while !frontier.is_empty() {
        let mut next = Vec::new();
        for node in &frontier {
            if node.depth >= mirrored_lights {
                continue;
            }
            let intensity = lights[node.light].intensity;
            for (m, &(n, offset)) in planes.iter().enumerate() {
                if node.mirror == Some(m) {
                    out.pruned_invalid += 1;
                    continue;
                }
                let source_distance = n.dot(node.position) - offset;
                if source_distance <= 0.0 {
                    out.pruned_invalid += 1;
                    continue;
                }
                let window = match node.mirror {
                    None => rectangles[m].clone(),
                    Some(last) => {
                        let mut w =
                            clip_by(&rectangles[m], |p| planes[last].0.dot(p) - planes[last].1);
                        for plane in side_planes(node.position, &node.window) {
                            if w.len() < 3 {
                                break;
                            }
                            w = clip_by(&w, |p| plane.0.dot(p) + plane.1);
                        }
                        w
                    }
                };
                if window.len() < 3 || polygon_area(&window) < MIN_WINDOW_AREA {
                    out.pruned_invalid += 1;
                    continue;
                }
                let attenuation = node.attenuation * scene.mirrors[m].reflectance;
                if attenuation.max_element() < min_throughput {
                    out.pruned_dim += 1;
                    let levels = mirrored_lights - node.depth;
                    bound += albedo_max / std::f64::consts::PI
                        * intensity.max_element() as f64
                        * attenuation.max_element() as f64
                        * extensions(levels)
                        / (source_distance * source_distance);
                    continue;
                }
                if out.images.len() >= MAX_LIGHT_IMAGES {
                    return Err(TooManyLightImages {
                        mirrored_lights,
                        min_throughput,
                    });
                }
                let position = node.position - 2.0 * source_distance * n;
                let mut beam = vec![Vec4::new(
                    n.x as f32,
                    n.y as f32,
                    n.z as f32,
                    -offset as f32,
                )];
                beam.extend(
                    side_planes(position, &window).map(|(pn, pw)| {
                        Vec4::new(pn.x as f32, pn.y as f32, pn.z as f32, pw as f32)
                    }),
                );
                let index = out.images.len();
                out.images.push(LightImage {
                    light: node.light,
                    position: position.as_vec3(),
                    intensity: intensity * attenuation,
                    mirror: m,
                    parent: node.image,
                    depth: node.depth + 1,
                    beam,
                });
                next.push(Node {
                    position,
                    window,
                    attenuation,
                    mirror: Some(m),
                    image: Some(index),
                    depth: node.depth + 1,
                    light: node.light,
                });
            }
        }
        frontier = next;
    }
    out.pruned_bound = bound as f32;
    Ok(out)
}

/// The planes `(n, w)` (unit `n`, `n·x + w ≥ 0` inside) through `apex` and each edge of the
/// convex polygon `window`, facing its inside: the sides of the cone from `apex` through it.
fn side_planes(apex: DVec3, window: &[DVec3]) -> impl Iterator<Item = (DVec3, f64)> + '_ {
    let centroid = window.iter().copied().sum::<DVec3>() / window.len().max(1) as f64;
    (0..window.len()).filter_map(move |i| {
        let (a, b) = (window[i], window[(i + 1) % window.len()]);
        let n = (a - apex).cross(b - apex);
        let n = n.try_normalize()?;
        let n = if n.dot(centroid - apex) < 0.0 { -n } else { n };
        Some((n, -n.dot(apex)))
    })
}

/// Area of a planar convex polygon in 3-D.
fn polygon_area(poly: &[DVec3]) -> f64 {
    let mut sum = DVec3::ZERO;
    for i in 1..poly.len().saturating_sub(1) {
        sum += (poly[i] - poly[0]).cross(poly[i + 1] - poly[0]);
    }
    0.5 * sum.length()
}

/// The straight legs of the light path from `x` back to the real light through image
/// `index`: points `x, c_j, …, c₁, L` (the mirror hits found by folding the line to each
/// image back) and the mirror each `c` lies on. Calls `leg(a, a_mirror, b, b_mirror)` for
/// each leg from `x` towards the light and stops at the first that returns `false`;
/// returns whether all returned `true`.
pub fn for_each_leg(
    images: &[LightImage],
    lights: &[crate::PointLight],
    index: usize,
    x: Vec3,
    mut leg: impl FnMut(Vec3, Option<usize>, Vec3, Option<usize>) -> bool,
) -> bool {
    let mut from = x;
    let mut from_mirror = None;
    let mut current = Some(index);
    while let Some(i) = current {
        let image = &images[i];
        let hit = image.mirror_point(from);
        if !leg(from, from_mirror, hit, Some(image.mirror)) {
            return false;
        }
        from = hit;
        from_mirror = Some(image.mirror);
        current = image.parent;
        if current.is_none() {
            return leg(from, from_mirror, lights[image.light].position, None);
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::parse_scene;
    use std::path::Path;

    /// The beam test in lanes answers as the one-point test, on `mirror_room_lit`'s images
    /// (up to 8 mirrors) and points in and around the room, lanes not shaded false; and the
    /// written-out dot product is glam's `Vec4::dot`, bit for bit, so the test's answers are
    /// those of the truths traced before it was written out.
    #[test]
    fn beam_test_in_lanes_is_the_one_point_test() {
        const L: usize = 16;
        let scene = crate::load::bundled_scene("mirror_room_lit.json");
        let images = &scene.lighting.images.images;
        assert!(images.len() > 100);
        let mut next = crate::test_support::unit_floats(0x2545_f491_4f6c_dd1d);
        let (mut lit, mut unlit) = (0, 0);
        for _ in 0..20 {
            let mut p = [[0.0f32; L]; 3];
            let mut shaded = [false; L];
            for i in 0..L {
                shaded[i] = next() < 0.9;
                p[0][i] = 5.0 * next() - 2.5;
                p[1][i] = 3.5 * next() - 0.25;
                p[2][i] = 5.0 * next() - 2.5;
            }
            for image in images {
                let lanes = image.lights_lanes(&shaded, &p);
                for i in 0..L {
                    let x = Vec3::new(p[0][i], p[1][i], p[2][i]);
                    assert_eq!(lanes[i], shaded[i] && image.lights(x), "lane {i}");
                    if shaded[i] {
                        *if lanes[i] { &mut lit } else { &mut unlit } += 1;
                    }
                    for plane in &image.beam {
                        assert_eq!(
                            beam_side(*plane, x).to_bits(),
                            plane.dot(x.extend(1.0)).to_bits()
                        );
                    }
                }
            }
        }
        assert!(lit > 1000 && unlit > 1000, "{lit} lit, {unlit} not");
    }

    /// Two facing mirrors at z = ±1 (reflectance 0.8, wide enough to count as infinite for
    /// points near the axis), a light at `light`, `lighting` as given.
    fn parallel_pair(light: [f32; 3], lighting: &str, objects: &str) -> Scene {
        let text = format!(
            r#"{{ "camera": {{ "position": [0, 0, 0.5], "look_at": [0, -1, 0], "fov_y_deg": 40,
                "width": 16, "height": 16 }},
              "mirrors": [
                {{ "center": [0, 0, -1], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 2000,
                   "height": 2000, "reflectance": [0.8, 0.8, 0.8] }},
                {{ "center": [0, 0, 1], "normal": [0, 0, -1], "up": [0, 1, 0], "width": 2000,
                   "height": 2000, "reflectance": [0.8, 0.8, 0.8] }} ],
              "objects": [ {objects} ],
              "lights": [ {{ "position": {light:?}, "intensity": [2, 2, 2] }} ],
              "lighting": {lighting} }}"#
        );
        parse_scene(&text, Path::new("pair.json")).unwrap()
    }

    /// The closed form for two parallel mirrors 2 apart: the light at z₀ has images at
    /// `4m + z₀` (|2m| reflections) and `4m + 2 − z₀` (|2m + 1| reflections); a point lit by
    /// all of them with ≤ k reflections receives Σ ρʲ·I·max(0, n·l)/r².
    fn pair_irradiance(light: Vec3, x: Vec3, n: Vec3, k: i32, rho: f32, intensity: f32) -> f32 {
        let mut e = 0.0;
        for m in -k..=k {
            for (z, j) in [
                (4.0 * m as f32 + light.z, (2 * m).abs()),
                (4.0 * m as f32 + 2.0 - light.z, (2 * m + 1).abs()),
            ] {
                if j > k {
                    continue;
                }
                let to = Vec3::new(light.x, light.y, z) - x;
                let cos = n.dot(to.normalize()).max(0.0);
                e += rho.powi(j) * intensity * cos / to.length_squared();
            }
        }
        e
    }

    #[test]
    fn parallel_mirrors_light_a_patch_with_the_sum_over_images() {
        let light = Vec3::new(0.1, 0.5, 0.3);
        let albedo = Vec3::splat(0.5);
        for k in [0u32, 1, 2, 5, 8] {
            let scene = parallel_pair(
                light.to_array(),
                &format!(r#"{{ "mirrored_lights": {k} }}"#),
                "",
            );
            assert_eq!(scene.lighting.images.images.len(), 2 * k as usize);
            for x in [
                Vec3::new(0.4, -0.5, -0.2),
                Vec3::new(-0.7, -0.5, 0.8),
                Vec3::new(0.0, -0.5, 0.0),
            ] {
                let got = scene
                    .lighting
                    .diffuse_radiance(x, Vec3::Y, Vec3::Y, albedo, Vec3::ZERO);
                let want = 0.5 / std::f32::consts::PI
                    * pair_irradiance(light, x, Vec3::Y, k as i32, 0.8, 2.0);
                assert!(
                    (got.x - want).abs() <= 1e-5 * want,
                    "k = {k}, x = {x}: {} vs closed form {want}",
                    got.x
                );
            }
        }
    }

    /// Brute force: fold the segment from `x` to the image back through the chain's mirrors
    /// and check each crossing (front face, inside the rectangle, in order).
    fn valid_by_folding(scene: &Scene, set: &LightImages, index: usize, x: Vec3) -> bool {
        let mut from = x.as_dvec3();
        let mut current = Some(index);
        while let Some(i) = current {
            let image = &set.images[i];
            let mirror = &scene.mirrors[image.mirror];
            let n = mirror.normal.as_dvec3();
            let c = mirror.center.as_dvec3();
            let target = image.position.as_dvec3();
            let (da, db) = (n.dot(from - c), n.dot(target - c));
            if da <= 0.0 || db >= 0.0 {
                return false;
            }
            let hit = from + (target - from) * (da / (da - db));
            let local = hit - c;
            let right = mirror.right().as_dvec3();
            if local.dot(right).abs() > 0.5 * mirror.width as f64
                || local.dot(mirror.up.as_dvec3()).abs() > 0.5 * mirror.height as f64
            {
                return false;
            }
            from = hit;
            current = image.parent;
        }
        true
    }

    #[test]
    fn beams_agree_with_folding_the_segment_back() {
        // Finite, tilted mirrors: windows get clipped, beams split.
        let text = r#"{ "camera": { "position": [0, 1, 0], "look_at": [0, 1, -1], "fov_y_deg": 60,
            "width": 16, "height": 16 },
          "mirrors": [
            { "center": [0, 1.5, -2], "normal": [0.1, 0, 1], "up": [0, 1, 0], "width": 3, "height": 2 },
            { "center": [0.3, 1.2, 2], "normal": [0, 0.05, -1], "up": [0, 1, 0], "width": 2, "height": 3 },
            { "center": [-2, 1.5, 0], "normal": [1, 0, 0.2], "up": [0, 1, 0], "width": 3.5, "height": 2.5 } ],
          "lights": [ { "position": [0.4, 2.2, 0.3], "intensity": [1, 1, 1] } ],
          "lighting": { "mirrored_lights": 5 } }"#;
        let scene = parse_scene(text, Path::new("tilted.json")).unwrap();
        let set = &scene.lighting.images;
        assert!(set.images.len() > 10, "{} images", set.images.len());
        assert!(set.pruned_invalid > 0);
        // A deterministic spread of points in and around the mirrors' box.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f32 / (1u64 << 53) as f32
        };
        let (mut lit, mut checked) = (0, 0);
        for _ in 0..4000 {
            let x = Vec3::new(5.0 * next() - 2.5, 3.0 * next(), 5.0 * next() - 2.5);
            for i in 0..set.images.len() {
                let by_beam = set.images[i].lights(x);
                let by_folding = valid_by_folding(&scene, set, i, x);
                if by_beam != by_folding {
                    // Only a hair from a beam's boundary may the two roundings disagree.
                    let margin = set.images[i]
                        .beam
                        .iter()
                        .map(|p| p.dot(x.extend(1.0)).abs())
                        .fold(f32::INFINITY, f32::min);
                    assert!(
                        margin < 1e-4,
                        "image {i}, x = {x}: beam {by_beam}, folding {by_folding}"
                    );
                }
                lit += usize::from(by_folding);
                checked += 1;
            }
        }
        assert!(
            lit > checked / 50,
            "only {lit} of {checked} lit: the test sees too little"
        );
    }

    #[test]
    fn pruning_bound_holds() {
        let light = Vec3::new(0.1, 0.5, 0.3);
        let full = parallel_pair(light.to_array(), r#"{ "mirrored_lights": 24 }"#, "");
        let mut pruned = full.clone();
        pruned.enumerate_light_images(0.05).unwrap();
        assert!(pruned.lighting.images.pruned_dim > 0);
        assert!(pruned.lighting.images.images.len() < full.lighting.images.images.len());
        let mut all = full.clone();
        all.enumerate_light_images(0.0).unwrap();
        assert_eq!(all.lighting.images.images.len(), 48);
        let bound = pruned.lighting.images.pruned_bound;
        // The bound covers the scene's own surfaces: here only the mirrors' backs.
        let albedo = match full.geometry.surfaces[0] {
            crate::Surface::Mirror { back_albedo, .. } => back_albedo,
            _ => unreachable!("the scene holds only mirrors"),
        };
        let mut worst = 0.0f32;
        for i in 0..200 {
            let t = i as f32 / 200.0;
            let x = Vec3::new(2.0 * t - 1.0, -0.5, 1.9 * t - 0.95);
            for n in [Vec3::Y, Vec3::Z, -Vec3::Z, Vec3::new(0.6, 0.8, 0.0)] {
                let a = all.lighting.diffuse_radiance(x, n, n, albedo, Vec3::ZERO);
                let p = pruned
                    .lighting
                    .diffuse_radiance(x, n, n, albedo, Vec3::ZERO);
                worst = worst.max((a - p).max_element());
            }
        }
        assert!(
            worst > 0.0,
            "the pruning must change something to test the bound"
        );
        assert!(worst <= bound, "changed a point by {worst}, bound {bound}");
    }

    #[test]
    fn shadow_legs_fold_through_the_mirrors() {
        let light = Vec3::new(0.1, 0.5, 0.3);
        let scene = parallel_pair(light.to_array(), r#"{ "mirrored_lights": 3 }"#, "");
        let x = Vec3::new(0.4, -0.5, -0.2);
        let set = &scene.lighting.images.images;
        for (i, image) in set.iter().enumerate() {
            let mut legs = Vec::new();
            let all = for_each_leg(set, &scene.lighting.lights, i, x, |a, am, b, bm| {
                legs.push((a, am, b, bm));
                true
            });
            assert!(all);
            assert_eq!(legs.len(), image.depth as usize + 1);
            assert_eq!(legs[0].0, x);
            assert_eq!(legs.last().unwrap().2, light);
            // Consecutive legs meet on a mirror, the folded path is as long as |x − L′|.
            let mut length = 0.0;
            for w in legs.windows(2) {
                assert_eq!(w[0].2, w[1].0);
                assert_eq!(w[0].3, w[1].1);
                let m = w[0].3.unwrap();
                assert!(scene.mirrors[m].plane().signed_distance(w[0].2).abs() < 1e-5);
            }
            for (a, _, b, _) in &legs {
                length += a.distance(*b);
            }
            assert!((length - x.distance(image.position)).abs() < 1e-4);
            // Stopping at a blocked leg.
            let mut asked = 0;
            assert!(!for_each_leg(
                set,
                &scene.lighting.lights,
                i,
                x,
                |_, _, _, _| {
                    asked += 1;
                    false
                }
            ));
            assert_eq!(asked, 1);
        }
    }

    #[test]
    fn the_image_budget_is_refused_with_the_field() {
        // A mirror room's chains multiply: 6 walls and 64 mirrors deep exceed 2¹⁶ images.
        let walls = [
            ([0, 0, -1], [0, 0, 1]),
            ([0, 0, 1], [0, 0, -1]),
            ([-1, 0, 0], [1, 0, 0]),
            ([1, 0, 0], [-1, 0, 0]),
        ]
        .map(|(c, n)| {
            format!(
                r#"{{ "center": {c:?}, "normal": {n:?}, "up": [0, 1, 0], "width": 2, "height": 2,
                      "reflectance": [1, 1, 1] }}"#
            )
        })
        .join(",");
        let text = format!(
            r#"{{ "camera": {{ "position": [0, 0, 0], "look_at": [0, 0, -1], "fov_y_deg": 60,
                "width": 8, "height": 8 }}, "mirrors": [{walls}],
              "lights": [ {{ "position": [0.1, 0.2, 0.3], "intensity": [1, 1, 1] }} ],
              "lighting": {{ "mirrored_lights": 64 }} }}"#
        );
        let e = parse_scene(&text, Path::new("room.json"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("room.json: lighting.mirrored_lights:") && e.contains("65536"),
            "{e}"
        );
        let e = parse_scene(&text.replace(": 64 }", ": 65 }"), Path::new("room.json"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("lighting.mirrored_lights: must be in [0, 64]"),
            "{e}"
        );
        let e = parse_scene(
            &text.replace(r#""mirrored_lights": 64"#, r#""mirrored_light": 2"#),
            Path::new("room.json"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("mirrored_light"), "{e}");
    }

    #[test]
    fn default_lighting_keeps_the_hash_and_the_contract() {
        let light = [0.1, 0.5, 0.3];
        let plain = parallel_pair(light, "{}", "");
        let off = parallel_pair(light, r#"{ "shadows": false, "mirrored_lights": 0 }"#, "");
        assert_eq!(plain.content_hash(), off.content_hash());
        assert!(plain.lighting.images.images.is_empty());
        let on = parallel_pair(light, r#"{ "mirrored_lights": 1 }"#, "");
        assert_ne!(plain.content_hash(), on.content_hash());
        let shadows = parallel_pair(light, r#"{ "shadows": true }"#, "");
        assert_ne!(plain.content_hash(), shadows.content_hash());
    }
}
