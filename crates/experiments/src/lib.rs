//! The experiment registry, the twin of the raster method table: every experiment mirrorbox
//! measures is one module here — its sweeps (or sequence, or script), its report section when
//! it has one of its own, its book chapter — and one row of [`EXPERIMENTS`]. From the table
//! follow the CLI (`mirrorbox experiment NAME`, `--list`, `--main-job`), the main job
//! (`scripts/run.sh` runs `mirrorbox experiment --main-job`), the report writer (every
//! sweep's report is offered every experiment's section) and the book (`mirrorbox readme`
//! fills each chapter's `experiment-NAME` region, and fails when a chapter lacks it).
//! CONTRIBUTING.md, "Adding an experiment", says how to add one.

use mirrorbox_harness::SweepConfig;
use mirrorbox_harness::sequence::SequenceConfig;
use mirrorbox_report::Section;
use mirrorbox_report::overview::OtherReport;
use mirrorbox_report::readme::RegionSource;
use std::path::{Path, PathBuf};

pub mod advise;
pub mod bumpy;
pub mod depth_scaling;
pub mod engine_reflections;
pub mod findings;
pub mod frontier;
pub mod lighting;
pub mod motion;
pub mod real_assets;
pub mod scripts;
pub mod stereo;
pub mod symmetry_scaling;
pub mod table1;
pub mod web_engines;

/// How an experiment is measured.
pub enum Measure {
    /// Sweeps, each writing one report folder, made from the experiment's output folder
    /// (default `reports/<folder>`; an experiment of several sweeps names the others after it).
    Sweeps(fn(&Path) -> Vec<SweepConfig>),
    /// Sequence sweeps along camera paths, from the output folder, this executable (each
    /// method's frames run in one child process) and the command line.
    Sequences(fn(&Path, PathBuf, String) -> SequenceConfig),
    /// A script of the repository (`scripts/…`) with its arguments, run from the repository
    /// root with `MIRRORBOX` set to this executable: measurements that are not sweeps.
    Script(&'static str, &'static [&'static str]),
}

/// One experiment (see the crate doc).
pub struct Experiment {
    /// `mirrorbox experiment NAME`.
    pub name: &'static str,
    /// What it measures, in one line (the CLI's help, the book's region).
    pub about: &'static str,
    /// Its report folder under `reports/`.
    pub folder: &'static str,
    pub measure: Measure,
    /// Its own report section, offered every sweep's records (the sections of the report
    /// crate, or one in the experiment's module); `None`: the report every sweep has.
    pub section: Option<Section>,
    /// The README/book regions made from its reports (`mirrorbox readme`), beside the region
    /// `experiment-NAME` every row has.
    pub regions: &'static [RegionSource],
    /// Its entry in the reports' overview when its report is not a sweep folder (a sequence
    /// sweep's, a script's); sweep folders are found by the overview itself.
    pub overview: Option<OtherReport>,
    /// Its chapter of the book, under `docs/book/src/`; the chapter holds the generated region
    /// `experiment-NAME`.
    pub chapter: &'static str,
    /// Run by the main job (`scripts/run.sh`), in the table's order.
    pub main_job: bool,
}

/// Every experiment, in the main job's order.
pub const EXPERIMENTS: &[&Experiment] = &[
    &table1::TABLE1,
    &table1::TABLE1_REPEAT,
    &table1::TABLE1_RUNS,
    &depth_scaling::DEPTH_SCALING,
    &symmetry_scaling::SYMMETRY_SCALING,
    &lighting::LIGHTING,
    &bumpy::BUMPY,
    &stereo::STEREO,
    &motion::MOTION,
    &frontier::FRONTIER,
    &engine_reflections::ENGINE_REFLECTIONS,
    &real_assets::REAL_ASSETS,
    &web_engines::WEB_ENGINES,
    &advise::ADVISE,
    &scripts::GPU_TRUTH,
    &scripts::LIGHTING_TRACE_COST,
    &scripts::MEMORY_PEAKS,
    &scripts::TRACER_BENCH,
    &scripts::VIEWER_FRAME_RATES,
    &scripts::CLUSTER,
    &scripts::GPU,
];

/// The experiment named `name`.
pub fn find(name: &str) -> Option<&'static Experiment> {
    EXPERIMENTS.iter().copied().find(|e| e.name == name)
}

/// Every experiment's own report section, once each, in the table's order: what every sweep's
/// report is offered.
pub fn sections() -> Vec<Section> {
    let mut out: Vec<Section> = Vec::new();
    for s in EXPERIMENTS.iter().filter_map(|e| e.section) {
        if !out.iter().any(|o| std::ptr::fn_addr_eq(*o, s)) {
            out.push(s);
        }
    }
    out
}

/// Every region made from the committed reports: the generic ones
/// ([`mirrorbox_report::readme::REGIONS`]), then each experiment's, in the table's order.
pub fn regions() -> Vec<RegionSource> {
    let mut out = mirrorbox_report::readme::REGIONS.to_vec();
    out.extend_from_slice(FINDINGS_REGIONS);
    for e in EXPERIMENTS {
        out.extend_from_slice(e.regions);
    }
    out
}

/// What was found ([`findings`]), quoted in the README and the book's introduction.
/// Then each chapter's own findings, at its top (region `found-<chapter>`).
const FINDINGS_REGIONS: &[RegionSource] = &[
    RegionSource {
        id: "findings",
        source: "table1",
        about: "what was found, ranked, computed from the committed records",
        generate: |reports| Ok(findings::with_paths(&findings::findings(reports)?)),
    },
    found("found-table1", "table1", |r| {
        findings::chapter_findings(r, "table1.md")
    }),
    found("found-gpu", "gpu", |r| {
        findings::chapter_findings(r, "gpu.md")
    }),
    found("found-frontier", "frontier_room", |r| {
        findings::chapter_findings(r, "frontier.md")
    }),
    found("found-exact-methods", "depth_scaling", |r| {
        findings::chapter_findings(r, "exact-methods.md")
    }),
    found("found-exchange", "web_engines", |r| {
        findings::chapter_findings(r, "exchange.md")
    }),
    found(
        "found-engine-reflections",
        "engine_reflections_ssr_room",
        |r| findings::chapter_findings(r, "engine-reflections.md"),
    ),
    found("found-stereo", "stereo", |r| {
        findings::chapter_findings(r, "stereo.md")
    }),
    found("found-lighting", "lighting", |r| {
        findings::chapter_findings(r, "lighting.md")
    }),
    found("found-symmetry", "symmetry_scaling", |r| {
        findings::chapter_findings(r, "symmetry.md")
    }),
    found("found-uneven-mirrors", "uneven_mirrors", |r| {
        findings::chapter_findings(r, "uneven-mirrors.md")
    }),
];

/// A chapter's findings region.
const fn found(
    id: &'static str,
    source: &'static str,
    generate: fn(&std::path::Path) -> Result<String, mirrorbox_report::readme::ReadmeError>,
) -> RegionSource {
    RegionSource {
        id,
        source,
        about: "the findings this chapter opens with, from the ranked findings",
        generate,
    }
}

/// The overview's entries of the reports that are not sweep folders, in the table's order.
pub fn other_reports() -> Vec<OtherReport> {
    EXPERIMENTS.iter().filter_map(|e| e.overview).collect()
}

/// `out` with `suffix` appended to its last component (`reports/lighting` →
/// `reports/lighting_room`): the second sweep of an experiment.
pub fn beside(out: &Path, suffix: &str) -> PathBuf {
    let mut s = out.as_os_str().to_os_string();
    s.push(suffix);
    s.into()
}

impl Experiment {
    /// Its default output folder, `reports/<folder>`.
    pub fn default_out(&self) -> PathBuf {
        Path::new("reports").join(self.folder)
    }

    /// The region of its chapter that `mirrorbox readme` fills from this row.
    pub fn region_id(&self) -> String {
        format!("experiment-{}", self.name)
    }

    /// The region's Markdown: what the experiment measures, the command that runs it, where it
    /// writes, whether the main job runs it (no links: a region may sit at any depth).
    pub fn region_text(&self) -> String {
        let how = match &self.measure {
            Measure::Sweeps(configs) => {
                let folders: Vec<String> = configs(&self.default_out())
                    .iter()
                    .map(|c| format!("`{}/`", c.out.display()))
                    .collect();
                format!(
                    "{} sweep{} into {}",
                    folders.len(),
                    if folders.len() == 1 { "" } else { "s" },
                    folders.join(" and ")
                )
            }
            Measure::Sequences(_) => format!(
                "sequence sweeps along camera paths into `{}/`",
                self.default_out().display()
            ),
            Measure::Script(script, args) => {
                let args = if args.is_empty() {
                    String::new()
                } else {
                    format!(" {}", args.join(" "))
                };
                format!(
                    "`{script}{args}`, writing under `{}/`",
                    self.default_out().display()
                )
            }
        };
        format!(
            "**Experiment `{}`** — {}.\n\n- Run: `mirrorbox experiment {}` — {how}.\n- Main job \
             (`scripts/run.sh`): {}.\n- Report section of its own: {}.\n",
            self.name,
            self.about,
            self.name,
            if self.main_job { "yes" } else { "no" },
            if self.section.is_some() { "yes" } else { "no" }
        )
    }
}
