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
//! - **Russian roulette** from segment `rr_from` (Mitsuba's `rr_depth`) on, survival probability max(throughput) ≤ 0.95;
//! - a shadow ray (to a point light, or to the sampled point on an emitter) is blocked by
//!   any hit nearer than a relative 10⁻⁴ short of its end (an any-hit query);
//! - every ray skips the **flat surface** it leaves ([`SceneBvh::flat_surface`]): the
//!   mirror, or all the diffuse triangles on the plane of the one it leaves, not only that
//!   triangle — a hit there can only be a self-intersection (issue 56: a ray leaving one of a
//!   floor's two triangles no longer enters the other's leaf).
//!
//! **Every sample its own random stream** (issue 41), split off its pixel's stream in
//! sample order ([`SplitMix64::split`]): so the samples of neighbouring pixels walk side by
//! side, [`LANES`] at a time — each round's closest-hit and shadow queries of the paths
//! before their first diffuse vertex (coherent) going to the BVH as packets, the scattered
//! ones after it one at a time — Russian roulette ending each lane on its own
//! ([`PathTracer::radiance_lanes`]);
//! one at a time, a sample draws the same numbers and takes the same steps
//! ([`PathTracer::radiance_one`]).
//!
//! A path's length is counted in segments, as Mitsuba's `max_depth` counts it (its
//! "depth"; here "depth" means mirror reflections only, docs/shading.md): 1 shows only
//! directly visible emitters, 2 adds direct light, and N visible reflections need N + 2. The ambient
//! term of the contract is not physical and is not used here.

use super::{Integrator, PathResult, Termination, face_normals};
use crate::bvh::packet::{LANES, LaneHits, LaneMask, NO_TRIANGLES, RayPacket, first_lanes, lanes};
use crate::bvh::{Hit, NO_QUERY, Query, SceneBvh};
use crate::cpu_features::{Vectorised, build_for, run_on};
use crate::hit_point::on_triangle_plane;
use crate::mirror_bounce::{MirrorPlanes, bounce_flat_lanes, reflect_on_plane};
use crate::sampler::SplitMix64;
use glam::Vec3;
use mirrorbox_scene::shading::{Interaction, interaction_with_point};
use mirrorbox_scene::{Ray, Scene, Surface};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathSettings {
    /// Longest path in segments (Mitsuba's `max_depth`).
    pub max_segments: u32,
    /// The segment count from which Russian roulette may end paths (Mitsuba's `rr_depth`).
    pub rr_from: u32,
    /// Seed of the per-pixel random streams.
    pub seed: u64,
}

impl Default for PathSettings {
    fn default() -> Self {
        PathSettings {
            max_segments: 66,
            rr_from: 5,
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

/// Diffuse vertices a path may have passed for its closest-hit queries to go to the packet
/// kernel; later queries go one at a time to the single-ray hierarchy. Camera rays and the
/// mirror chains after them are coherent (neighbouring samples, planar mirrors); the
/// cosine-sampled rays after a diffuse vertex are not, and a 32-lane packet of them visits
/// the union of their nodes. Measured (one thread, 640×360, 16 spp, 10 segments, AMD EPYC
/// AVX-512): everything in packets 1.12 s (`mirror_box`) and 2.24 s (`mirror_room`); 1:
/// 0.73 s and 1.55 s; 2: 0.72 s and 1.64 s (with a packet kernel that skipped the diffuse
/// triangle a ray leaves, since removed: the same on `mirror_box`, slower on `mirror_room`).
/// The lanes skip the flat surface they leave since issue 56's seventeenth session, as the
/// kernel can: 2 measured again then, ×1.159 / ×1.241 (`mirror_box` / `mirror_room`, Intel
/// Xeon): slower still.
const PACKET_VERTICES: u32 = 1;

/// Likewise for the next-event shadow rays: those from a path's first diffuse vertex start
/// at neighbouring points and go towards one light (or one emitter), and are traced as
/// any-hit packets; later ones one at a time (measured with [`PACKET_VERTICES`] 1: none in
/// packets 0.78 s and 1.63 s; 1: 0.73 s and 1.55 s; 2: 0.74 s and 1.68 s).
const PACKET_SHADOW_VERTICES: u32 = 1;

/// A round's bounces off flat mirrors are computed lane by lane where at most this many
/// lanes bounce, else side by side over all [`LANES`] ([`bounce_flat_lanes`]).
const FEW_FLAT_LANES: u32 = 4;

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Cosine-weighted direction around unit `n` (Malley's method): a unit vector up to
/// rounding, not normalised again (as Mitsuba's `square_to_cosine_hemisphere` in its frame;
/// the normalisation's square root and division measured ~1 % of `path`, issue 56).
fn cosine_sample(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let r = u1.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u2;
    let (t, b) = n.any_orthonormal_pair();
    let (sin, cos) = phi.sin_cos();
    t * (r * cos) + b * (r * sin) + n * (1.0 - u1).max(0.0).sqrt()
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
}

/// The shadow ray from `p` along unit `dir` towards a point `dist` away, and its far limit:
/// hits nearer than that point by a relative 10⁻⁴ block it (it lies on a surface, or is a
/// light). The caller has the direction and distance already.
#[inline(always)]
fn segment(p: Vec3, dir: Vec3, dist: f32) -> (Ray, f32) {
    (Ray { origin: p, dir }, dist * (1.0 - 1e-4))
}

/// Whether a point light at `light` lights a diffuse point `p` with normal `n` from its
/// side (before its shadow ray is asked), and the cosine and squared distance of its
/// contribution, with the vector to the light and its length (for [`segment`]).
#[inline(always)]
fn faces_light(p: Vec3, n: Vec3, light: Vec3) -> (bool, f32, f32, Vec3, f32) {
    let to = light - p;
    let r2 = to.length_squared();
    let dist = r2.sqrt();
    let cos = n.dot(to) / dist;
    (cos > 0.0 && r2 > 1e-8, cos, r2, to, dist)
}

/// What a path does after [`PathTracer::vertex`].
enum Vertex {
    End(Termination),
    /// Its next ray is `walk.ray`.
    Next,
    /// Its next ray is `walk.ray` bounced off this flat mirror plane (unit normal, offset).
    FlatBounce(([f32; 3], f32)),
}

/// A shadow ray asked by the path in lane `.0`, of kind `.1` (point light, or the emitter
/// sample), with its answer (blocked) where it was traced at once.
type Asked = (usize, usize, ShadowRay, Option<bool>);

/// A path between its vertices: its next ray and what it carries.
#[derive(Clone, Copy)]
struct Walk {
    ray: Ray,
    beta: Vec3,
    radiance: Vec3,
    rays: u32,
    bounces: u32,
    /// Solid-angle pdf of the BSDF sample that produced `ray`; None after the camera or a
    /// mirror.
    bsdf_pdf: Option<f32>,
    /// The flat surface `ray` leaves ([`SceneBvh::flat_surface`]: a mirror, or the plane
    /// of the diffuse triangle it leaves; skipped by its query), if any.
    leaving: Option<usize>,
    /// Segments so far.
    segments: u32,
    /// Diffuse vertices passed so far.
    diffuse_vertices: u32,
}

impl Walk {
    fn start(ray: Ray) -> Self {
        Walk {
            ray,
            beta: Vec3::ONE,
            radiance: Vec3::ZERO,
            rays: 0,
            bounces: 0,
            bsdf_pdf: None,
            leaving: None,
            segments: 0,
            diffuse_vertices: 0,
        }
    }

    /// The ray found nothing: the background, seen through the path's throughput (its ray
    /// counted). The path ends ([`Termination::Escaped`]).
    #[inline(always)]
    fn escape(&mut self, background: Vec3) {
        self.rays += 1;
        self.radiance += self.beta * background;
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

/// A next-event shadow ray a path vertex asks for, and the radiance it adds when nothing
/// blocks it: the ray from the shaded point (on flat surface `leaving`, skipped) towards a
/// point light or a point on an emitter, blocked by any hit in `[0, t_max)`.
#[derive(Clone, Copy)]
struct ShadowRay {
    ray: Ray,
    t_max: f32,
    leaving: usize,
    contribution: Vec3,
}

impl PathTracer<'_> {
    /// One vertex of a path: `hit` is the closest hit of `walk.ray` (skipping the flat
    /// surface it leaves). Adds what is seen there (the background, or an emitter's
    /// emission with its MIS weight), asks `shadow(k, ray)` for each next-event shadow ray
    /// — `k` the point light's index, or the number of lights for the emitter sample —
    /// whose contribution the caller adds, in the order asked, where it is unblocked; then
    /// samples the next ray and plays Russian roulette. Returns how the path ended, if it
    /// did, or, with `DEFER_FLAT`, the plane of the flat mirror whose bounce of `walk.ray`
    /// the caller computes ([`bounce_flat_lanes`], the same bits as
    /// [`MirrorPlanes::reflect`], side by side for a packet's lanes).
    ///
    /// The shadow rays' answers change no random number and no later ray, so a caller may
    /// trace them after this returns: one path at a time ([`PathTracer::radiance_one`]) or
    /// [`LANES`] paths' together ([`PathTracer::radiance_lanes`]), to the same bits.
    #[inline(always)]
    fn vertex<const DEFER_FLAT: bool>(
        &self,
        w: &mut Walk,
        hit: Option<Hit>,
        rng: &mut SplitMix64,
        mut shadow: impl FnMut(usize, ShadowRay),
    ) -> Vertex {
        let scene = self.scene;
        let g = &scene.geometry;
        // The ray's two vectors apart, not the 24-byte `Ray` copied: that copy was stored as
        // 16 + 8 bytes, and the direction read back as 8 bytes across the two stores, which
        // no store forwarding serves (a wait for the stores to retire: 7 % of `path`
        // `mirror_box` on one instruction by `perf` on an Intel Xeon; ×0.884 / ×0.895 on
        // `mirror_box` / `mirror_room` there, issue 56's thirteenth session).
        let (origin, dir) = (w.ray.origin, w.ray.dir);
        let Some(hit) = hit else {
            w.escape(scene.background);
            return Vertex::End(Termination::Escaped);
        };
        w.rays += 1;
        let mut flat = None;
        let n_f = self.normals[hit.triangle];
        let front = n_f.dot(dir) < 0.0;
        let (inter, p) = interaction_with_point(g, hit.triangle, front, move || {
            on_triangle_plane(g, hit.triangle, origin.as_dvec3(), dir.as_dvec3(), hit.t)
        });
        if let Interaction::Diffuse { emission, .. } = inter
            && front
            && emission != Vec3::ZERO
        {
            let weight = match w.bsdf_pdf {
                None => 1.0,
                Some(p_bsdf) => {
                    let cos_l = n_f.dot(-dir).max(1e-8);
                    let p_light = self.area_pdf[hit.triangle] * hit.t * hit.t / cos_l;
                    p_bsdf * p_bsdf / (p_bsdf * p_bsdf + p_light * p_light)
                }
            };
            w.radiance += w.beta * emission * weight;
        }
        if w.segments + 1 >= self.settings.max_segments {
            return Vertex::End(Termination::Depth);
        }
        match inter {
            Interaction::Reflect { reflectance } => {
                let Surface::Mirror { mirror, .. } = *g.surface(hit.triangle) else {
                    unreachable!("only mirrors reflect")
                };
                w.beta *= reflectance;
                match self.mirror_planes.flat_plane_f32(mirror) {
                    // The caller bounces the ray ([`Vertex::FlatBounce`]).
                    Some(plane) if DEFER_FLAT => flat = Some(plane),
                    Some((n, offset)) => {
                        let (origin, dir) =
                            reflect_on_plane(n, offset, origin.to_array(), dir.to_array());
                        w.ray = Ray {
                            origin: Vec3::from(origin),
                            dir: Vec3::from(dir),
                        };
                    }
                    None => {
                        let Some((origin, dir)) =
                            self.mirror_planes
                                .reflect(mirror, origin.as_dvec3(), dir.as_dvec3())
                        else {
                            return Vertex::End(Termination::Absorbed);
                        };
                        w.ray = Ray {
                            origin: origin.as_vec3(),
                            dir: dir.as_vec3(),
                        };
                    }
                }
                w.bsdf_pdf = None;
                w.leaving = Some(mirror);
                w.bounces += 1;
            }
            Interaction::Diffuse { albedo, .. } => {
                let p = p.expect("a diffuse interaction comes with its point");
                let leaving = self.bvh.flat_surface(hit.triangle);
                let n = if front { n_f } else { -n_f };
                let f = albedo * std::f32::consts::FRAC_1_PI;
                let lights = &scene.lighting.lights;
                for (l, light) in lights.iter().enumerate() {
                    let (faces, cos, r2, to, dist) = faces_light(p, n, light.position);
                    if faces {
                        let (ray, t_max) = segment(p, to * (1.0 / dist), dist);
                        let contribution = w.beta * f * light.intensity * (cos / r2);
                        shadow(
                            l,
                            ShadowRay {
                                ray,
                                t_max,
                                leaving,
                                contribution,
                            },
                        );
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
                    let dist = r2.sqrt();
                    let l = to * (1.0 / dist);
                    let cos_p = n.dot(l);
                    let cos_l = -self.normals[e.triangle].dot(l);
                    if cos_p > 0.0 && cos_l > 0.0 {
                        let p_light = self.area_pdf[e.triangle] * r2 / cos_l;
                        let p_bsdf = cos_p * std::f32::consts::FRAC_1_PI;
                        let weight = p_light * p_light / (p_light * p_light + p_bsdf * p_bsdf);
                        // The emission at q (its texture's), the selection by factor.
                        let emission = g.diffuse_at(e.triangle, q).map_or(e.emission, |d| d.1);
                        let (ray, t_max) = segment(p, l, dist);
                        let contribution = w.beta * f * emission * (cos_p / p_light) * weight;
                        shadow(
                            lights.len(),
                            ShadowRay {
                                ray,
                                t_max,
                                leaving,
                                contribution,
                            },
                        );
                    }
                }
                let dir = cosine_sample(n, rng.next_unit(), rng.next_unit());
                w.bsdf_pdf = Some(n.dot(dir) * std::f32::consts::FRAC_1_PI);
                w.beta *= albedo; // f·cos/pdf = ρ/π·cos/(cos/π)
                w.ray = Ray { origin: p, dir };
                w.leaving = Some(leaving);
                w.diffuse_vertices += 1;
            }
        }
        w.segments += 1;
        if w.segments >= self.settings.rr_from {
            let q = w.beta.max_element().min(0.95);
            if q <= 0.0 || rng.next_unit() >= q {
                return Vertex::End(Termination::Roulette);
            }
            w.beta *= 1.0 / q;
        }
        match flat {
            Some(plane) => Vertex::FlatBounce(plane),
            None => Vertex::Next,
        }
    }

    /// Radiance along `ray`, random numbers from `rng` (the sample's own stream), one query
    /// at a time through the single-ray hierarchy. `unblocked` holds a vertex's unblocked
    /// shadow contributions until they are added (the caller's, kept from path to path: a
    /// fresh one allocated for every path with a diffuse hit).
    fn radiance_one(
        &self,
        ray: Ray,
        rng: &mut SplitMix64,
        unblocked: &mut Vec<Vec3>,
    ) -> PathResult {
        let mut w = Walk::start(ray);
        loop {
            let hit = self
                .bvh
                .closest_hit_skipping(&w.ray, 0.0, f32::INFINITY, w.leaving, None);
            unblocked.clear();
            let end = self.vertex::<false>(&mut w, hit, rng, |_, s| {
                if !self
                    .bvh
                    .occluded(&s.ray, 0.0, s.t_max, Some(s.leaving), None)
                {
                    unblocked.push(s.contribution);
                }
            });
            for &c in unblocked.iter() {
                w.radiance += c;
                w.rays += 1;
            }
            if let Vertex::End(end) = end {
                return w.result(end);
            }
        }
    }

    /// The radiance of each of `rays` (one per entry of `rngs`, each sample's own stream),
    /// in order, into `out`: [`LANES`] paths walk side by side, and each round's coherent
    /// queries go to the BVH as packets — the closest hits of the paths before their first
    /// diffuse vertex (camera rays, mirror chains) as one packet, the shadow rays of their
    /// first diffuse vertex as one any-hit packet per point light and one for the emitter
    /// samples; the scattered queries after it go one at a time ([`PACKET_VERTICES`],
    /// [`PACKET_SHADOW_VERTICES`]).
    /// Russian roulette ends each lane on its own. Every path takes the same steps as
    /// [`PathTracer::radiance_one`] with the same stream, so with the same answers from the
    /// hierarchy the results are the same bits.
    ///
    /// Compiled for the CPU's widest vectors ([`crate::cpu_features`], kernel inlined).
    fn radiance_lanes(
        &self,
        rays: &[Ray],
        rngs: &mut [SplitMix64],
        asked: &mut Vec<Asked>,
        out: &mut Vec<PathResult>,
    ) {
        struct Work<'w, 'a> {
            path: &'w PathTracer<'a>,
            rays: &'w [Ray],
            rngs: &'w mut [SplitMix64],
            asked: &'w mut Vec<Asked>,
            out: &'w mut Vec<PathResult>,
        }
        impl Vectorised for Work<'_, '_> {
            type Output = ();
            #[inline(always)]
            fn run(self) {
                self.run_wide::<8>()
            }
            #[inline(always)]
            fn run_wide<const F32_LANES: usize>(self) {
                self.path
                    .radiance_lanes_inline::<F32_LANES>(self.rays, self.rngs, self.asked, self.out)
            }
        }
        run_on(
            build_for(self.gains_from_512_bits()),
            Work {
                path: self,
                rays,
                rngs,
                asked,
                out,
            },
        )
    }

    #[inline(always)]
    fn radiance_lanes_inline<const F32_LANES: usize>(
        &self,
        rays: &[Ray],
        rngs: &mut [SplitMix64],
        asked: &mut Vec<Asked>,
        out: &mut Vec<PathResult>,
    ) {
        let kinds = self.scene.lighting.lights.len() + 1;
        let mut packet = RayPacket::default();
        let mut hits = LaneHits::default();
        let mut t_max = [0.0f32; LANES];
        // A round's flat-mirror bounces, per lane (set for the lanes that have one).
        let mut normal = [[0.0f32; LANES]; 3];
        let mut offset = [0.0f32; LANES];
        let (mut origin, mut dir) = ([[0.0f32; LANES]; 3], [[0.0f32; LANES]; 3]);
        // Per kind of shadow ray (light, then emitter), the round's blocked lanes.
        let mut blocked: Vec<LaneMask> = Vec::with_capacity(kinds);
        // A round's single queries and their answers (closest hits, then shadow rays): set
        // up once per call, not per round (only the first `n` entries of a batch are read,
        // each written first; a round's `single` is read only in the lanes it queried).
        let mut single: [Option<Hit>; LANES] = [None; LANES];
        let mut queries = [NO_QUERY; LANES];
        let mut lane_of = [0usize; LANES];
        let mut answers = [None; LANES];
        for (chunk, rngs) in rays.chunks(LANES).zip(rngs.chunks_mut(LANES)) {
            let mut walks = [Walk::start(chunk[0]); LANES];
            for (w, &ray) in walks.iter_mut().zip(chunk) {
                w.ray = ray;
            }
            let mut ends = [Termination::Escaped; LANES];
            let mut active = first_lanes(chunk.len());
            // The lanes past their first diffuse vertex ([`PACKET_VERTICES`]), kept as a mask
            // rather than read from each walk every round (`path` ×0.991 / ×0.994 in one
            // process, `mirror_room` / `mirror_box`, issue 56's eleventh session).
            let mut scattered: LaneMask = 0;
            while active != 0 {
                // Paths before their first diffuse vertex (camera rays and mirror chains)
                // are coherent: their queries go to the packet kernel; later ones are
                // scattered, and go one at a time to the single-ray hierarchy. (Every lane
                // skips the flat surface it leaves, a mirror or a diffuse plane: the packet
                // kernel's closest hits can take a lane after any vertex.)
                let coherent = active & !scattered;
                for lane in lanes(coherent) {
                    let w = &walks[lane];
                    debug_assert!(w.diffuse_vertices < PACKET_VERTICES);
                    packet.set(lane, &w.ray, w.leaving);
                }
                if coherent != 0 {
                    self.bvh
                        .closest_hit_lanes_inline::<F32_LANES>(&packet, coherent, &mut hits);
                }
                // The scattered lanes' queries one after another, before any lane's vertex:
                // a run of traversals with nothing between them, which the processor
                // overlaps better than traversals interleaved with the vertices' code.
                // (Two at a time through the 8-wide hierarchy: `SceneBvh::queries_inline`.)
                let mut n = 0;
                for lane in lanes(active & !coherent) {
                    let w = &walks[lane];
                    queries[n] = Query {
                        ray: w.ray,
                        t_min: 0.0,
                        t_max: f32::INFINITY,
                        skip_flat: w.leaving,
                        skip_triangle: None,
                    };
                    lane_of[n] = lane;
                    n += 1;
                }
                self.bvh
                    .queries_inline::<false>(&queries[..n], &mut answers[..n]);
                for (&lane, &answer) in lane_of[..n].iter().zip(&answers[..n]) {
                    single[lane] = answer;
                }
                asked.clear();
                let mut flat = [false; LANES];
                let mut flat_lanes: LaneMask = 0;
                // The lanes whose ray escaped, first: the vertex loop below then meets only
                // hits, without a branch per lane on whether there is one (`path` ×0.986–×0.996
                // / ×0.986–×0.994 on `mirror_room` / `mirror_box` in one process, issue 56's
                // twelfth session).
                let mut escaped = hits.misses() & coherent;
                for lane in lanes(active & !coherent) {
                    escaped |= LaneMask::from(single[lane].is_none()) << lane;
                }
                for lane in lanes(escaped) {
                    walks[lane].escape(self.scene.background);
                    ends[lane] = Termination::Escaped;
                }
                active &= !escaped;
                for lane in lanes(active) {
                    let w = &mut walks[lane];
                    let in_packet = coherent >> lane & 1 == 1;
                    let hit = if in_packet {
                        hits.get(lane)
                    } else {
                        single[lane]
                    };
                    // A shadow ray not traced in a packet is answered one at a time after
                    // the round's vertices (`Some` marks it; its answer goes in then).
                    let shadow_in_packet = w.diffuse_vertices < PACKET_SHADOW_VERTICES;
                    let step = self.vertex::<true>(w, hit, &mut rngs[lane], |k, s| {
                        asked.push((lane, k, s, (!shadow_in_packet).then_some(false)))
                    });
                    match step {
                        Vertex::End(end) => {
                            ends[lane] = end;
                            active &= !(1 << lane);
                        }
                        Vertex::FlatBounce((n, off)) => {
                            flat[lane] = true;
                            flat_lanes |= 1 << lane;
                            for k in 0..3 {
                                normal[k][lane] = n[k];
                                origin[k][lane] = w.ray.origin[k];
                                dir[k][lane] = w.ray.dir[k];
                            }
                            offset[lane] = off;
                        }
                        Vertex::Next => {}
                    }
                    scattered |=
                        LaneMask::from(walks[lane].diffuse_vertices >= PACKET_VERTICES) << lane;
                }
                // The round's bounces off flat mirrors (f32): side by side where many lanes
                // bounce, else lane by lane (the same arithmetic: `reflect_on_plane`).
                if flat_lanes.count_ones() > FEW_FLAT_LANES {
                    bounce_flat_lanes(&flat, &normal, &offset, &mut origin, &mut dir);
                    for lane in lanes(flat_lanes) {
                        let at =
                            |a: &[[f32; LANES]; 3]| Vec3::new(a[0][lane], a[1][lane], a[2][lane]);
                        walks[lane].ray = Ray {
                            origin: at(&origin),
                            dir: at(&dir),
                        };
                    }
                } else {
                    for lane in lanes(flat_lanes) {
                        let at = |a: &[[f32; LANES]; 3]| [a[0][lane], a[1][lane], a[2][lane]];
                        let (o, d) =
                            reflect_on_plane(at(&normal), offset[lane], at(&origin), at(&dir));
                        walks[lane].ray = Ray {
                            origin: Vec3::from(o),
                            dir: Vec3::from(d),
                        };
                    }
                }
                if asked.is_empty() {
                    continue;
                }
                // The shadow rays traced one at a time (two at a time through the 8-wide
                // hierarchy), LANES per call.
                let mut singles = asked.iter_mut().filter(|a| a.3.is_some()).peekable();
                while singles.peek().is_some() {
                    let mut of: [Option<&mut Option<bool>>; LANES] = Default::default();
                    let mut n = 0;
                    for (_, _, s, answer) in singles.by_ref().take(LANES) {
                        queries[n] = Query {
                            ray: s.ray,
                            t_min: 0.0,
                            t_max: s.t_max,
                            skip_flat: Some(s.leaving),
                            skip_triangle: None,
                        };
                        of[n] = Some(answer);
                        n += 1;
                    }
                    self.bvh
                        .queries_inline::<true>(&queries[..n], &mut answers[..n]);
                    for (answer, blocked) in of[..n].iter_mut().zip(&answers[..n]) {
                        if let Some(answer) = answer {
                            **answer = Some(blocked.is_some());
                        }
                    }
                }
                // The round's shadow rays: one any-hit packet per light (and one for the
                // emitter samples); a lane asks at most one of each.
                blocked.clear();
                for k in 0..kinds {
                    let mut mask: LaneMask = 0;
                    for &(lane, _, s, _) in asked.iter().filter(|a| a.1 == k && a.3.is_none()) {
                        packet.set(lane, &s.ray, Some(s.leaving));
                        t_max[lane] = s.t_max;
                        mask |= 1 << lane;
                    }
                    let b = if mask == 0 {
                        0
                    } else {
                        self.bvh.occluded_lanes_inline::<F32_LANES>(
                            &packet,
                            mask,
                            &t_max,
                            &NO_TRIANGLES,
                        )
                    };
                    blocked.push(b);
                }
                for &(lane, k, s, answer) in asked.iter() {
                    if !answer.unwrap_or(blocked[k] >> lane & 1 == 1) {
                        let w = &mut walks[lane];
                        w.radiance += s.contribution;
                        w.rays += 1;
                    }
                }
            }
            out.extend((0..chunk.len()).map(|lane| walks[lane].result(ends[lane])));
        }
    }
}

impl Integrator for PathTracer<'_> {
    /// Radiance along `ray`: the sample's own stream is split off the pixel's `rng`
    /// ([`SplitMix64::split`]), as [`Integrator::radiance_all`] splits one per sample.
    fn radiance(&self, ray: Ray, rng: &mut SplitMix64) -> PathResult {
        self.radiance_one(ray, &mut rng.split(), &mut Vec::new())
    }

    /// No: a path's walk is mostly scalar and 8-lane code (the vertices, the single-ray
    /// traversal), which 512-bit vectors do not speed up, and on an Intel CPU the few 32-lane
    /// loops that use them presumably slow the clock for all of it (Intel's AVX-512 licences;
    /// the clock is not measurable in this project's VMs, but the timings fit: any 512-bit
    /// code in a render costs the whole render). A render in AVX2 there, against
    /// AVX-512 (Intel Xeon, 2 cores, one thread, 640×360, 16 spp, paired over 8 rounds; issue
    /// 56's thirteenth session): `mirror_box` ×0.942 [0.927–0.972], `mirror_room` ×0.967
    /// [0.928–0.980]; with only the walk in AVX2 (the image row and the camera rays in
    /// AVX-512) ×1.020 / ×1.026, slower. `whitted` is ×1.05–1.07 faster in AVX-512 and keeps it.
    fn gains_from_512_bits(&self) -> bool {
        false
    }

    /// Enough pixels to fill a call's packets when packets are traced (at least one;
    /// `packet_pixels`): every sample has its own stream, so any samples can walk side by side.
    fn pixels_per_call(&self, samples_per_pixel: usize) -> usize {
        super::packet_pixels(self.bvh, samples_per_pixel)
    }

    /// Each ray's stream split off its pixel's in order (as [`Integrator::radiance`] does),
    /// then [`LANES`] paths side by side ([`PathTracer::radiance_lanes`]) when the BVH
    /// traces packets, else one at a time.
    fn radiance_all(&self, rays: &[Ray], rngs: &mut [SplitMix64], out: &mut Vec<PathResult>) {
        out.clear();
        let per_pixel = super::rays_per_pixel(rays, rngs);
        // Buffers kept per thread from call to call (a call is a few pixels).
        thread_local! {
            static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::default();
        }
        SCRATCH.with_borrow_mut(
            |Scratch {
                 streams,
                 asked,
                 unblocked,
             }| {
                streams.clear();
                for rng in rngs.iter_mut() {
                    streams.extend((0..per_pixel).map(|_| rng.split()));
                }
                if self.bvh.packets() {
                    self.radiance_lanes(rays, streams, asked, out);
                } else {
                    out.extend(
                        rays.iter()
                            .zip(streams.iter_mut())
                            .map(|(&ray, rng)| self.radiance_one(ray, rng, unblocked)),
                    );
                }
            },
        );
    }
}

/// [`PathTracer`]'s buffers for one [`Integrator::radiance_all`] call: each sample's stream,
/// the shadow rays a round asks for, a vertex's unblocked contributions.
#[derive(Default)]
struct Scratch {
    streams: Vec<SplitMix64>,
    asked: Vec<Asked>,
    unblocked: Vec<Vec3>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_scene::load::parse_scene;
    use std::path::Path;

    /// A path that meets the floor leaves its flat surface, not only the triangle it met: its
    /// next ray and its shadow ray skip the floor's plane (both of its triangles), and a path
    /// that meets a mirror leaves that mirror. (With two mirrors the floor's flat surface, 2,
    /// is neither floor triangle's index, so skipping the triangle fails this.)
    #[test]
    fn a_vertex_leaves_the_flat_surface_it_meets() {
        let scene = parse_scene(
            r#"{
              "camera": { "position": [0, 1, 3], "look_at": [0, 0, 0], "fov_y_deg": 60,
                          "width": 8, "height": 8 },
              "mirrors": [ { "center": [0, 1, -2], "normal": [0, 0, 1], "up": [0, 1, 0],
                             "width": 2, "height": 2 },
                           { "center": [0, 1, 2], "normal": [0, 0, -1], "up": [0, 1, 0],
                             "width": 2, "height": 2 } ],
              "objects": [ { "type": "quad", "size": [4, 4],
                             "transform": { "rotate_deg": [-90, 0, 0] } } ],
              "lights": [ { "position": [0, 2, 0], "intensity": [5, 5, 5] } ]
            }"#,
            Path::new("vertex.json"),
        )
        .unwrap();
        let g = &scene.geometry;
        let bvh = SceneBvh::build(g);
        let tracer = PathTracer::new(&scene, &bvh, PathSettings::default());
        let floor: Vec<usize> = (0..g.triangles.len())
            .filter(|&i| matches!(g.surface(i), Surface::Diffuse { .. }))
            .collect();
        assert_eq!(floor.len(), 2);
        let flat = bvh.flat_surface(floor[0]);
        assert_eq!(flat, bvh.flat_surface(floor[1]));
        assert!(floor.iter().all(|&t| t != flat), "{floor:?} against {flat}");
        let mut rng = SplitMix64::for_pixel(3, 0);
        for (x, z) in [(0.5, 0.5), (-0.5, -0.5), (1.5, -1.0), (-1.0, 1.5)] {
            let ray = Ray {
                origin: Vec3::new(x, 1.0, z),
                dir: Vec3::NEG_Y,
            };
            let hit = bvh.closest_hit(&ray, 0.0, f32::INFINITY, None).unwrap();
            assert!(floor.contains(&hit.triangle));
            let mut w = Walk::start(ray);
            let mut shadows = Vec::new();
            let step =
                tracer.vertex::<false>(&mut w, Some(hit), &mut rng, |_, s| shadows.push(s.leaving));
            assert!(matches!(step, Vertex::Next));
            assert_eq!(w.leaving, Some(flat), "from ({x}, {z})");
            assert_eq!(shadows, vec![flat], "from ({x}, {z})");
        }
        let ray = Ray {
            origin: Vec3::new(0.0, 1.0, 0.0),
            dir: Vec3::NEG_Z,
        };
        let hit = bvh.closest_hit(&ray, 0.0, f32::INFINITY, None).unwrap();
        let Surface::Mirror { mirror, .. } = *g.surface(hit.triangle) else {
            panic!("the ray meets the mirror")
        };
        let mut w = Walk::start(ray);
        tracer.vertex::<false>(&mut w, Some(hit), &mut rng, |_, _| {});
        assert_eq!(w.leaving, Some(mirror));
    }
}
