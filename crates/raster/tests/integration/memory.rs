//! The memory estimate (`mirrorbox_raster::memory`, issue 37) against wgpu's own counters:
//! for every registered method at its defaults (and with shadow maps) on a few bundled
//! scenes, the GPU bytes the device holds while the frame is alive
//! (`RenderOutput::gpu_memory`, read on a fresh device so nothing else is counted) are held
//! to the part of the estimate the counters can see, both ways. What they cannot see:
//!
//! - the readback buffer, freed before the counters are read: `views × H × ⌈16·W⌉₂₅₆` bytes;
//! - [`WGPU_UNSEEN`]: the 64 KiB of `mirrorbox_raster::memory::WGPU_DEVICE_BYTES` for
//!   timestamp queries, staging belts and bookkeeping;
//! - the parts in [`UNSEEN_PARTS`], which the counters never hold.
//!
//! The estimate's part they can see is at least the measured bytes (less
//! [`UNDERCOUNT_ALLOWED`]): it bounds what a frame holds, so a part every frame has, left out
//! of it, fails (one shadow-map layer: checked). In the `ray-query` and `unrolled` rows the
//! [`OVERCOUNTED_PARTS`] give that bound their excess as slack. Without them, the part is at
//! most the measured bytes plus [`SLACK_SHARE`] of them, for layout rounding and uniform
//! records counted at 256 bytes where lavapipe aligns them tighter — not a fixed allowance
//! (issue 50: the old `1.5 × measured + 1 MiB` was 28 render targets of 64×36, so an estimate
//! counting a mirror-texture set twice passed). Both bounds are set from lavapipe's layouts
//! (Mesa 25.0.7): measured at 64×36 on every row of both tests (2026-11-30), the estimate
//! exceeds the counters by at most 1.1 % of the measured bytes (11 408 bytes, `feedback` in
//! the lit room with shadow maps) and falls short of them by at most 284 bytes. A
//! mirror-texture set counted twice adds ≥ 53 504 bytes (6.6 % of `naive`'s 805 380 on
//! `mirror_box`), a render target 46 080 (5.7 %): both fail.

use mirrorbox_raster::memory::{MemoryEstimate, buffer_bytes};
use mirrorbox_raster::{Gpu, METHODS, Method, RenderSettings, plan_frame, render_planned};
use mirrorbox_scene::Scene;

/// wgpu's device allowance that its counters do not list (the rest of
/// `WGPU_DEVICE_BYTES`, its 512 KiB zero buffer, they do).
const WGPU_UNSEEN: u64 = 64 << 10;

/// Parts of an estimate the counters never hold while the frame lives, with why.
const UNSEEN_PARTS: [(&str, &str); 1] = [(
    mirrorbox_raster::methods::ray_query::ACCELERATION_STRUCTURES,
    "wgpu's counters do not include acceleration structures",
)];

/// Parts the estimate counts at more than the counters hold while the frame lives, on
/// purpose, with why: they count towards its lower bound and not its upper one.
const OVERCOUNTED_PARTS: [(&str, &str); 2] = [
    (
        "the BLAS inputs and triangle records",
        "ray-query drops the BLAS inputs once the acceleration structures are built and keeps \
         the triangle records",
    ),
    (
        "the path instances",
        "unrolled counts them at their largest: every item of every visible piece",
    ),
];

/// Bytes the counters may hold beyond what the estimate counts for them: the `cubemap`
/// frames in the lit room measure up to 284 bytes more than their estimate (2026-11-30,
/// 64×36, light images 2–7 deep; the scene buffers' part grows with the images as measured,
/// so the rest is in the method's own buffers or textures, not found). Far below a part the
/// estimate could miss: one shadow-map layer of this test's is 64 KiB.
const UNDERCOUNT_ALLOWED: u64 = 1 << 10;

/// The share of the measured bytes the estimate may exceed them by, beyond what they cannot
/// see and the parts counted at their largest.
const SLACK_SHARE: f64 = 0.02;

/// The GPU bytes of `estimate`'s parts named in `parts`.
fn bytes_of(estimate: &MemoryEstimate, parts: &[(&str, &str)]) -> u64 {
    estimate
        .parts
        .iter()
        .filter(|p| parts.iter().any(|(what, _)| *what == p.what))
        .map(|p| p.gpu_bytes)
        .sum()
}

/// Holds the estimate to the counters (`measured` bytes) of a frame of `views` views of
/// `w × h` pixels, both ways. What it counts that the counters can see — its GPU bytes
/// without the [`UNSEEN_PARTS`], the readback buffers and [`WGPU_UNSEEN`] — is at least the
/// measured bytes less [`UNDERCOUNT_ALLOWED`] (the estimate bounds what a frame holds);
/// without the [`OVERCOUNTED_PARTS`] too, at most [`SLACK_SHARE`] of them more (it is not
/// loose). `key` names the frame. Returns both differences from the measured bytes, as the
/// row of the test's table says them.
fn hold_to_counters(
    key: &str,
    estimate: &MemoryEstimate,
    measured: u64,
    views: u64,
    (w, h): (u32, u32),
) -> String {
    let readback = views * buffer_bytes((u64::from(w) * 16).next_multiple_of(256) * u64::from(h));
    let seen = estimate
        .gpu_bytes
        .checked_sub(bytes_of(estimate, &UNSEEN_PARTS) + readback + WGPU_UNSEEN)
        .unwrap_or_else(|| {
            panic!("{key}: an estimate without its readback, wgpu's share: {estimate}")
        });
    assert!(
        measured <= seen + UNDERCOUNT_ALLOWED,
        "{key}: wgpu holds {measured} bytes, more than the {seen} the estimate counts for \
         what its counters see and {UNDERCOUNT_ALLOWED} ({} in all; {:?})",
        estimate.gpu_bytes,
        estimate.parts
    );
    let exact = seen - bytes_of(estimate, &OVERCOUNTED_PARTS);
    let slack = (SLACK_SHARE * measured as f64) as u64;
    assert!(
        exact <= measured + slack,
        "{key}: the estimate is loose: {exact} bytes for what the counters see (without the \
         parts counted at their largest), above the {measured} they hold plus {SLACK_SHARE} of \
         them ({:?})",
        estimate.parts
    );
    let percent = |bytes: u64| 100.0 * (bytes as f64 - measured as f64) / measured as f64;
    format!(
        "measured {measured}, estimate {}; the part the counters see {seen} ({:+.2} %), \
         without the parts counted at their largest {exact} ({:+.2} %)",
        estimate.gpu_bytes,
        percent(seen),
        percent(exact)
    )
}

fn scene(name: &str, w: u32, h: u32) -> Scene {
    let mut s = mirrorbox_scene::load::bundled_scene(name);
    s.camera = s.camera.with_size(w, h);
    s
}

#[test]
fn gpu_estimate_bounds_wgpus_counters_for_every_method() {
    let mut rows = Vec::new();
    let mut refused = Vec::new();
    // Each scene at its own light-image depth, but the lit room at 3 (40 images), not its 8
    // (477): its `cubemap` and `ssr` frames with shadow maps took 5–6.5 s each, 24 of this
    // test's 30 s. `mirror_box_lit` keeps 8-deep chains.
    for (name, mirrored_lights) in [
        ("mirror_box.json", None),
        ("mirror_box_lit.json", None),
        ("mirror_room_lit.json", Some(3)),
        ("symmetry_star.json", None),
        ("bumpy_pair.json", None),
    ] {
        let mut s = scene(name, 64, 36);
        if let Some(depth) = mirrored_lights {
            s.lighting.mirrored_lights = depth;
            s.enumerate_light_images(s.lighting.images.min_throughput)
                .expect("the lit room's 3-deep light images");
        }
        // Shadow maps are drawn only where the scene asks for shadows (elsewhere `map` is
        // `none` with a warning): measured only there.
        let variants: &[&str] = if s.lighting.shadows {
            &["none", "map"]
        } else {
            &["none"]
        };
        for entry in METHODS {
            for &shadows in variants {
                let mut method = Method::defaults(entry)
                    .with_text(&mirrorbox_raster::lighting::SHADOWS, shadows)
                    .unwrap();
                if shadows == "map" {
                    method = method
                        .with_text(&mirrorbox_raster::lighting::SHADOW_MAP_SIZE, "128")
                        .unwrap();
                }
                let settings = RenderSettings {
                    warmup: 0,
                    ..RenderSettings::new(method)
                };
                let planned = match plan_frame(&s, &settings) {
                    Ok(p) => p,
                    Err(e) => {
                        // A refused configuration (too many passes …) builds nothing.
                        refused.push(format!("{name} {} {shadows}: refused ({e})", entry.name));
                        continue;
                    }
                };
                let estimate = planned.memory_estimate(&s, &settings);
                // A fresh device: its counters hold this frame only.
                let gpu = Gpu::new().expect("a wgpu adapter");
                let out = render_planned(&gpu, &s, planned, &settings).unwrap();
                let measured = out.gpu_memory.buffer_bytes + out.gpu_memory.texture_bytes;
                let key = format!("{name} {} shadows={shadows}", entry.name);
                let size = (s.camera.width, s.camera.height);
                let row = hold_to_counters(&key, &estimate, measured, 1, size);
                rows.push(format!("{key}: {row}"));
            }
        }
    }
    println!("{}", rows.join("\n"));
    // Every other row measured: a refused plan drops its row, and a refusal that crept in
    // (the lit room's shadow maps, the largest estimates, say) would go unseen. Refused by
    // design: `ray-query` with shadow maps (it traces its shadow legs), and `path-textures`
    // in the lit room (over --max-passes).
    let expected = |r: &String| {
        (r.contains(" ray-query map: ") && r.contains("--shadows must be none for ray-query"))
            || (r.starts_with("mirror_room_lit.json path-textures ")
                && r.contains("scene passes per frame"))
    };
    let unexpected: Vec<&String> = refused.iter().filter(|r| !expected(r)).collect();
    assert!(
        unexpected.is_empty(),
        "refused, so not measured: {unexpected:#?}"
    );
    assert_eq!(refused.len(), 4, "{refused:#?}");
}

/// A stereo pair (each eye its own frame, or `--stereo-mirrors shared`'s joint frame).
#[test]
fn pair_estimate_bounds_wgpus_counters() {
    let s = scene("stereo_box.json", 64, 36);
    let rig = s.stereo.expect("stereo_box has a rig");
    let eyes = mirrorbox_scene::stereo::Eye::BOTH.map(|e| s.eye(&rig, e));
    for key in [
        "naive",
        "naive stereo-mirrors=shared",
        "portal",
        "cubemap",
        "symmetry",
    ] {
        let settings = RenderSettings {
            warmup: 0,
            ..RenderSettings::new(Method::parse(key).unwrap())
        };
        let planned =
            mirrorbox_raster::stereo_pair::plan_pair([&eyes[0], &eyes[1]], &settings).unwrap();
        let estimate = planned.memory_estimate([&eyes[0], &eyes[1]], &settings);
        let gpu = Gpu::new().expect("a wgpu adapter");
        let out = mirrorbox_raster::stereo_pair::render_pair(
            &gpu,
            [&eyes[0], &eyes[1]],
            planned,
            &settings,
        )
        .unwrap();
        let measured = out.gpu_memory.buffer_bytes + out.gpu_memory.texture_bytes;
        let size = (s.camera.width, s.camera.height);
        println!(
            "{key}: {}",
            hold_to_counters(key, &estimate, measured, 2, size)
        );
    }
}

#[test]
fn over_budget_plans_are_refused_before_any_gpu_work() {
    let s = scene("mirror_box.json", 64, 36);
    let method = Method::parse("cubemap cube-size=2048").unwrap();
    let settings = RenderSettings::new(method);
    let planned = plan_frame(&s, &settings).unwrap();
    let estimate = planned.memory_estimate(&s, &settings);
    // Two mirrors × two sets × six faces of 2048² × (16 + 4) bytes: 1.9 GiB of cube maps.
    assert!(estimate.gpu_bytes > 1 << 30, "{estimate}");
    let err = planned
        .check_memory(&s, &settings, 1 << 30)
        .unwrap_err()
        .to_string();
    assert!(err.contains("above --memory-budget 1.00 GiB"), "{err}");
    assert!(err.contains("the cube maps"), "{err}");
    assert!(err.contains("lower --cube-size"), "{err}");
    assert!(planned.check_memory(&s, &settings, 4 << 30).is_ok());
}
