//! Stereo mirrors (issue 17, seed 002's per-eye mirror cameras): per-eye mirror textures
//! against the head's shared ones.

pub mod section;

use crate::{Experiment, Measure};
use mirrorbox_harness::{AxisValues, SweepConfig, axes};
use mirrorbox_raster::Method;
use std::path::{Path, PathBuf};

/// `stereo_box` (the paper's box with a green marker on the wall behind the viewer): per-eye
/// mirror textures against the head's shared ones (`stereo-mirrors=shared`) for the paper's
/// method at n = 2 and the exact `path-textures`, the plain `naive` and the exact geometry
/// method `unrolled` (per eye only), each as a stereo pair at IPD 0 … 0.1 and as a mono frame;
/// 320×180, α 0.9, 6 timed frames after one warm-up.
pub fn sweep(out: &Path) -> SweepConfig {
    let methods = [
        "naive",
        "naive stereo-mirrors=shared",
        "auxiliary n=2",
        "auxiliary n=2 stereo-mirrors=shared",
        "path-textures depth=64",
        "path-textures depth=64 stereo-mirrors=shared",
        "unrolled depth=64",
    ]
    .iter()
    .map(|m| Method::parse(m).unwrap_or_else(|e| panic!("preset: {e}")))
    .collect();
    SweepConfig {
        scene: PathBuf::from("scenes/stereo_box.json"),
        axes: vec![AxisValues {
            axis: &axes::STEREO_IPD,
            values: vec![
                None,
                Some(0.0),
                Some(0.025),
                Some(0.05),
                Some(0.075),
                Some(0.1),
            ],
        }],
        marker: Some("marker".into()),
        width: Some(320),
        height: Some(180),
        frames: 6,
        warmup: 1,
        ..SweepConfig::preset(out.to_path_buf(), methods, vec![0.9])
    }
}

pub const STEREO: Experiment = Experiment {
    name: "stereo",
    about: "stereo mirrors: per-eye mirror textures against shared ones as the IPD grows",
    folder: "stereo",
    measure: Measure::Sweeps(|out| vec![sweep(out)]),
    section: Some(section::section),
    regions: section::REGIONS,
    chapter: "stereo.md",
    main_job: true,
    overview: None,
};
