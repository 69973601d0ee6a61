//! The open exchange (issue 53): any renderer scored against the truth.
//!
//! Out (`mirrorbox export-views`, [`export_views`]): a folder with the scene as glTF
//! (`mirrorbox_scene::gltf_export`), the scene file that reads it back (`scene.json`), per
//! view the camera in every convention a client may need and the traced truth with and
//! without mirrors (`views.json`, `truth/`). In (`mirrorbox score`, [`crate::score`]): a
//! client's images and timings, scored as a sweep scores our methods. The exchange's fields:
//! `docs/exchange.md`.

use crate::{HarnessError, Summary, SweepConfig, io, truth};
use glam::{Mat4, Vec3};
use mirrorbox_scene::Scene;
use mirrorbox_scene::gltf_export::{self, BIN_NAME, camera_frame, clip_planes};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The version of `views.json` (and of `timing.json`, read by `score`).
pub const FORMAT_VERSION: u32 = 1;
/// Most views one export may hold (each is traced twice).
pub const MAX_VIEWS: usize = 64;

/// What a client must do to draw what the truth shows (`docs/shading.md`, in short). Written
/// into `views.json`; every rule is one a client can check in its own code.
pub const CLIENT_RULES: &[&str] = &[
    "Write linear radiance: no tone mapping, no exposure, no dithering; an EXR (float or half) holds it as it is, an 8-bit PNG holds it sRGB-encoded (its quantisation stated), top row first.",
    "Diffuse surfaces are Lambertian and two-sided, shaded with their face normal (the glTF NORMAL attribute): L = E·[front] + ρ/π · Σ I·max(0, n·l)/r² + ρ·A, with ρ the base colour (× its texture, decoded from sRGB), E the emissive factor × strength (× its texture), I a point light's colour × intensity read as W/sr (glTF candela), A the scene's extras.mirrorbox.ambient.",
    "No shadows and no light reflected by mirrors onto surfaces, unless views.json's lighting says otherwise; no indirect light; no specular term on diffuse surfaces.",
    "A mirror (metallic 1, roughness 0, extras.mirrorbox_mirror) reflects reflectance × the radiance of the reflected ray, at every angle (no Fresnel); its back is diffuse with back_albedo.",
    "A ray that leaves the scene sees extras.mirrorbox.background; a mirror a method can no longer follow shows extras.mirrorbox.terminal × the reflectances so far.",
    "Textures: bilinear between the four texels around the sample, no mip-maps, wrap modes and KHR_texture_transform as glTF says; alpha ignored (opaque).",
    "Pixel (x, y), y down, is the mean of the radiance at the s × s sub-pixel positions (x + (i + ½)/s, y + (j + ½)/s) of the view's ssaa s: render at s× the size and box-filter, or sample those positions.",
];

/// One camera of a view list (`--views FILE`): where it is and where it looks; the scene's
/// up and field of view unless given.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ViewSpec {
    pub name: String,
    pub position: [f32; 3],
    pub look_at: [f32; 3],
    #[serde(default)]
    pub up: Option<[f32; 3]>,
    #[serde(default)]
    pub fov_y_deg: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ViewList {
    views: Vec<ViewSpec>,
}

/// What to export.
#[derive(Clone, Debug, Default)]
pub struct ExportSettings {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub ssaa: u32,
    /// Every mirror's reflectance set to α (a sweep's α), else the scene's.
    pub alpha: Option<f32>,
    /// The views; empty: the scene's camera, named `camera`.
    pub views: Vec<ViewSpec>,
}

/// `views.json`: one exported view.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ExportedView {
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// Sub-pixel grid side: each pixel is the mean of ssaa × ssaa samples.
    pub ssaa: u32,
    pub camera: ViewCamera,
    /// World to camera (right-handed, the camera looking down −z), column-major.
    pub view_matrix: [f32; 16],
    /// Perspective with OpenGL's depth range (−1…1), column-major.
    pub projection_gl: [f32; 16],
    /// Perspective with Vulkan's, WebGPU's and Direct3D's depth range (0…1), column-major.
    pub projection_zero_to_one: [f32; 16],
    /// The truth (linear radiance, EXR) and beside it its sRGB PNG and its mirror mask
    /// (`<name>.mirrors.png`: red where a primary ray first meets a mirror's front).
    pub truth: String,
    /// The truth of the scene without its mirrors: a client's error there is its floor.
    pub floor: String,
    /// The scene's content hash at this view (the truth's key).
    pub scene_hash: String,
    /// Whether this view is the scene's own camera, the one a `mirrorbox sweep` shows:
    /// `score --with` sets our sweep beside this view only.
    #[serde(default)]
    pub scene_camera: bool,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ViewCamera {
    pub position: [f32; 3],
    pub look_at: [f32; 3],
    pub up: [f32; 3],
    pub right: [f32; 3],
    pub forward: [f32; 3],
    pub fov_y_deg: f32,
    pub aspect: f32,
    pub near: f32,
    pub far: f32,
    /// The output transform's multiplier (metrics and pictures apply it; a client does not).
    pub exposure: f32,
}

/// `views.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ViewsFile {
    pub format: String,
    pub version: u32,
    /// The glTF file, relative to this one.
    pub gltf: String,
    /// The mirrorbox scene file that reads the glTF back (`mirrorbox trace scene.json`).
    pub scene: String,
    /// The scene file exported, as given.
    pub source: String,
    /// Every mirror's reflectance: the export's `--alpha`, else the scene's own where its
    /// mirrors share one grey reflectance; `None` where they do not.
    pub alpha: Option<f32>,
    /// The scene hash (`Record::scene_hash`) a `mirrorbox sweep` of the exported scene at the
    /// export's size records, which `score --with` holds a sweep to. `None` in exports
    /// written before it was kept (their sweeps are compared by the scene's file name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sweep_scene_hash: Option<String>,
    /// Not in the file: the export's mirrors have different reflectances, so no one α stands
    /// for them (`alpha` is `None` for that reason, not for want of it). Set where the export
    /// is written and by [`crate::score::read_views`].
    #[serde(skip)]
    pub mirrors_differ: bool,
    pub contract: Contract,
    pub views: Vec<ExportedView>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Contract {
    pub document: String,
    pub version: u32,
    pub ambient: [f32; 3],
    pub background: [f32; 3],
    pub terminal: [f32; 3],
    /// "direct, no shadows" for the default contract.
    pub lighting: String,
    /// The truth: its integrator and limits.
    pub truth: String,
    pub rules: Vec<String>,
}

/// The contract's version (`docs/shading.md`): raised when a rule a client follows changes.
pub const CONTRACT_VERSION: u32 = 1;

/// Reads a `--views FILE`: `{"views": [{"name", "position", "look_at", "up"?, "fov_y_deg"?}]}`,
/// 1 to [`MAX_VIEWS`] views with distinct names of letters, digits, `-` and `_`.
pub fn read_view_list(path: &Path) -> Result<Vec<ViewSpec>, HarnessError> {
    let bad = |message: String| HarnessError::Exchange(format!("{}: {message}", path.display()));
    // A file error names the path itself.
    let text = mirrorbox_files::read_bounded_text(path, 1 << 20, "a view list")
        .map_err(|e| HarnessError::Exchange(e.to_string()))?;
    let list: ViewList = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
    if list.views.is_empty() || list.views.len() > MAX_VIEWS {
        return Err(bad(format!(
            "views: {} views; 1 to {MAX_VIEWS} are allowed",
            list.views.len()
        )));
    }
    let names: Vec<&str> = list.views.iter().map(|v| v.name.as_str()).collect();
    if let Some(problem) = view_name_problem(&names) {
        return Err(bad(problem));
    }
    // What can be checked without the scene (its up and field of view fill the gaps, and
    // [`view_scene`] checks the result).
    for (i, v) in list.views.iter().enumerate() {
        let (position, look_at) = (Vec3::from_array(v.position), Vec3::from_array(v.look_at));
        if let Some(problem) =
            camera_problem(position, look_at, v.up.map(Vec3::from_array), v.fov_y_deg)
        {
            return Err(bad(format!("views[{i}] ({:?}): {problem}", v.name)));
        }
    }
    Ok(list.views)
}

/// Every view of a `--views FILE` (read by [`read_view_list`]) applied to `scene` and checked
/// ([`view_scene`]) before any work: a problem only the scene shows (a view without `up`
/// looking along the scene camera's) is refused naming the file and the view.
pub fn check_views(path: &Path, views: &[ViewSpec], scene: &Scene) -> Result<(), HarnessError> {
    for (i, v) in views.iter().enumerate() {
        view_scene(scene, v)
            .map_err(|e| HarnessError::Exchange(format!("{}: views[{i}]: {e}", path.display())))?;
    }
    Ok(())
}

/// What is wrong with a list of view names, as `views[i].name …`, if anything: each is a
/// [`valid_name`] (it becomes part of file names), given once, and none is another's name
/// followed by `_floor` — view `a`'s floor truth is `truth/a_floor.exr`, which is view
/// `a_floor`'s truth (`docs/exchange.md`).
pub fn view_name_problem(names: &[&str]) -> Option<String> {
    for (i, name) in names.iter().enumerate() {
        if !valid_name(name) {
            return Some(format!(
                "views[{i}].name {name:?}: 1 to 64 letters, digits, '-' or '_'"
            ));
        }
        if names[..i].contains(name) {
            return Some(format!("views[{i}].name {name:?} appears twice"));
        }
    }
    for (i, name) in names.iter().enumerate() {
        if let Some(j) = names.iter().position(|n| format!("{n}_floor") == *name) {
            return Some(format!(
                "views[{i}].name {name:?}: the floor truth of views[{j}] {:?} has that name \
                 (truth/{name}.exr); a view's name may not be another's followed by _floor",
                names[j]
            ));
        }
    }
    None
}

/// A file-name-safe view, client or variant name.
pub fn valid_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 64
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}

/// What an export wrote.
pub struct Exported {
    pub views: usize,
    pub files: usize,
    pub truths_traced: usize,
}

/// Writes the exchange for `scene_path` into `dir` (see the module docs). `dir`'s parent must
/// exist; `dir` itself is made, or replaced when it holds an earlier export (its `views.json`)
/// or nothing. Everything is written into `dir.partial` first and moved into place at the end,
/// so a failed export leaves no half-written folder.
pub fn export_views(
    scene_path: &Path,
    dir: &Path,
    settings: &ExportSettings,
) -> Result<Exported, HarnessError> {
    replaceable(dir, "views.json", "export", is_views_file)?;
    let mut config = SweepConfig::new(
        scene_path.to_path_buf(),
        dir.to_path_buf(),
        Vec::new(),
        // A sweep's validation wants an α; the scene's own reflectances stay without one.
        vec![settings.alpha.unwrap_or(1.0)],
    );
    config.width = settings.width;
    config.height = settings.height;
    config.ssaa = settings.ssaa.max(1);
    let (mut base, _, _) = crate::base_scene(&config)?;
    // Views `score` could not compare: refused before their truths are traced.
    if let Some(problem) =
        crate::score::scoring_memory_problem(base.camera.width, base.camera.height)
    {
        return Err(HarnessError::Exchange(format!(
            "{}: {problem}",
            scene_path.display()
        )));
    }
    // What a sweep of this scene hashes, before the export's α (a sweep sets α per point).
    let sweep_scene_hash = format!("{:016x}", base.content_hash());
    if let Some(a) = settings.alpha {
        base.set_reflectance(Vec3::splat(a))
            .map_err(|source| HarnessError::LightImages {
                scene: base.source.clone(),
                source,
            })?;
    }
    let threshold = base.lighting.images.min_throughput;
    base.enumerate_light_images(threshold)
        .map_err(|source| HarnessError::LightImages {
            scene: base.source.clone(),
            source,
        })?;
    let files = gltf_export::export(&base)
        .map_err(|e| HarnessError::Exchange(format!("{}: {e}", scene_path.display())))?;
    in_staged_folder(dir, |partial| {
        let truth_dir = partial.join("truth");
        std::fs::create_dir_all(&truth_dir).map_err(io(&truth_dir))?;
        write_export(
            &base,
            &sweep_scene_hash,
            &files,
            partial,
            &config,
            settings,
            scene_path,
        )
    })
}

/// Runs `write` on `dir.partial` (made empty first, and locked until its files are in
/// place), then puts that folder in `dir`'s place, replacing what was there; where `write`
/// fails, removes it: a folder of the exchange (an export, a score, a merge, an advice) is
/// written whole or not at all, and an earlier one in `dir` stays whole until the new one is.
/// The earlier folder is marked ([`EARLIER_MARK`]) and moved aside to `dir.partial-earlier`
/// before the new one is moved in, then unmarked and removed: a process stopped at any step
/// leaves the earlier folder whole or the new one in place. A run that finds a marked aside
/// and no `dir` puts it back and stops (the command's checks of `dir` ran before it was
/// back); a `dir.partial-earlier` without the mark is not ours, and is refused untouched.
pub(crate) fn in_staged_folder<T>(
    dir: &Path,
    write: impl FnOnce(&Path) -> Result<T, HarnessError>,
) -> Result<T, HarnessError> {
    let partial = staging_folder(dir);
    let aside = earlier_folder(dir);
    let ours = |folder: &Path| folder.join(EARLIER_MARK).is_file();
    if aside.exists() && !ours(&aside) {
        return Err(HarnessError::Exchange(format!(
            "{}: exists and is not an earlier {} moved aside by mirrorbox; rename it or choose \
             another output folder",
            aside.display(),
            dir.display()
        )));
    }
    if partial.exists() {
        // A stale stage goes, removed under its lock; one another process is writing is
        // refused.
        let stale = mirrorbox_files::FolderLock::try_acquire(&partial)?;
        std::fs::remove_dir_all(&partial).map_err(io(&partial))?;
        drop(stale);
    }
    if aside.exists() && !dir.exists() {
        // A run stopped between moving the earlier folder aside and moving its own in: the
        // earlier one goes back, and this run stops there, so that the command's own checks
        // of its output folder (made before this) see what is in it now.
        std::fs::rename(&aside, dir).map_err(io(dir))?;
        let _ = std::fs::remove_file(dir.join(EARLIER_MARK));
        return Err(HarnessError::Exchange(format!(
            "{}: put back from {} (a run stopped while replacing it); run the command again",
            dir.display(),
            aside.display()
        )));
    }
    // An earlier run's leftover aside (ours, and `dir` in place): unmarked first, so that a
    // removal cut short is never put back.
    let remove_aside = || {
        let _ = std::fs::remove_file(aside.join(EARLIER_MARK));
        let _ = std::fs::remove_dir_all(&aside);
    };
    if aside.exists() {
        remove_aside();
    }
    std::fs::create_dir_all(&partial).map_err(io(&partial))?;
    let stage_lock = mirrorbox_files::FolderLock::try_acquire(&partial)?;
    let done = match write(&partial) {
        Ok(done) => done,
        Err(e) => {
            let _ = std::fs::remove_dir_all(&partial);
            drop(stage_lock);
            return Err(e);
        }
    };
    // From here a failure leaves the earlier folder as it was and removes the staged one (a
    // complete `.partial` had been left beside an output that was a file).
    let fail = |e: HarnessError| {
        let _ = std::fs::remove_dir_all(&partial);
        e
    };
    if dir.exists() {
        if aside.exists() {
            return Err(fail(HarnessError::Exchange(format!(
                "{}: could not be removed; remove it and run the command again",
                aside.display()
            ))));
        }
        std::fs::write(dir.join(EARLIER_MARK), "").map_err(|e| fail(io(dir)(e)))?;
        if let Err(e) = std::fs::rename(dir, &aside) {
            let _ = std::fs::remove_file(dir.join(EARLIER_MARK));
            return Err(fail(io(dir)(e)));
        }
    }
    if let Err(e) = std::fs::rename(&partial, dir) {
        // Put the earlier folder back.
        if std::fs::rename(&aside, dir).is_ok() {
            let _ = std::fs::remove_file(dir.join(EARLIER_MARK));
        }
        return Err(fail(io(dir)(e)));
    }
    drop(stage_lock);
    // A failure here loses nothing: the new folder is in place.
    remove_aside();
    Ok(done)
}

/// The file that marks a folder [`in_staged_folder`] moved aside as mirrorbox's.
const EARLIER_MARK: &str = ".mirrorbox-earlier";

/// Where [`in_staged_folder`] stages `dir`: `dir.partial`, replaced on each run.
pub(crate) fn staging_folder(dir: &Path) -> PathBuf {
    PathBuf::from(format!("{}.partial", dir.display()))
}

/// Where [`in_staged_folder`] keeps `dir`'s earlier contents while it swaps them.
fn earlier_folder(dir: &Path) -> PathBuf {
    PathBuf::from(format!("{}.partial-earlier", dir.display()))
}

/// Refuses an input folder that is `out`'s staging folder or its earlier contents moved
/// aside, which writing `out` would delete before reading it.
pub(crate) fn not_the_stage_of(out: &Path, input: &Path) -> Result<(), HarnessError> {
    let resolved = mirrorbox_files::resolved(input);
    let staged = [staging_folder(out), earlier_folder(out)]
        .iter()
        .any(|stage| stage.exists() && resolved == mirrorbox_files::resolved(stage));
    if staged {
        return Err(HarnessError::Exchange(format!(
            "{}: the folder where {} is staged (it is replaced first): rename it or choose \
             another output folder",
            input.display(),
            out.display()
        )));
    }
    Ok(())
}

/// Whether [`in_staged_folder`] may write `dir`: its parent exists, and it is absent, empty,
/// or holds an earlier output of the same command: its `marker` file (e.g. `views.json`), a
/// JSON object that `ours` recognises as that command's. A file of the marker's name alone
/// is not enough: a folder holding a user's own `views.json` (a `--views` list) had been
/// replaced whole, the user's files with it. Checked before any work, so that a mistyped
/// folder costs nothing.
pub(crate) fn replaceable(
    dir: &Path,
    marker: &str,
    what: &str,
    ours: fn(&serde_json::Value) -> bool,
) -> Result<(), HarnessError> {
    crate::check_output_parent(dir)?;
    let empty = std::fs::read_dir(dir).is_ok_and(|mut d| d.next().is_none());
    if !dir.exists() || empty {
        return Ok(());
    }
    let earlier = mirrorbox_files::open_regular(&dir.join(marker), MAX_MARKER_BYTES, marker)
        .ok()
        .and_then(|f| {
            serde_json::from_reader::<_, serde_json::Value>(std::io::BufReader::new(f)).ok()
        })
        .is_some_and(|v| ours(&v));
    if !earlier {
        return Err(HarnessError::Exchange(format!(
            "{}: exists and holds no earlier {what} (its {marker}); give a new or empty folder",
            dir.display()
        )));
    }
    Ok(())
}

/// The largest marker file [`replaceable`] reads (an advice's `advice.json` with every
/// candidate of a long search is a few hundred KB).
const MAX_MARKER_BYTES: u64 = 64 << 20;

/// Whether `v` is an export's `views.json` (for [`replaceable`]).
pub(crate) fn is_views_file(v: &serde_json::Value) -> bool {
    v["format"] == "mirrorbox-views"
}

/// The one grey reflectance every mirror of `scene` has, if any.
pub(crate) fn uniform_alpha(scene: &Scene) -> Option<f32> {
    let first = scene.mirrors.first()?.reflectance;
    let grey = first.x == first.y && first.y == first.z;
    (grey && scene.mirrors.iter().all(|m| m.reflectance == first)).then_some(first.x)
}

/// `base` is the scene exported (α set, light images enumerated; its camera the scene's own);
/// `sweep_scene_hash` the hash a sweep of it records, taken before them.
fn write_export(
    base: &Scene,
    sweep_scene_hash: &str,
    files: &gltf_export::GltfFiles,
    out: &Path,
    config: &SweepConfig,
    settings: &ExportSettings,
    scene_path: &Path,
) -> Result<Exported, HarnessError> {
    let write = |name: &str, bytes: &[u8]| -> Result<(), HarnessError> {
        let p = out.join(name);
        if let Some(parent) = p.parent() {
            std::fs::create_dir_all(parent).map_err(io(parent))?;
        }
        std::fs::write(&p, bytes).map_err(io(&p))
    };
    write("scene.gltf", files.json.as_bytes())?;
    write(BIN_NAME, &files.bin)?;
    for (name, bytes) in &files.images {
        write(name, bytes)?;
    }
    write(
        "scene.json",
        gltf_export::scene_file(base, "scene.gltf").as_bytes(),
    )?;
    let specs = if settings.views.is_empty() {
        let c = &base.camera;
        vec![ViewSpec {
            name: "camera".into(),
            position: c.position.to_array(),
            look_at: c.look_at.to_array(),
            up: Some(c.up.to_array()),
            fov_y_deg: Some(c.fov_y_deg),
        }]
    } else {
        settings.views.clone()
    };
    let mut summary = Summary::default();
    let mut views = Vec::with_capacity(specs.len());
    let truth_dir = out.join("truth");
    for spec in &specs {
        let scene = view_scene(base, spec)?;
        let floor_scene = scene.without_mirrors();
        for (s, name) in [
            (&scene, spec.name.clone()),
            (&floor_scene, format!("{}_floor", spec.name)),
        ] {
            let (_, path) = truth(s, config, &truth_dir, &mut summary)?;
            for (from, to) in [
                (path.clone(), truth_dir.join(format!("{name}.exr"))),
                (
                    path.with_extension("png"),
                    truth_dir.join(format!("{name}.png")),
                ),
                (
                    crate::mask_path(&path),
                    truth_dir.join(format!("{name}.mirrors.png")),
                ),
            ] {
                std::fs::rename(&from, &to).map_err(io(&to))?;
            }
        }
        let mut view = exported_view(&scene, spec, config.ssaa);
        view.scene_camera = same_camera(&scene.camera, &base.camera);
        views.push(view);
    }
    let l = &base.lighting;
    let alpha = settings.alpha.or_else(|| uniform_alpha(base));
    let doc = ViewsFile {
        format: "mirrorbox-views".into(),
        version: FORMAT_VERSION,
        gltf: "scene.gltf".into(),
        scene: "scene.json".into(),
        source: scene_path.display().to_string(),
        alpha,
        sweep_scene_hash: Some(sweep_scene_hash.to_string()),
        mirrors_differ: alpha.is_none(),
        contract: Contract {
            document: "docs/shading.md".into(),
            version: CONTRACT_VERSION,
            ambient: l.ambient.to_array(),
            background: base.background.to_array(),
            terminal: base.terminal.to_array(),
            lighting: l.describe(),
            truth: format!(
                "whitted, max depth {}, min throughput {}",
                config.truth.max_depth, config.truth.min_throughput
            ),
            rules: CLIENT_RULES.iter().map(|r| r.to_string()).collect(),
        },
        views,
    };
    write("views.json", serde_json::to_string_pretty(&doc)?.as_bytes())?;
    Ok(Exported {
        views: specs.len(),
        files: 4 + files.images.len() + 6 * specs.len(),
        truths_traced: summary.truths_traced,
    })
}

/// Whether two cameras see alike: the same position, look-at and field of view, and ups
/// along one direction (a view's up is normalised, the scene's may not be).
fn same_camera(a: &mirrorbox_scene::camera::Camera, b: &mirrorbox_scene::camera::Camera) -> bool {
    a.position == b.position
        && a.look_at == b.look_at
        && a.fov_y_deg == b.fov_y_deg
        && a.up.normalize().abs_diff_eq(b.up.normalize(), 1e-6)
}

/// `base` seen from `spec`: its camera moved, checked (position and look-at apart, up not
/// along the view, field of view in (0, 170]).
pub fn view_scene(base: &Scene, spec: &ViewSpec) -> Result<Scene, HarnessError> {
    let mut scene = base.clone();
    let c = &mut scene.camera;
    c.position = Vec3::from_array(spec.position);
    c.look_at = Vec3::from_array(spec.look_at);
    if let Some(up) = spec.up {
        c.up = Vec3::from_array(up);
    }
    if let Some(fov) = spec.fov_y_deg {
        c.fov_y_deg = fov;
    }
    if let Some(problem) = camera_problem(c.position, c.look_at, Some(c.up), Some(c.fov_y_deg)) {
        let up = if spec.up.is_none() && problem.starts_with("up") {
            " (up is the scene camera's: the view gives none)"
        } else {
            ""
        };
        return Err(HarnessError::Exchange(format!(
            "view {:?}: {problem}{up}",
            spec.name
        )));
    }
    c.up = c.up.normalize();
    Ok(scene)
}

/// What is wrong with a camera, if anything: its position and look-at inside the scene
/// extent (as a scene file's camera: [`mirrorbox_scene::limits::within_extent`]) and apart,
/// its `up` (where known) finite and not along the view direction, its vertical field of
/// view (where known) in (0, 170] degrees.
fn camera_problem(
    position: Vec3,
    look_at: Vec3,
    up: Option<Vec3>,
    fov_y_deg: Option<f32>,
) -> Option<String> {
    use mirrorbox_scene::limits::{MAX_COORDINATE, within_extent};
    if !within_extent(position) || !within_extent(look_at) {
        return Some(format!(
            "position and look_at must lie within the scene extent, every coordinate within \
             ±{MAX_COORDINATE:e}"
        ));
    }
    let forward = look_at - position;
    if forward.length() < 1e-6 {
        return Some("position and look_at must be apart".into());
    }
    if up.is_some_and(|up| !up.is_finite() || forward.normalize().cross(up).length() < 1e-6) {
        return Some("up must be finite and not along the view direction".into());
    }
    if fov_y_deg.is_some_and(|f| !mirrorbox_scene::limits::fov_ok(f)) {
        return Some("fov_y_deg must be in (0, 170] degrees".into());
    }
    None
}

fn exported_view(scene: &Scene, spec: &ViewSpec, ssaa: u32) -> ExportedView {
    let c = &scene.camera;
    let (right, up, forward) = camera_frame(scene);
    let (near, far) = clip_planes(scene);
    let aspect = c.aspect();
    ExportedView {
        name: spec.name.clone(),
        width: c.width,
        height: c.height,
        ssaa,
        camera: ViewCamera {
            position: c.position.to_array(),
            look_at: c.look_at.to_array(),
            up: up.to_array(),
            right: right.to_array(),
            forward: forward.to_array(),
            fov_y_deg: c.fov_y_deg,
            aspect,
            near,
            far,
            exposure: c.exposure,
        },
        view_matrix: c.view().to_cols_array(),
        projection_gl: gl_projection(c, near, far).to_cols_array(),
        projection_zero_to_one: c.projection(near, far).to_cols_array(),
        truth: format!("truth/{}.exr", spec.name),
        floor: format!("truth/{}_floor.exr", spec.name),
        scene_hash: format!("{:016x}", scene.content_hash()),
        scene_camera: false,
    }
}

/// The camera's projection with OpenGL's and WebGL's depth range (−1…1), beside
/// [`mirrorbox_scene::camera::Camera::projection`]'s 0…1 (Vulkan, WebGPU, Direct3D). An
/// exported camera has no lens shift (stereo is refused).
fn gl_projection(c: &mirrorbox_scene::camera::Camera, near: f32, far: f32) -> Mat4 {
    glam::camera::rh::proj::opengl::perspective(c.fov_y_deg.to_radians(), c.aspect(), near, far)
}

/// A `views.json` as an export writes it, for tests of what reads it.
#[cfg(test)]
pub(crate) mod tests_support {
    use super::*;

    pub fn sample_view() -> ViewsFile {
        let scene = mirrorbox_scene::load::load_scene(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mirror_box.json"),
        )
        .unwrap();
        let spec = ViewSpec {
            name: "camera".into(),
            position: scene.camera.position.to_array(),
            look_at: scene.camera.look_at.to_array(),
            up: None,
            fov_y_deg: None,
        };
        ViewsFile {
            format: "mirrorbox-views".into(),
            version: FORMAT_VERSION,
            gltf: "scene.gltf".into(),
            scene: "scene.json".into(),
            source: "scenes/mirror_box.json".into(),
            alpha: Some(0.9),
            sweep_scene_hash: None,
            mirrors_differ: false,
            contract: Contract {
                document: "docs/shading.md".into(),
                version: CONTRACT_VERSION,
                ambient: [0.0; 3],
                background: [0.0; 3],
                terminal: [0.0; 3],
                lighting: scene.lighting.describe(),
                truth: "whitted".into(),
                rules: CLIENT_RULES.iter().map(|r| r.to_string()).collect(),
            },
            views: vec![exported_view(&scene, &spec, 1)],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The files under `dir` with their bytes, relative paths sorted; the lock file (the
    /// stage's, held while it is written, as a sweep folder's) left out.
    fn contents(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
        let mut out = Vec::new();
        let mut todo = vec![dir.to_path_buf()];
        while let Some(d) = todo.pop() {
            for e in std::fs::read_dir(&d).unwrap().flatten() {
                if e.path().is_dir() {
                    todo.push(e.path());
                } else if e.file_name() != mirrorbox_files::LOCK_FILE {
                    let rel = e.path().strip_prefix(dir).unwrap().to_path_buf();
                    out.push((rel, std::fs::read(e.path()).unwrap()));
                }
            }
        }
        out.sort();
        out
    }

    /// A write that fails half-way leaves the earlier folder as it was and no stage behind; one
    /// that succeeds replaces the folder whole (no file of the earlier one left) and leaves
    /// neither the stage nor the earlier folder's copy; a stale stage is cleared first.
    #[test]
    fn a_staged_folder_is_written_whole_or_not_at_all() {
        let root = tempfile::tempdir().unwrap();
        let dir = root.path().join("out");
        std::fs::create_dir_all(dir.join("images")).unwrap();
        std::fs::write(dir.join("records.jsonl"), "earlier\n").unwrap();
        std::fs::write(dir.join("images/a.png"), [1, 2, 3]).unwrap();
        let earlier = contents(&dir);
        let failed = in_staged_folder(&dir, |partial| -> Result<(), HarnessError> {
            std::fs::create_dir_all(partial.join("images")).unwrap();
            std::fs::write(partial.join("images/a.png"), [9, 9]).unwrap();
            std::fs::write(partial.join("records.jsonl"), "half\n").unwrap();
            Err(HarnessError::Exchange("failed half-way".into()))
        });
        assert!(failed.is_err());
        assert_eq!(contents(&dir), earlier);
        let names = |root: &Path| -> Vec<String> {
            let mut n: Vec<String> = std::fs::read_dir(root)
                .unwrap()
                .flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect();
            n.sort();
            n
        };
        assert_eq!(names(root.path()), ["out"]);
        // A stale stage (a process stopped while writing) is cleared, not mixed in.
        std::fs::create_dir_all(staging_folder(&dir)).unwrap();
        std::fs::write(staging_folder(&dir).join("stale.txt"), "x").unwrap();
        in_staged_folder(&dir, |partial| {
            std::fs::write(partial.join("records.jsonl"), "new\n").map_err(io(partial))
        })
        .unwrap();
        assert_eq!(
            contents(&dir),
            [(PathBuf::from("records.jsonl"), b"new\n".to_vec())]
        );
        assert_eq!(names(root.path()), ["out"]);
        // A run stopped after moving the earlier folder aside: the next puts it back and
        // stops, writing nothing (the command's own checks of OUT ran before it was back).
        std::fs::write(dir.join(EARLIER_MARK), "").unwrap();
        std::fs::rename(&dir, earlier_folder(&dir)).unwrap();
        let kept = in_staged_folder(&dir, |_| -> Result<(), HarnessError> {
            panic!("written before the earlier folder was checked again")
        });
        assert!(kept.unwrap_err().to_string().contains("put back"));
        assert_eq!(
            contents(&dir),
            [(PathBuf::from("records.jsonl"), b"new\n".to_vec())]
        );
        assert_eq!(names(root.path()), ["out"]);
        // A folder of that name that mirrorbox did not move aside is the user's: refused,
        // untouched, before anything is written.
        let theirs = earlier_folder(&dir);
        std::fs::create_dir(&theirs).unwrap();
        std::fs::write(theirs.join("notes.txt"), "mine").unwrap();
        let refused = in_staged_folder(&dir, |_| -> Result<(), HarnessError> {
            panic!("written despite the refusal")
        });
        assert!(
            refused
                .unwrap_err()
                .to_string()
                .contains("is not an earlier")
        );
        assert_eq!(
            contents(&theirs),
            [(PathBuf::from("notes.txt"), b"mine".to_vec())]
        );
        assert_eq!(
            contents(&dir),
            [(PathBuf::from("records.jsonl"), b"new\n".to_vec())]
        );
    }

    /// A point on the view axis at `near` lands on the near end of each depth range and one
    /// at `far` on the far end; the camera's position maps to the origin.
    #[test]
    fn the_matrices_put_near_and_far_at_the_ends_of_each_depth_range() {
        let (pos, fwd) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.0, -1.0));
        let c = mirrorbox_scene::camera::Camera {
            position: pos,
            look_at: pos + fwd,
            up: Vec3::Y,
            fov_y_deg: 1f32.to_degrees(),
            width: 150,
            height: 100,
            exposure: 1.0,
            shift_x: 0.0,
        };
        let view = c.view();
        assert!(view.transform_point3(pos).length() < 1e-6);
        for (projection, lo) in [
            (gl_projection(&c, 0.1, 100.0), -1.0),
            (c.projection(0.1, 100.0), 0.0),
        ] {
            let p = projection * view;
            let ndc = |d: f32| {
                let c = p * (pos + fwd * d).extend(1.0);
                c.z / c.w
            };
            assert!((ndc(0.1) - lo).abs() < 1e-4, "{}", ndc(0.1));
            assert!((ndc(100.0) - 1.0).abs() < 1e-4, "{}", ndc(100.0));
        }
    }

    /// A view list's errors name the file once, then the field or the file's problem.
    #[test]
    fn a_view_list_error_names_the_file_once() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("nothere.json");
        let bad = dir.path().join("bad.json");
        std::fs::write(&bad, r#"{"views": []}"#).unwrap();
        let apart = dir.path().join("apart.json");
        std::fs::write(
            &apart,
            r#"{"views": [{"name": "a", "position": [0, 1, 2], "look_at": [0, 1, 0]},
                          {"name": "b", "position": [0, 1, 2], "look_at": [0, 1, 2]}]}"#,
        )
        .unwrap();
        let up = dir.path().join("up.json");
        std::fs::write(
            &up,
            r#"{"views": [{"name": "a", "position": [0, 1, 2], "look_at": [0, 1, 0],
                           "up": [0, 0, 3]}]}"#,
        )
        .unwrap();
        // A scene file's camera is refused beyond the scene extent: a view's is too.
        let far = dir.path().join("far.json");
        std::fs::write(
            &far,
            r#"{"views": [{"name": "a", "position": [1e9, 1, 2], "look_at": [0, 1, 0]}]}"#,
        )
        .unwrap();
        let fov = dir.path().join("fov.json");
        std::fs::write(
            &fov,
            r#"{"views": [{"name": "a", "position": [0, 1, 2], "look_at": [0, 1, 0],
                           "fov_y_deg": 180}]}"#,
        )
        .unwrap();
        for (path, problem) in [
            (&missing, "cannot read a view list"),
            (&bad, "views: 0 views"),
            (
                &apart,
                "views[1] (\"b\"): position and look_at must be apart",
            ),
            (&up, "views[0] (\"a\"): up must be finite and not along"),
            (&fov, "views[0] (\"a\"): fov_y_deg must be in (0, 170]"),
            (
                &far,
                "views[0] (\"a\"): position and look_at must lie within the scene extent, \
                 every coordinate within ±1e6",
            ),
        ] {
            let message = read_view_list(path).unwrap_err().to_string();
            let name = path.display().to_string();
            assert_eq!(message.matches(&name).count(), 1, "{message}");
            assert!(message.contains(problem), "{message}");
        }
    }
}
