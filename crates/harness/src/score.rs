//! The exchange's way in (`mirrorbox score EXPORT RUN -o OUT`, issue 53, `docs/exchange.md`):
//! a client's images (`RUN/<client>/<variant>/<view>.exr` or `.png`) and timings
//! (`timing.json`) compared with the export's truths exactly as a sweep compares our methods,
//! written as the same records and report. A variant named `floor` drew the scene without its
//! mirrors and is compared with the floor truth.

use crate::exchange::{
    ExportedView, FORMAT_VERSION, MAX_VIEWS, ViewsFile, valid_name, view_name_problem,
};
use crate::{HarnessError, ViewFiles, compare_views, io};
use mirrorbox_report::{Record, SweepInfo, write_report};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Most frames one view's timing may list.
pub const MAX_FRAMES: usize = 10_000;
pub use mirrorbox_report::MAX_FRAME_MS;
/// Most clients × variants one run may hold.
pub const MAX_VARIANTS: usize = 256;

/// `timing.json` of one variant.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Timing {
    pub format: String,
    pub version: u32,
    pub engine: String,
    pub engine_version: String,
    pub device: String,
    #[serde(default)]
    pub driver: String,
    pub timing: String,
    #[serde(default)]
    pub parameters: BTreeMap<String, serde_json::Value>,
    #[serde(default)]
    pub equivalent: Option<String>,
    /// How the variant follows the contract, in prose (materials, units, targets): for the
    /// report, not for the variant's name.
    #[serde(default)]
    pub notes: Option<String>,
    #[serde(deserialize_with = "each_key_once")]
    pub views: BTreeMap<String, Vec<f64>>,
    /// Each view's `scene_hash` as the client read it from views.json: where given, `score`
    /// holds the run to the export it was drawn from (a run of another export's views of the
    /// same names and sizes had been scored against this one's truths).
    #[serde(default)]
    pub scene_hashes: BTreeMap<String, String>,
}

/// `timing.json`'s `views`, each view's key given once: a map read as serde reads one would
/// keep the last of two `"camera"` entries and drop the other's frames unsaid.
fn each_key_once<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<BTreeMap<String, Vec<f64>>, D::Error> {
    struct Views;
    impl<'de> serde::de::Visitor<'de> for Views {
        type Value = BTreeMap<String, Vec<f64>>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a map from view names to frame times in ms")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut map: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = BTreeMap::new();
            while let Some((key, frames)) = map.next_entry::<String, Vec<f64>>()? {
                if out.contains_key(&key) {
                    return Err(serde::de::Error::custom(format!(
                        "views: view {key:?} is given twice"
                    )));
                }
                out.insert(key, frames);
            }
            Ok(out)
        }
    }
    d.deserialize_map(Views)
}

/// How to score: the command line (for the report), our sweeps to set beside the run
/// (`--with`), and the report sections (the experiments' registry).
#[derive(Default)]
pub struct ScoreSettings {
    pub command: String,
    pub with: Vec<PathBuf>,
    pub sections: Vec<mirrorbox_report::Section>,
}

/// What a score wrote.
pub struct Scored {
    pub records: usize,
    pub variants: usize,
    /// Pictures that are much nearer their truth upside down or decoded from sRGB
    /// ([`picture_hint`]): scored as given, and said (variants.md, the command's output).
    pub hints: Vec<String>,
}

/// How much nearer its truth a picture must come, transformed, to be called mis-encoded.
const HINT_FACTOR: f64 = 3.0;

/// A client's picture that comes much nearer its truth (by [`HINT_FACTOR`], in mean absolute
/// difference of linear radiance) upside down, or — an EXR — decoded from sRGB: the two
/// mistakes a client makes that score as a large error and nothing else (row 0 is the top;
/// an EXR holds linear radiance: docs/exchange.md). Decoded, it must also come within half
/// the distance of the nearest flat picture. Said, not refused: a renderer may be that far
/// off.
fn picture_hint(truth: &Path, image: &Path) -> Result<Option<String>, HarnessError> {
    let t =
        mirrorbox_image::read_image(truth).map_err(|e| HarnessError::Exchange(e.to_string()))?;
    let p =
        mirrorbox_image::read_image(image).map_err(|e| HarnessError::Exchange(e.to_string()))?;
    let w = t.width as usize;
    let distance = |at: &dyn Fn(usize) -> [f32; 3]| -> f64 {
        let sum: f64 = (0..t.pixels.len())
            .map(|i| {
                let (a, b) = (t.pixels[i], at(i));
                (0..3).map(|c| f64::from((a[c] - b[c]).abs())).sum::<f64>()
            })
            .sum();
        sum / (3 * t.pixels.len()).max(1) as f64
    };
    let given = distance(&|i| p.pixels[i]);
    let flipped = distance(&|i| {
        let (x, y) = (i % w, i / w);
        p.pixels[(t.height as usize - 1 - y) * w + x]
    });
    let is_exr = image
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    let decoded = is_exr.then(|| distance(&|i| p.pixels[i].map(mirrorbox_image::srgb::decode)));
    // Decoding darkens every value in (0, 1), so it brings any picture brighter than a dark
    // truth nearer, a flat grey one as well: only a decoded picture within half the distance
    // of the nearest flat picture (the mean absolute deviation from the truth's per-channel
    // medians) shows the truth's structure, which a renderer's sRGB-encoded output keeps. A
    // flat truth has no structure to keep (that distance is 0): there, decoding must bring
    // the picture ten thousand times nearer.
    let flat = || {
        let median = [0, 1, 2].map(|c| {
            let mut channel: Vec<f32> = t.pixels.iter().map(|px| px[c]).collect();
            let mid = channel.len() / 2;
            *channel.select_nth_unstable_by(mid, f32::total_cmp).1
        });
        distance(&|_| median)
    };
    let name = image.display();
    Ok(if given > HINT_FACTOR * flipped {
        Some(format!(
            "{name}: upside down? Flipped vertically it is {:.1}× nearer the truth; images are \
             stored top row first",
            given / flipped.max(f64::MIN_POSITIVE)
        ))
    } else {
        decoded
            .filter(|&d| given > HINT_FACTOR * d && (d < 0.5 * flat() || d <= 1e-4 * given))
            .map(|d| {
                format!(
                    "{name}: sRGB-encoded? Decoded from sRGB it is {:.1}× nearer the truth; an EXR \
                 holds linear radiance",
                    given / d.max(f64::MIN_POSITIVE)
                )
            })
    })
}

/// A parameter short enough to name a variant by: at most [`MAX_KNOB_CHARS`] characters, no
/// spaces, in the key and the value (a description belongs in `notes`).
fn is_knob(key: &str, value: &str) -> bool {
    [key, value]
        .iter()
        .all(|t| t.chars().count() <= MAX_KNOB_CHARS && !t.contains(char::is_whitespace))
}

/// The longest parameter key or value shown in a variant's name.
pub const MAX_KNOB_CHARS: usize = 20;

fn refused(path: &Path, message: impl std::fmt::Display) -> HarnessError {
    HarnessError::Exchange(format!("{}: {message}", path.display()))
}

/// Reads `EXPORT/views.json`.
pub fn read_views(export: &Path) -> Result<ViewsFile, HarnessError> {
    let path = export.join("views.json");
    if !export.is_dir() {
        return Err(refused(
            export,
            if export.exists() {
                "is a file; EXPORT is the folder `mirrorbox export-views` wrote"
            } else {
                "does not exist; EXPORT is the folder `mirrorbox export-views` wrote"
            },
        ));
    }
    if !path.exists() {
        return Err(refused(
            export,
            "holds no views.json: not an export (`mirrorbox export-views` writes one)",
        ));
    }
    // The file's own error names it.
    let text = mirrorbox_files::read_bounded_text(&path, 16 << 20, "views.json")
        .map_err(|e| HarnessError::Exchange(e.to_string()))?;
    let mut views: ViewsFile = serde_json::from_str(&text).map_err(|e| refused(&path, e))?;
    if views.format != "mirrorbox-views" || views.version != FORMAT_VERSION {
        return Err(refused(
            &path,
            format!(
                "format {:?} version {}: mirrorbox-views version {FORMAT_VERSION} is read",
                views.format, views.version
            ),
        ));
    }
    check_views(&views).map_err(|problem| refused(&path, problem))?;
    views.mirrors_differ = views.alpha.is_none() && views.sweep_scene_hash.is_some();
    // An export older than the scene hashes left `alpha` out where it was not given, whether
    // or not its mirrors shared one (their scores said α = 1): the exported scene says which.
    // One that does not load keeps the old reading (no α kept: 1 in the records).
    if views.alpha.is_none()
        && views.sweep_scene_hash.is_none()
        && let Ok(scene) = mirrorbox_scene::load_scene(&export.join(&views.scene))
    {
        views.alpha = crate::exchange::uniform_alpha(&scene);
        views.mirrors_differ = views.alpha.is_none();
    }
    Ok(views)
}

/// Why views of `width × height` could not be scored within the default memory budget, if
/// they could not: `score` compares each picture with its truth as `compare` does (about
/// [`mirrorbox_image::metrics::COMPARE_BYTES_PER_PIXEL`] bytes a pixel), and refuses what
/// `compare` refuses by default. `export-views` refuses such views before tracing them.
pub(crate) fn scoring_memory_problem(width: u32, height: u32) -> Option<String> {
    let need = mirrorbox_image::metrics::compare_bytes(width, height);
    (need > mirrorbox_raster::DEFAULT_MEMORY_BUDGET).then(|| {
        format!(
            "{width}×{height} would need about {:.1} GB to score ({} bytes a pixel), above \
             {:.1} GB: export smaller views",
            need as f64 / 1e9,
            mirrorbox_image::metrics::COMPARE_BYTES_PER_PIXEL,
            mirrorbox_raster::DEFAULT_MEMORY_BUDGET as f64 / 1e9
        )
    })
}

/// What an export writes and `score` relies on, checked field by field: 1 to [`MAX_VIEWS`]
/// views; names that are file-name safe, distinct and free of `_floor` clashes (they become
/// parts of file names); sizes an image read can have; `truth` and `floor` inside the export
/// folder (they are read from it).
fn check_views(views: &ViewsFile) -> Result<(), String> {
    // A reflectance (the records carry it as the points' α).
    if let Some(a) = views.alpha
        && !(0.0..=1.0).contains(&a)
    {
        return Err(format!("alpha {a}: a reflectance, 0 to 1, or null"));
    }
    if views.views.is_empty() || views.views.len() > MAX_VIEWS {
        return Err(format!(
            "views: {} views; 1 to {MAX_VIEWS} are read",
            views.views.len()
        ));
    }
    let names: Vec<&str> = views.views.iter().map(|v| v.name.as_str()).collect();
    if let Some(problem) = view_name_problem(&names) {
        return Err(problem);
    }
    let sides = mirrorbox_image::metrics::MIN_SIDE..=mirrorbox_image::MAX_IMAGE_SIDE;
    for (i, v) in views.views.iter().enumerate() {
        for (field, side) in [("width", v.width), ("height", v.height)] {
            if !sides.contains(&side) {
                return Err(format!(
                    "views[{i}].{field} {side}: {} to {} pixels",
                    sides.start(),
                    sides.end()
                ));
            }
        }
        if u64::from(v.width) * u64::from(v.height) > mirrorbox_image::MAX_PIXELS {
            return Err(format!(
                "views[{i}]: {}×{} is more than {} pixels",
                v.width,
                v.height,
                mirrorbox_image::MAX_PIXELS
            ));
        }
        if let Some(problem) = scoring_memory_problem(v.width, v.height) {
            return Err(format!("views[{i}]: {problem}"));
        }
        let grid_sides = 1..=mirrorbox_raster::MAX_SSAA;
        if !grid_sides.contains(&v.ssaa) {
            return Err(format!(
                "views[{i}].ssaa {}: a sub-pixel grid side of {} to {} (export-views' --ssaa)",
                v.ssaa,
                grid_sides.start(),
                grid_sides.end()
            ));
        }
        for (field, file) in [("truth", &v.truth), ("floor", &v.floor)] {
            if !crate::is_inner_path(file) {
                return Err(format!(
                    "views[{i}].{field} {file:?}: a path inside the export folder (relative, \
                     without ..), e.g. \"truth/{}.exr\"",
                    v.name
                ));
            }
        }
    }
    Ok(())
}

fn read_timing(path: &Path, views: &ViewsFile) -> Result<Timing, HarnessError> {
    // A file error names the path itself.
    let text = mirrorbox_files::read_bounded_text(path, 16 << 20, "a timing file")
        .map_err(|e| HarnessError::Exchange(e.to_string()))?;
    // JSON has no NaN or infinity: a client writing one gets serde's bare position, said
    // here with what is read.
    let t: Timing = serde_json::from_str(&text).map_err(|e| {
        refused(
            path,
            format!(
                "{e}: a timing file is {{\"format\": \"mirrorbox-timing\", \"version\": \
                 {FORMAT_VERSION}, \"views\": {{VIEW: [ms, …]}}, …}}, each time a finite JSON \
                 number > 0 (docs/exchange.md)"
            ),
        )
    })?;
    if t.format != "mirrorbox-timing" || t.version != FORMAT_VERSION {
        return Err(refused(
            path,
            format!(
                "format {:?} version {}: mirrorbox-timing version {FORMAT_VERSION} is read",
                t.format, t.version
            ),
        ));
    }
    for v in &views.views {
        let Some(frames) = t.views.get(&v.name) else {
            return Err(refused(
                path,
                format!("views: no frames for view {:?}", v.name),
            ));
        };
        if frames.is_empty() || frames.len() > MAX_FRAMES {
            return Err(refused(
                path,
                format!(
                    "views.{}: {} frames; 1 to {MAX_FRAMES} are read",
                    v.name,
                    frames.len()
                ),
            ));
        }
        // A 0 is no frame's time but a timer too coarse for one frame; it would make a
        // median of 0 and speed ratios of infinity.
        if let Some(bad) = frames
            .iter()
            .find(|ms| !ms.is_finite() || **ms <= 0.0 || **ms > MAX_FRAME_MS)
        {
            return Err(refused(
                path,
                format!(
                    "views.{}: {bad} ms is not a frame's time (finite, > 0, at most \
                     {MAX_FRAME_MS} ms, a day; a timer too coarse for one frame reads 0: time \
                     several frames together and give each their mean)",
                    v.name
                ),
            ));
        }
    }
    if let Some(extra) = t
        .views
        .keys()
        .find(|k| !views.views.iter().any(|v| &v.name == *k))
    {
        return Err(refused(
            path,
            format!("views.{extra}: no such view in views.json"),
        ));
    }
    for (view, hash) in &t.scene_hashes {
        match views.views.iter().find(|v| &v.name == view) {
            None => {
                return Err(refused(
                    path,
                    format!("scene_hashes.{view}: no such view in views.json"),
                ));
            }
            Some(v) if &v.scene_hash != hash => {
                return Err(refused(
                    path,
                    format!(
                        "scene_hashes.{view}: {hash}, but this export's view {view:?} is {}: \
                         the run was drawn from another export",
                        v.scene_hash
                    ),
                ));
            }
            Some(_) => {}
        }
    }
    // A misspelt method would match none of ours, and the comparison would say "–" unsaid.
    if let Some(e) = &t.equivalent
        && mirrorbox_raster::registry::find(e).is_none()
    {
        return Err(refused(
            path,
            format!(
                "equivalent: {e:?} is no mirrorbox method; one of {} (or leave it out)",
                mirrorbox_raster::METHODS
                    .iter()
                    .map(|m| m.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    Ok(t)
}

/// The method name of `client/variant` in the records and the report: the client's own for
/// its `floor` variant (its no-mirror floor), else `<client>-<variant>`.
fn method_name(client: &str, variant: &str) -> String {
    if variant == "floor" {
        client.to_string()
    } else {
        format!("{client}-{variant}")
    }
}

/// Refuses a run in which two variants would be one method in the report (`a-b/c` and
/// `a/b-c` are both `a-b-c`: their rows and points would be told apart by nothing), or a
/// variant would take the name of one of mirrorbox's methods (`path/textures`), which a
/// `--with` sweep's points carry.
fn check_method_names(found: &[(String, String, PathBuf)]) -> Result<(), HarnessError> {
    let mut seen: BTreeMap<String, String> = BTreeMap::new();
    for (client, variant, dir) in found {
        let name = method_name(client, variant);
        if mirrorbox_raster::registry::find(&name).is_some() {
            return Err(refused(
                dir,
                format!(
                    "{client}/{variant} would be method {name:?} in the report, the name of \
                     mirrorbox's own method: rename the client or the variant"
                ),
            ));
        }
        let this = format!("{client}/{variant}");
        if let Some(other) = seen.insert(name.clone(), this.clone()) {
            return Err(refused(
                dir,
                format!(
                    "{this} and {other} would both be method {name:?} in the report: rename a \
                     client or variant"
                ),
            ));
        }
    }
    Ok(())
}

/// The stem of the report's pictures of `client/variant` at `view` (`images/<stem>.png`, with
/// `_flip` and `_inset` beside it).
fn picture_stem(client: &str, variant: &str, view: &str) -> String {
    format!("{client}_{variant}_{view}")
}

/// Refuses a run whose pictures would share a file in the report: names may hold `_`, so
/// `a_b/c` and `a/b_c` (or a view `x_flip` beside `x`'s heat map) would write one file and
/// both rows would show it.
fn check_picture_names(
    found: &[(String, String, PathBuf)],
    views: &ViewsFile,
) -> Result<(), HarnessError> {
    let mut seen: BTreeMap<String, (String, String)> = BTreeMap::new();
    for (client, _, dir) in found {
        // The report's own pictures begin so: `truth_<view>.png`, `with<k>_…` (a `--with`
        // sweep's).
        let reserved = client == "truth"
            || client
                .strip_prefix("with")
                .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()));
        if reserved {
            return Err(refused(
                dir,
                format!(
                    "client name {client:?} is the report's own (its truth pictures are \
                     truth_<view>.png, a --with sweep's with<k>_…): rename the client"
                ),
            ));
        }
    }
    for (client, variant, dir) in found {
        for v in &views.views {
            let stem = picture_stem(client, variant, &v.name);
            for file in [
                format!("{stem}.png"),
                format!("{stem}_flip.png"),
                format!("{stem}_inset.png"),
            ] {
                let this = (format!("{client}/{variant}"), v.name.clone());
                if let Some((other, view)) = seen.insert(file.clone(), this.clone())
                    && (&other, &view) != (&this.0, &this.1)
                {
                    return Err(refused(
                        dir,
                        format!(
                            "its pictures of view {:?} and those of {other} at view {view:?} \
                             would share images/{file} in the report: rename a client, variant \
                             or view",
                            v.name
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Every `RUN/<client>/<variant>/` folder, sorted; hidden folders (a name beginning with
/// `.`) are no client's or variant's.
fn variants(run: &Path) -> Result<Vec<(String, String, PathBuf)>, HarnessError> {
    // A mistyped RUN is the user's input (exit 2), not a failure to read.
    if !run.is_dir() {
        return Err(refused(run, "is not a folder (RUN/<client>/<variant>/)"));
    }
    let list = |dir: &Path| -> Result<Vec<(String, PathBuf)>, HarnessError> {
        let mut out = Vec::new();
        for e in std::fs::read_dir(dir).map_err(io(dir))? {
            let e = e.map_err(io(dir))?;
            let name = e.file_name().to_string_lossy().into_owned();
            // A hidden entry is a client's staging (`.three.tmp-…`, a run being written or
            // one that was killed), not a client or a variant.
            if e.path().is_dir() && !name.starts_with('.') {
                if !valid_name(&name) {
                    return Err(refused(
                        &e.path(),
                        "a client or variant name is 1 to 64 letters, digits, '-' or '_'",
                    ));
                }
                out.push((name, e.path()));
            }
        }
        out.sort();
        Ok(out)
    };
    let mut out = Vec::new();
    for (client, dir) in list(run)? {
        for (variant, vdir) in list(&dir)? {
            out.push((client.clone(), variant, vdir));
            if out.len() > MAX_VARIANTS {
                return Err(refused(run, format!("more than {MAX_VARIANTS} variants")));
            }
        }
    }
    if out.is_empty() {
        return Err(refused(run, "holds no <client>/<variant>/ folder"));
    }
    Ok(out)
}

/// Refuses an image in a variant folder that is no view's (`c.exr` where views.json has no
/// view `c`): its view was misnamed, and it was skipped unsaid (a `timing.json` naming an
/// unknown view is refused alike).
fn check_no_stray_image(dir: &Path, views: &ViewsFile) -> Result<(), HarnessError> {
    for e in std::fs::read_dir(dir).map_err(io(dir))? {
        let path = e.map_err(io(dir))?.path();
        let image = path
            .extension()
            .is_some_and(|x| x.eq_ignore_ascii_case("exr") || x.eq_ignore_ascii_case("png"));
        let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
        if image
            && let Some(stem) = stem
            && !views.views.iter().any(|v| v.name == stem)
        {
            let case = views
                .views
                .iter()
                .find(|v| v.name.eq_ignore_ascii_case(&stem))
                .map(|v| format!(" (it differs only in case from view {:?})", v.name))
                .unwrap_or_default();
            return Err(refused(
                &path,
                format!(
                    "an image of no view{case}: views.json has {} (a variant folder holds \
                     <view>.exr or <view>.png and timing.json)",
                    views
                        .views
                        .iter()
                        .map(|v| format!("{:?}", v.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// A view's image in a variant folder: `<view>.exr`, else `<view>.png`; checked for its size
/// and for pixels that are not radiance (NaN, infinite, negative).
fn view_image(dir: &Path, view: &crate::exchange::ExportedView) -> Result<PathBuf, HarnessError> {
    let exr = dir.join(format!("{}.exr", view.name));
    let png = dir.join(format!("{}.png", view.name));
    if exr.is_file() && png.is_file() {
        // One would be scored and the other ignored unsaid.
        return Err(refused(
            dir,
            format!(
                "two images of view {:?} ({0}.exr and {0}.png): keep the one to score",
                view.name
            ),
        ));
    }
    // A folder, device or FIFO of a picture's name is named as such (a folder `camera.exr`
    // had been said to differ only in case).
    if let Some(odd) = [&exr, &png]
        .into_iter()
        .find(|p| p.exists() && !p.is_file())
    {
        return Err(refused(
            odd,
            format!(
                "view {:?}'s picture is not a regular file (a folder, a device or a FIFO)",
                view.name
            ),
        ));
    }
    let path = if exr.is_file() { exr } else { png };
    if !path.is_file() {
        let hint = picture_elsewhere(dir, &view.name);
        return Err(refused(
            dir,
            format!(
                "no image of view {:?} ({0}.exr or {0}.png){hint}",
                view.name
            ),
        ));
    }
    check_view_picture(&path, view).map_err(HarnessError::Exchange)?;
    Ok(path)
}

/// Where `dir` has no picture of view `name`, the one it has under another name, as a hint
/// for the refusal: one whose extension differs only in case (`camera.EXR`), one in a format
/// score does not read (a client's `camera.jpg`) or without an extension; else what the
/// folder holds. (An EXR or PNG of another stem, `Camera.png` among them, was refused before:
/// `check_no_stray_image`.)
fn picture_elsewhere(dir: &Path, name: &str) -> String {
    let names: Vec<String> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|e| e.file_name().into_string().ok())
        .collect();
    // `camera.EXR`: its stem is the view's, so no stray; its extension's case is the miss.
    let wanted = [format!("{name}.exr"), format!("{name}.png")];
    let near: Vec<&str> = names
        .iter()
        .map(String::as_str)
        .filter(|n| wanted.iter().any(|w| w.eq_ignore_ascii_case(n)))
        .collect();
    if !near.is_empty() {
        return format!("; {} differs only in case", near.join(", "));
    }
    let unread: Vec<&str> = names
        .iter()
        .map(String::as_str)
        .filter(|n| {
            *n == name
                || n.rsplit_once('.').is_some_and(|(stem, ext)| {
                    stem == name
                        && !["exr", "png", "json"]
                            .iter()
                            .any(|k| ext.eq_ignore_ascii_case(k))
                })
        })
        .collect();
    if !unread.is_empty() {
        return format!(
            "; {} is in a format score does not read, or has no extension (a picture is \
             <view>.exr, linear radiance, or <view>.png, 8-bit sRGB)",
            unread.join(", ")
        );
    }
    // Nothing like it: what the folder does hold, so that a misnamed picture is seen.
    let mut others: Vec<&str> = names
        .iter()
        .map(String::as_str)
        .filter(|n| *n != "timing.json")
        .collect();
    others.sort_unstable();
    match others.len() {
        0 => "; the folder holds only timing.json".to_string(),
        n if n <= 6 => format!("; the folder holds {}", others.join(", ")),
        n => format!(
            "; the folder holds {} and {} more",
            others[..6].join(", "),
            n - 6
        ),
    }
}

/// Checks the image at `path` as a picture of `view`'s radiance: readable, the view's size
/// (compared by its header, before it is decoded), every pixel finite and ≥ 0
/// ([`mirrorbox_image::RgbImage::radiance_problem`]). The error names the file.
fn check_view_picture(path: &Path, view: &crate::exchange::ExportedView) -> Result<(), String> {
    // The image's own errors name its file.
    let size = mirrorbox_image::image_size(path).map_err(|e| e.to_string())?;
    if let Some(problem) = size_problem(size, view) {
        return Err(format!("{}: {problem}", path.display()));
    }
    let img = mirrorbox_image::read_image(path).map_err(|e| e.to_string())?;
    match img.radiance_problem() {
        Some(problem) => Err(format!("{}: {problem}", path.display())),
        None => Ok(()),
    }
}

/// Why an image of `(width, height)` is not one of `view`, if it is not.
fn size_problem(
    (width, height): (u32, u32),
    view: &crate::exchange::ExportedView,
) -> Option<String> {
    ((width, height) != (view.width, view.height)).then(|| {
        format!(
            "is {width}×{height}; view {:?} is {}×{}",
            view.name, view.width, view.height
        )
    })
}

/// Checks the export's truth `views[i].<field>` (`file`, relative to `export`) as a client's
/// image is checked — readable, the view's size, radiance in every pixel — and its sRGB
/// picture beside it (copied into the report): the export is an input like the run, read
/// before anything is written.
fn check_truth(
    export: &Path,
    i: usize,
    field: &str,
    file: &str,
    view: &crate::exchange::ExportedView,
) -> Result<(), HarnessError> {
    let path = export.join(file);
    let at = |e: &dyn std::fmt::Display| HarnessError::Exchange(format!("views[{i}].{field}: {e}"));
    check_view_picture(&path, view).map_err(|e| at(&e))?;
    let picture = path.with_extension("png");
    if picture != path {
        mirrorbox_files::open_regular(
            &picture,
            mirrorbox_image::MAX_IMAGE_FILE_BYTES,
            "the truth's sRGB picture",
        )
        .map_err(|e| at(&e))?;
    }
    Ok(())
}

/// Why our record `r` (a `score --with` sweep's) is not of the exported scene at one of its
/// views, if it is not. The scene by the hash a sweep of it records (else, in an export
/// written before the hash was kept, by the scene file's name); the view by the one at the
/// scene's own camera ([`crate::exchange::ExportedView::scene_camera`]; else, in an older
/// export, any of its size); and, for every export, the view's size and ssaa and no scene
/// axis.
fn not_of_the_export(views: &ViewsFile, r: &Record) -> Option<String> {
    match &views.sweep_scene_hash {
        Some(hash) if &r.scene_hash != hash => {
            return Some(format!(
                "a sweep of {} (scene hash {}), not of the scene exported ({}, {hash})",
                r.scene, r.scene_hash, views.source
            ));
        }
        Some(_) => {}
        None => {
            let same_file = match (
                Path::new(&r.scene).canonicalize(),
                Path::new(&views.source).canonicalize(),
            ) {
                (Ok(x), Ok(y)) => x == y,
                _ => Path::new(&r.scene).file_name() == Path::new(&views.source).file_name(),
            };
            if !same_file {
                return Some(format!(
                    "a sweep of {}, not of the scene exported ({})",
                    r.scene, views.source
                ));
            }
        }
    }
    let view = if views.sweep_scene_hash.is_some() {
        views.views.iter().find(|v| v.scene_camera)
    } else {
        views
            .views
            .iter()
            .find(|v| (v.width, v.height) == (r.width, r.height))
    };
    let Some(v) = view else {
        return Some(
            "no view of the export is the scene's own camera, the one a sweep shows".into(),
        );
    };
    if (v.width, v.height, v.ssaa) != (r.width, r.height, r.ssaa) {
        return Some(format!(
            "{}×{}, ssaa {}; view {:?} is {}×{}, ssaa {}",
            r.width, r.height, r.ssaa, v.name, v.width, v.height, v.ssaa
        ));
    }
    (!r.axes.is_empty()).then(|| {
        format!(
            "swept along {} (a camera turn, a tilt, lights): not view {:?} as exported",
            r.axes.keys().cloned().collect::<Vec<_>>().join(", "),
            v.name
        )
    })
}

/// Our own sweeps (`--with`), set beside the run's variants in one report: their records as
/// they are (their own truth, device and timing), each with its folder, checked to be of the
/// export's scene, views and α, and their pictures files of their folders.
fn our_sweeps(views: &ViewsFile, with: &[PathBuf]) -> Result<Vec<(PathBuf, Record)>, HarnessError> {
    let mut ours: Vec<(PathBuf, Record)> = Vec::new();
    for dir in with {
        let sweep = mirrorbox_report::load_sweep(dir).map_err(|e| refused(dir, e))?;
        if sweep.info.is_score() {
            return Err(refused(
                dir,
                "an earlier score, not a sweep of ours: --with takes a `mirrorbox sweep`'s \
                 folder (its variants would be listed twice)",
            ));
        }
        if let Some(r) = sweep.records.iter().find(|r| {
            !views
                .views
                .iter()
                .any(|v| v.width == r.width && v.height == r.height)
        }) {
            return Err(refused(
                dir,
                format!(
                    "{}: {}×{} is not the size of any view of the export",
                    r.key, r.width, r.height
                ),
            ));
        }
        // Of the scene exported, at a view's camera, size and ssaa, and its α: another
        // scene's floor and points, another view's, or another α's, were set beside the
        // variants as if comparable (found by reviews). The scene by its content (an edited
        // scene, or another of the same file name, is not the exported one); by its file
        // where the export predates the hashes.
        for r in sweep.records.iter().filter(|r| !r.is_external()) {
            if let Some(problem) = not_of_the_export(views, r) {
                return Err(refused(dir, format!("{}: {problem}", r.key)));
            }
        }
        if let Some(alpha) = views.alpha
            && let Some(r) = sweep
                .records
                .iter()
                .find(|r| r.kind == "point" && !r.is_external() && r.alpha != alpha)
        {
            return Err(refused(
                dir,
                format!(
                    "{}: α = {}, not the export's α = {alpha} (sweep only that α beside it)",
                    r.key, r.alpha
                ),
            ));
        }
        // Where the export's mirrors differ ([`read_views`]), no sweep (one α for every
        // mirror) shows its scene.
        if views.mirrors_differ
            && let Some(r) = sweep
                .records
                .iter()
                .find(|r| r.kind == "point" && !r.is_external())
        {
            return Err(refused(
                dir,
                format!(
                    "{}: a sweep sets one α for every mirror (here {}), and the export's mirrors \
                     have different reflectances: export with --alpha to compare a sweep",
                    r.key, r.alpha
                ),
            ));
        }
        // Their pictures are copied into the report: each must be a file in the sweep's images/.
        for r in &sweep.records {
            crate::check_record_pictures(dir, r).map_err(HarnessError::Exchange)?;
        }
        ours.extend(sweep.records.into_iter().map(|r| (dir.clone(), r)));
    }
    Ok(ours)
}

/// Refuses a score's output folder that holds a sweep (or any sweep.json but an earlier
/// score's).
fn check_not_a_sweep(out: &Path) -> Result<(), HarnessError> {
    // A sweep folder has a sweep.json too: replacing it would lose its records and cached
    // truths (found by a review). Only an earlier score's is replaced, told by its sweep.json
    // alone (a sweep stopped before its first point has no records to load).
    let description = out.join("sweep.json");
    if description.is_file() {
        match mirrorbox_report::read_sweep_info(out).ok() {
            Some(info) if info.is_score() => {}
            Some(info) => {
                return Err(refused(
                    out,
                    format!(
                        "holds a sweep of {} ({}), not an earlier score: give a new or empty \
                         folder",
                        info.scene, info.backend
                    ),
                ));
            }
            None => {
                return Err(refused(
                    out,
                    "holds a sweep.json that is no earlier score's: give a new or empty folder",
                ));
            }
        }
    }
    Ok(())
}

/// What every scored view of one score shares: the export, the stage the score is written
/// into, the export's views, the run's time and whether its mirrors' α is per mirror.
struct ScoreStage<'a> {
    export: &'a Path,
    stage: &'a Path,
    views: &'a ViewsFile,
    run: &'a str,
    per_mirror: bool,
}

/// The truth a variant's picture of view `v` is scored against: the view's, or its floor
/// truth for a variant named `floor`.
fn truth_of(export: &Path, variant: &str, v: &ExportedView) -> PathBuf {
    export.join(if variant == "floor" {
        &v.floor
    } else {
        &v.truth
    })
}

/// The record of a variant's (`client`, `variant`, its `timing`) picture `image` of view `vi`:
/// compared with the export's truth (its floor truth for a variant named `floor`), its
/// pictures written into the stage's images/.
fn scored_record(
    ctx: &ScoreStage,
    (client, variant, timing): (&str, &str, &Timing),
    vi: usize,
    v: &ExportedView,
    image: &PathBuf,
) -> Result<Record, HarnessError> {
    let (export, partial, views) = (ctx.export, ctx.stage, ctx.views);
    let images_dir = partial.join("images");
    let floor = variant == "floor";
    let truth = truth_of(export, variant, v);
    let slug = picture_stem(client, variant, &v.name);
    let files = ViewFiles {
        raster: images_dir.join(format!("{slug}.png")),
        heat: images_dir.join(format!("{slug}_flip.png")),
        truth: images_dir.join(format!(
            "truth_{}{}.png",
            v.name,
            if floor { "_floor" } else { "" }
        )),
    };
    let compared = compare_views(
        std::slice::from_ref(&truth),
        std::slice::from_ref(image),
        v.camera.exposure,
        None,
        &files,
    )?;
    let frames_ms = timing.views[&v.name].clone();
    let interval = mirrorbox_report::stats::median_interval(&frames_ms);
    let rel = |p: &Path| {
        p.strip_prefix(partial)
            .unwrap_or(p)
            .to_string_lossy()
            .into_owned()
    };
    let png = image
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    Ok(Record {
        key: format!(
            "{client}/{variant}|{}|a{}|{}x{}|ssaa{}",
            v.name,
            views.alpha.map_or("-".to_string(), |a| a.to_string()),
            v.width,
            v.height,
            v.ssaa
        ),
        kind: if floor { "floor" } else { "point" }.into(),
        scene: views.source.clone(),
        scene_hash: v.scene_hash.clone(),
        method: method_name(client, variant),
        // The variant's short knobs (its name in legends and tables), then the
        // method it is meant to match; every parameter is in variants.md.
        method_options: timing
            .parameters
            .iter()
            .map(|(k, v)| (k, v.to_string().trim_matches('"').to_string()))
            .filter(|(k, v)| is_knob(k, v))
            .map(|(k, v)| format!("{k}={v}"))
            .chain(timing.equivalent.iter().map(|e| format!("equivalent={e}")))
            .collect::<Vec<_>>()
            .join(" "),
        axes: if views.views.len() > 1 {
            [(mirrorbox_report::axis::VIEW.to_string(), vi as f64)]
                .into_iter()
                .collect()
        } else {
            BTreeMap::new()
        },
        values: [
            (mirrorbox_report::value::SCENE_CAMERA, v.scene_camera),
            (mirrorbox_report::value::ALPHA_PER_MIRROR, ctx.per_mirror),
        ]
        .into_iter()
        .filter(|&(_, on)| on)
        .map(|(name, _)| (name.to_string(), 1.0))
        .collect(),
        legacy: Default::default(),
        stereo: None,
        device: None,
        n: None,
        depth: None,
        // Where the mirrors differ (`per_mirror`), or an older export kept no α and its scene
        // does not load, 1 stands for none; the reports say "per mirror" for the first.
        alpha: views.alpha.unwrap_or(1.0),
        width: v.width,
        height: v.height,
        ssaa: v.ssaa,
        ms_median: mirrorbox_report::stats::median(&frames_ms),
        ms_min: frames_ms.iter().copied().fold(f64::INFINITY, f64::min),
        ms_interval: interval.map(|i| [i.low, i.high]),
        frames: frames_ms.len() as u32,
        frames_ms,
        timing_order: mirrorbox_report::EXTERNAL_TIMING.into(),
        run: Some(ctx.run.to_string()),
        peak_memory_bytes: None,
        plan_ms: None,
        encode_ms: None,
        gpu_buffer_bytes: None,
        gpu_texture_bytes: None,
        timing_source: timing.timing.clone(),
        passes: 0,
        draws: 0,
        texture_renders: 0,
        reflections: 0,
        triangles: None,
        paths: None,
        paths_pruned: None,
        metrics: compared.metrics,
        mirror_metrics: compared.mirror_metrics,
        mirror_pixel_share: compared.mirror_pixel_share,
        split: None,
        adapter: timing.device.clone(),
        backend: format!("{} {}", timing.engine, timing.engine_version),
        color_format: if png {
            "png8 (sRGB)".into()
        } else {
            // The image was read before (`check_view_picture`): its type is float or half.
            let samples = mirrorbox_image::exr_rgb_samples(image).unwrap_or("float");
            format!("exr ({samples})")
        },
        truth_image: rel(&files.truth),
        raster_image: rel(&files.raster),
        heatmap_image: rel(&files.heat),
    })
}

/// Scores `run` against `export` into `out` (see the module docs). Every input is read and
/// checked before anything is written; the report goes to `out.partial` and is moved into
/// place at the end (an earlier score in `out` is replaced).
pub fn score(
    export: &Path,
    run: &Path,
    out: &Path,
    settings: &ScoreSettings,
) -> Result<Scored, HarnessError> {
    let command = settings.command.as_str();
    let views = read_views(export)?;
    let ours = our_sweeps(&views, &settings.with)?;
    let found = variants(run)?;
    check_picture_names(&found, &views)?;
    check_method_names(&found)?;
    // Which sweep.json is a score's, check_not_a_sweep says (naming a sweep's).
    crate::exchange::replaceable(out, "sweep.json", "score", serde_json::Value::is_object)?;
    check_not_a_sweep(out)?;
    for input in [export, run]
        .into_iter()
        .chain(settings.with.iter().map(PathBuf::as_path))
    {
        crate::exchange::not_the_stage_of(out, input)?;
    }
    // Everything read and checked first: the export's truths that the variants are compared
    // with (the floor truths for variants named `floor`), then each variant's files.
    let floor = found.iter().any(|(_, variant, _)| variant == "floor");
    let mirrors = found.iter().any(|(_, variant, _)| variant != "floor");
    for (i, v) in views.views.iter().enumerate() {
        if mirrors {
            check_truth(export, i, "truth", &v.truth, v)?;
        }
        if floor {
            check_truth(export, i, "floor", &v.floor, v)?;
        }
    }
    let mut inputs = Vec::new();
    for (client, variant, dir) in &found {
        let timing_file = dir.join("timing.json");
        if !timing_file.exists() {
            // A run nested a level too deep, or a variant without its times.
            return Err(refused(
                dir,
                "no timing.json: a variant folder RUN/<client>/<variant>/ holds <view>.exr (or \
                 .png) and timing.json (docs/exchange.md)",
            ));
        }
        let timing = read_timing(&timing_file, &views)?;
        // A stray image first: `cam.exr` beside no `camera.exr` is named as what it is.
        check_no_stray_image(dir, &views)?;
        let mut images = Vec::new();
        for v in &views.views {
            images.push(view_image(dir, v)?);
        }
        inputs.push((client, variant, timing, images));
    }
    crate::exchange::in_staged_folder(out, |partial| {
        let images_dir = partial.join("images");
        std::fs::create_dir_all(&images_dir).map_err(io(&images_dir))?;
        let mut records = Vec::new();
        // A scored folder is one run: the outside variants share the run of our sweep beside
        // them (`--with`, measured with them), else the scoring's time. (No paired ratio is
        // taken with an outside variant: its timing order is its own.)
        let run_started = ours
            .iter()
            .filter_map(|(_, r)| r.run.clone())
            .max()
            .unwrap_or_else(crate::now_rfc3339);
        let per_mirror = views.mirrors_differ;
        let stage = ScoreStage {
            export,
            stage: partial,
            views: &views,
            run: &run_started,
            per_mirror,
        };
        let mut hints = Vec::new();
        for (client, variant, timing, images) in &inputs {
            for (vi, (v, image)) in views.views.iter().zip(images).enumerate() {
                records.push(scored_record(
                    &stage,
                    (client, variant, timing),
                    vi,
                    v,
                    image,
                )?);
                hints.extend(picture_hint(&truth_of(export, variant, v), image)?);
            }
        }
        // Our records' pictures come along (`images/with<k>_…`), so that their rows show.
        for (k, dir) in settings.with.iter().enumerate() {
            for (_, r) in ours.iter().filter(|(d, _)| d == dir) {
                let mut r = r.clone();
                // Each sweep's records known as its own: their floors are two timings, and
                // keys alike (every sweep's floor has one) had kept only the last sweep's.
                r.values
                    .insert(mirrorbox_report::value::WITH_SWEEP.into(), k as f64);
                if k > 0 {
                    r.key = format!("{}|with={k}", r.key);
                }
                for image in [
                    &mut r.truth_image,
                    &mut r.raster_image,
                    &mut r.heatmap_image,
                ] {
                    let from = dir.join(&*image);
                    let name = Path::new(image.as_str())
                        .file_name()
                        .map(|n| format!("images/with{k}_{}", n.to_string_lossy()));
                    if let (true, Some(name)) = (from.is_file(), name) {
                        let to = partial.join(&name);
                        std::fs::copy(&from, &to).map_err(io(&to))?;
                        *image = name;
                    }
                }
                records.push(r);
            }
        }
        let lines: String = records
            .iter()
            .map(|r| serde_json::to_string(r).map(|l| l + "\n"))
            .collect::<Result<_, _>>()?;
        let results = partial.join("results.jsonl");
        std::fs::write(&results, lines).map_err(io(&results))?;
        let devices = mirrorbox_report::document::distinct(
            inputs
                .iter()
                .map(|(_, _, t, _)| format!("{} ({} {})", t.device, t.engine, t.engine_version)),
        );
        let drivers = mirrorbox_report::document::distinct(
            inputs
                .iter()
                .map(|(_, _, t, _)| t.driver.clone())
                .filter(|d| !d.is_empty()),
        );
        let first = &views.views[0];
        let info = SweepInfo {
            command: command.to_string(),
            date: crate::now_rfc3339(),
            cpu: crate::cpu_description(),
            adapter: devices.join("; "),
            backend: "external (mirrorbox score)".into(),
            device_type: "external".into(),
            driver: drivers.join("; "),
            versions: format!(
                "mirrorbox {}, exchange version {FORMAT_VERSION}",
                env!("CARGO_PKG_VERSION")
            ),
            scene: views.source.clone(),
            resolution: format!(
                "{}x{}, ssaa {} (truth: the same {}x{} sub-pixel grid)",
                first.width, first.height, first.ssaa, first.ssaa, first.ssaa
            ),
            truth: views.contract.truth.clone(),
            commit: crate::source_commit(),
            exact_methods: mirrorbox_raster::METHODS
                .iter()
                .filter(|e| e.exact)
                .map(|e| e.name.to_string())
                .collect(),
            ..SweepInfo::default()
        };
        let sweep = partial.join("sweep.json");
        std::fs::write(&sweep, serde_json::to_string_pretty(&info)?).map_err(io(&sweep))?;
        write_report(partial, &info, &records, &settings.sections)?;
        // Each variant's engine, knobs and notes (how it follows the contract), in prose.
        let mut variants_md = String::from("# The variants scored\n\n");
        for (client, variant, t, _) in &inputs {
            variants_md.push_str(&format!(
                "## {client}/{variant}\n\n- Engine: {} {}\n- Device: {}{}\n- Timing: {}\n",
                t.engine,
                t.engine_version,
                t.device,
                if t.driver.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", t.driver)
                },
                t.timing
            ));
            if let Some(e) = &t.equivalent {
                variants_md.push_str(&format!("- Meant to match: `{e}`\n"));
            }
            for (k, v) in &t.parameters {
                variants_md.push_str(&format!("- `{k}`: {}\n", v.to_string().trim_matches('"')));
            }
            if let Some(n) = &t.notes {
                variants_md.push_str(&format!("\n{n}\n"));
            }
            variants_md.push('\n');
        }
        if !hints.is_empty() {
            variants_md.push_str("## Pictures that look mis-encoded\n\n");
            for h in &hints {
                variants_md.push_str(&format!("- {h}\n"));
            }
        }
        let variants_file = partial.join("variants.md");
        std::fs::write(&variants_file, variants_md).map_err(io(&variants_file))?;
        Ok(Scored {
            records: records.len(),
            variants: inputs.len(),
            hints,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dark truth with little structure, a client's picture of it sRGB-encoded (said), and
    /// a flat grey picture that decoding brings 29× nearer (not said: decoded, it is no
    /// nearer than the nearest flat picture; it had been called sRGB-encoded).
    #[test]
    fn only_a_picture_that_keeps_the_truths_structure_is_called_srgb_encoded() {
        let dir = tempfile::tempdir().unwrap();
        let (w, h) = (16u32, 16u32);
        let image = |f: &dyn Fn(u32, u32) -> [f32; 3]| mirrorbox_image::RgbImage {
            width: w,
            height: h,
            pixels: (0..w * h).map(|i| f(i % w, i / w)).collect(),
        };
        let truth = image(&|x, y| [0.02 + 0.01 * ((x + y) % 2) as f32, 0.02, 0.03]);
        let save = |name: &str, img: &mirrorbox_image::RgbImage| {
            let path = dir.path().join(name);
            mirrorbox_image::write_exr(&path, img, &[]).unwrap();
            path
        };
        let t = save("truth.exr", &truth);
        let encoded = image(&|x, y| {
            let i = (y * w + x) as usize;
            truth.pixels[i].map(mirrorbox_image::srgb::encode)
        });
        let hint = picture_hint(&t, &save("encoded.exr", &encoded)).unwrap();
        assert!(hint.is_some_and(|h| h.contains("sRGB-encoded?")));
        let grey = image(&|_, _| [0.025, 0.02, 0.03].map(mirrorbox_image::srgb::encode));
        assert_eq!(picture_hint(&t, &save("grey.exr", &grey)).unwrap(), None);
        // A flat truth, and that grey picture exactly its encoding: said.
        let flat = save("flat.exr", &image(&|_, _| [0.025, 0.02, 0.03]));
        let hint = picture_hint(&flat, &save("grey.exr", &grey)).unwrap();
        assert!(hint.is_some_and(|h| h.contains("sRGB-encoded?")));
    }

    fn schema(name: &str) -> serde_json::Value {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../docs/exchange")
            .join(name);
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
    }

    /// The published schema of timing.json says what `score` reads: its example is read, a
    /// file without any one required field is refused, and so is one with a field the schema
    /// does not name (additionalProperties: false).
    #[test]
    fn the_timing_schema_is_what_score_reads() {
        let s = schema("timing.schema.json");
        let example = s["examples"][0].clone();
        assert!(serde_json::from_value::<Timing>(example.clone()).is_ok());
        let properties: Vec<&String> = s["properties"].as_object().unwrap().keys().collect();
        for required in s["required"].as_array().unwrap() {
            let mut doc = example.clone();
            doc.as_object_mut()
                .unwrap()
                .remove(required.as_str().unwrap());
            assert!(serde_json::from_value::<Timing>(doc).is_err(), "{required}");
        }
        let required = s["required"].as_array().unwrap();
        for p in &properties {
            assert!(example.get(p.as_str()).is_some(), "the example shows {p}");
            if !required.iter().any(|r| r == p.as_str()) {
                let mut doc = example.clone();
                doc.as_object_mut().unwrap().remove(p.as_str());
                assert!(
                    serde_json::from_value::<Timing>(doc).is_ok(),
                    "{p} is optional"
                );
            }
        }
        // null where the schema allows it (as absent), and nowhere else.
        for p in &properties {
            let nullable = s["properties"][p.as_str()]["type"]
                .as_array()
                .is_some_and(|t| t.iter().any(|t| t == "null"));
            let mut doc = example.clone();
            doc[p.as_str()] = serde_json::Value::Null;
            assert_eq!(
                serde_json::from_value::<Timing>(doc).is_ok(),
                nullable,
                "{p}: null"
            );
        }
        let mut doc = example;
        doc["unknown"] = serde_json::json!(1);
        assert!(serde_json::from_value::<Timing>(doc).is_err());
    }

    /// An export older than the scene hashes, without `alpha`: its scene says the α (the
    /// mirrors' one grey reflectance), or that the mirrors differ; one whose scene is gone
    /// keeps no α. An export with the hashes and no α has mirrors that differ.
    #[test]
    fn an_older_export_takes_its_alpha_from_its_scene() {
        let dir = tempfile::tempdir().unwrap();
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let scene = std::fs::read_to_string(root.join("scenes/mirror_box.json")).unwrap();
        let mut views = crate::exchange::tests_support::sample_view();
        (views.alpha, views.sweep_scene_hash) = (None, None);
        std::fs::write(
            dir.path().join("views.json"),
            serde_json::to_string(&views).unwrap(),
        )
        .unwrap();
        let read = || read_views(dir.path()).unwrap();
        assert_eq!(
            (read().alpha, read().mirrors_differ),
            (None, false),
            "no scene"
        );
        std::fs::write(dir.path().join("scene.json"), &scene).unwrap();
        assert_eq!((read().alpha, read().mirrors_differ), (Some(0.9), false));
        let tinted = scene.replacen("[0.9, 0.9, 0.9]", "[0.9, 0.8, 0.9]", 1);
        assert_ne!(tinted, scene);
        std::fs::write(dir.path().join("scene.json"), &tinted).unwrap();
        assert_eq!((read().alpha, read().mirrors_differ), (None, true));
        // With the hashes, no α is the mirrors differing, whatever the scene file.
        views.sweep_scene_hash = Some("00".into());
        std::fs::write(
            dir.path().join("views.json"),
            serde_json::to_string(&views).unwrap(),
        )
        .unwrap();
        std::fs::write(dir.path().join("scene.json"), &scene).unwrap();
        assert_eq!((read().alpha, read().mirrors_differ), (None, true));
    }

    /// A views.json that an export could not have written is refused naming the field, in
    /// the file: no view, a name that is no file name or that clashes, a size no image has,
    /// a truth outside the export folder. (An empty list panicked, a name such as
    /// `../../x` was used as a path.)
    #[test]
    fn a_views_json_is_checked_field_by_field() {
        let dir = tempfile::tempdir().unwrap();
        let good = crate::exchange::tests_support::sample_view();
        let write = |views: &ViewsFile| {
            std::fs::write(
                dir.path().join("views.json"),
                serde_json::to_string(views).unwrap(),
            )
            .unwrap();
        };
        write(&good);
        assert!(read_views(dir.path()).is_ok());
        let with = |edit: &dyn Fn(&mut ViewsFile)| {
            let mut views = good.clone();
            edit(&mut views);
            views
        };
        let second = |views: &mut ViewsFile, name: &str| {
            let mut v = views.views[0].clone();
            v.name = name.into();
            views.views.push(v);
        };
        for (views, needle) in [
            (with(&|v| v.views.clear()), "views: 0 views; 1 to 64"),
            (
                with(&|v| {
                    let one = v.views[0].clone();
                    v.views = vec![one; MAX_VIEWS + 1];
                }),
                "views: 65 views",
            ),
            (
                with(&|v| v.views[0].name = "../../../secret/x".into()),
                "views[0].name \"../../../secret/x\"",
            ),
            (
                with(&|v| v.views[0].name = "sub/cam".into()),
                "views[0].name \"sub/cam\"",
            ),
            (
                with(&|v| second(v, "camera")),
                "views[1].name \"camera\" appears twice",
            ),
            (
                with(&|v| second(v, "camera_floor")),
                "views[1].name \"camera_floor\": the floor truth of views[0]",
            ),
            (with(&|v| v.views[0].width = 0), "views[0].width 0"),
            (
                with(&|v| v.views[0].ssaa = 0),
                "views[0].ssaa 0: a sub-pixel grid side of 1 to",
            ),
            (with(&|v| v.views[0].ssaa = 9), "views[0].ssaa 9"),
            (
                with(&|v| v.views[0].height = 70_000),
                "views[0].height 70000",
            ),
            (
                with(&|v| v.views[0].truth = "../elsewhere/t.exr".into()),
                "views[0].truth \"../elsewhere/t.exr\"",
            ),
            (
                with(&|v| v.views[0].floor = "/etc/passwd".into()),
                "views[0].floor \"/etc/passwd\"",
            ),
        ] {
            write(&views);
            let e = read_views(dir.path()).unwrap_err().to_string();
            assert!(e.contains(needle), "{needle}: {e}");
            assert!(e.contains("views.json"), "{e}");
        }
    }

    /// A view given twice in timing.json's `views` is refused naming it, as a field given
    /// twice at the top is (serde's map kept the last silently).
    #[test]
    fn a_view_given_twice_in_a_timing_file_is_refused() {
        let s = schema("timing.schema.json");
        let mut text = s["examples"][0].to_string();
        let views = text.find("\"views\":{").unwrap() + "\"views\":{".len();
        text.insert_str(views, r#""camera":[5],"#);
        let e = serde_json::from_str::<Timing>(&text)
            .unwrap_err()
            .to_string();
        assert!(e.contains("view \"camera\" is given twice"), "{e}");
    }

    /// A time JSON cannot hold (NaN, 1e400) is refused with what a timing file is, not with
    /// serde's position alone; a missing file names its path once.
    #[test]
    fn a_timing_file_json_cannot_read_says_what_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let views = crate::exchange::tests_support::sample_view();
        let s = schema("timing.schema.json");
        let good = s["examples"][0].to_string();
        let path = dir.path().join("timing.json");
        for bad in ["NaN", "1e400"] {
            let text = good.replacen(
                "\"views\":{\"camera\":[",
                &format!("\"views\":{{\"camera\":[{bad},"),
                1,
            );
            assert_ne!(text, good);
            std::fs::write(&path, text).unwrap();
            let e = read_timing(&path, &views).unwrap_err().to_string();
            assert!(
                e.contains("each time a finite JSON number > 0"),
                "{bad}: {e}"
            );
        }
        let missing = dir.path().join("nothere/timing.json");
        let e = read_timing(&missing, &views).unwrap_err().to_string();
        assert_eq!(e.matches("nothere/timing.json").count(), 1, "{e}");
    }

    /// An export's views.json holds every field the schema requires, at every level.
    #[test]
    fn views_json_as_written_has_what_its_schema_requires() {
        let s = schema("views.schema.json");
        let view = crate::exchange::tests_support::sample_view();
        let doc = serde_json::to_value(&view).unwrap();
        let check = |schema: &serde_json::Value, doc: &serde_json::Value, at: &str| {
            for r in schema["required"].as_array().unwrap() {
                assert!(doc.get(r.as_str().unwrap()).is_some(), "{at}.{r}");
            }
        };
        check(&s, &doc, "views.json");
        check(&s["properties"]["contract"], &doc["contract"], "contract");
        let item = &s["properties"]["views"]["items"];
        check(item, &doc["views"][0], "views[0]");
        check(
            &item["properties"]["camera"],
            &doc["views"][0]["camera"],
            "views[0].camera",
        );
    }
}
