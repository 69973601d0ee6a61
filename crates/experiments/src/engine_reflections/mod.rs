//! What engines ship (issue 39): screen-space reflections (`ssr`, each fallback) and
//! ray-query reflections (`ray-query`) beside the exact raster methods and the paper's
//! `auxiliary n=2`, on mirror_box and mirror_room at 320×180: error and ms/frame against the
//! depth cap, and `ssr`'s error against the share of reflections off screen, over camera
//! turns. Not in the main job (its budget is spent; `docs/budgets.md`): run it with
//! `mirrorbox experiment engine-reflections`.

pub mod section;

use crate::{Experiment, Measure, beside};
use mirrorbox_harness::axes::{AxisValues, CAMERA_YAW};
use mirrorbox_harness::{SweepConfig, swept};
use mirrorbox_raster::Method;
use mirrorbox_trace::WhittedSettings;
use std::path::{Path, PathBuf};

fn parse(m: &str) -> Method {
    Method::parse(m).unwrap_or_else(|e| panic!("preset: {e}"))
}

/// The three fallbacks of `ssr`.
fn ssr_methods() -> Vec<Method> {
    ["none", "cubemap", "planar"]
        .iter()
        .map(|f| parse(&format!("ssr ssr-fallback={f}")))
        .collect()
}

/// A sweep of `scene` at 320×180, α = 0.9 (a chain fades below the truth's 10⁻⁴ after 88
/// reflections, so depth 64 is near the truth and the error against depth converges), five
/// timed frames after one warm-up.
fn sweep(scene: &str, out: &Path, methods: Vec<Method>, axes: Vec<AxisValues>) -> SweepConfig {
    SweepConfig {
        scene: PathBuf::from(scene),
        width: Some(320),
        height: Some(180),
        frames: 5,
        warmup: 1,
        axes,
        ..SweepConfig::new(PathBuf::new(), out.to_path_buf(), methods, vec![0.9])
    }
}

/// Depth 1 … `deepest` for the exact methods (unrolled and portal to `raster_deepest`: the
/// room's paths multiply), `auxiliary n=2` and `ssr`.
fn depth_sweep(scene: &str, out: &Path, deepest: u32, raster_deepest: u32) -> SweepConfig {
    let depths = |max: u32| (0..=6).map(|k| 1u32 << k).filter(move |d| *d <= max);
    let mut methods = swept("ray-query", depths(deepest));
    methods.extend(swept("unrolled", depths(raster_deepest)));
    methods.extend(swept("portal", depths(raster_deepest)));
    methods.push(parse("auxiliary n=2"));
    methods.extend(ssr_methods());
    sweep(scene, out, methods, Vec::new())
}

/// `ssr` with each fallback, the camera turned from −90° to 90° in steps of 22.5°, against
/// the **one-bounce** truth (`--max-depth 1`): `ssr` shows one bounce, so what remains is what
/// the screen lacks (and its march's artefacts), not the deeper reflections no one-bounce
/// method shows (those are the depth sweeps' question). `planar` is exact at one bounce: its
/// error is the march's alone.
fn screen_sweep(scene: &str, out: &Path) -> SweepConfig {
    let yaws = (-4..=4).map(|k| Some(22.5 * f64::from(k))).collect();
    SweepConfig {
        truth: WhittedSettings {
            max_depth: 1,
            ..WhittedSettings::default()
        },
        ..sweep(
            scene,
            out,
            ssr_methods(),
            vec![AxisValues {
                axis: &CAMERA_YAW,
                values: yaws,
            }],
        )
    }
}

pub const ENGINE_REFLECTIONS: Experiment = Experiment {
    name: "engine-reflections",
    about: "screen-space and ray-query reflections beside the exact methods: error and ms against depth, ssr against the reflections off screen",
    folder: "engine_reflections",
    // The room caps unrolled and portal at depth 16 (unrolled's 8 M triangle bound).
    measure: Measure::Sweeps(|out| {
        vec![
            depth_sweep("scenes/mirror_box.json", out, 64, 64),
            depth_sweep("scenes/mirror_room.json", &beside(out, "_room"), 64, 16),
            screen_sweep("scenes/mirror_box.json", &beside(out, "_ssr")),
            screen_sweep("scenes/mirror_room.json", &beside(out, "_ssr_room")),
        ]
    }),
    section: Some(section::section),
    regions: &[],
    chapter: "engine-reflections.md",
    main_job: false,
    overview: None,
};
