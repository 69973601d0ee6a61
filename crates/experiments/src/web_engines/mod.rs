//! The planar reflections web engines ship, scored against the truth through the exchange
//! (issue 53, `docs/exchange.md`): three.js' `Reflector` and `CubeCamera` probes, Babylon.js'
//! `MirrorTexture` and `ReflectionProbe` (and each engine's no-mirror floor), drawn in headless
//! Chromium by `clients/web`, beside our equivalents (`naive`, `cubemap`, `feedback`) and the
//! exact methods swept on the same software
//! rasterizer (SwiftShader, loaded by wgpu from Chromium's Vulkan ICD), on mirror_box,
//! mirror_room and textured_box at 320×180, α = 0.9. Run by `scripts/measure-web-engines.sh`.

pub mod section;

use crate::{Experiment, Measure};
use mirrorbox_report::document::{Block, markdown};
use mirrorbox_report::load_sweep;
use mirrorbox_report::readme::{ReadmeError, RegionSource};
use std::path::Path;

/// The scored folders, one per scene, with the scene's name.
const FOLDERS: [(&str, &str); 3] = [
    ("web_engines", "mirror_box"),
    ("web_engines_room", "mirror_room"),
    ("web_engines_textured", "textured_box"),
];

/// The book's region: each scene's external variants beside our equivalents (the report
/// section of each scored folder, under the scene's name).
fn findings(reports: &Path) -> Result<String, ReadmeError> {
    let mut blocks = Vec::new();
    for (folder, scene) in FOLDERS {
        let sweep = load_sweep(&reports.join(folder))?;
        let mut section = section::section(&sweep.info, &sweep.records);
        if section.is_empty() {
            return Err(ReadmeError(format!(
                "reports/{folder} holds no external variant"
            )));
        }
        // The section's own heading and paragraph stand once, above the scenes.
        section.drain(..2.min(section.len()));
        blocks.push(Block::Heading(
            3,
            format!("{scene} ([`reports/{folder}/`](../../../reports/{folder}/report.md))"),
        ));
        blocks.extend(section);
    }
    Ok(markdown(&blocks))
}

pub const WEB_ENGINES: Experiment = Experiment {
    name: "web-engines",
    about: "three.js' and Babylon.js' planar reflections in headless Chromium, scored through the exchange beside our equivalents on the same software rasterizer",
    folder: "web_engines",
    measure: Measure::Script("scripts/measure-web-engines.sh", &[]),
    section: Some(section::section),
    regions: &[RegionSource {
        id: "web-engines",
        source: "web_engines",
        about: "the web engines' variants beside our equivalents and exact methods, per scene",
        generate: findings,
    }],
    chapter: "exchange.md",
    main_job: false,
    overview: None,
};
