//! What each millisecond buys (issue 38): every method at a few settings on both bundled
//! mirror scenes, at 320×180 and α = 1 — the points of the overview's cross-method frontier
//! (`reports/index.html`).

use crate::{Experiment, Measure, beside};
use mirrorbox_harness::{SweepConfig, swept};
use mirrorbox_raster::Method;
use std::path::{Path, PathBuf};

/// The scenes of the frontier (file stems under `scenes/`), in the overview's order: its
/// charts (`frontier_<scene>.svg`) are drawn for these. Each sweeps with its own settings
/// (below, by name).
pub const SCENES: [&str; 2] = [BOX, ROOM];
const BOX: &str = "mirror_box";
const ROOM: &str = "mirror_room";

/// Every method of the paper and its successors at the settings given, 320×180, α = 1, five
/// timed frames after one warm-up.
fn sweep(scene: &str, out: &Path, n: &[u32], depths: &[u32], path_textures: bool) -> SweepConfig {
    let parse = |m: &str| Method::parse(m).unwrap_or_else(|e| panic!("preset: {e}"));
    let mut methods = vec![parse("naive")];
    methods.extend(swept("auxiliary", n.iter().copied()));
    if path_textures {
        methods.extend(swept("path-textures", depths.iter().copied()));
    }
    methods.extend(swept("portal", depths.iter().copied()));
    methods.extend(swept("unrolled", depths.iter().copied()));
    // What engines ship (issue 39): ray queries at the same depths, screen-space reflections
    // with each fallback.
    methods.extend(swept("ray-query", depths.iter().copied()));
    for fallback in ["none", "cubemap", "planar"] {
        methods.push(parse(&format!("ssr ssr-fallback={fallback}")));
    }
    methods.push(parse("feedback history=16"));
    for size in [128, 512] {
        methods.push(parse(&format!("cubemap cube-size={size} history=16")));
    }
    SweepConfig {
        scene: PathBuf::from(scene),
        width: Some(320),
        height: Some(180),
        frames: 5,
        warmup: 1,
        ..SweepConfig::new(PathBuf::new(), out.to_path_buf(), methods, vec![1.0])
    }
}

pub const FRONTIER: Experiment = Experiment {
    name: "frontier",
    about: "every method at a few settings on mirror_box and mirror_room: the overview's error-against-time frontier",
    folder: "frontier_box",
    // The room leaves out path-textures (over 5 000 passes past depth 4) and auxiliary n ≥ 2
    // (3 761 passes, 2.9 s/frame), and caps the depth at 16 (unrolled's 8 M triangle bound).
    measure: Measure::Sweeps(|out| {
        let room = out.parent().unwrap_or(Path::new("")).join("frontier_room");
        let room = if out.ends_with("frontier_box") {
            room
        } else {
            beside(out, "_room")
        };
        let file = |stem: &str| format!("scenes/{stem}.json");
        vec![
            sweep(&file(BOX), out, &[0, 1, 2, 3], &[1, 4, 16, 64], true),
            sweep(&file(ROOM), &room, &[0, 1], &[1, 2, 4, 8, 16], false),
        ]
    }),
    section: None,
    regions: &[],
    chapter: "frontier.md",
    main_job: true,
    overview: None,
};
