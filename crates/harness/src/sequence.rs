//! Sequence sweeps (issue 22): every method and the truth rendered frame by frame along a
//! camera path, each frame compared with the truth of that frame
//! (`mirrorbox sweep --path`, and `mirrorbox experiment motion`).
//!
//! Each sequence runs in a child process of this executable — `trace --sequence` for the
//! truth, `render --sequence` per method — so a stateful method (`feedback`) carries its
//! state from frame to frame as an engine would, and whatever lavapipe leaves behind per
//! frame (see [`crate::worker`]) goes back to the system when the sequence's process exits.
//! The frames land in `OUT/cache/<scenario>/` and are removed once compared; the records,
//! plots and the filmstrips of the stateful methods' worst frames stay in `OUT/`.

use crate::HarnessError;
use mirrorbox_image::metrics::Metrics;
use mirrorbox_image::{RgbImage, read_image};
use mirrorbox_raster::{Method, ParamValue};
use mirrorbox_report::sequence::{FrameRecord, MotionInfo, ScenarioInfo, write_motion_report};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Most frames of one sequence (a sequence sweep keeps every frame's images on disk).
pub const MAX_SEQUENCE_FRAMES: u32 = 1000;

/// One camera run: a scene (its `camera.path`, or a still camera), where it starts, how
/// fast path time passes per frame, and the methods rendered along it.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// A file-name-safe name (`still`, `slow`).
    pub name: String,
    /// One sentence for the report, ending before the scene's name.
    pub description: String,
    pub scene: PathBuf,
    /// Path time of frame 0, seconds.
    pub start: f64,
    /// Frames per second of path time: frame k is at `start + k / fps`.
    pub fps: f64,
    pub frames: u32,
    pub methods: Vec<Method>,
}

/// A sequence sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SequenceConfig {
    pub out: PathBuf,
    pub scenarios: Vec<Scenario>,
    /// Image size (default: each scene camera's), as `--width` / `--height` give it.
    pub width: Option<u32>,
    pub height: Option<u32>,
    /// Supersampling of the raster (the truth traces the same s×s grid, `--spp s²`).
    pub ssaa: u32,
    /// The truth's depth and throughput cut (`trace --max-depth`, `--min-throughput`).
    pub truth: mirrorbox_trace::WhittedSettings,
    /// Untimed and timed redraws of each frame (a frame's time is their median).
    pub warmup: u32,
    pub timed: u32,
    /// This executable (`mirrorbox`), run as the sequences' child processes.
    pub exe: PathBuf,
    pub command: String,
    /// Whether an earlier sequence sweep's report in `out` may be replaced (`--fresh`): a
    /// sequence sweep is not resumable and writes its folder anew.
    pub replace: bool,
}

/// Refuses an output folder a sequence sweep would spoil: one holding another kind of report
/// (its files would stay beside the new ones, and `report` would read them), or an earlier
/// sequence sweep's without `replace` (`--fresh`). Before, an earlier sequence sweep's
/// records were silently replaced.
fn check_sequence_out(out: &Path, replace: bool) -> Result<(), HarnessError> {
    let refuse = |why: String| crate::folder_refused(out, why);
    use crate::{ADVICE_FILES, SEQUENCE_FILES, SWEEP_FILES};
    if let Some(f) = SWEEP_FILES
        .iter()
        .chain(&ADVICE_FILES)
        .find(|f| out.join(f).exists())
    {
        return Err(refuse(format!(
            "holds another kind of report ({f}); a sequence sweep needs a folder of its own: \
             name another --out"
        )));
    }
    // A folder where the sweep will write a file: refused before rendering, not after.
    if let Some(f) = SEQUENCE_FILES.iter().find(|f| out.join(f).is_dir()) {
        return Err(refuse(format!(
            "{f} is a folder where the sweep writes a file: move it, or name another --out"
        )));
    }
    if !replace && let Some(f) = SEQUENCE_FILES.iter().find(|f| out.join(f).exists()) {
        return Err(refuse(format!(
            "holds an earlier sequence sweep ({f}), which this one would replace (a sequence \
             sweep is not resumed): pass --fresh to replace it, or name another --out"
        )));
    }
    Ok(())
}

impl SequenceConfig {
    /// Checks the sizes and counts before any work (exit 2 for the CLI).
    pub fn validate(&self) -> Result<(), HarnessError> {
        let bad = |m: String| Err(HarnessError::Sequence(m));
        if self.scenarios.is_empty() {
            return bad("no scenario to render".into());
        }
        for s in &self.scenarios {
            if !(1..=MAX_SEQUENCE_FRAMES).contains(&s.frames) {
                return bad(format!(
                    "--path must be in [1, {MAX_SEQUENCE_FRAMES}] frames, got {}",
                    s.frames
                ));
            }
            if !(s.fps.is_finite() && s.fps > 0.0 && s.fps <= 1000.0) {
                return bad(format!("--fps must be in (0, 1000], got {}", s.fps));
            }
            if s.methods.is_empty() {
                return bad(format!("scenario {}: no method", s.name));
            }
        }
        self.truth.check()?;
        // What the child processes would refuse, refused here before any folder is made (as
        // `sweep` refuses it): the scene, its size and the render settings, every frame's
        // time. Before, a bad one failed in a child (exit 1) after the folders were made.
        for s in &self.scenarios {
            let mut scene = mirrorbox_scene::load_scene(&s.scene)?;
            crate::check_compared_scene(
                &mut scene,
                (self.width, self.height),
                mirrorbox_raster::RenderSettings {
                    method: Method::named(crate::FLOOR_METHOD)
                        .expect("the floor method is registered"),
                    ssaa: self.ssaa,
                    frames: self.timed,
                    warmup: self.warmup,
                },
            )?;
            for k in 0..s.frames {
                let t = s.start + f64::from(k) / s.fps;
                if !(t.is_finite() && t.abs() <= 1e9) {
                    return bad(format!(
                        "--time: frame {k} is at {t} s; path times are finite and within ±1e9"
                    ));
                }
                scene
                    .camera_at_time(t)
                    .map_err(|e| HarnessError::Sequence(format!("{}: {e}", s.scene.display())))?;
            }
        }
        Ok(())
    }
}

/// The command-line flags of a configured method, every option not at its default:
/// `auxiliary n=2` → `--method auxiliary --n 2`.
fn method_flags(method: &Method) -> Vec<String> {
    let entry = method.entry();
    let mut flags = vec!["--method".to_string(), entry.name.to_string()];
    for (o, v) in entry.options.iter().zip(method.params().values()) {
        match v {
            _ if *v == o.default => {}
            ParamValue::Switch(true) => flags.push(format!("--{}", o.name)),
            ParamValue::Switch(false) => {}
            v => flags.extend([format!("--{}", o.name), v.to_string()]),
        }
    }
    flags
}

/// Runs `exe args`, returning its standard output; a failure names the command and its
/// standard error.
fn run(exe: &Path, args: &[String]) -> Result<String, HarnessError> {
    let out = Command::new(exe)
        .args(args)
        .output()
        .map_err(|e| HarnessError::Worker(format!("cannot start {}: {e}", exe.display())))?;
    if !out.status.success() {
        return Err(HarnessError::Worker(format!(
            "mirrorbox {} failed ({}): {}",
            args.join(" "),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        )));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Frame `k` of a sequence written to `base` (`truth.exr` → `truth_0003.exr`).
fn frame_path(base: &Path, k: u32) -> PathBuf {
    let stem = base.file_stem().unwrap_or_default().to_string_lossy();
    base.with_file_name(format!("{stem}_{k:04}.exr"))
}

/// The flags every child of `s` shares: its scene, frames, path time and size.
fn sequence_flags(config: &SequenceConfig, s: &Scenario) -> Vec<String> {
    let mut flags = vec![
        s.scene.display().to_string(),
        "--sequence".into(),
        s.frames.to_string(),
        "--fps".into(),
        s.fps.to_string(),
        "--time".into(),
        s.start.to_string(),
    ];
    for (flag, v) in [("--width", config.width), ("--height", config.height)] {
        if let Some(v) = v {
            flags.extend([flag.to_string(), v.to_string()]);
        }
    }
    flags
}

/// The median distance the camera moves per frame along `s`.
fn camera_step(s: &Scenario) -> Result<f64, HarnessError> {
    let scene = mirrorbox_scene::load_scene(&s.scene)?;
    let mut steps = Vec::new();
    let mut last = None;
    for k in 0..s.frames {
        let t = s.start + f64::from(k) / s.fps;
        let at = scene
            .at_time(t)
            .map_err(|e| HarnessError::Sequence(format!("{}: {e}", s.scene.display())))?;
        let p = at.camera.position;
        if let Some(q) = last {
            steps.push(f64::from(p.distance(q)));
        }
        last = Some(p);
    }
    Ok(if steps.is_empty() {
        0.0
    } else {
        mirrorbox_report::stats::median(&steps)
    })
}

/// Renders `method`'s frames of `s` in one child process (a stateful method carries its state
/// from frame to frame there). Returns each frame's summary and its EXR.
///
/// Until Mesa 25 a stateless method's sequence was split into children of at most 600 scene
/// passes, the first of a single frame: Mesa 22.3's lavapipe kept about 4 MB per executed pass
/// until the process exited. Mesa 25 does not (docs/budgets.md), and every child compiled its
/// shaders again — about 2 s each on lavapipe, 60 children where one per sequence makes 24:
/// `auxiliary n=4` (139 passes) rendered 12 frames of `motion` in seven children.
fn render_sequence(
    config: &SequenceConfig,
    s: &Scenario,
    method: &Method,
    dir: &Path,
) -> Result<(Vec<serde_json::Value>, Vec<PathBuf>), HarnessError> {
    let base = dir.join(format!("{}_0000.png", method.slug()));
    let mut args = vec!["render".to_string()];
    args.extend(sequence_flags(config, s));
    args.extend(method_flags(method));
    args.extend([
        "--ssaa".into(),
        config.ssaa.to_string(),
        "--warmup".into(),
        config.warmup.to_string(),
        "--frames".into(),
        config.timed.to_string(),
        "--json".into(),
        "-o".into(),
        base.display().to_string(),
    ]);
    let stdout = run(&config.exe, &args)?;
    let summaries: Vec<serde_json::Value> = stdout
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect();
    if summaries.len() != s.frames as usize {
        return Err(HarnessError::Worker(format!(
            "render --sequence {} printed {} frame summaries",
            s.frames,
            summaries.len()
        )));
    }
    let images = (0..s.frames).map(|k| frame_path(&base, k)).collect();
    Ok((summaries, images))
}

/// Runs every scenario, writes the report into `config.out`, and returns the records.
/// `progress` hears one line per finished sequence.
pub fn run_sequences(
    config: &SequenceConfig,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<FrameRecord>, HarnessError> {
    config.validate()?;
    crate::check_output_parent(&config.out)?;
    check_sequence_out(&config.out, config.replace)?;
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| HarnessError::Io { path, source }
    };
    std::fs::create_dir_all(&config.out).map_err(io(&config.out))?;
    // The filmstrips are drawn here and moved beside the report once it is written: drawn
    // straight into OUT, a run failing later had left an earlier report beside some of this
    // run's strips of the same names.
    let strips_dir = config.out.join("cache").join("filmstrips");
    if strips_dir.exists() {
        std::fs::remove_dir_all(&strips_dir).map_err(io(&strips_dir))?;
    }
    std::fs::create_dir_all(&strips_dir).map_err(io(&strips_dir))?;
    let mut records = Vec::new();
    let mut scenarios = Vec::new();
    let mut device = String::new();
    let mut size = (0, 0);
    for s in &config.scenarios {
        let dir = config.out.join("cache").join(&s.name);
        std::fs::create_dir_all(&dir).map_err(io(&dir))?;
        let truth_base = dir.join("truth.exr");
        let mut args = vec!["trace".to_string()];
        args.extend(sequence_flags(config, s));
        args.extend([
            "--spp".into(),
            (config.ssaa * config.ssaa).to_string(),
            "--max-depth".into(),
            config.truth.max_depth.to_string(),
            "--min-throughput".into(),
            config.truth.min_throughput.to_string(),
            "-o".into(),
        ]);
        args.push(truth_base.display().to_string());
        run(&config.exe, &args)?;
        let truths: Vec<RgbImage> = (0..s.frames)
            .map(|k| read_image(&frame_path(&truth_base, k)))
            .collect::<Result<_, _>>()?;
        size = (truths[0].width, truths[0].height);
        let exposure = mirrorbox_scene::load_scene(&s.scene)?.camera.exposure;
        progress(&format!("{}: truth of {} frames", s.name, s.frames));
        let mut filmstrips = Vec::new();
        for method in &s.methods {
            let (summaries, images) = render_sequence(config, s, method, &dir)?;
            // A stateful method's worst frames go into a filmstrip.
            let stateful = method
                .entry()
                .accepts(&mirrorbox_raster::methods::feedback::HISTORY);
            let mut flips: Vec<(f64, u32)> = Vec::new();
            // Every frame compared with its truth, the frames spread over the cores (the
            // child has rendered them: nothing is timed here).
            let metrics: Vec<Metrics> = (0..s.frames as usize)
                .into_par_iter()
                .map(|k| {
                    let image = read_image(&images[k])?;
                    Ok(mirrorbox_image::metrics::compare(
                        &truths[k], &image, exposure,
                    )?)
                })
                .collect::<Result<_, HarnessError>>()?;
            for ((k, summary), m) in (0..s.frames).zip(&summaries).zip(metrics) {
                // The child's summary, every field it must give (a missing one had become a
                // NaN or a 0 in the records unsaid).
                let field = |name: &str| {
                    summary[name].as_f64().ok_or_else(|| {
                        HarnessError::Worker(format!(
                            "{}, frame {k}: the render's --json summary has no number {name:?}",
                            s.name
                        ))
                    })
                };
                let (ms, passes, reflections) = (
                    field("ms_per_frame_median")?,
                    field("passes")?,
                    field("depth")?,
                );
                device = summary["adapter"].as_str().unwrap_or("").to_string();
                records.push(FrameRecord {
                    scenario: s.name.clone(),
                    method: method.key(),
                    exact: method.entry().exact,
                    frame: k,
                    time: s.start + f64::from(k) / s.fps,
                    flip_mean: m.flip_mean,
                    flip_p95: m.flip_p95,
                    relmse: m.relmse,
                    psnr: m.psnr,
                    ms,
                    passes: passes as usize,
                    reflections: reflections as usize,
                });
                flips.push((m.flip_mean, k));
            }
            if stateful {
                // Named by the method, or by its key where the scenario has other settings
                // of it (history=0..8): each keeps its own strip.
                let shared = s
                    .methods
                    .iter()
                    .filter(|m| m.name() == method.name())
                    .count()
                    > 1;
                let which = if shared {
                    slug(&method.key())
                } else {
                    method.name().to_string()
                };
                let name = format!("filmstrip_{}_{which}.png", s.name);
                flips.sort_by(|a, b| b.0.total_cmp(&a.0));
                let mut worst: Vec<u32> = flips.iter().take(3).map(|f| f.1).collect();
                worst.sort_unstable();
                let rows: Vec<(RgbImage, RgbImage)> = worst
                    .iter()
                    .map(|&k| Ok((truths[k as usize].clone(), read_image(&images[k as usize])?)))
                    .collect::<Result<_, HarnessError>>()?;
                write_filmstrip(&strips_dir.join(&name), &rows, exposure)?;
                filmstrips.push((method.key(), name, worst));
            }
            progress(&format!(
                "{}: {} over {} frames",
                s.name,
                method.key(),
                s.frames
            ));
        }
        // The frames are compared and the filmstrips drawn: their images go (a scenario's
        // are ~150 MB at the preset's size).
        std::fs::remove_dir_all(&dir).map_err(io(&dir))?;
        scenarios.push(ScenarioInfo {
            name: s.name.clone(),
            description: s.description.clone(),
            scene: s.scene.display().to_string(),
            frames: s.frames,
            fps: s.fps,
            step: camera_step(s)?,
            filmstrips,
        });
    }
    let info = MotionInfo {
        draws: Some([config.warmup, config.timed]),
        commit: crate::source_commit(),
        records_commit: String::new(),
        command: config.command.clone(),
        date: crate::now_rfc3339(),
        device,
        cpu: crate::cpu_description(),
        width: size.0,
        height: size.1,
        truth: format!(
            "mirrorbox trace (Whitted, at most {} reflections, throughput cut {}), {} spp on the raster's {}×{} SSAA grid",
            config.truth.max_depth,
            config.truth.min_throughput,
            config.ssaa * config.ssaa,
            config.ssaa,
            config.ssaa
        ),
        scenarios,
    };
    write_motion_report(&config.out, &info, &records)?;
    // This run's filmstrips beside its report, and an earlier run's (replaced, `--fresh`)
    // that it does not name gone: only now, so that a run failing before its report leaves
    // the earlier one whole.
    let named: Vec<&str> = info
        .scenarios
        .iter()
        .flat_map(|s| s.filmstrips.iter().map(|(_, name, _)| name.as_str()))
        .collect();
    for name in &named {
        let to = config.out.join(name);
        std::fs::rename(strips_dir.join(name), &to).map_err(io(&to))?;
    }
    std::fs::remove_dir(&strips_dir).map_err(io(&strips_dir))?;
    // The cache folder held only the scenarios' frames and the strips.
    let _ = std::fs::remove_dir(config.out.join("cache"));
    if let Ok(entries) = std::fs::read_dir(&config.out) {
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.starts_with("filmstrip_")
                && name.ends_with(".png")
                && !named.contains(&name.as_str())
            {
                std::fs::remove_file(e.path()).map_err(io(&e.path()))?;
            }
        }
    }
    Ok(records)
}

/// One row per frame: truth | method | FLIP heat map (the three side by side, 8-bit sRGB).
fn write_filmstrip(
    path: &Path,
    rows: &[(RgbImage, RgbImage)],
    exposure: f32,
) -> Result<(), HarnessError> {
    let Some((first, _)) = rows.first() else {
        return Ok(());
    };
    let (w, h) = (first.width as usize, first.height as usize);
    let width = 3 * w;
    let mut bytes = vec![0u8; width * h * rows.len() * 3];
    for (r, (truth, method)) in rows.iter().enumerate() {
        let c = mirrorbox_image::metrics::compare_detailed(truth, method, exposure)?;
        let heat: Vec<u8> = c
            .flip_map
            .iter()
            .flat_map(|&v| mirrorbox_image::colormap::heat(v))
            .collect();
        for (i, pane) in [&c.reference_srgb8, &c.test_srgb8, &heat]
            .into_iter()
            .enumerate()
        {
            for y in 0..h {
                let src = &pane[y * w * 3..(y + 1) * w * 3];
                let dst = ((r * h + y) * width + i * w) * 3;
                bytes[dst..dst + w * 3].copy_from_slice(src);
            }
        }
    }
    let mut staged = mirrorbox_files::StagedFiles::new();
    mirrorbox_image::stage_png_bytes(
        &mut staged,
        path,
        width as u32,
        (h * rows.len()) as u32,
        &bytes,
    )?;
    staged.commit()?;
    Ok(())
}

/// A method key as part of a file name: letters, digits, `-`, `.` and `_` kept, anything else
/// (spaces, `=`) as `_`.
fn slug(key: &str) -> String {
    key.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn methods_become_their_command_line_flags() {
        let m = |k: &str| method_flags(&Method::parse(k).unwrap());
        assert_eq!(m("auxiliary n=2"), ["--method", "auxiliary", "--n", "2"]);
        assert_eq!(
            m("feedback history=16"),
            ["--method", "feedback", "--history", "16"]
        );
        assert_eq!(
            m("unrolled depth=8 fragment-clipping=true"),
            [
                "--method",
                "unrolled",
                "--depth",
                "8",
                "--fragment-clipping"
            ]
        );
        assert_eq!(m("naive"), ["--method", "naive"]);
        assert_eq!(
            m("auxiliary n=1 max-passes=100"),
            ["--method", "auxiliary", "--n", "1", "--max-passes", "100"],
            "options outside the key are passed too"
        );
    }
}
