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
        let x = x.extend(1.0);
        self.beam[0].dot(x) > 0.0 && self.beam[1..].iter().all(|p| p.dot(x) >= 0.0)
    }
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
    let planes: Vec<(DVec3, f64)> = scene
        .mirrors
        .iter()
        .map(|m| {
            let n = m.normal.as_dvec3().normalize();
            (n, n.dot(m.center.as_dvec3()))
        })
        .collect();
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
                            clip_f64(&rectangles[m], |p| planes[last].0.dot(p) - planes[last].1);
                        for plane in side_planes(node.position, &node.window) {
                            if w.len() < 3 {
                                break;
                            }
                            w = clip_f64(&w, |p| plane.0.dot(p) + plane.1);
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
                let mut beam = vec![Vec4::new(n.x as f32, n.y as f32, n.z as f32, -offset as f32)];
                beam.extend(
                    side_planes(position, &window)
                        .map(|(pn, pw)| Vec4::new(pn.x as f32, pn.y as f32, pn.z as f32, pw as f32)),
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

/// Keeps the part of convex polygon `poly` where `distance(p) ≥ 0` (Sutherland–Hodgman in
/// f64: images of deep chains lie far away, and their windows stay exact).
fn clip_f64(poly: &[DVec3], distance: impl Fn(DVec3) -> f64) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        let (da, db) = (distance(a), distance(b));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
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
        let plane = image.beam[0];
        let (da, db) = (
            plane.dot(from.extend(1.0)),
            plane.dot(image.position.extend(1.0)),
        );
        let hit = from + (image.position - from) * (da / (da - db));
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
