//! Symmetry planes (seed 001): the seed's method, pruned copies and the CPU-baked mesh against
//! the number of planes p.

pub mod planes;
pub mod section;

use crate::{Experiment, Measure};
use mirrorbox_harness::{SweepConfig, along, axes};
use mirrorbox_raster::Method;
use std::path::{Path, PathBuf};

/// The seed's method (instanced, and one draw per copy), the pruned copies and the baked mesh
/// for p = 0…10 of `symmetry_many`'s ten planes; no mirrors, so one α.
pub fn sweep(out: &Path) -> SweepConfig {
    let named = |name: &str| Method::named(name).unwrap_or_else(|e| panic!("preset: {e}"));
    let per_copy = named("symmetry")
        .with_text(
            &mirrorbox_raster::methods::symmetry::SYMMETRY_DRAWS,
            "per-copy",
        )
        .unwrap_or_else(|e| panic!("preset: {e}"));
    let methods = vec![
        named("symmetry"),
        per_copy,
        named("symmetry-pruned"),
        named("symmetry-baked"),
    ];
    // The seed's method takes seconds per frame at p = 10 on a CPU rasterizer (2^10 copies of
    // 5 708 triangles): 6 timed frames (the fewest that give an interval) after one warm-up
    // keep the preset within minutes.
    SweepConfig {
        scene: PathBuf::from("scenes/symmetry_many.json"),
        axes: vec![along(&axes::SYMMETRY_PLANES, (0..=10).map(f64::from))],
        frames: 6,
        warmup: 1,
        ..SweepConfig::preset(out.to_path_buf(), methods, vec![1.0])
    }
}

pub const SYMMETRY_SCALING: Experiment = Experiment {
    name: "symmetry-scaling",
    about: "the symmetry-plane methods' cost against the number of planes p = 0…10",
    folder: "symmetry_scaling",
    measure: Measure::Sweeps(|out| vec![sweep(out)]),
    section: Some(section::section),
    regions: section::REGIONS,
    chapter: "symmetry.md",
    main_job: true,
    overview: None,
};
