//! Uneven mirrors (issue 16, seed 002's uneven mirrors): the engines' tricks for normal-mapped
//! mirrors against a truth that reflects about the perturbed normal at every depth.

pub mod section;

use crate::{Experiment, Measure, beside};
use mirrorbox_harness::{SweepConfig, along, axes, with_options};
use mirrorbox_raster::Method;
use std::path::{Path, PathBuf};

/// The tricks measured (`crates/raster/src/uneven.rs`).
/// (`march` with a 16-pixel texture margin was measured until issue 38: its error equalled
/// the plain march's at every tilt on both scenes, at more cost.)
const BUMP_VARIANTS: [&str; 8] = [
    "bump=flat",
    "bump=distort bump-strength=0.25",
    "bump=distort",
    "bump=distort bump-strength=1",
    "bump=distort bump-strength=2",
    "bump=distort-distance bump-strength=2",
    "bump=proxy",
    "bump=march",
];

/// `bumpy_pair`: the paper's method at its published n = 2 with every trick — the bump
/// ignored, the screen-space distortion at four strengths and its 1/distance form, the proxy
/// plane, the march — and, beside them, the march
/// at n = 4, the exact `unrolled` at depth 64 (which shows the mirror flat) and the exact
/// `path-textures` at depth 64 with four tricks; against truths whose rippled mirror tilts by
/// 0, 1, 2.5, 5 and 10°; 320×180, 6 timed frames after one warm-up.
pub fn sweep(out: &Path) -> SweepConfig {
    SweepConfig {
        scene: PathBuf::from("scenes/bumpy_pair.json"),
        ..variants(
            out,
            "auxiliary n=2",
            &[
                "auxiliary n=4 bump=march",
                "unrolled depth=64",
                "path-textures depth=64 bump=flat",
                "path-textures depth=64 bump=distort bump-strength=1",
                "path-textures depth=64 bump=proxy",
                "path-textures depth=64 bump=march",
            ],
        )
    }
}

/// [`sweep`] on `bumpy_single` (one normal-mapped mirror: `naive` is the paper's method
/// there, and exact for a flat mirror).
pub fn single_sweep(out: &Path) -> SweepConfig {
    SweepConfig {
        scene: PathBuf::from("scenes/bumpy_single.json"),
        ..variants(out, "naive", &["unrolled depth=64"])
    }
}

fn variants(out: &Path, base: &str, extra: &[&str]) -> SweepConfig {
    let base = Method::parse(base).unwrap_or_else(|e| panic!("preset: {e}"));
    let mut methods: Vec<Method> = BUMP_VARIANTS
        .iter()
        .map(|v| with_options(&base, v))
        .collect();
    methods.extend(
        extra
            .iter()
            .map(|m| Method::parse(m).unwrap_or_else(|e| panic!("preset: {e}"))),
    );
    SweepConfig {
        axes: vec![along(&axes::BUMP_AMPLITUDE, [0.0, 1.0, 2.5, 5.0, 10.0])],
        width: Some(320),
        height: Some(180),
        frames: 6,
        warmup: 1,
        ..SweepConfig::preset(out.to_path_buf(), methods, vec![0.9])
    }
}

pub const BUMPY: Experiment = Experiment {
    name: "bumpy",
    about: "uneven mirrors: the engines' tricks against the truth as the bump's tilt grows",
    folder: "uneven_mirrors",
    measure: Measure::Sweeps(|out| vec![sweep(out), single_sweep(&beside(out, "_single"))]),
    section: Some(section::section),
    regions: section::REGIONS,
    chapter: "uneven-mirrors.md",
    main_job: true,
    overview: None,
};
