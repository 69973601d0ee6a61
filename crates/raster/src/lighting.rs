//! The lighting option every raster method shares (issue 15, `docs/shading.md`): whether the
//! lights' images through mirrors light the scene (`mirrored`, what the scene's
//! `lighting.mirrored_lights` asks for) or are ignored (`direct`, what a mirror camera alone
//! gives — seed 002's listed limit). The images themselves are drawn by the contract's WGSL
//! (`shaders/shading.wgsl`): one extra light per image, each lighting a fragment only inside
//! its beam.

use crate::method::{OptionKind, OptionSpec, ParamValue, Params};
use mirrorbox_scene::Scene;
use std::borrow::Cow;

/// `--lights direct|mirrored`.
pub static LIGHTS: OptionSpec = OptionSpec {
    name: "lights",
    help: "Light through mirrors: `mirrored` adds the lights' images the scene's \
           lighting.mirrored_lights asks for (exact per-fragment beam test), `direct` ignores \
           them (a mirror camera's lighting alone).",
    kind: OptionKind::Choice {
        values: &["mirrored", "direct"],
    },
    default: ParamValue::Choice("mirrored"),
    sweep: None,
    in_key: true,
};

/// The scene a method with `params` renders: `scene` itself, or with `lights=direct` a copy
/// without light images.
pub fn lit_scene<'a>(scene: &'a Scene, params: &Params) -> Cow<'a, Scene> {
    let direct = params.get(&LIGHTS) == Some(ParamValue::Choice("direct"));
    if direct && !scene.lighting.images.images.is_empty() {
        let mut s = scene.clone();
        s.lighting.images.images.clear();
        Cow::Owned(s)
    } else {
        Cow::Borrowed(scene)
    }
}
