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
