//! Moving cameras (issue 22): error over time of the stateful methods (previous-frame
//! feedback, cube maps) against the stateless ones, still and walking.

use crate::{Experiment, Measure};
use mirrorbox_harness::sequence::{Scenario, SequenceConfig};
use mirrorbox_raster::Method;
use mirrorbox_report::overview::OtherReport;
use mirrorbox_report::sequence;
use std::path::{Path, PathBuf};

/// Frames per scenario.
const FRAMES: u32 = 12;

/// A still camera on the paper's box and `mirror_box_walk`'s path at two speeds, real time
/// and three times it (the stateful methods starting from 16 frames at the first view, as if
/// they had been showing it), beside `auxiliary` n = 0…4 and an exact method at depth 64;
/// 12 frames each (feedback converges within 3, and its lag shows from the first step). Each
/// frame is drawn once untimed and once timed (its time: one GPU-timestamped frame; the report
/// gives the median over the sequence's frames). Fewer frames and no quarter-speed walk than
/// before issue 38: the main job's 15 minutes had to hold the frontier experiment.
pub fn sequences(out: &Path, exe: PathBuf, command: String) -> SequenceConfig {
    let stateless: Vec<Method> = (0..=4)
        .map(|n| Method::parse(&format!("auxiliary n={n}")))
        .chain([Method::parse("unrolled depth=64")])
        .collect::<Result<_, _>>()
        .expect("the preset's methods are registered");
    let with_feedback = |history: u32| {
        let mut m: Vec<Method> = [
            format!("feedback history={history}"),
            format!("cubemap cube-size=256 history={history}"),
        ]
        .iter()
        .map(|k| Method::parse(k).expect("registered"))
        .collect();
        m.extend(stateless.iter().cloned());
        m
    };
    let walk = |name: &str, fps: f64, words: &str| Scenario {
        name: name.into(),
        description: format!("The camera walks the path of {words}"),
        scene: "scenes/mirror_box_walk.json".into(),
        start: 0.0,
        fps,
        frames: FRAMES,
        methods: with_feedback(16),
    };
    SequenceConfig {
        out: out.to_path_buf(),
        scenarios: vec![
            Scenario {
                name: "still".into(),
                description: "A still camera (the paper's view), `feedback` from its first frame:"
                    .into(),
                scene: "scenes/mirror_box.json".into(),
                start: 0.0,
                fps: 30.0,
                frames: FRAMES,
                methods: with_feedback(0),
            },
            walk("medium", 30.0, "real time (30 frames per second):"),
            walk("fast", 10.0, "three times real time:"),
        ],
        width: Some(320),
        height: Some(180),
        ssaa: 1,
        truth: mirrorbox_trace::WhittedSettings::default(),
        warmup: 1,
        timed: 1,
        exe,
        command,
        // The caller's `--fresh` (the main job passes it).
        replace: false,
    }
}

pub const MOTION: Experiment = Experiment {
    name: "motion",
    about: "error over time of previous-frame feedback and cube maps, still and walking",
    folder: "motion",
    measure: Measure::Sequences(sequences),
    section: None,
    regions: &[mirrorbox_report::readme::RegionSource {
        id: "motion",
        source: "motion",
        about: "error over time: feedback, cubemap, auxiliary and an exact method, still and walking (mirrorbox experiment motion)",
        generate: |reports| {
            let (info, records) = sequence::read_motion(&reports.join("motion"))
                .map_err(mirrorbox_report::readme::ReadmeError)?;
            Ok(sequence::summary(
                &info,
                &records,
                "mirrorbox experiment motion",
                "reports/motion/report.md",
            ))
        },
    }],
    chapter: "motion.md",
    main_job: true,
    overview: Some(OtherReport {
        report: "motion/report.md",
        data: "motion/frames.jsonl",
        scene: "scenes/mirror_box_walk.json",
    }),
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_motion_preset_is_valid_and_bad_counts_are_refused() {
        let mut c = sequences(Path::new("out"), "mirrorbox".into(), String::new());
        // Its scenes from the repository root, as `experiment` runs it (validate loads them).
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        for s in &mut c.scenarios {
            s.scene = root.join(&s.scene);
        }
        c.validate().unwrap();
        assert_eq!(c.scenarios.len(), 3);
        let mut bad = c.clone();
        bad.scenarios[0].frames = 0;
        assert!(bad.validate().unwrap_err().to_string().contains("--path"));
        let mut bad = c;
        bad.scenarios[1].fps = f64::NAN;
        assert!(bad.validate().unwrap_err().to_string().contains("--fps"));
    }
}
