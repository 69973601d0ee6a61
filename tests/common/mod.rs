//! What the end-to-end tests share: the repository root and running `mirrorbox` as a user
//! does (a real process, its exit code and its output).
#![allow(dead_code)] // each test file uses its own subset

use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::process::Command;

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

pub struct Output {
    pub code: i32,
    pub stdout: String,
    pub stderr: String,
}

pub fn mirrorbox(args: &[&str], envs: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_mirrorbox"));
    cmd.args(args).current_dir(repo());
    // Images, not times: keep Mesa's shader cache, which timing commands turn off (issue 54;
    // `scripts/test.sh` says so for every process of the suite).
    cmd.env("MESA_SHADER_CACHE_DISABLE", "false");
    for (k, v) in envs {
        cmd.env(k, v);
    }
    let out = cmd.output().expect("run mirrorbox");
    Output {
        code: out.status.code().expect("exited normally, not by a signal"),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// Runs `mirrorbox ARGS` and checks that it refused them: exit 2, `expected` in its message.
pub fn assert_refused(args: &[&str], expected: &str) {
    let run = mirrorbox(args, &[]);
    assert_eq!(run.code, 2, "{args:?}: {}", run.stderr);
    assert!(run.stderr.contains(expected), "{args:?}: {}", run.stderr);
}

/// A small valid two-mirror scene; each test breaks or extends one thing in it.
pub fn valid_scene() -> Value {
    json!({
        "camera": { "position": [0, 1, 3], "look_at": [0, 1, 0], "fov_y_deg": 60,
                    "width": 32, "height": 24 },
        "mirrors": [
            { "center": [0, 1, -2], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 4, "height": 3 },
            { "center": [0, 1, 2], "normal": [0, 0, -1], "up": [0, 1, 0], "width": 4, "height": 3 }
        ],
        "objects": [ { "type": "sphere", "radius": 0.5 } ],
        "lights": [ { "position": [0, 2.5, 0], "intensity": [10, 10, 10] } ]
    })
}

/// A sweep folder's records (`results.jsonl`), none if it has no file.
pub fn sweep_records(dir: &Path) -> Vec<Value> {
    std::fs::read_to_string(dir.join("results.jsonl"))
        .unwrap_or_default()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// The arguments of the small sweep the shard tests split (mirror_box, 48×27, 7 points).
pub const SMALL_SWEEP: [&str; 15] = [
    "scenes/mirror_box.json",
    "--methods",
    "naive,auxiliary",
    "--n",
    "0,1",
    "--alpha",
    "0.7,0.9",
    "--width",
    "48",
    "--height",
    "27",
    "--frames",
    "1",
    "--warmup",
    "0",
];

/// Runs `cmd` to its end and asserts that it succeeded (the message: `what`, then its stderr);
/// its output.
pub fn succeed(cmd: &mut Command, what: &str) -> std::process::Output {
    let out = cmd.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        out.status.success(),
        "{what}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// How many pixels of two images of one size differ in any bit of any channel (0: the same
/// image bit for bit).
pub fn pixels_differing_in_bits(
    a: &mirrorbox_image::RgbImage,
    b: &mirrorbox_image::RgbImage,
) -> usize {
    assert_eq!((a.width, a.height), (b.width, b.height), "image sizes");
    a.pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| p.map(f32::to_bits) != q.map(f32::to_bits))
        .count()
}

/// A merged sweep (`merged`, its folder `merged_dir`) holds exactly the points of `full`
/// (folder `full_dir`), with the same errors (metrics may differ in the last bit: parallel
/// sums) and the same raster and truth pictures, byte for byte.
pub fn assert_same_points(full: &[Value], full_dir: &Path, merged: &[Value], merged_dir: &Path) {
    assert_eq!(merged.len(), full.len(), "points");
    for r in merged {
        let f = full
            .iter()
            .find(|f| f["key"] == r["key"])
            .unwrap_or_else(|| panic!("{} is not a point of the unsharded sweep", r["key"]));
        for m in ["flip_mean", "rmse", "ssim"] {
            let (a, b) = (
                f["metrics"][m].as_f64().unwrap(),
                r["metrics"][m].as_f64().unwrap(),
            );
            assert!((a - b).abs() <= 1e-12 * a.abs().max(1.0), "{m}: {a} vs {b}");
        }
        for image in ["raster_image", "truth_image"] {
            let name = r[image].as_str().unwrap();
            assert_eq!(
                std::fs::read(merged_dir.join(name)).unwrap(),
                std::fs::read(full_dir.join(name)).unwrap(),
                "{name}"
            );
        }
    }
}
