//! The planar reflections web engines ship, scored against the truth through the exchange
//! (issue 53, `docs/exchange.md`): three.js' `Reflector` and a `CubeCamera` probe (and each
//! engine's no-mirror floor), drawn in headless Chromium by `clients/web`, beside our
//! equivalents (`naive`, `cubemap`) and the exact methods swept on the same software
//! rasterizer (SwiftShader, loaded by wgpu from Chromium's Vulkan ICD), on mirror_box,
//! mirror_room and textured_box at 320×180, α = 0.9. Run by `scripts/measure-web-engines.sh`.

pub mod section;

use crate::{Experiment, Measure};

pub const WEB_ENGINES: Experiment = Experiment {
    name: "web-engines",
    about: "three.js' planar reflections in headless Chromium, scored through the exchange beside our equivalents on the same software rasterizer",
    folder: "web_engines",
    measure: Measure::Script("scripts/measure-web-engines.sh", &[]),
    section: Some(section::section),
    regions: &[],
    chapter: "exchange.md",
    main_job: false,
    overview: None,
};
