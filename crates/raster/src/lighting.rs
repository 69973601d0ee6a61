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

/// `--shadows none|map`.
pub static SHADOWS: OptionSpec = OptionSpec {
    name: "shadows",
    help: "Shadows of the scene's lighting.shadows contract: `none` lights every point its lights \
           and light images reach geometrically (no occlusion), `map` tests every straight leg \
           with shadow maps — a cube map per light, one map per light image rendered through its \
           last mirror (crates/raster/src/shadow_maps.rs).",
    kind: OptionKind::Choice {
        values: &["none", "map"],
    },
    default: ParamValue::Choice("none"),
    sweep: None,
    in_key: true,
};

/// What `mirrorbox advise` offers beside every candidate on a scene whose lighting asks for
/// shadows (`lighting.shadows`): the same with shadow maps, at each of these sizes (texels per
/// side) — the truth traces every shadow ray, so a candidate without them is wrong wherever a
/// shadow falls, and cheaper.
pub const ADVISE_SHADOW_MAP_SIZES: &[u32] = &[256, 1024];

/// `--shadow-map-size N`: texels per side of every shadow map layer.
pub static SHADOW_MAP_SIZE: OptionSpec = OptionSpec {
    name: "shadow-map-size",
    help: "Texels per side of each shadow map (with --shadows map).",
    kind: OptionKind::Count { min: 16, max: 4096 },
    default: ParamValue::Count(1024),
    sweep: None,
    in_key: true,
};

/// `--shadow-bias B`: the constant part of the depth bias, in scene units.
pub static SHADOW_BIAS: OptionSpec = OptionSpec {
    name: "shadow-bias",
    help: "Constant depth bias of the shadow test, scene units (with --shadows map); a slope term \
           of one texel's footprint is added to it.",
    kind: OptionKind::Real {
        min: 0.0,
        min_open: false,
        max: Some(1.0),
    },
    default: ParamValue::Real(DEFAULT_SHADOW_BIAS),
    sweep: None,
    in_key: true,
};

/// The default constant bias (scene units; the bundled scenes are a few units across).
pub const DEFAULT_SHADOW_BIAS: f32 = 0.02;

/// Whether a method's options ask for shadow maps.
pub fn wants_shadow_maps(params: &Params) -> bool {
    params.get(&SHADOWS) == Some(ParamValue::Choice("map"))
}

/// The shadow maps a method draws for `scene`: `None` without `--shadows map`, and where the
/// scene's contract has no shadows (`lighting.shadows` false: nothing occludes, so maps
/// would only make the image disagree with the truth).
pub fn shadow_settings(
    scene: &Scene,
    params: &Params,
) -> Option<crate::shadow_plan::ShadowSettings> {
    (scene.lighting.shadows && wants_shadow_maps(params)).then(|| {
        crate::shadow_plan::ShadowSettings {
            size: params.count(&SHADOW_MAP_SIZE),
            bias: params.real(&SHADOW_BIAS),
        }
    })
}
