//! Shadows and mirrored lights (issue 15, seed 002's mirrored light sources): each raster
//! lighting variant against truths lit through chains of up to k mirrors.

pub mod section;
pub mod trace_cost;

use crate::{Experiment, Measure, beside};
use mirrorbox_harness::{SweepConfig, along, axes, swept, with_options};
use std::path::{Path, PathBuf};

/// The raster lighting variants measured: ignoring the light images, and drawing them (the
/// default).
const LIGHTING_VARIANTS: [&str; 2] = ["lights=direct", ""];

/// The shadow-map sizes measured (`--shadows map`), on [`SHADOWED_METHODS`] only: each layer
/// is a scene pass, so they are the experiment's dearest points on a CPU rasterizer (2048²
/// was measured until issue 38; its error was 0.7× 1024²'s at twice the time, and the main
/// job's 15 minutes had to hold the frontier experiment).
const SHADOW_MAP_SIZES: [u32; 2] = [256, 1024];

/// The methods also measured with shadow maps: the exact method and the paper's method at its
/// published n = 2.
const SHADOWED_METHODS: [&str; 2] = ["unrolled depth=64", "auxiliary n=2"];

/// `mirror_box_lit`: the paper's auxiliary method n = 0…4 and the exact methods at depth 64,
/// each ignoring mirrored light (`lights=direct`) and with the light images, two of them also
/// with shadow maps, against truths lit through k = 0, 1, 2, 4, 8 mirrors, with shadows; at
/// 320×180, 6 timed frames after one warm-up.
pub fn sweep(out: &Path) -> SweepConfig {
    let mut methods = Vec::new();
    let mut bases = swept(crate::table1::rows::PAPER_METHOD, 0..=4);
    bases.extend(swept("unrolled", [64]));
    bases.extend(swept("portal", [64]));
    for base in &bases {
        for variant in LIGHTING_VARIANTS {
            methods.push(with_options(base, variant));
        }
        if SHADOWED_METHODS.contains(&base.key().as_str()) {
            for size in SHADOW_MAP_SIZES {
                methods.push(with_options(
                    base,
                    &format!("shadows=map shadow-map-size={size}"),
                ));
            }
        }
    }
    SweepConfig {
        scene: PathBuf::from("scenes/mirror_box_lit.json"),
        axes: vec![along(&axes::MIRRORED_LIGHTS, [0.0, 1.0, 2.0, 4.0, 8.0])],
        width: Some(320),
        height: Some(180),
        frames: 6,
        warmup: 1,
        ..SweepConfig::preset(out.to_path_buf(), methods, vec![0.9])
    }
}

/// [`sweep`]'s mirror-room variant, smaller: the room's light images grow with k² (477 at
/// k = 8) and its reflection paths branch, so a frame costs ~1 s on a CPU rasterizer even at
/// 160×90. `unrolled` at depth 12 with α = 0.7 (0.7¹² = 1.4 % left to what the cut leaves
/// out), both lighting variants and shadow maps of 256² (483 layers at k = 8; 512² was
/// measured until issue 38), k = 0, 4, 8.
pub fn room_sweep(out: &Path) -> SweepConfig {
    let mut methods = Vec::new();
    for base in swept("unrolled", [12]) {
        for variant in LIGHTING_VARIANTS {
            methods.push(with_options(&base, variant));
        }
        methods.push(with_options(&base, "shadows=map shadow-map-size=256"));
    }
    SweepConfig {
        scene: PathBuf::from("scenes/mirror_room_lit.json"),
        axes: vec![along(&axes::MIRRORED_LIGHTS, [0.0, 4.0, 8.0])],
        width: Some(160),
        height: Some(90),
        frames: 6,
        warmup: 1,
        ..SweepConfig::preset(out.to_path_buf(), methods, vec![0.7])
    }
}

pub const LIGHTING: Experiment = Experiment {
    name: "lighting",
    about: "shadows and mirrored lights: each raster lighting variant against truths lit through up to k mirrors",
    folder: "lighting",
    measure: Measure::Sweeps(|out| vec![sweep(out), room_sweep(&beside(out, "_room"))]),
    section: Some(section::section),
    regions: section::REGIONS,
    chapter: "lighting.md",
    main_job: true,
    overview: None,
};
