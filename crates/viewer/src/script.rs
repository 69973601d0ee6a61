//! `mirrorbox view --script FILE`: timed actions that drive the viewer as a person would,
//! for tests and reproducible demos. One action per line; `#` starts a comment.
//!
//! | action | effect |
//! |---|---|
//! | `frames N` | draw N frames |
//! | `seconds S` | draw frames for S seconds (keys and the mouse work meanwhile) |
//! | `wait-truth [SECONDS]` | draw frames until the live truth of the current view is complete (default 300 s; past it the viewer fails, exit 1) |
//! | `method NAME [OPTION=VALUE]...` | switch the method, as `sweep` keys name it (`auxiliary n=2`) |
//! | `ssaa S` | supersampling factor |
//! | `error difference\|flip` | the error view's map |
//! | `truth on\|off` | the live truth (off: the method has the CPU to itself, for timing) |
//! | `walk FORWARD RIGHT UP` | move the camera by these scene units along the view |
//! | `turn YAW PITCH` | turn by degrees (positive: right, up) |
//! | `look X Y Z at X Y Z` | place the camera at a point looking at another |
//! | `reset-camera` | back to the scene's camera |
//! | `resize W H` | ask for a window of W × H pixels |
//! | `screenshot PATH.png` | the window as shown, with the method, truth and heat map beside it (see the viewer's docs) |
//! | `save-camera PATH.json` | a copy of the scene file with the current camera |
//! | `exit` | close the viewer (exit 0); the end of the script does the same |

use mirrorbox_raster::Method;
use std::path::{Path, PathBuf};

/// Most actions a script may hold, and most frames one `frames` line may ask for.
pub const MAX_ACTIONS: usize = 10_000;
pub const MAX_FRAMES: u32 = 100_000;
/// Largest window side a script (`resize`) or `--window` may ask for.
pub const MAX_WINDOW_SIDE: u32 = 8192;
/// Smallest window side, as `--window` takes it (`resize 1 1` had been taken: panes of 0 px).
pub const MIN_WINDOW_SIDE: u32 = 64;
/// Largest script file read.
pub const MAX_SCRIPT_BYTES: u64 = 1 << 20;

#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    Frames(u32),
    Seconds(f64),
    WaitTruth { seconds: f64 },
    Method(Method),
    Ssaa(u32),
    Error(crate::error_view::ErrorMode),
    Truth(bool),
    Walk([f32; 3]),
    Turn { yaw: f32, pitch: f32 },
    Look { position: [f32; 3], at: [f32; 3] },
    ResetCamera,
    Resize(u32, u32),
    Screenshot(PathBuf),
    SaveCamera(PathBuf),
    Exit,
}

/// A script action with where it came from, for messages.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    pub line: usize,
    pub action: Action,
}

/// A script's problem at `file:line`; line 0 is the file as a whole (it could not be read),
/// whose message names the file itself.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("{}{message}", where_in(file, *line))]
pub struct ScriptError {
    pub file: String,
    pub line: usize,
    pub message: String,
}

/// `file:line: ` before a message, nothing for line 0 (the message names the file).
fn where_in(file: &str, line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!("{file}:{line}: ")
    }
}

/// Reads and parses a script file (at most [`MAX_SCRIPT_BYTES`]).
pub fn read_script(path: &Path) -> Result<Vec<Step>, ScriptError> {
    let text = mirrorbox_files::read_bounded_text(path, MAX_SCRIPT_BYTES, "viewer script")
        .map_err(|e| ScriptError {
            file: path.display().to_string(),
            line: 0,
            message: e.to_string(),
        })?;
    parse_script(&text, &path.display().to_string())
}

/// Parses a script's text; `file` names it in errors.
pub fn parse_script(text: &str, file: &str) -> Result<Vec<Step>, ScriptError> {
    let mut steps = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let error = |message: String| ScriptError {
            file: file.into(),
            line: i + 1,
            message,
        };
        if steps.len() == MAX_ACTIONS {
            return Err(error(format!("more than {MAX_ACTIONS} actions")));
        }
        let action = parse_action(line).map_err(error)?;
        steps.push(Step {
            line: i + 1,
            action,
        });
    }
    Ok(steps)
}

/// Checks the files `action` would write (a screenshot and its companions, a scene copy),
/// before the window opens: their folder exists, none is a folder, and none is one of
/// `inputs` (`(what, path)`: the scene file, the script). Without it a screenshot `s.png`
/// replaced a scene `s.json` with its metadata, and a missing folder failed only after the
/// window ran.
pub fn check_writes(action: &Action, inputs: &[(&str, &Path)]) -> Result<(), String> {
    let files = match action {
        Action::Screenshot(png) => crate::screenshot::files(png).to_vec(),
        Action::SaveCamera(json) => vec![json.clone()],
        _ => return Ok(()),
    };
    check_files(&files, inputs)?;
    // A scene copy goes beside the scene, whose relative paths it keeps.
    if let (Action::SaveCamera(json), Some((_, scene))) =
        (action, inputs.iter().find(|(what, _)| *what == SCENE_INPUT))
    {
        crate::scene_copy::beside(scene, json)?;
    }
    Ok(())
}

/// The name of the scene file among [`check_writes`]'s `inputs`.
pub const SCENE_INPUT: &str = "the scene";

/// [`check_writes`] for files written together (the first one's folder is theirs): the
/// folder exists, none is a folder, none is one of `inputs`. Also the check of `view --log`.
pub fn check_files(files: &[PathBuf], inputs: &[(&str, &Path)]) -> Result<(), String> {
    let parent = mirrorbox_files::folder_of(&files[0]);
    if !parent.is_dir() {
        return Err(format!(
            "{}: folder {} does not exist",
            files[0].display(),
            parent.display()
        ));
    }
    for file in files {
        if file.is_dir() {
            return Err(format!(
                "{}: would write this file, but it is a folder",
                file.display()
            ));
        }
        for (what, input) in inputs {
            if mirrorbox_files::resolved(file) == mirrorbox_files::resolved(input) {
                return Err(format!(
                    "{} would be written, but it is {what} ({}); choose another name",
                    file.display(),
                    input.display()
                ));
            }
        }
    }
    Ok(())
}

/// [`check_writes`] for every step of a script read from `file`, naming the line.
pub fn check_script_writes(
    steps: &[Step],
    file: &str,
    inputs: &[(&str, &Path)],
) -> Result<(), ScriptError> {
    for step in steps {
        check_writes(&step.action, inputs).map_err(|message| ScriptError {
            file: file.into(),
            line: step.line,
            message,
        })?;
    }
    Ok(())
}

fn parse_action(line: &str) -> Result<Action, String> {
    let mut words = line.split_whitespace();
    let verb = words.next().unwrap_or("");
    let args: Vec<&str> = words.collect();
    let count = |n: usize, usage: &str| {
        if args.len() == n {
            Ok(())
        } else {
            Err(format!("`{verb}` takes {usage}, got {line:?}"))
        }
    };
    let real = |s: &str, what: &str| -> Result<f32, String> {
        s.parse::<f32>()
            .ok()
            .filter(|v| v.is_finite() && v.abs() <= 1e6)
            .ok_or_else(|| format!("{what} must be a number within ±1e6, got {s:?}"))
    };
    let whole = |s: &str, what: &str, min: u32, max: u32| -> Result<u32, String> {
        s.parse::<u32>()
            .ok()
            .filter(|v| (min..=max).contains(v))
            .ok_or_else(|| format!("{what} must be a whole number in [{min}, {max}], got {s:?}"))
    };
    Ok(match verb {
        "frames" => {
            count(1, "one count")?;
            Action::Frames(whole(args[0], "the frame count", 1, MAX_FRAMES)?)
        }
        "seconds" => {
            count(1, "a number of seconds")?;
            let seconds = f64::from(real(args[0], "the time")?);
            if !(seconds > 0.0 && seconds <= 86_400.0) {
                return Err(format!(
                    "the time must be in (0, 86400] seconds, got {seconds}"
                ));
            }
            Action::Seconds(seconds)
        }
        "wait-truth" => {
            if args.len() > 1 {
                return Err(format!(
                    "`wait-truth` takes at most one number of seconds, got {line:?}"
                ));
            }
            let seconds = match args.first() {
                Some(s) => f64::from(real(s, "the timeout")?),
                None => 300.0,
            };
            if !(seconds > 0.0 && seconds <= 86_400.0) {
                return Err(format!(
                    "the timeout must be in (0, 86400] seconds, got {seconds}"
                ));
            }
            Action::WaitTruth { seconds }
        }
        "method" => {
            if args.is_empty() {
                return Err(format!(
                    "`method` takes a method name and options, e.g. `method auxiliary n=2` (known: {})",
                    mirrorbox_raster::registry::names()
                ));
            }
            Action::Method(Method::parse(&args.join(" ")).map_err(|e| e.to_string())?)
        }
        "ssaa" => {
            count(1, "one factor")?;
            Action::Ssaa(whole(
                args[0],
                "the SSAA factor",
                1,
                mirrorbox_raster::MAX_SSAA,
            )?)
        }
        "error" => {
            count(1, "`difference` or `flip`")?;
            Action::Error(crate::error_view::ErrorMode::parse(args[0]).ok_or_else(|| {
                format!("the error map is `difference` or `flip`, got {:?}", args[0])
            })?)
        }
        "truth" => {
            count(1, "`on` or `off`")?;
            Action::Truth(match args[0] {
                "on" => true,
                "off" => false,
                other => return Err(format!("`truth` takes `on` or `off`, got {other:?}")),
            })
        }
        "walk" => {
            count(3, "three distances (forward, right, up)")?;
            Action::Walk([
                real(args[0], "forward")?,
                real(args[1], "right")?,
                real(args[2], "up")?,
            ])
        }
        "turn" => {
            count(2, "two angles in degrees (yaw, pitch)")?;
            Action::Turn {
                yaw: real(args[0], "yaw")?,
                pitch: real(args[1], "pitch")?,
            }
        }
        "look" => {
            if args.len() != 7 || args[3] != "at" {
                return Err(format!("`look` takes `X Y Z at X Y Z`, got {line:?}"));
            }
            let p = |i: usize| real(args[i], "a coordinate");
            let position = [p(0)?, p(1)?, p(2)?];
            let at = [p(4)?, p(5)?, p(6)?];
            if position == at {
                return Err("`look`: the camera cannot look at its own position".into());
            }
            Action::Look { position, at }
        }
        "reset-camera" => {
            count(0, "nothing")?;
            Action::ResetCamera
        }
        "resize" => {
            count(2, "a width and a height in pixels")?;
            Action::Resize(
                whole(args[0], "the width", MIN_WINDOW_SIDE, MAX_WINDOW_SIDE)?,
                whole(args[1], "the height", MIN_WINDOW_SIDE, MAX_WINDOW_SIDE)?,
            )
        }
        "screenshot" => {
            count(1, "a .png path")?;
            if !args[0].ends_with(".png") {
                return Err(format!(
                    "the screenshot path must end in .png, got {:?}",
                    args[0]
                ));
            }
            Action::Screenshot(PathBuf::from(args[0]))
        }
        "save-camera" => {
            count(1, "a .json path")?;
            if !args[0].ends_with(".json") {
                return Err(format!(
                    "the scene copy's path must end in .json, got {:?}",
                    args[0]
                ));
            }
            Action::SaveCamera(PathBuf::from(args[0]))
        }
        "exit" => {
            count(0, "nothing")?;
            Action::Exit
        }
        other => {
            return Err(format!(
                "unknown action {other:?} (known: frames, seconds, wait-truth, method, ssaa, error, truth, \
                 walk, turn, look, reset-camera, resize, screenshot, save-camera, exit)"
            ));
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_script_parses_with_comments_and_blank_lines() {
        let steps = parse_script(
            "# a tour\nframes 3\n\nmethod auxiliary n=2  # the paper's\nwalk 0.5 0 0\nturn 10 -5\n\
             look 0 1 2 at 0 1 -2\nresize 800 600\nwait-truth 60\nerror flip\nssaa 2\n\
             screenshot out.png\nsave-camera view.json\nreset-camera\nexit\n",
            "tour.txt",
        )
        .unwrap();
        assert_eq!(steps.len(), 13);
        assert_eq!(
            steps[0],
            Step {
                line: 2,
                action: Action::Frames(3)
            }
        );
        assert_eq!(steps[1].line, 4);
        assert_eq!(
            steps[1].action,
            Action::Method(Method::parse("auxiliary n=2").unwrap())
        );
        assert_eq!(steps[6].action, Action::WaitTruth { seconds: 60.0 });
    }

    #[test]
    fn bad_lines_name_the_file_the_line_and_what_is_allowed() {
        let cases = [
            (
                "frames 0",
                "frame count must be a whole number in [1, 100000]",
            ),
            ("frames", "`frames` takes one count"),
            ("method nope", "unknown method"),
            ("method auxiliary n=99", "--n must be"),
            (
                "resize 0 10",
                "the width must be a whole number in [64, 8192]",
            ),
            ("walk 1 nan 0", "right must be a number"),
            ("screenshot out.jpg", "must end in .png"),
            ("look 0 0 0 at 0 0 0", "its own position"),
            ("fly", "unknown action \"fly\""),
            ("wait-truth -1", "the timeout must be in (0, 86400]"),
            ("error blur", "`difference` or `flip`"),
            ("truth maybe", "`truth` takes `on` or `off`"),
            ("seconds 0", "the time must be in (0, 86400]"),
        ];
        for (line, expected) in cases {
            let e = parse_script(&format!("frames 1\n{line}\n"), "s.txt").unwrap_err();
            assert_eq!((e.file.as_str(), e.line), ("s.txt", 2), "{line}");
            assert!(e.message.contains(expected), "{line}: {}", e.message);
        }
    }
}
