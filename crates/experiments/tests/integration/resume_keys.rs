//! Sweeps resume by key: the keys this code gives the preset sweeps must be exactly those of
//! the `results.jsonl` files written before the method registry existed (copied into
//! `tests/data/` from `reports/` at commit 83da7cf), or every earlier sweep would be measured
//! again from scratch.

use mirrorbox_experiments::{bumpy, depth_scaling, lighting, stereo, symmetry_scaling, table1};
use mirrorbox_harness::{SweepConfig, point_keys};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn keys_in(file: &str) -> BTreeSet<String> {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(file)).unwrap();
    text.lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            v["key"].as_str().unwrap().to_string()
        })
        .collect()
}

fn keys_of(mut config: SweepConfig) -> BTreeSet<String> {
    config.scene = root().join(&config.scene);
    let keys = point_keys(&config).unwrap();
    let set: BTreeSet<String> = keys.iter().cloned().collect();
    assert_eq!(set.len(), keys.len(), "duplicate keys: {keys:?}");
    set
}

/// Table 1 moved from 9 to 15 timed frames (issue 54); at the earlier frame count the keys
/// are the earlier ones.
#[test]
fn table1_keys_are_those_of_earlier_sweeps() {
    let preset = table1::sweep("unused".as_ref());
    assert_eq!(preset.frames, 15);
    let now = keys_of(SweepConfig {
        frames: 9,
        ..preset
    });
    let before = keys_in("tests/data/table1_results_session2.jsonl");
    assert_eq!(now, before);
    assert_eq!(now.len(), 1 + 2 * (5 + 2));
}

/// The preset moved from 5 to 9 timed frames (a new experiment, measured again, with a 95 %
/// interval per median); at the earlier frame count the keys are the earlier ones.
#[test]
fn depth_scaling_keys_are_those_of_earlier_sweeps() {
    let preset = depth_scaling::sweep("unused".as_ref());
    assert_eq!(preset.frames, 9);
    let now = keys_of(SweepConfig {
        frames: 5,
        ..preset
    });
    let before = keys_in("tests/data/depth_scaling_results_session2.jsonl");
    assert_eq!(now, before);
    assert_eq!(now.len(), 1 + 2 * 11);
}

#[test]
fn the_paper_method_is_registered() {
    let m = mirrorbox_raster::registry::find(mirrorbox_experiments::table1::rows::PAPER_METHOD)
        .expect("Table 1's method is in the raster registry");
    assert!(m.swept.is_some_and(|o| o.name == "n"));
}

/// The committed reports of the presets with scene axes: this code's keys are the keys in
/// their `results.jsonl` (a resumed sweep measures nothing again), and every record read back
/// carries its axes in the map, the ones written before the map included.
#[test]
fn the_axis_presets_resume_from_the_committed_reports() {
    for (config, folder, axis) in [
        (
            symmetry_scaling::sweep("unused".as_ref()),
            "symmetry_scaling",
            "planes",
        ),
        (
            lighting::sweep("unused".as_ref()),
            "lighting",
            "mirrored_lights",
        ),
        (
            lighting::room_sweep("unused".as_ref()),
            "lighting_room",
            "mirrored_lights",
        ),
        (
            bumpy::sweep("unused".as_ref()),
            "uneven_mirrors",
            "bump_deg",
        ),
        (
            bumpy::single_sweep("unused".as_ref()),
            "uneven_mirrors_single",
            "bump_deg",
        ),
        (stereo::sweep("unused".as_ref()), "stereo", "stereo_ipd"),
    ] {
        let now = keys_of(config);
        let path = root().join("reports").join(folder).join("results.jsonl");
        let records = mirrorbox_report::read_records(&path).unwrap();
        let committed: BTreeSet<String> = records.iter().map(|r| r.key.clone()).collect();
        assert_eq!(now, committed, "{folder}");
        for r in records.iter().filter(|r| r.kind == "point") {
            let fragment = format!("|{axis}=");
            if r.key.contains(&fragment) {
                let v = r
                    .axis(axis)
                    .unwrap_or_else(|| panic!("{folder}: {} has no {axis}", r.key));
                let text = r
                    .key
                    .split(&fragment)
                    .nth(1)
                    .unwrap()
                    .split('|')
                    .next()
                    .unwrap();
                assert_eq!(text.parse::<f64>().unwrap(), v, "{folder}: {}", r.key);
            }
        }
    }
}
