//! The experiments measured by a script rather than a sweep: costs of the truth, memory
//! peaks, benches against Mitsuba, the viewer's frame rates, a cluster run and the GPU
//! measurements (each script's header says what it does and writes).

pub mod gpu;

use crate::{Experiment, Measure};
use mirrorbox_report::overview::OtherReport;
use mirrorbox_report::readme::{RegionSource, report_body_region, report_summary_region};

pub const LIGHTING_TRACE_COST: Experiment = Experiment {
    name: "lighting-trace-cost",
    about: "the truth's cost against the mirrored-light depth k (one trace per k, median of runs)",
    folder: "lighting",
    measure: Measure::Script("scripts/lighting-trace-cost.sh", &[]),
    section: None,
    regions: crate::lighting::trace_cost::REGIONS,
    chapter: "lighting.md",
    main_job: true,
    overview: None,
};

pub const MEMORY_PEAKS: Experiment = Experiment {
    name: "memory-peaks",
    about: "the peak memory of every bundled scene with every method, against the 2 GB budget",
    folder: "memory",
    measure: Measure::Script("scripts/memory-peaks.sh", &[]),
    section: None,
    regions: &[],
    chapter: "robustness.md",
    main_job: true,
    overview: Some(OtherReport {
        report: "memory/peaks.md",
        data: "memory/peaks.md",
        scene: "every bundled scene",
    }),
};

pub const TRACER_BENCH: Experiment = Experiment {
    name: "tracer-bench",
    about: "the tracer against Mitsuba 3's compiled kernel, per round, one record per CPU kind, vector width and core count",
    folder: "tracer",
    measure: Measure::Script("scripts/bench-tracer.sh", &["7", "16"]),
    section: None,
    regions: TRACER_BENCH_REGIONS,
    chapter: "tracer-performance.md",
    main_job: false,
    overview: Some(OtherReport {
        report: "tracer/bench.md",
        data: "tracer/bench.json",
        scene: "scenes/mirror_box.json, scenes/mirror_room.json",
    }),
};

pub const GPU_TRUTH: Experiment = Experiment {
    name: "gpu-truth",
    about: "the truth traced on the GPU by ray queries against the CPU truth: time and largest difference at 640×360×16",
    folder: "gpu_truth",
    measure: Measure::Script("scripts/gpu-truth-bench.sh", &["5"]),
    section: None,
    regions: &[],
    chapter: "engine-reflections.md",
    main_job: false,
    overview: None,
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
    regions: VIEWER_FRAME_RATES_REGIONS,
    chapter: "viewer.md",
    main_job: false,
    overview: Some(OtherReport {
        report: "viewer/frame_rates.md",
        data: "viewer/frame_rates.json",
        scene: "scenes/mirror_box.json",
    }),
};

pub const CLUSTER: Experiment = Experiment {
    name: "cluster",
    about: "Table 1 unsharded against four shards through a local Slurm, merged (needs root)",
    folder: "cluster",
    measure: Measure::Script("scripts/measure-sharded-table1.sh", &[]),
    section: None,
    regions: &[],
    chapter: "cluster.md",
    main_job: false,
    overview: None,
};

pub const GPU: Experiment = Experiment {
    name: "gpu",
    about: "every GPU measurement in one command, on a lent GPU machine (scripts/gpu-prepare.sh builds it)",
    folder: "gpu",
    measure: Measure::Script("scripts/gpu-measure.sh", &[]),
    section: None,
    regions: gpu::REGIONS,
    chapter: "gpu.md",
    main_job: false,
    overview: Some(OtherReport {
        report: "gpu/README.md",
        data: "gpu/info.json",
        scene: "–",
    }),
};

/// The regions of the tracer chapter: the script's report, and its summary.
const TRACER_BENCH_REGIONS: &[RegionSource] = &[
    RegionSource {
        id: "tracer-bench",
        source: "tracer/bench.md",
        about: "the tracer against Mitsuba 3 side by side (scripts/bench-tracer.sh)",
        generate: |reports| report_body_region(&reports.join("tracer/bench.md")),
    },
    RegionSource {
        id: "tracer-bench-summary",
        source: "tracer/bench.md",
        about: "the tracer against Mitsuba 3: one row per CPU kind, vector width and core count measured, with the goals",
        generate: |reports| report_summary_region(&reports.join("tracer/bench.md")),
    },
];

/// The region of the viewer chapter: the script's report.
const VIEWER_FRAME_RATES_REGIONS: &[RegionSource] = &[RegionSource {
    id: "viewer-frame-rates",
    source: "viewer/frame_rates.md",
    about: "`mirrorbox view`'s frame rates per method, still and walking (scripts/viewer-frame-rates.sh)",
    generate: |reports| report_body_region(&reports.join("viewer/frame_rates.md")),
}];
