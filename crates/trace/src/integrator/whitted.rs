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

use super::{Integrator, PathResult, Termination, camera_rays, face_normals};
use crate::bvh::packet::{LANES, LaneHits, LaneMask, NO_TRIANGLE, RayPacket, first_lanes, lanes};
use crate::bvh::{Hit, NO_QUERY, Query, SceneBvh};
use crate::cpu_features::{Vectorised, lane_bits, widest};
use crate::hit_point::{on_triangle_plane, on_triangle_plane_lanes};
use crate::mirror_bounce::{MirrorPlanes, bounce_flat_lanes};
use crate::sampler::SplitMix64;
use glam::{DVec3, Vec2, Vec3};
use mirrorbox_scene::camera::RayGenerator;
use mirrorbox_scene::lanes::{set_lanes, store_unmasked};
use mirrorbox_scene::shading::{Interaction, Leg, LegsClear, interaction_with_point};
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
        bvh.prepare_packets();
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
        let Some((ray, t_max, skip_triangle)) = leg_query(a, a_mirror, from, b) else {
            return true;
        };
        !self.bvh.occluded(&ray, 0.0, t_max, a_mirror, skip_triangle)
    }

    /// [`Whitted::leg_unoccluded`] for a batch of legs at most one per lane (the round's
    /// diffuse lanes', [`mirrorbox_scene::Lighting::diffuse_radiance_lanes_with`]): traced
    /// as one any-hit packet, the same answers. `from` is each lane's shaded triangle.
    #[inline(always)]
    fn legs_clear_inline(&self, legs: &[Leg], clear: &mut [bool], from: &[usize; LANES]) {
        let queries = legs.iter().map(|leg| {
            let query = leg_query(leg.a, leg.a_mirror, from[leg.lane], leg.b);
            (leg, query)
        });
        // The queries are made twice, to count them and to use them: keeping them in an array
        // instead measured ×1.10 slower on the lit scenes (the array's writes cost more than
        // the arithmetic).
        let traced = queries.clone().filter(|(_, query)| query.is_some()).count();
        // A packet costs about as much for a few lanes as for all: few legs go one at a time.
        if traced < MIN_PACKET_LEGS {
            // Two at a time through the 8-wide hierarchy (`SceneBvh::queries`, a call out of
            // the walk: inlined, the lit walk measured ×1.04 slower with the any-hit leaf's
            // early answer, out of line ×0.99 / ×0.96 on `mirror_box_lit` / `mirror_room_lit`).
            let mut asked = [NO_QUERY; MIN_PACKET_LEGS];
            let mut of = [0; MIN_PACKET_LEGS];
            let mut n = 0;
            for (j, (leg, query)) in queries.enumerate() {
                clear[j] = true;
                if let Some((ray, t_max, skip_triangle)) = query {
                    asked[n] = Query {
                        ray,
                        t_min: 0.0,
                        t_max,
                        skip_flat: leg.a_mirror,
                        skip_triangle,
                    };
                    of[n] = j;
                    n += 1;
                }
            }
            let mut blocked = [None; MIN_PACKET_LEGS];
            self.bvh.queries::<true>(&asked[..n], &mut blocked[..n]);
            for (&j, blocked) in of[..n].iter().zip(&blocked[..n]) {
                clear[j] = blocked.is_none();
            }
            return;
        }
        let mut packet = RayPacket::default();
        let mut t_max = [0.0f32; LANES];
        let mut skip = [NO_TRIANGLE; LANES];
        let mut mask: LaneMask = 0;
        for (leg, query) in queries {
            if let Some((ray, t, skip_triangle)) = query {
                packet.set(leg.lane, &ray, leg.a_mirror);
                t_max[leg.lane] = t;
                skip[leg.lane] = skip_triangle.map_or(NO_TRIANGLE, |t| t as u32);
                mask |= 1 << leg.lane;
            }
        }
        // (Compiled inside the lighting's lane loops, which do not know their vector build:
        // the kernel's triangle chunks of the AVX2 build, whatever the build.)
        let blocked = self
            .bvh
            .occluded_lanes_inline::<8>(&packet, mask, &t_max, &skip);
        for (leg, clear) in legs.iter().zip(clear.iter_mut()) {
            *clear = blocked >> leg.lane & 1 == 0;
        }
    }

    /// Radiance along `ray` (what [`Integrator::radiance`] returns; no random numbers).
    pub fn radiance(&self, ray: Ray) -> PathResult {
        self.trace(ray, |_, _, _| {})
    }

    /// Radiance along `ray`, calling `on_mirror(k, point, mirror)` at the k-th reflection
    /// (k from 1) with the exact hit point (tests and diagnostics; the closure inlines away).
    pub fn trace(&self, ray: Ray, mut on_mirror: impl FnMut(u32, DVec3, usize)) -> PathResult {
        let (mut origin, mut dir) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
        let mut leaving = None;
        let mut carried = Carried::START;
        loop {
            let query = Ray {
                origin: origin.as_vec3(),
                dir: dir.as_vec3(),
            };
            let hit = self.bvh.closest_hit(&query, 0.0, f32::INFINITY, leaving);
            let mirror = match self.step(&mut carried, &query, (origin, dir), hit) {
                Next::End(end) => return carried.result(end),
                Next::Diffuse(d) => {
                    let end = self.shade(&mut carried, &d);
                    return carried.result(end);
                }
                Next::Reflect(mirror) => mirror,
            };
            let Some(next) = self.mirror_planes.reflect(mirror, origin, dir) else {
                return carried.result(Termination::Absorbed);
            };
            (origin, dir) = next;
            leaving = Some(mirror);
            on_mirror(carried.bounces, origin, mirror);
        }
    }

    /// [`Whitted::radiance`] of each of the rays `starts` gives, in order, into `out`: the
    /// rays walk their paths side by side, and each round's closest-hit queries go to the BVH
    /// together as one packet ([`SceneBvh::closest_hits`]). Every path takes the same steps as
    /// alone, so the results are the same. Compiled for the CPU's widest vectors
    /// ([`crate::cpu_features`]), kernel included.
    pub fn radiance_packet(&self, starts: Starts<'_>, out: &mut Vec<PathResult>) {
        struct Work<'w, 'a, const SHADED_IN_LANES: bool> {
            whitted: &'w Whitted<'a>,
            starts: Starts<'w>,
            out: &'w mut Vec<PathResult>,
        }
        impl<const SHADED_IN_LANES: bool> Vectorised for Work<'_, '_, SHADED_IN_LANES> {
            type Output = ();
            #[inline(always)]
            fn run(self) {
                self.run_wide::<8>()
            }
            #[inline(always)]
            fn run_wide<const F32_LANES: usize>(self) {
                self.whitted
                    .radiance_packet_inline::<SHADED_IN_LANES, F32_LANES>(self.starts, self.out)
            }
        }
        // Compiled apart for lighting shaded in lane loops and for lighting with shadow legs
        // or light images: the first walk holds no shadow-leg traversal, so changes to the
        // any-hit code do not move it (they moved it by 3 %, the compiler's layout).
        if self.scene.lighting.lanes_apply() {
            widest(Work::<true> {
                whitted: self,
                starts,
                out,
            })
        } else {
            widest(Work::<false> {
                whitted: self,
                starts,
                out,
            })
        }
    }

    /// [`Whitted::radiance_packet`]'s work. The walks are kept as structure of arrays
    /// ([`Walks`]): the packet's rays are rounded to f32 in one lane loop, the round's
    /// bounces off flat mirrors are computed in another ([`bounce_flat_lanes`], f64), and
    /// its diffuse hits are shaded in a third where there are no shadow legs or light images
    /// ([`mirrorbox_scene::Lighting::direct_radiance_lanes`]). The step's decisions are
    /// taken once for the lanes that met one triangle ([`Whitted::step_on_first_triangle`]),
    /// the rest lane by lane ([`Whitted::step_lane`]).
    #[inline(always)]
    fn radiance_packet_inline<const SHADED_IN_LANES: bool, const F32_LANES: usize>(
        &self,
        starts: Starts<'_>,
        out: &mut Vec<PathResult>,
    ) {
        let lighting = &self.scene.lighting;
        // A round's diffuse hits are shaded side by side: without shadow legs or light
        // images in lane loops (`SHADED_IN_LANES`, the lighting's `lanes_apply`), else with each
        // light's legs traced as one packet.
        debug_assert_eq!(SHADED_IN_LANES, lighting.lanes_apply());
        let mut round = Round::default();
        let mut walks = Walks::default();
        for first in (0..starts.count()).step_by(LANES) {
            let n = (starts.count() - first).min(LANES);
            walks.start(&starts, first, n);
            let mut packet = RayPacket::default();
            let mut hits = LaneHits::default();
            while walks.active != 0 {
                packet.set_rays_f64(&walks.origin, &walks.dir);
                self.bvh
                    .closest_hit_lanes_inline::<F32_LANES>(&packet, walks.active, &mut hits);
                round.flat = [false; LANES];
                round.diffuse = [false; LANES];
                // The lanes on one triangle together where the shading is in lane loops too
                // (with shadow legs or light images, at one sample per pixel, that measured
                // ×1.02–1.04 slower).
                let one_by_one = if SHADED_IN_LANES {
                    self.step_on_first_triangle(&mut walks, &mut packet, &hits, &mut round)
                } else {
                    walks.active
                };
                for lane in lanes(one_by_one) {
                    self.step_lane(lane, &mut walks, &mut packet, &hits, &mut round);
                }
                let Round {
                    flat,
                    plane_normal,
                    plane_offset,
                    diffuse,
                    shading,
                    shaded_triangle,
                } = &round;
                if diffuse.iter().any(|&f| f) {
                    let [p, n, to_viewer, albedo, emission] = shading;
                    let mut legs = [0u32; LANES];
                    let shaded = if SHADED_IN_LANES {
                        lighting.direct_radiance_lanes(p, n, to_viewer, albedo, emission)
                    } else {
                        // Shadow legs or light images: each light's legs as one packet.
                        lighting.diffuse_radiance_lanes_with(
                            diffuse,
                            p,
                            n,
                            to_viewer,
                            albedo,
                            emission,
                            &mut legs,
                            RoundLegs {
                                whitted: self,
                                from: shaded_triangle,
                            },
                        )
                    };
                    let shaded_lanes = (0..LANES).fold(0, |m: LaneMask, lane| {
                        m | LaneMask::from(diffuse[lane]) << lane
                    });
                    let carried = &mut walks.carried;
                    for (rays, legs) in carried.rays.iter_mut().zip(legs) {
                        *rays += legs;
                    }
                    carried.add(shaded_lanes, &shaded);
                }
                if flat.iter().any(|&f| f) {
                    bounce_flat_lanes::<f64, LANES>(
                        flat,
                        plane_normal,
                        plane_offset,
                        &mut walks.origin,
                        &mut walks.dir,
                    );
                }
            }
            out.extend((0..n).map(|lane| walks.carried.get(lane).result(walks.ends[lane])));
        }
    }

    /// A round's step for lane `lane` of `walks`, whose closest hit is in `hits`: ends it,
    /// or leaves its diffuse hit or flat-mirror bounce to the round's lane loops (`round`),
    /// or bounces it off an uneven mirror.
    #[inline(always)]
    fn step_lane(
        &self,
        lane: usize,
        walks: &mut Walks,
        packet: &mut RayPacket,
        hits: &LaneHits,
        round: &mut Round,
    ) {
        let Walks {
            origin,
            dir,
            carried,
            ends,
            active,
        } = walks;
        let (query, _) = packet.lane(lane);
        let exact = (
            DVec3::new(origin[0][lane], origin[1][lane], origin[2][lane]),
            DVec3::new(dir[0][lane], dir[1][lane], dir[2][lane]),
        );
        let mut c = carried.get(lane);
        let next = self.step(&mut c, &query, exact, hits.get(lane));
        carried.set(lane, c);
        let mirror = match next {
            Next::End(end) => {
                ends[lane] = end;
                *active &= !(1 << lane);
                return;
            }
            Next::Diffuse(d) => {
                ends[lane] = Termination::Diffuse;
                *active &= !(1 << lane);
                round.diffuse[lane] = true;
                round.shaded_triangle[lane] = d.triangle;
                let values = [d.p, d.normal, d.to_viewer, d.albedo, d.emission];
                for (a, value) in round.shading.iter_mut().zip(values) {
                    for k in 0..3 {
                        a[k][lane] = value[k];
                    }
                }
                return;
            }
            Next::Reflect(mirror) => mirror,
        };
        packet.set_skip(lane, Some(mirror));
        if let Some((n, off)) = self.mirror_planes.flat_plane(mirror) {
            round.flat[lane] = true;
            for k in 0..3 {
                round.plane_normal[k][lane] = n[k];
            }
            round.plane_offset[lane] = off;
            return;
        }
        let o = DVec3::new(origin[0][lane], origin[1][lane], origin[2][lane]);
        let d = DVec3::new(dir[0][lane], dir[1][lane], dir[2][lane]);
        let Some((o, d)) = self.mirror_planes.reflect(mirror, o, d) else {
            ends[lane] = Termination::Absorbed;
            *active &= !(1 << lane);
            return;
        };
        for k in 0..3 {
            origin[k][lane] = o[k];
            dir[k][lane] = d[k];
        }
    }

    /// A round's step for the active lanes of `walks` that met what the first of them met
    /// (one triangle, or nothing: all of them in most rounds, 95 % on `mirror_box` and 78 % on
    /// `mirror_room` at 16 spp): the decisions [`Whitted::step`] takes per lane (which
    /// surface, which side, escaped, reflected or shaded) taken once for them, the arithmetic
    /// in lane loops, the same bits. Returns the active lanes it left to be stepped one by one
    /// ([`Whitted::step_lane`]): the others, or all of them, unchanged, where that surface is
    /// textured or an uneven mirror or the lanes met a mirror from both sides. Lane loops
    /// write their values in every lane, so the lanes it leaves are stepped after it.
    #[inline(always)]
    fn step_on_first_triangle(
        &self,
        walks: &mut Walks,
        packet: &mut RayPacket,
        hits: &LaneHits,
        round: &mut Round,
    ) -> LaneMask {
        let Walks {
            origin,
            dir,
            carried,
            ends,
            active,
        } = walks;
        let first = hits.triangle[active.trailing_zeros() as usize];
        let group = lane_bits::<LANES>(|lane| hits.triangle[lane] == first) & *active;
        let others = *active & !group;
        if first == NO_TRIANGLE {
            carried.count_ray(group);
            let background = self.scene.background.to_array().map(|b| [b; LANES]);
            carried.add(group, &background);
            for lane in lanes(group) {
                ends[lane] = Termination::Escaped;
            }
            *active &= !group;
            return others;
        }
        let triangle = first as usize;
        let geometry = &self.scene.geometry;
        let surface = geometry.surface(triangle);
        let face = self.face_normals[triangle];
        let front = match surface {
            // Two-sided: the side does not matter.
            mirrorbox_scene::Surface::Diffuse { maps, .. } => {
                if !maps.is_empty() {
                    return *active;
                }
                true
            }
            mirrorbox_scene::Surface::Mirror { .. } => {
                let [x, y, z] = packet.dirs();
                let (mut all_front, mut all_back) = (true, true);
                for (lane, ((&x, &y), &z)) in x.iter().zip(y).zip(z).enumerate() {
                    let inactive = group >> lane & 1 == 0;
                    let front = face.dot(Vec3::new(x, y, z)) < 0.0;
                    all_front &= inactive | front;
                    all_back &= inactive | !front;
                }
                if !(all_front || all_back) {
                    return *active;
                }
                all_front
            }
        };
        match mirrorbox_scene::shading::interaction(surface, front) {
            Interaction::Reflect { reflectance } => {
                let mirrorbox_scene::Surface::Mirror { mirror, .. } = *surface else {
                    unreachable!("only mirrors reflect")
                };
                let Some((n, off)) = self.mirror_planes.flat_plane(mirror) else {
                    return *active;
                };
                carried.count_ray(group);
                let cut = carried.reflect(group, reflectance, &self.settings, self.scene.terminal);
                for lane in lanes(cut) {
                    ends[lane] = if carried.bounces[lane] >= self.settings.max_depth {
                        Termination::Depth
                    } else {
                        Termination::Throughput
                    };
                }
                *active &= !cut;
                let go_on = group & !cut;
                // Lane loops: the round's lane loops and the next traversal read these
                // arrays whole, and a vector load of lanes just written one at a time waits
                // for those stores (store-to-load forwarding fails).
                packet.set_skip_lanes(go_on, mirror);
                // The round's first writer of its flags (cleared before, stepped lanes after).
                debug_assert!(!round.flat.iter().any(|&f| f));
                round.flat = lane_flags(go_on);
                for lane in 0..LANES {
                    for k in 0..3 {
                        round.plane_normal[k][lane] = n[k];
                    }
                    round.plane_offset[lane] = off;
                }
            }
            Interaction::Diffuse { albedo, emission } => {
                let [p, normal, to_viewer, albedos, emissions] = &mut round.shading;
                on_triangle_plane_lanes(geometry, triangle, origin, dir, &hits.t, p);
                let dirs = packet.dirs();
                for lane in 0..LANES {
                    for k in 0..3 {
                        normal[k][lane] = face[k];
                        to_viewer[k][lane] = -dirs[k][lane];
                        albedos[k][lane] = albedo[k];
                        emissions[k][lane] = emission[k];
                    }
                }
                carried.count_ray(group);
                for lane in lanes(group) {
                    ends[lane] = Termination::Diffuse;
                }
                // Lane loops, as the flat lanes above.
                debug_assert!(!round.diffuse.iter().any(|&f| f));
                round.diffuse = lane_flags(group);
                set_lanes(&mut round.shaded_triangle, group, triangle);
                *active &= !group;
            }
        }
        others
    }

    /// The radiance a diffuse hit sends back along the path, shadow legs traced (the
    /// contract's [`mirrorbox_scene::Lighting::diffuse_radiance_with`]); ends the path.
    #[inline(always)]
    fn shade(&self, carried: &mut Carried, d: &DiffuseHit) -> Termination {
        let mut legs = 0;
        let shaded = self.scene.lighting.diffuse_radiance_with(
            d.p,
            d.normal,
            d.to_viewer,
            d.albedo,
            d.emission,
            |a, a_mirror, b, _| {
                legs += 1;
                self.leg_unoccluded(a, a_mirror, d.triangle, b)
            },
        );
        carried.rays += legs;
        carried.radiance += carried.throughput * shaded;
        Termination::Diffuse
    }

    /// One step of a path: `hit` is the closest hit of `query` (the path's current ray,
    /// rounded to f32 from `exact`, its origin and direction in f64). Ends it (escaped, or
    /// cut at a mirror), asks for the shading of a diffuse hit (at the point re-solved on
    /// the triangle's plane from `exact`, [`on_triangle_plane`]), or, at a mirror, takes its
    /// reflectance and asks for the bounce; the caller computes those two.
    #[inline(always)]
    fn step(
        &self,
        carried: &mut Carried,
        query: &Ray,
        exact: (DVec3, DVec3),
        hit: Option<Hit>,
    ) -> Next {
        let scene = self.scene;
        carried.rays += 1;
        let Some(hit) = hit else {
            return Next::End(self.escape(carried));
        };
        let normal = self.face_normals[hit.triangle];
        let front = normal.dot(query.dir) < 0.0;
        let surface = scene.geometry.surface(hit.triangle);
        let (interaction, p) = interaction_with_point(&scene.geometry, hit.triangle, front, || {
            on_triangle_plane(&scene.geometry, hit.triangle, exact.0, exact.1, hit.t)
        });
        match interaction {
            Interaction::Diffuse { albedo, emission } => Next::Diffuse(DiffuseHit {
                p: p.expect("a diffuse interaction comes with its point"),
                normal,
                to_viewer: -query.dir,
                albedo,
                emission,
                triangle: hit.triangle,
            }),
            Interaction::Reflect { reflectance } => {
                let mirrorbox_scene::Surface::Mirror { mirror, .. } = *surface else {
                    unreachable!("only mirrors reflect")
                };
                match self.reflect(carried, reflectance) {
                    Some(cut) => Next::End(cut),
                    None => Next::Reflect(mirror),
                }
            }
        }
    }

    /// The step's end of a path whose ray meets nothing: the background, times the
    /// throughput.
    #[inline(always)]
    fn escape(&self, carried: &mut Carried) -> Termination {
        carried.radiance += carried.throughput * self.scene.background;
        Termination::Escaped
    }

    /// The step at a mirror's front of `reflectance`: the path is cut (`max_depth` reflections
    /// followed, or a throughput that would fall below `min_throughput`; the scene's
    /// `terminal` radiance, times the throughput so far), or it takes the reflectance into its
    /// throughput and counts the bounce (`None`).
    #[inline(always)]
    fn reflect(&self, carried: &mut Carried, reflectance: Vec3) -> Option<Termination> {
        let next = carried.throughput * reflectance;
        let cut = if carried.bounces >= self.settings.max_depth {
            Some(Termination::Depth)
        } else if next.max_element() < self.settings.min_throughput {
            Some(Termination::Throughput)
        } else {
            None
        };
        if let Some(reason) = cut {
            carried.radiance += carried.throughput * self.scene.terminal;
            return Some(reason);
        }
        carried.throughput = next;
        carried.bounces += 1;
        None
    }
}

/// A packet's paths walked side by side: their rays in f64 lanes (for plane-exact
/// bounces), what each carries, how each ended, and which still walk.
struct Walks {
    origin: [[f64; LANES]; 3],
    dir: [[f64; LANES]; 3],
    carried: CarriedLanes,
    ends: [Termination; LANES],
    active: LaneMask,
}

impl Default for Walks {
    fn default() -> Self {
        Walks {
            origin: [[0.0; LANES]; 3],
            dir: [[0.0; LANES]; 3],
            carried: CarriedLanes::START,
            ends: [Termination::Escaped; LANES],
            active: 0,
        }
    }
}

impl Walks {
    /// The walks of `starts`' rays `first..first + n` (`n` at most [`LANES`]) from their
    /// start, in place (kept across packets: no copies of the lanes).
    #[inline(always)]
    fn start(&mut self, starts: &Starts<'_>, first: usize, n: usize) {
        starts.write(first, n, &mut self.origin, &mut self.dir);
        self.carried = CarriedLanes::START;
        self.ends = [Termination::Escaped; LANES];
        self.active = first_lanes(n);
    }
}

/// Where a packet walk's rays come from: given ([`Integrator::radiance_all`]), or made from
/// the camera in the walks' lanes ([`CameraStarts`]). One type for both, so that each walk is
/// compiled once per vector build (a type each doubled the walks: the trace crate's build
/// took 55 s instead of 43), at no measured cost.
#[derive(Clone, Copy)]
pub enum Starts<'s> {
    Rays(&'s [Ray]),
    Camera(CameraStarts<'s>),
}

impl Starts<'_> {
    /// How many rays.
    fn count(&self) -> usize {
        match self {
            Starts::Rays(rays) => rays.len(),
            Starts::Camera(camera) => camera.positions.len(),
        }
    }

    /// Rays `first..first + n` (`n` at most [`LANES`]) written as f64 lanes into `origin`
    /// and `dir`; lanes past `n` repeat ray `first + n − 1` (they are never active).
    #[inline(always)]
    fn write(
        &self,
        first: usize,
        n: usize,
        origin: &mut [[f64; LANES]; 3],
        dir: &mut [[f64; LANES]; 3],
    ) {
        match self {
            Starts::Rays(rays) => RayPacket::write_f64_lanes(&rays[first..first + n], origin, dir),
            Starts::Camera(camera) => camera.write(first, n, origin, dir),
        }
    }
}

/// The camera rays through image positions ([`Integrator::radiance_at`]), made in lane loops
/// straight into the walks' f64 lanes: no buffer of rays to fill and read back.
#[derive(Clone, Copy)]
pub struct CameraStarts<'s> {
    pub camera: &'s RayGenerator,
    pub positions: &'s [Vec2],
}

impl CameraStarts<'_> {
    #[inline(always)]
    fn write(
        &self,
        first: usize,
        n: usize,
        origin: &mut [[f64; LANES]; 3],
        dir: &mut [[f64; LANES]; 3],
    ) {
        let made = self
            .camera
            .dirs_through::<LANES>(&self.positions[first..first + n]);
        for (lanes, o) in origin.iter_mut().zip(self.camera.origin().to_array()) {
            *lanes = [f64::from(o); LANES];
        }
        for (lanes, made) in dir.iter_mut().zip(&made) {
            for (d, &m) in lanes.iter_mut().zip(made) {
                *d = f64::from(m);
            }
        }
    }
}

/// The lanes of `mask` as flags, in a lane loop.
#[inline(always)]
fn lane_flags(mask: LaneMask) -> [bool; LANES] {
    let mut flags = [false; LANES];
    for (lane, f) in flags.iter_mut().enumerate() {
        *f = mask >> lane & 1 == 1;
    }
    flags
}

/// What a round's steps leave to its lane loops: the lanes bouncing off a flat mirror, with
/// its plane, and the diffuse hits to shade, with what the shading needs (`shading`: point,
/// normal, direction to the viewer, albedo, emission). The flags are the round's; the values
/// are set for the lanes that have one and read (past values in the others, never used) by
/// whole-packet loops, kept across rounds and packets: zeroing them every round cost 2 %
/// (memset).
struct Round {
    flat: [bool; LANES],
    plane_normal: [[f64; LANES]; 3],
    plane_offset: [f64; LANES],
    diffuse: [bool; LANES],
    shading: [[[f32; LANES]; 3]; 5],
    shaded_triangle: [usize; LANES],
}

impl Default for Round {
    fn default() -> Self {
        Round {
            flat: [false; LANES],
            plane_normal: [[0.0; LANES]; 3],
            plane_offset: [0.0; LANES],
            diffuse: [false; LANES],
            shading: [[[0.0; LANES]; 3]; 5],
            shaded_triangle: [0; LANES],
        }
    }
}

/// A round's legs traced by [`Whitted::legs_clear_inline`] (`from`: each lane's shaded
/// triangle), inline in the walk compiled for the CPU's features.
struct RoundLegs<'w, 'a> {
    whitted: &'w Whitted<'a>,
    from: &'w [usize; LANES],
}

impl LegsClear for RoundLegs<'_, '_> {
    #[inline(always)]
    fn clear(&mut self, legs: &[Leg], clear: &mut [bool]) {
        self.whitted.legs_clear_inline(legs, clear, self.from)
    }
}

/// Fewest legs traced as a packet ([`Whitted::legs_clear_inline`]); fewer go one at a time.
/// Measured on `mirror_room_lit` / `mirror_box_lit` at k = 8, 1 spp, one thread: against
/// the legs one at a time, every batch a packet ×1.10 / ×0.72, batches of 8 and more ×0.87 /
/// ×0.68; against 8, 4 ×1.07 / ×1.03 and 16 ×0.98 / ×1.01. Again with the packets and the
/// singles compiled into the walk: 4 ×1.12 / ×1.06, 16 ×1.03 / ×1.04 against 8.
const MIN_PACKET_LEGS: usize = 8;

/// The shadow query of the leg from `a` (on mirror `a_mirror`, or else on triangle `from`,
/// either skipped) to `b`: its ray, far limit (hits within 10⁻⁴ of its length from `b` not
/// counted) and skipped triangle; `None` for a leg of length zero, which nothing blocks.
#[inline(always)]
fn leg_query(
    a: Vec3,
    a_mirror: Option<usize>,
    from: usize,
    b: Vec3,
) -> Option<(Ray, f32, Option<usize>)> {
    let d = b - a;
    let length = d.length();
    if length == 0.0 {
        return None;
    }
    let ray = Ray {
        origin: a,
        dir: d / length,
    };
    let skip_triangle = if a_mirror.is_none() { Some(from) } else { None };
    Some((ray, length * (1.0 - 1e-4), skip_triangle))
}

/// What a path carries from step to step (its ray is kept by the caller: in f64, for
/// plane-exact bounces).
#[derive(Clone, Copy)]
struct Carried {
    throughput: Vec3,
    radiance: Vec3,
    bounces: u32,
    rays: u32,
}

impl Carried {
    const START: Carried = Carried {
        throughput: Vec3::ONE,
        radiance: Vec3::ZERO,
        bounces: 0,
        rays: 0,
    };

    fn result(&self, termination: Termination) -> PathResult {
        PathResult {
            radiance: self.radiance,
            bounces: self.bounces,
            termination,
            rays: self.rays,
        }
    }
}

/// [`Carried`] for a packet's lanes, as structure of arrays: the steps taken for a group of
/// lanes at once ([`Whitted::step_on_first_triangle`]) and the shading's sums are lane loops
/// over it, with [`Carried`]'s arithmetic per lane (the same bits).
struct CarriedLanes {
    throughput: [[f32; LANES]; 3],
    radiance: [[f32; LANES]; 3],
    bounces: [u32; LANES],
    rays: [u32; LANES],
}

impl CarriedLanes {
    const START: CarriedLanes = CarriedLanes {
        throughput: [[1.0; LANES]; 3],
        radiance: [[0.0; LANES]; 3],
        bounces: [0; LANES],
        rays: [0; LANES],
    };

    #[inline(always)]
    fn get(&self, lane: usize) -> Carried {
        Carried {
            throughput: Vec3::new(
                self.throughput[0][lane],
                self.throughput[1][lane],
                self.throughput[2][lane],
            ),
            radiance: Vec3::new(
                self.radiance[0][lane],
                self.radiance[1][lane],
                self.radiance[2][lane],
            ),
            bounces: self.bounces[lane],
            rays: self.rays[lane],
        }
    }

    #[inline(always)]
    fn set(&mut self, lane: usize, c: Carried) {
        for k in 0..3 {
            self.throughput[k][lane] = c.throughput[k];
            self.radiance[k][lane] = c.radiance[k];
        }
        self.bounces[lane] = c.bounces;
        self.rays[lane] = c.rays;
    }

    /// Each lane of `group` casts one more ray.
    #[inline(always)]
    fn count_ray(&mut self, group: LaneMask) {
        for (lane, rays) in self.rays.iter_mut().enumerate() {
            *rays += group >> lane & 1;
        }
    }

    /// Each lane of `group` gains `radiance` times its throughput ([`Whitted::escape`]'s and
    /// the shading's sum).
    #[inline(always)]
    fn add(&mut self, group: LaneMask, radiance: &[[f32; LANES]; 3]) {
        let sums = self.radiance.iter_mut().zip(&self.throughput).zip(radiance);
        for ((sum, throughput), radiance) in sums {
            let mut new = [0.0; LANES];
            for (lane, ((n, &t), &r)) in new.iter_mut().zip(throughput).zip(radiance).enumerate() {
                let s = sum[lane];
                *n = if group >> lane & 1 == 1 { s + t * r } else { s };
            }
            store_unmasked(sum, new);
        }
    }

    /// [`Whitted::reflect`] for every lane of `group` at a mirror of `reflectance`: returns
    /// the lanes cut (the scene's `terminal` radiance added); the others took the reflectance
    /// and counted the bounce.
    #[inline(always)]
    fn reflect(
        &mut self,
        group: LaneMask,
        reflectance: Vec3,
        settings: &WhittedSettings,
        terminal: Vec3,
    ) -> LaneMask {
        let mut cut: LaneMask = 0;
        for lane in 0..LANES {
            let next = [0, 1, 2].map(|k| self.throughput[k][lane] * reflectance[k]);
            let dim = next[0].max(next[1].max(next[2])) < settings.min_throughput;
            let deep = self.bounces[lane] >= settings.max_depth;
            cut |= LaneMask::from(deep | dim) << lane;
        }
        cut &= group;
        let go_on = group & !cut;
        for k in 0..3 {
            let (mut radiance, mut throughput) = ([0.0; LANES], [0.0; LANES]);
            let (old_r, old_t) = (&self.radiance[k], &self.throughput[k]);
            for (lane, (new, (&r, &t))) in
                radiance.iter_mut().zip(old_r.iter().zip(old_t)).enumerate()
            {
                *new = if cut >> lane & 1 == 1 {
                    r + t * terminal[k]
                } else {
                    r
                };
            }
            for (lane, (new, &t)) in throughput.iter_mut().zip(old_t).enumerate() {
                *new = if go_on >> lane & 1 == 1 {
                    t * reflectance[k]
                } else {
                    t
                };
            }
            store_unmasked(&mut self.radiance[k], radiance);
            store_unmasked(&mut self.throughput[k], throughput);
        }
        for (lane, bounces) in self.bounces.iter_mut().enumerate() {
            *bounces += go_on >> lane & 1;
        }
        cut
    }
}

/// A diffuse hit to shade: what the contract's shading needs.
struct DiffuseHit {
    p: Vec3,
    normal: Vec3,
    to_viewer: Vec3,
    albedo: Vec3,
    emission: Vec3,
    triangle: usize,
}

/// What [`Whitted::step`] decided.
enum Next {
    End(Termination),
    /// Shade this diffuse hit ([`Whitted::shade`]); the path ends there.
    Diffuse(DiffuseHit),
    /// Reflect off this mirror (the throughput already includes its reflectance).
    Reflect(usize),
}

impl Integrator for Whitted<'_> {
    fn radiance(&self, ray: Ray, _rng: &mut SplitMix64) -> PathResult {
        Whitted::radiance(self, ray)
    }

    /// Enough pixels to fill a call's packets when packets are traced, at any sample count
    /// (`packet_pixels`): at one sample per pixel (the sweeps' truths) a packet is 32
    /// neighbouring pixels of a row. (Below 4 samples rays went one at a time while the
    /// single-ray default was obvhs's CWBVH, whose answers differ from the packets' at mirror
    /// corners, to keep the 1-spp truths' bits; the 8-wide hierarchy answers as the packets
    /// do: issue 56, `mirror_room` at 1 spp ×0.30.)
    fn pixels_per_call(&self, samples_per_pixel: usize) -> usize {
        super::packet_pixels(self.bvh, samples_per_pixel)
    }

    /// As packets when the BVH traces them.
    fn radiance_all(&self, rays: &[Ray], _rngs: &mut [SplitMix64], out: &mut Vec<PathResult>) {
        out.clear();
        if self.bvh.packets() {
            self.radiance_packet(Starts::Rays(rays), out);
        } else {
            out.extend(rays.iter().map(|&ray| Whitted::radiance(self, ray)));
        }
    }

    /// As packets when the BVH traces them, their camera rays made in the walks' lanes
    /// ([`CameraStarts`]).
    fn radiance_at(
        &self,
        camera: &RayGenerator,
        positions: &[Vec2],
        rays: &mut Vec<Ray>,
        rngs: &mut [SplitMix64],
        out: &mut Vec<PathResult>,
    ) {
        if !self.bvh.packets() {
            rays.clear();
            camera_rays(camera, positions, rays, self.gains_from_512_bits());
            return self.radiance_all(rays, rngs, out);
        }
        out.clear();
        self.radiance_packet(Starts::Camera(CameraStarts { camera, positions }), out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_scene::load::parse_scene;

    /// A round whose lanes all meet one mirror triangle, some at its front and some at its
    /// back, is walked as each ray alone: the front ones reflect, the back ones are shaded
    /// with the mirror's back albedo (a round on one triangle must not take one lane's side
    /// for all). The bundled scenes have no such round.
    #[test]
    fn a_packet_meeting_both_sides_of_one_mirror_is_each_ray_alone() {
        let json = serde_json::json!({
            "camera": { "position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0],
                        "fov_y_deg": 45, "width": 16, "height": 16 },
            "mirrors": [{ "name": "both sides", "center": [0, 0, 0], "normal": [0, 0, 1],
                          "up": [0, 1, 0], "width": 2, "height": 2,
                          "reflectance": [0.9, 0.8, 0.7], "back_albedo": [0.2, 0.4, 0.6] }],
            "objects": [{ "type": "quad", "name": "floor", "size": [10, 10],
                          "transform": { "translate": [0, -2, 0], "rotate_deg": [-90, 0, 0] },
                          "albedo": [0.5, 0.5, 0.5] }],
            "lights": [{ "position": [0, 3, 3], "intensity": [10, 10, 10] }],
            "background": [0.1, 0.2, 0.3]
        });
        let scene = parse_scene(&json.to_string(), std::path::Path::new("both.json")).unwrap();
        assert!(scene.lighting.lanes_apply());
        let bvh = SceneBvh::build(&scene.geometry);
        let whitted = Whitted::new(&scene, &bvh, WhittedSettings::default());
        // Even lanes from the front (z > 0), odd ones from the back, all aimed near (−0.8, 0):
        // inside one of the quad's two triangles whichever diagonal splits it.
        let rays: Vec<Ray> = (0..LANES)
            .map(|lane| {
                let side = if lane % 2 == 0 { 2.0 } else { -2.0 };
                let origin = Vec3::new(0.3, 0.5, side);
                let jitter = lane as f32 / LANES as f32 * 0.05;
                let target = Vec3::new(-0.8 + jitter, jitter, 0.0);
                Ray {
                    origin,
                    dir: (target - origin).normalize(),
                }
            })
            .collect();
        let first: Vec<_> = rays
            .iter()
            .map(|ray| {
                bvh.closest_hit(ray, 0.0, f32::INFINITY, None)
                    .unwrap()
                    .triangle
            })
            .collect();
        assert!(first.iter().all(|&t| t == first[0]), "{first:?}");
        let mut packet = Vec::new();
        whitted.radiance_packet(Starts::Rays(&rays), &mut packet);
        let mut ends = [0; 2];
        for (lane, (ray, got)) in rays.iter().zip(&packet).enumerate() {
            let alone = whitted.radiance(*ray);
            assert_eq!(
                got.radiance.to_array().map(f32::to_bits),
                alone.radiance.to_array().map(f32::to_bits),
                "lane {lane}"
            );
            assert_eq!(
                (got.bounces, got.termination, got.rays),
                (alone.bounces, alone.termination, alone.rays),
                "lane {lane}"
            );
            ends[usize::from(alone.bounces > 0)] += 1;
        }
        // Half reflected, half shaded at the back.
        assert_eq!(ends, [LANES / 2, LANES / 2]);
    }
}
