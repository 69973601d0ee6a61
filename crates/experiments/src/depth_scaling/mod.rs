//! The exact methods' cost per bounce: `portal` and `unrolled` at depth 1 … 1024.

pub mod exact;
pub mod section;

use crate::{Experiment, Measure};
use mirrorbox_harness::{SweepConfig, swept};
use std::path::Path;

/// `portal` and `unrolled` at depth 1 to 1024 on mirror_box with perfect mirrors (α = 1: no
/// path ends by attenuation, only when its portal holds no pixel centre).
pub fn sweep(out: &Path) -> SweepConfig {
    let methods = ["portal", "unrolled"]
        .into_iter()
        .flat_map(|m| swept(m, (0..=10).map(|k| 1 << k)))
        .collect();
    SweepConfig::preset(out.to_path_buf(), methods, vec![1.0])
}

pub const DEPTH_SCALING: Experiment = Experiment {
    name: "depth-scaling",
    about: "the exact methods' cost against the depth cap, 1 to 1024 mirrors along a path",
    folder: "depth_scaling",
    measure: Measure::Sweeps(|out| vec![sweep(out)]),
    section: Some(section::section),
    regions: section::REGIONS,
    chapter: "exact-methods.md",
    main_job: true,
    overview: None,
};
