//! The seed paper's Table 1 (seed 000): its auxiliary-mirror method at n = 0…4, with the exact
//! methods at depth 64 beside it — run twice by the main job, the second run into its own
//! folder, so that two consecutive runs stand side by side.

pub mod rows;
pub mod section;

use crate::{Experiment, Measure};
use mirrorbox_harness::{SweepConfig, swept};
use std::path::Path;

/// The auxiliary method for n = 0…4 on mirror_box at α = 1 and the paper's 0.7, with
/// `portal` and `unrolled` at depth 64 beside it; [`FRAMES`] timed frames.
pub fn sweep(out: &Path) -> SweepConfig {
    let mut methods = swept(rows::PAPER_METHOD, 0..=4);
    // A preset is a fixed experiment: its methods are named, not taken from the table.
    for m in ["portal", "unrolled"] {
        methods.extend(swept(m, [64]));
    }
    SweepConfig {
        frames: FRAMES,
        ..SweepConfig::preset(out.to_path_buf(), methods, vec![1.0, 0.7])
    }
}

/// Table 1's timed rounds: more than the presets' 9, because its speed verdicts are the
/// project's headline. With 9, one run in six on the shared 2-core machine left `portal`
/// depth 64 against n = 2 "not shown apart" (paired interval 0.99–1.65×) where the others
/// said faster; with 15, three trial runs gave intervals within 1.29–1.55× (issue 54; the
/// committed runs: `table1-runs`). Cost: about 12 s more per run.
pub const FRAMES: u32 = 15;

pub const TABLE1: Experiment = Experiment {
    name: "table1",
    about: "the paper's Table 1: its auxiliary mirrors at n = 0…4 against the truth, with the exact methods beside it",
    folder: "table1",
    measure: Measure::Sweeps(|out| vec![sweep(out)]),
    section: Some(section::table1_section),
    regions: section::REGIONS,
    chapter: "table1.md",
    main_job: true,
    overview: None,
};

pub const TABLE1_REPEAT: Experiment = Experiment {
    name: "table1-repeat",
    about: "Table 1 measured again right after the first run: how much two runs differ",
    folder: "table1_repeat",
    measure: Measure::Sweeps(|out| vec![sweep(out)]),
    section: Some(section::table1_section),
    regions: section::REPEAT_REGIONS,
    chapter: "table1.md",
    main_job: true,
    overview: None,
};

pub const TABLE1_RUNS: Experiment = Experiment {
    name: "table1-runs",
    about: "Table 1 ten times more: back to back in both orders, and with Mesa's shader cache cold, warm and off; do its speed verdicts hold from run to run?",
    folder: "table1_runs",
    measure: Measure::Script("scripts/measure-table1-runs.sh", &[]),
    section: None,
    regions: section::RUNS_REGIONS,
    chapter: "table1.md",
    main_job: false,
    overview: None,
};
