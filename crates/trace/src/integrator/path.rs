//! The `path` integrator: physically based, for comparison with Mitsuba 3's `path`.
//!
//! Unidirectional path tracing of the same surfaces as the contract (two-sided Lambertian,
//! one-sided emission, perfect mirrors with a diffuse back), with shadows and diffuse
//! interreflection, which the Whitted model leaves out:
//! - **next-event estimation**: every point light through a shadow ray; one emissive
//!   triangle chosen in proportion to its area × emitted luminance, a uniform point on it,
//!   combined with BSDF sampling by multiple importance sampling (power heuristic);
//! - cosine-weighted sampling of the diffuse lobe on the side the path arrives from;
//! - mirrors are delta reflections (no light sampling through them, as in Mitsuba: light that
//!   reaches a surface only via a mirror is found by BSDF sampling alone);
//! - the background is a constant environment emitter, found by escaping rays;
//! - **Russian roulette** from depth `rr_depth` on, survival probability max(throughput) ≤ 0.95.
//!
//! Depth follows Mitsuba's `max_depth`: it counts path segments, so 1 shows only directly
//! visible emitters, 2 adds direct light, and N visible reflections need N + 2. The ambient
//! term of the contract is not physical and is not used here.

use super::{Integrator, PathResult, Termination, face_normals};
use crate::bvh::packet::{LANES, LaneMask, NO_TRIANGLE, RayPacket, first_lanes, lanes};
use crate::bvh::{Hit, SceneBvh};
use crate::cpu_features::{Vectorised, widest};
use crate::mirror_bounce::{MirrorPlanes, bounce_flat_lanes};
use crate::sampler::SplitMix64;
use glam::Vec3;
use mirrorbox_scene::shading::{Interaction, interaction_at};
use mirrorbox_scene::{Ray, Scene, Surface};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSettings {
    /// Longest path in segments (Mitsuba's `max_depth`).
    pub max_depth: u32,
    /// Depth from which Russian roulette may end paths (Mitsuba's `rr_depth`).
    pub rr_depth: u32,
    /// Seed of the per-pixel random streams.
    pub seed: u64,
}

impl Default for PathSettings {
    fn default() -> Self {
        PathSettings {
            max_depth: 66,
            rr_depth: 5,
            seed: 0,
        }
    }
}

struct Emitter {
    triangle: usize,
    area: f32,
    emission: Vec3,
}

pub struct PathTracer<'a> {
    scene: &'a Scene,
    bvh: &'a SceneBvh,
    settings: PathSettings,
    normals: Vec<Vec3>,
    emitters: Vec<Emitter>,
    /// Cumulative selection probabilities of `emitters`.
    cdf: Vec<f32>,
    /// Per triangle: the area density of emitter sampling, selection probability / area (0
    /// for non-emitters); turned into a solid-angle pdf by distance² / cos.
    area_pdf: Vec<f32>,
    mirror_planes: MirrorPlanes,
}

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Cosine-weighted direction around unit `n` (Malley's method).
fn cosine_sample(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let r = u1.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u2;
    let (t, b) = n.any_orthonormal_pair();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
}

impl<'a> PathTracer<'a> {
    pub fn new(scene: &'a Scene, bvh: &'a SceneBvh, settings: PathSettings) -> Self {
        let g = &scene.geometry;
        let normals = face_normals(g);
        let mut emitters = Vec::new();
        for (i, t) in g.triangles.iter().enumerate() {
            if let Surface::Diffuse { emission, .. } = g.surface(i)
                && luminance(*emission) > 0.0
            {
                let area = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
                emitters.push(Emitter {
                    triangle: i,
                    area,
                    emission: *emission,
                });
            }
        }
        let weights: Vec<f32> = emitters
            .iter()
            .map(|e| e.area * luminance(e.emission))
            .collect();
        let total: f32 = weights.iter().sum();
        let mut cdf = Vec::with_capacity(weights.len());
        let mut acc = 0.0;
        let mut area_pdf = vec![0.0; g.triangles.len()];
        for (e, w) in emitters.iter().zip(&weights) {
            acc += w / total;
            cdf.push(acc);
            area_pdf[e.triangle] = w / total / e.area;
        }
        let mirror_planes = MirrorPlanes::new(scene);
        bvh.prepare_packets();
        PathTracer {
            scene,
            bvh,
            settings,
            normals,
            emitters,
            cdf,
            area_pdf,
            mirror_planes,
        }
    }

    /// Whether the segment from `p` (on triangle `from`) to `q` is unblocked; `q` lies on
    /// triangle `to`, or is a point light (`None`: then any hit blocks it, and the any-hit
    /// query answers without looking for the closest).
    fn visible(&self, p: Vec3, from: usize, q: Vec3, to: Option<usize>) -> bool {
        let (ray, t_max) = segment(p, q);
        if to.is_none() {
            return !self.bvh.occluded(&ray, 0.0, t_max, None, Some(from));
        }
        match self
            .bvh
            .closest_hit_skipping(&ray, 0.0, t_max, None, Some(from))
        {
            None => true,
            Some(h) => Some(h.triangle) == to,
        }
    }
}

/// The shadow ray from `p` towards `q` and its far limit: hits nearer than `q` by a
/// relative 10⁻⁴ block it (`q` itself lies on a surface, or is a light).
#[inline(always)]
fn segment(p: Vec3, q: Vec3) -> (Ray, f32) {
    let d = q - p;
    let dist = d.length();
    let ray = Ray {
        origin: p,
        dir: d / dist,
    };
    (ray, dist * (1.0 - 1e-4))
}

/// Whether a point light at `light` lights a diffuse point `p` with normal `n` from its
/// side (before its shadow ray is asked), and the cosine and squared distance of its
/// contribution.
#[inline(always)]
fn faces_light(p: Vec3, n: Vec3, light: Vec3) -> (bool, f32, f32) {
    let to = light - p;
    let r2 = to.length_squared();
    let cos = n.dot(to) / r2.sqrt();
    (cos > 0.0 && r2 > 1e-8, cos, r2)
}

/// The closest hit of one query of a path, found ahead of the path (by a packet).
#[derive(Clone, Copy)]
struct Hinted {
    ray: Ray,
    skip_mirror: Option<usize>,
    hit: Option<Hit>,
}

/// What the paths of up to [`LANES`] rays know before they draw a random number
/// ([`PathTracer::mirror_chains`]): each query of their mirror chains with its hit, and
/// where a chain ends on a diffuse surface, whether each point light lights that point.
#[derive(Default)]
struct Ahead {
    /// `rounds[k][i]`: the k-th query of ray `i`'s path and its closest hit.
    rounds: Vec<[Option<Hinted>; LANES]>,
    /// Per lane, the round whose hit (diffuse) ends its chain: its first diffuse vertex;
    /// `u32::MAX` where the chain ends otherwise.
    diffuse_round: [u32; LANES],
    /// Per point light, the lanes whose shadow ray from their first diffuse vertex was
    /// traced, and of those, the lanes it found unblocked.
    traced: Vec<LaneMask>,
    lit: Vec<LaneMask>,
}

impl Ahead {
    /// Whether the shadow ray from lane `lane`'s diffuse vertex in round `round` to light
    /// `light` is unblocked, if it was traced ahead.
    fn lit(&self, lane: usize, round: u32, light: usize) -> Option<bool> {
        (self.diffuse_round[lane] == round && self.traced[light] >> lane & 1 == 1)
            .then(|| self.lit[light] >> lane & 1 == 1)
    }
}

/// Fewest rays of a pixel whose mirror chains are traced as packets.
const MIN_PACKET: usize = 4;

/// How far past `rr_depth` the mirror chains are traced ahead ([`PathTracer::mirror_chains`]).
const CHAIN_PAST_ROULETTE: u32 = 8;

impl PathTracer<'_> {
    /// The deterministic start of each of `rays`' paths (at most [`LANES`] rays) — the
    /// camera ray and the chain of front-facing mirror reflections after it, which draw no
    /// random numbers (Russian roulette may end the path there, but does not change the next
    /// ray) — traced side by side: every round's closest-hit queries go to the BVH as one
    /// packet. `ahead.rounds[k][i]` gets the k-th query of ray `i`'s path with its hit, for
    /// [`PathTracer::radiance_hinted`]. The chain's rays are computed as the path computes
    /// them (f32 rays, the bounce in f64). Where a chain ends on a diffuse surface, the
    /// shadow rays from there to the point lights are deterministic too: traced as any-hit
    /// packets, one per light, into `ahead.lit`.
    ///
    /// Compiled for the CPU's widest vectors ([`crate::cpu_features`], kernel inlined); the
    /// bounces off flat mirrors are computed in one lane loop ([`bounce_flat_lanes`]).
    fn mirror_chains(&self, rays: &[Ray], ahead: &mut Ahead) {
        struct Work<'w, 'a> {
            path: &'w PathTracer<'a>,
            rays: &'w [Ray],
            ahead: &'w mut Ahead,
        }
        impl Vectorised for Work<'_, '_> {
            type Output = ();
            #[inline(always)]
            fn run(self) {
                self.path.mirror_chains_inline(self.rays, self.ahead)
            }
        }
        widest(Work {
            path: self,
            rays,
            ahead,
        })
    }

    #[inline(always)]
    fn mirror_chains_inline(&self, rays: &[Ray], ahead: &mut Ahead) {
        let g = &self.scene.geometry;
        let rounds = &mut ahead.rounds;
        rounds.clear();
        ahead.diffuse_round = [u32::MAX; LANES];
        // The first diffuse vertices: point and normal on the side the path arrives from.
        let mut vertex = [(Vec3::ZERO, Vec3::ZERO); LANES];
        let mut on_triangle = [NO_TRIANGLE; LANES];
        // The chains' rays: f32 values (as the path holds them) in f64 lanes (the bounce's
        // input).
        let (mut origin, mut dir) = RayPacket::f64_lanes(rays);
        let mut normal = [[0.0f64; LANES]; 3];
        let mut offset = [0.0f64; LANES];
        let mut active = first_lanes(rays.len());
        let mut packet = RayPacket::default();
        let mut hits = [None; LANES];
        // Chains are traced ahead to at most CHAIN_PAST_ROULETTE queries past the depth
        // where Russian roulette starts: deeper, it has ended most paths, and the rest go one
        // ray at a time (`mirror_room` at depth 66, one thread: 1.94 s traced to the end,
        // 1.79 s with this limit).
        let chain_limit = (self.settings.max_depth)
            .min(self.settings.rr_depth.saturating_add(CHAIN_PAST_ROULETTE));
        while active != 0 {
            packet.set_rays_f64(&origin, &dir);
            self.bvh.closest_hits_inline(&packet, active, &mut hits);
            rounds.push([None; LANES]);
            // The path follows a front-facing mirror to its next query, unless that query
            // would be past the depth limit.
            let deeper = (rounds.len() as u32) < chain_limit;
            let index = rounds.len() as u32 - 1;
            let round = rounds.last_mut().expect("just pushed");
            let mut flat = [false; LANES];
            for lane in lanes(active) {
                let (ray, skip_mirror) = packet.lane(lane);
                round[lane] = Some(Hinted {
                    ray,
                    skip_mirror,
                    hit: hits[lane],
                });
                let Some(hit) = hits[lane] else {
                    active &= !(1 << lane);
                    continue;
                };
                let n_f = self.normals[hit.triangle];
                let front = n_f.dot(ray.dir) < 0.0;
                let mirror = match *g.surface(hit.triangle) {
                    Surface::Mirror { mirror, .. } if front => Some(mirror),
                    _ => None,
                };
                let Some(mirror) = mirror.filter(|_| deeper) else {
                    // The path shades a diffuse hit unless it is at the depth limit.
                    if mirror.is_none() && index + 1 < self.settings.max_depth {
                        ahead.diffuse_round[lane] = index;
                        let n = if front { n_f } else { -n_f };
                        vertex[lane] = (ray.at(hit.t), n);
                        on_triangle[lane] = hit.triangle as u32;
                    }
                    active &= !(1 << lane);
                    continue;
                };
                packet.set_skip(lane, Some(mirror));
                if let Some((n, off)) = self.mirror_planes.flat_plane(mirror) {
                    flat[lane] = true;
                    for k in 0..3 {
                        normal[k][lane] = n[k];
                    }
                    offset[lane] = off;
                    continue;
                }
                let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
                let Some((o, d)) = self.mirror_planes.reflect(mirror, o, d) else {
                    active &= !(1 << lane);
                    continue;
                };
                for k in 0..3 {
                    origin[k][lane] = o[k] as f32 as f64;
                    dir[k][lane] = d[k] as f32 as f64;
                }
            }
            if flat.iter().any(|&f| f) {
                bounce_flat_lanes::<LANES, true>(&flat, &normal, &offset, &mut origin, &mut dir);
            }
        }
        // The first diffuse vertices' shadow rays, as the path asks them
        // (`PathTracer::visible` towards a point light).
        let diffuse = lanes(first_lanes(rays.len()))
            .filter(|&lane| ahead.diffuse_round[lane] != u32::MAX)
            .fold(0, |mask: LaneMask, lane| mask | 1 << lane);
        ahead.traced.clear();
        ahead.lit.clear();
        let mut t_max = [0.0f32; LANES];
        for light in &self.scene.lighting.lights {
            let mut traced: LaneMask = 0;
            for lane in lanes(diffuse) {
                let (p, n) = vertex[lane];
                if faces_light(p, n, light.position).0 {
                    let (ray, far) = segment(p, light.position);
                    packet.set(lane, &ray, None);
                    t_max[lane] = far;
                    traced |= 1 << lane;
                }
            }
            let blocked = if traced == 0 {
                0
            } else {
                self.bvh
                    .occluded_lanes_inline(&packet, traced, &t_max, &on_triangle)
            };
            ahead.traced.push(traced);
            ahead.lit.push(traced & !blocked);
        }
    }

    /// Radiance along `ray`, random numbers from `rng`; the closest hit of the path's k-th
    /// query is taken from `ahead.rounds[k][lane]` when that is the same query (ray bits
    /// and skips), else asked of the BVH, and so are the point lights' shadow rays from
    /// the diffuse hit that ends the chain. With nothing ahead, [`Integrator::radiance`].
    fn radiance_hinted(
        &self,
        ray: Ray,
        rng: &mut SplitMix64,
        ahead: Option<&Ahead>,
        lane: usize,
    ) -> PathResult {
        let rounds = ahead.map_or(&[][..], |a| &a.rounds[..]);
        let scene = self.scene;
        let g = &scene.geometry;
        let mut ray = ray;
        let mut beta = Vec3::ONE;
        let mut radiance = Vec3::ZERO;
        let mut rays = 0u32;
        let mut bounces = 0u32;
        // Solid-angle pdf of the BSDF sample that produced `ray`; None after the camera or a mirror.
        let mut bsdf_pdf: Option<f32> = None;
        let mut from_triangle: Option<usize> = None;
        let mut from_mirror: Option<usize> = None;
        let mut depth = 0u32;
        let termination = loop {
            rays += 1;
            let hinted = rounds.get(depth as usize).and_then(|r| r[lane].as_ref());
            let hinted = hinted.filter(|h| {
                from_triangle.is_none()
                    && h.skip_mirror == from_mirror
                    && h.ray.origin.to_array().map(f32::to_bits)
                        == ray.origin.to_array().map(f32::to_bits)
                    && h.ray.dir.to_array().map(f32::to_bits)
                        == ray.dir.to_array().map(f32::to_bits)
            });
            let was_hinted = hinted.is_some();
            let hit = match hinted {
                Some(h) => h.hit,
                None => self.bvh.closest_hit_skipping(
                    &ray,
                    0.0,
                    f32::INFINITY,
                    from_mirror,
                    from_triangle,
                ),
            };
            let Some(hit) = hit else {
                radiance += beta * scene.background;
                break Termination::Escaped;
            };
            let p = ray.at(hit.t);
            let n_f = self.normals[hit.triangle];
            let front = n_f.dot(ray.dir) < 0.0;
            let inter = interaction_at(g, hit.triangle, p, front);
            if let Interaction::Diffuse { emission, .. } = inter
                && front
                && emission != Vec3::ZERO
            {
                let weight = match bsdf_pdf {
                    None => 1.0,
                    Some(p_bsdf) => {
                        let cos_l = n_f.dot(-ray.dir).max(1e-8);
                        let p_light = self.area_pdf[hit.triangle] * hit.t * hit.t / cos_l;
                        p_bsdf * p_bsdf / (p_bsdf * p_bsdf + p_light * p_light)
                    }
                };
                radiance += beta * emission * weight;
            }
            if depth + 1 >= self.settings.max_depth {
                break Termination::Depth;
            }
            match inter {
                Interaction::Reflect { reflectance } => {
                    let Surface::Mirror { mirror, .. } = *g.surface(hit.triangle) else {
                        unreachable!("only mirrors reflect")
                    };
                    beta *= reflectance;
                    // After a hinted query, the chain's next query is this very bounce
                    // (computed from the same ray and hit, the same way): take its ray.
                    let chained = rounds
                        .get(depth as usize + 1)
                        .and_then(|r| r[lane].as_ref())
                        .filter(|h| was_hinted && h.skip_mirror == Some(mirror));
                    if let Some(next) = chained {
                        ray = next.ray;
                    } else {
                        let Some((origin, dir)) = self.mirror_planes.reflect(
                            mirror,
                            ray.origin.as_dvec3(),
                            ray.dir.as_dvec3(),
                        ) else {
                            break Termination::Absorbed;
                        };
                        ray = Ray {
                            origin: origin.as_vec3(),
                            dir: dir.as_vec3(),
                        };
                    }
                    bsdf_pdf = None;
                    from_mirror = Some(mirror);
                    from_triangle = None;
                    bounces += 1;
                }
                Interaction::Diffuse { albedo, .. } => {
                    let n = if front { n_f } else { -n_f };
                    let f = albedo * std::f32::consts::FRAC_1_PI;
                    for (l, light) in scene.lighting.lights.iter().enumerate() {
                        let (faces, cos, r2) = faces_light(p, n, light.position);
                        // Traced ahead where this is the hinted diffuse hit that ends
                        // the mirror chain (the same point, so the same shadow ray).
                        let ahead_lit = ahead
                            .filter(|_| was_hinted)
                            .and_then(|a| a.lit(lane, depth, l));
                        if faces
                            && ahead_lit.unwrap_or_else(|| {
                                self.visible(p, hit.triangle, light.position, None)
                            })
                        {
                            rays += 1;
                            radiance += beta * f * light.intensity * (cos / r2);
                        }
                    }
                    if !self.emitters.is_empty() {
                        let u = rng.next_unit();
                        let k = self
                            .cdf
                            .partition_point(|&c| c <= u)
                            .min(self.emitters.len() - 1);
                        let e = &self.emitters[k];
                        let t = g.triangles[e.triangle];
                        let (mut a, mut b) = (rng.next_unit(), rng.next_unit());
                        if a + b > 1.0 {
                            (a, b) = (1.0 - a, 1.0 - b);
                        }
                        let q = t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b;
                        let to = q - p;
                        let r2 = to.length_squared();
                        let l = to / r2.sqrt();
                        let cos_p = n.dot(l);
                        let cos_l = -self.normals[e.triangle].dot(l);
                        if cos_p > 0.0
                            && cos_l > 0.0
                            && self.visible(p, hit.triangle, q, Some(e.triangle))
                        {
                            rays += 1;
                            let p_light = self.area_pdf[e.triangle] * r2 / cos_l;
                            let p_bsdf = cos_p * std::f32::consts::FRAC_1_PI;
                            let w = p_light * p_light / (p_light * p_light + p_bsdf * p_bsdf);
                            // The emission at q (its texture's), the selection by factor.
                            let emission = g.diffuse_at(e.triangle, q).map_or(e.emission, |d| d.1);
                            radiance += beta * f * emission * (cos_p / p_light) * w;
                        }
                    }
                    let dir = cosine_sample(n, rng.next_unit(), rng.next_unit());
                    bsdf_pdf = Some(n.dot(dir) * std::f32::consts::FRAC_1_PI);
                    beta *= albedo; // f·cos/pdf = ρ/π·cos/(cos/π)
                    ray = Ray { origin: p, dir };
                    from_triangle = Some(hit.triangle);
                    from_mirror = None;
                }
            }
            depth += 1;
            if depth >= self.settings.rr_depth {
                let q = beta.max_element().min(0.95);
                if q <= 0.0 || rng.next_unit() >= q {
                    break Termination::Roulette;
                }
                beta /= q;
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

impl Integrator for PathTracer<'_> {
    /// Radiance along `ray`, random numbers from `rng`.
    fn radiance(&self, ray: Ray, rng: &mut SplitMix64) -> PathResult {
        self.radiance_hinted(ray, rng, None, 0)
    }

    /// Enough pixels to fill a packet's lanes with their mirror chains when packets are
    /// traced and a pixel has enough samples to make one ([`MIN_PACKET`]), at least one;
    /// each pixel keeps its own stream, so the images do not change.
    fn pixels_per_call(&self, samples_per_pixel: usize) -> usize {
        super::packet_pixels(self.bvh, samples_per_pixel, MIN_PACKET)
    }

    /// One ray at a time in order, each pixel's rays sharing its stream, as
    /// [`Integrator::radiance`]; when the BVH traces packets, the deterministic mirror chains
    /// at the start of the paths are traced first, [`LANES`] rays side by side (two pixels'
    /// at 16 samples: [`Integrator::pixels_per_call`]), and each path takes its hits from
    /// there.
    fn radiance_all(&self, rays: &[Ray], rngs: &mut [SplitMix64], out: &mut Vec<PathResult>) {
        out.clear();
        let per_pixel = super::rays_per_pixel(rays, rngs);
        if !self.bvh.packets() || rays.len() < MIN_PACKET {
            for (pixel, rng) in rays.chunks(per_pixel).zip(rngs) {
                out.extend(
                    pixel
                        .iter()
                        .map(|&ray| self.radiance_hinted(ray, rng, None, 0)),
                );
            }
            return;
        }
        // One buffer per thread, kept from pixel to pixel: a fresh one per pixel, up to
        // 2 KB per round and `max_depth` rounds, went to `mmap` and page faults (5 % at the
        // default depth of 66).
        thread_local! {
            static AHEAD: std::cell::RefCell<Ahead> = std::cell::RefCell::new(Ahead::default());
        }
        AHEAD.with_borrow_mut(|ahead| {
            for (chunk_index, chunk) in rays.chunks(LANES).enumerate() {
                self.mirror_chains(chunk, ahead);
                for (lane, &ray) in chunk.iter().enumerate() {
                    let rng = &mut rngs[(chunk_index * LANES + lane) / per_pixel];
                    out.push(self.radiance_hinted(ray, rng, Some(ahead), lane));
                }
            }
        });
    }
}
