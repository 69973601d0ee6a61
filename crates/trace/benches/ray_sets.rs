//! The traversal kernel alone on fixed ray sets (issue 19): closest hits per second for the
//! camera rays of `mirror_box` at 640×360 (one per pixel centre), for the rays leaving the
//! first mirror those hit, and for the rays leaving their tenth mirror — the coherence a
//! packet kernel would exploit falls from set to set (planar mirrors keep neighbours
//! neighbours; edges and the sphere scatter them): the default single-ray hierarchy and
//! the packet kernel (`bvh::packet`) on the same sets. The `single_` groups: camera and
//! scattered rays one query per call, scattered rays in batches as `path` traces them, and
//! rays that miss the scene (a query's fixed cost), per hierarchy (`-- single_` runs only
//! them; `tools/mitsuba/ray_costs.py` times Mitsuba's Embree on the same kinds of rays).
//! Run: `cargo bench -p mirrorbox-trace --bench ray_sets`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use mirrorbox_scene::{Ray, Scene, Surface};
use mirrorbox_trace::SceneBvh;
use mirrorbox_trace::bvh::packet::{LANES, RayPacket, first_lanes};
use mirrorbox_trace::bvh::{BvhKind, Query};
use mirrorbox_trace::mirror_bounce::MirrorPlanes;

/// A ray with the mirror it leaves (skipped by the query, as the integrators do).
type Leaving = (Ray, Option<usize>);

/// The camera rays, then per bounce the rays leaving the mirror the previous set hit.
fn ray_sets(scene: &Scene, bvh: &SceneBvh, bounces: usize) -> Vec<Vec<Leaving>> {
    let cam = &scene.camera;
    let rays = cam.ray_generator();
    let planes = MirrorPlanes::new(scene);
    let mut sets = vec![
        (0..cam.height)
            .flat_map(|y| (0..cam.width).map(move |x| (x, y)))
            .map(|(x, y)| (rays.ray(x as f32 + 0.5, y as f32 + 0.5), None))
            .collect::<Vec<Leaving>>(),
    ];
    for _ in 0..bounces {
        let next = sets
            .last()
            .expect("a set")
            .iter()
            .filter_map(|(ray, leaving)| {
                let hit = bvh.closest_hit(ray, 0.0, f32::INFINITY, *leaving)?;
                let Surface::Mirror { mirror, .. } = *scene.geometry.surface(hit.triangle) else {
                    return None;
                };
                let (o, d) = planes.reflect(mirror, ray.origin.as_dvec3(), ray.dir.as_dvec3())?;
                Some((
                    Ray {
                        origin: o.as_vec3(),
                        dir: d.as_vec3(),
                    },
                    Some(mirror),
                ))
            })
            .collect();
        sets.push(next);
    }
    sets
}

/// A fixed pseudo-random sequence in [0, 1) from `seed` (a 64-bit LCG's top 24 bits).
fn units(seed: u64) -> impl FnMut() -> f32 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Scattered rays, as `path`'s after a diffuse vertex: from the diffuse points the camera
/// rays hit, in directions uniform over the hemisphere about the normal on the camera's side,
/// each with the triangle it leaves (its flat surface skipped, [`queries`]; a fixed
/// pseudo-random sequence).
fn scattered(scene: &Scene, bvh: &SceneBvh, camera_rays: &[Leaving]) -> Vec<(Ray, usize)> {
    let mut unit = units(0x9e37_79b9_7f4a_7c15);
    camera_rays
        .iter()
        .filter_map(|(ray, _)| {
            let hit = bvh.closest_hit(ray, 0.0, f32::INFINITY, None)?;
            let Surface::Diffuse { .. } = *scene.geometry.surface(hit.triangle) else {
                return None;
            };
            let [a, b, c] = scene.geometry.triangles[hit.triangle];
            let mut n = (b - a).cross(c - a).normalize();
            if n.dot(ray.dir) > 0.0 {
                n = -n;
            }
            let mut d = glam::Vec3::new(2.0 * unit() - 1.0, 2.0 * unit() - 1.0, 2.0 * unit() - 1.0);
            while d.length_squared() > 1.0 || d.length_squared() < 1e-6 {
                d = glam::Vec3::new(2.0 * unit() - 1.0, 2.0 * unit() - 1.0, 2.0 * unit() - 1.0);
            }
            let d = d.normalize();
            let dir = if d.dot(n) < 0.0 { -d } else { d };
            let origin = ray.origin + ray.dir * hit.t;
            Some((Ray { origin, dir }, hit.triangle))
        })
        .collect()
}

/// `n` rays from 10 units around (0, 1000, 0), each pointing away from that point and
/// upwards (uniform directions over the upper hemisphere): far above the bundled scenes and
/// leaving them, so a query is its setup and the root's box test
/// (`tools/mitsuba/ray_costs.py` times the same for Mitsuba's Embree).
fn rays_missing_the_scene(n: usize) -> Vec<Ray> {
    let mut unit = units(0x2545_f491_4f6c_dd1d);
    (0..n)
        .map(|_| {
            let y = unit();
            let phi = std::f32::consts::TAU * unit();
            let r = (1.0 - y * y).max(0.0).sqrt();
            let dir = glam::Vec3::new(r * phi.cos(), y, r * phi.sin());
            Ray {
                origin: glam::Vec3::new(0.0, 1000.0, 0.0) + dir * 10.0,
                dir,
            }
        })
        .collect()
}

/// Queries of `rays` from t = 0 to `t_max`, each skipping the flat surface of the triangle
/// it leaves, if any (as `path` asks; `bvh` numbers the flat surfaces, the same in every
/// hierarchy of one scene).
fn queries(
    bvh: &SceneBvh,
    rays: impl Iterator<Item = (Ray, Option<usize>)>,
    t_max: f32,
) -> Vec<Query> {
    rays.map(|(ray, leaving)| Query {
        ray,
        t_min: 0.0,
        t_max,
        skip_flat: leaving.map(|t| bvh.flat_surface(t)),
        skip_triangle: None,
    })
    .collect()
}

/// `queries` as `path` traces them, [`LANES`] per call to [`SceneBvh::queries`]: how many
/// are answered.
fn in_batches<const ANY_HIT: bool>(bvh: &SceneBvh, queries: &[Query]) -> usize {
    let mut out = [None; LANES];
    let mut found = 0;
    for batch in queries.chunks(LANES) {
        let out = &mut out[..batch.len()];
        bvh.queries::<ANY_HIT>(batch, out);
        found += out.iter().flatten().count();
    }
    found
}

/// Single rays only, through the 8-wide hierarchy and obvhs's CWBVH: camera rays and
/// scattered rays of `mirror_box` and `mirror_room` (the rays `path` sends one at a time),
/// closest hit and any hit, one query per call and in batches, and rays that miss (issue 56).
fn single(c: &mut Criterion) {
    for name in ["mirror_box", "mirror_room"] {
        let mut scene = mirrorbox_scene::load::bundled_scene(&format!("{name}.json"));
        scene.camera = scene.camera.with_size(320, 180);
        let reference = SceneBvh::build(&scene.geometry);
        let camera_rays = &ray_sets(&scene, &reference, 0)[0];
        let scattered = scattered(&scene, &reference, camera_rays);
        let missing = rays_missing_the_scene(10_000);
        let leaving = || scattered.iter().map(|&(r, t)| (r, Some(t)));
        let scattered_queries = queries(&reference, leaving(), f32::INFINITY);
        let scattered_within_1 = queries(&reference, leaving(), 1.0);
        let missing_queries = queries(
            &reference,
            missing.iter().map(|&r| (r, None)),
            f32::INFINITY,
        );
        let mut group = c.benchmark_group(format!("single_{name}_320x180"));
        group.sample_size(10);
        for kind in [BvhKind::Wide, BvhKind::Cwbvh] {
            let bvh = SceneBvh::build_with(&scene.geometry, kind);
            group.throughput(Throughput::Elements(camera_rays.len() as u64));
            group.bench_function(
                format!("camera {kind:?} ({} rays)", camera_rays.len()),
                |b| {
                    b.iter(|| {
                        camera_rays
                            .iter()
                            .filter(|(ray, _)| {
                                bvh.closest_hit(ray, 0.0, f32::INFINITY, None).is_some()
                            })
                            .count()
                    })
                },
            );
            group.throughput(Throughput::Elements(scattered.len() as u64));
            group.bench_function(
                format!("scattered {kind:?} ({} rays)", scattered.len()),
                |b| {
                    b.iter(|| {
                        scattered
                            .iter()
                            .filter(|(ray, tri)| {
                                bvh.closest_hit(
                                    ray,
                                    0.0,
                                    f32::INFINITY,
                                    Some(bvh.flat_surface(*tri)),
                                )
                                .is_some()
                            })
                            .count()
                    })
                },
            );
            // As `path` traces them: a round's queries in one batch, two at a time through the
            // 8-wide hierarchy (`SceneBvh::queries`).
            let n = scattered.len();
            group.bench_function(format!("scattered batches {kind:?} ({n} rays)"), |b| {
                b.iter(|| in_batches::<false>(&bvh, &scattered_queries))
            });
            group.bench_function(
                format!("scattered any-hit batches {kind:?} ({n} rays)"),
                |b| b.iter(|| in_batches::<true>(&bvh, &scattered_within_1)),
            );
            // Rays from far outside the scene, pointing away: the fixed cost of a query
            // (its setup and the root's box test), one per call and in batches.
            group.throughput(Throughput::Elements(missing.len() as u64));
            group.bench_function(format!("miss {kind:?} ({} rays)", missing.len()), |b| {
                b.iter(|| {
                    missing
                        .iter()
                        .filter(|ray| bvh.closest_hit(ray, 0.0, f32::INFINITY, None).is_some())
                        .count()
                })
            });
            group.bench_function(
                format!("miss batches {kind:?} ({} rays)", missing.len()),
                |b| b.iter(|| in_batches::<false>(&bvh, &missing_queries)),
            );
            group.throughput(Throughput::Elements(scattered.len() as u64));
            group.bench_function(
                format!("scattered any-hit {kind:?} ({} rays)", scattered.len()),
                |b| {
                    b.iter(|| {
                        scattered
                            .iter()
                            .filter(|(ray, tri)| {
                                bvh.occluded(ray, 0.0, 1.0, Some(bvh.flat_surface(*tri)), None)
                            })
                            .count()
                    })
                },
            );
        }
        group.finish();
    }
}

fn bench(c: &mut Criterion) {
    let mut scene = mirrorbox_scene::load::bundled_scene("mirror_box.json");
    scene.camera = scene.camera.with_size(640, 360);
    let bvh = SceneBvh::build(&scene.geometry);
    let sets = ray_sets(&scene, &bvh, 10);
    let mut group = c.benchmark_group("closest_hit_mirror_box_640x360");
    group.sample_size(10);
    for (name, set) in [
        ("primary", &sets[0]),
        ("after_1_bounce", &sets[1]),
        ("after_10_bounces", &sets[10]),
    ] {
        group.throughput(Throughput::Elements(set.len() as u64));
        group.bench_function(format!("{name} ({} rays)", set.len()), |b| {
            b.iter(|| {
                set.iter()
                    .filter(|(ray, leaving)| {
                        bvh.closest_hit(ray, 0.0, f32::INFINITY, *leaving).is_some()
                    })
                    .count()
            })
        });
        // The packet kernel on the same rays, LANES consecutive ones per packet (neighbouring
        // pixels of a row; the image loop packs two pixels' 16 samples, more coherent still).
        let packets: Vec<RayPacket> = set
            .chunks(LANES)
            .map(|chunk| {
                let mut packet = RayPacket::default();
                for (lane, (ray, leaving)) in chunk.iter().enumerate() {
                    packet.set(lane, ray, *leaving);
                }
                packet
            })
            .collect();
        group.bench_function(format!("{name} packets ({} rays)", set.len()), |b| {
            b.iter(|| {
                let mut hits = [None; LANES];
                let mut found = 0;
                for (packet, chunk) in packets.iter().zip(set.chunks(LANES)) {
                    let active = first_lanes(chunk.len());
                    bvh.closest_hits(packet, active, &mut hits);
                    found += hits[..chunk.len()].iter().flatten().count();
                }
                found
            })
        });
    }
    group.finish();
}

criterion_group!(benches, single, bench);
criterion_main!(benches);
