//! Tracer throughput on `scenes/mirror_box.json` at 640×360, reported by criterion as rays
//! per second ("elements" = rays cast, counted once up front; rendering is deterministic).
//! Compares the two obvhs hierarchies (CWBVH, BVH2) and two reflectances: 0.9 as in the scene
//! and the paper's α = 0.7. Run: `cargo bench -p mirrorbox-trace`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use mirrorbox_trace::{BvhKind, SceneBvh, TraceSettings, render};

fn bench(c: &mut Criterion) {
    let base = mirrorbox_scene::load::bundled_scene("mirror_box.json");
    let settings = TraceSettings::whitted(2);
    let mut group = c.benchmark_group("mirror_box_640x360_4spp");
    group.sample_size(10);
    for reflectance in [0.9f32, 0.7] {
        let mut scene = base.clone();
        scene.camera = scene.camera.with_size(640, 360);
        scene.set_reflectance(Vec3::splat(reflectance)).unwrap();
        for kind in [BvhKind::Cwbvh, BvhKind::Bvh2, BvhKind::Wide] {
            let bvh = SceneBvh::build_with(&scene.geometry, kind);
            let rays = render(&scene, &bvh, &settings, &|_| {}).stats.rays;
            group.throughput(Throughput::Elements(rays));
            group.bench_function(format!("{kind:?}/R={reflectance}"), |b| {
                b.iter(|| render(&scene, &bvh, &settings, &|_| {}))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
