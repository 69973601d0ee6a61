//! `--stereo` and `--ipd` of `trace` and `render` (seed 002's stereo, `crates/scene/src/stereo.rs`):
//! which rig, and where each eye's outputs go.

use crate::Failure;
use mirrorbox_scene::Scene;
use mirrorbox_scene::stereo::{Eye, Stereo};
use std::path::{Path, PathBuf};

/// The flags, shared by `trace` and `render`.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct StereoArgs {
    /// Render both eyes of the camera's `stereo` rig (docs/scene-format.md): one output per
    /// eye (OUT_left, OUT_right), a side-by-side PNG (OUT_sbs.png) and a red–cyan anaglyph
    /// (OUT_anaglyph.png).
    #[arg(long)]
    pub stereo: bool,
    /// Interpupillary distance in scene units, [0, 1] (implies --stereo; overrides the rig's,
    /// or makes an off-axis rig converging at look_at).
    #[arg(long, allow_negative_numbers = true)]
    pub ipd: Option<f32>,
}

impl StereoArgs {
    /// Whether a stereo pair is asked for (`--stereo` or `--ipd`): the outputs are each
    /// eye's and the pair's pictures.
    pub fn asked(&self) -> bool {
        self.stereo || self.ipd.is_some()
    }

    /// The rig to render, if any; exit 2 for `--stereo` on a mono camera or a bad `--ipd`.
    pub fn rig(&self, scene: &Scene) -> Result<Option<Stereo>, Failure> {
        if let Some(ipd) = self.ipd
            && !(ipd.is_finite() && (0.0..=1.0).contains(&ipd))
        {
            return Err(Failure::BadInput(format!(
                "--ipd must be in [0, 1] scene units, got {ipd}"
            )));
        }
        match (self.asked(), scene.stereo, self.ipd) {
            (false, _, _) => Ok(None),
            (true, Some(rig), None) => Ok(Some(rig)),
            (true, _, Some(ipd)) => Ok(Some(scene.stereo_rig(ipd))),
            (true, None, None) => Err(Failure::BadInput(format!(
                "--stereo: {} has no camera.stereo; add one (docs/scene-format.md) or give --ipd",
                scene.source.display()
            ))),
        }
    }
}

/// Each eye's scene (or the scene itself, mono) and the suffix its outputs take.
pub fn views(scene: &Scene, rig: Option<Stereo>) -> Vec<(Option<Eye>, Scene)> {
    match rig {
        None => vec![(None, scene.clone())],
        Some(rig) => Eye::BOTH
            .into_iter()
            .map(|e| (Some(e), scene.eye(&rig, e)))
            .collect(),
    }
}

/// The path an output of view `eye` takes.
pub fn eye_path(path: &Path, eye: Option<Eye>) -> PathBuf {
    match eye {
        None => path.to_path_buf(),
        Some(e) => mirrorbox_files::with_stem_suffix(path, e.name()),
    }
}
