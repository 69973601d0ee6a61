//! The experiments measured by a script rather than a sweep: costs of the truth, memory
//! peaks, benches against Mitsuba, the viewer's frame rates, a cluster run and the GPU
//! measurements (each script's header says what it does and writes).

use crate::{Experiment, Measure};

pub const LIGHTING_TRACE_COST: Experiment = Experiment {
    name: "lighting-trace-cost",
    about: "the truth's cost against the mirrored-light depth k (one trace per k, median of runs)",
    folder: "lighting",
    measure: Measure::Script("scripts/lighting-trace-cost.sh", &[]),
    section: None,
    chapter: "lighting.md",
    main_job: true,
};

pub const MEMORY_PEAKS: Experiment = Experiment {
    name: "memory-peaks",
    about: "the peak memory of every bundled scene with every method, against the 2 GB budget",
    folder: "memory",
    measure: Measure::Script("scripts/memory-peaks.sh", &[]),
    section: None,
    chapter: "robustness.md",
    main_job: true,
};

pub const TRACER_BENCH: Experiment = Experiment {
    name: "tracer-bench",
    about: "the tracer against Mitsuba 3's compiled kernel, per round, one record per CPU kind",
    folder: "tracer",
    measure: Measure::Script("scripts/bench-tracer.sh", &["7", "16"]),
    section: None,
    chapter: "tracer-performance.md",
    main_job: false,
};

pub const GPU_TRUTH: Experiment = Experiment {
    name: "gpu-truth",
    about: "the truth traced on the GPU by ray queries against the CPU truth: time and largest difference at 640×360×16",
    folder: "gpu_truth",
    measure: Measure::Script("scripts/gpu-truth-bench.sh", &["5"]),
    section: None,
    chapter: "engine-reflections.md",
    main_job: false,
};

pub const VIEWER_FRAME_RATES: Experiment = Experiment {
    name: "viewer-frame-rates",
    about: "the viewer's milliseconds between frames, standing and walking, per method",
    folder: "viewer",
    measure: Measure::Script(
        "scripts/viewer-frame-rates.sh",
        &["scenes/mirror_box.json", "3"],
    ),
    section: None,
    chapter: "viewer.md",
    main_job: false,
};

pub const CLUSTER: Experiment = Experiment {
    name: "cluster",
    about: "Table 1 unsharded against four shards through a local Slurm, merged (needs root)",
    folder: "cluster",
    measure: Measure::Script("scripts/measure-sharded-table1.sh", &[]),
    section: None,
    chapter: "cluster.md",
    main_job: false,
};

pub const GPU: Experiment = Experiment {
    name: "gpu",
    about: "every GPU measurement in one command, on a lent GPU machine (scripts/gpu-prepare.sh builds it)",
    folder: "gpu",
    measure: Measure::Script("scripts/gpu-measure.sh", &[]),
    section: None,
    chapter: "gpu.md",
    main_job: false,
};
