//! Real assets (issue 40): the paper's method (`auxiliary n = 0…4`, Table 1's sweep) and the
//! exact methods at depth 64 on scenes nobody here modelled by hand — a real CAD mesh (the
//! glTF sample `2CylinderEngine`, 110 k triangles, in the mirror box `mirrorbox import`
//! builds: `scenes/imported/engine_box.json`) and a textured asset (`scenes/textured_box.json`:
//! the project's glTF with base colour and emissive textures, a texture transform and a glTF
//! mirror, in the paper's box) — at 320×180, α = 1 and 0.7. Not in the main job (its budget
//! is spent; `docs/budgets.md`); the engine scene needs Debian's `assimp-testmodels`
//! (`scripts/install-system-deps.sh`).

use crate::{Experiment, Measure, beside};
use mirrorbox_harness::{SweepConfig, swept};
use std::path::{Path, PathBuf};

/// Table 1's methods on `scene` at 320×180, five timed frames after one warm-up.
fn sweep(scene: &str, out: &Path) -> SweepConfig {
    let mut methods = swept(crate::table1::rows::PAPER_METHOD, 0..=4);
    for m in ["portal", "unrolled"] {
        methods.extend(swept(m, [64]));
    }
    SweepConfig {
        scene: PathBuf::from(scene),
        width: Some(320),
        height: Some(180),
        frames: 5,
        warmup: 1,
        ..SweepConfig::new(PathBuf::new(), out.to_path_buf(), methods, vec![1.0, 0.7])
    }
}

pub const REAL_ASSETS: Experiment = Experiment {
    name: "real-assets",
    about: "the paper's method and the exact ones on real assets: a 110 k-triangle CAD engine (glTF) and a textured glTF, each in a mirror box",
    folder: "real_assets",
    measure: Measure::Sweeps(|out| {
        vec![
            sweep("scenes/imported/engine_box.json", out),
            sweep("scenes/textured_box.json", &beside(out, "_textured")),
        ]
    }),
    section: None,
    regions: &[],
    chapter: "real-assets.md",
    main_job: false,
    overview: None,
};
