//! The options of the uneven-mirror tricks (issue 16, seed 002's "uneven mirrors"): how a
//! method that holds a mirror's world in a screen-space texture reads it through a
//! perturbed normal (`docs/shading.md`, "Uneven mirrors"; `docs/methods.md`). The tricks run
//! in `shaders/recursive_texture.wgsl`'s `mirror_colour`; this file names them and their
//! parameters once for the registry.
//!
//! - `flat`: the bump is ignored (a plain mirror camera).
//! - `distort`: the three.js `Water` / Unity water form — the texture lookup moves on screen
//!   by `strength · (t_right, −t_up) · H` pixels (`t` the tangent-space normal, `H` the image
//!   height); `distort-distance` divides that by the eye's distance to the point (scene units),
//!   the falloff variant.
//! - `proxy`: Unreal's planar-reflection form — the reflected ray is intersected with a proxy
//!   plane parallel to the mirror at `proxy-distance` in front of it, and that point's mirror
//!   image is projected into the texture.
//! - `march`: the accurate screen-space form — the reflected ray is marched through the
//!   texture's stored distances (its alpha) until it passes behind the surface seen there,
//!   then refined by bisection; it cannot see what the mirror camera never rendered (outside
//!   the texture, or hidden behind a nearer surface).
//! - `normals`: a diagnostic, not a trick — the mirror shows its shading normal
//!   `(n + 1)/2`, for checking the WGSL normal against the CPU's.
//!
//! Every trick follows the contract's rule: where the perturbed reflection would leave
//! behind the mirror, the mirror shows black.

use crate::method::{OptionKind, OptionSpec, ParamValue, Params};

/// `--bump`: the trick a texture method reads an uneven mirror with.
pub static BUMP: OptionSpec = OptionSpec {
    name: "bump",
    help: "How an uneven mirror (a scene bump) reads its mirror texture: `march` (ray-march the \
           texture's distances), `proxy` (reflected ray meets a plane at --proxy-distance), \
           `distort` / `distort-distance` (screen-space offset by the normal, x --bump-strength), \
           `flat` (ignore the bump), `normals` (show the shading normal; a diagnostic).",
    kind: OptionKind::Choice {
        values: &[
            "march",
            "proxy",
            "distort",
            "distort-distance",
            "flat",
            "normals",
        ],
    },
    default: ParamValue::Choice("march"),
    sweep: None,
    in_key: true,
};

/// `--bump-strength`: the distortion tricks' scale.
pub static BUMP_STRENGTH: OptionSpec = OptionSpec {
    name: "bump-strength",
    help: "Screen offset per unit of the normal's tangential part, in image heights \
           (--bump distort; per scene unit of eye distance with distort-distance).",
    kind: OptionKind::Real {
        min: 0.0,
        min_open: false,
        max: Some(100.0),
    },
    default: ParamValue::Real(0.5),
    sweep: None,
    in_key: true,
};

/// `--proxy-distance`: where the proxy plane stands in front of the mirror.
pub static PROXY_DISTANCE: OptionSpec = OptionSpec {
    name: "proxy-distance",
    help: "Distance of the proxy plane in front of the mirror, scene units (--bump proxy).",
    kind: OptionKind::Real {
        min: 0.0,
        min_open: true,
        max: Some(1.0e4),
    },
    default: ParamValue::Real(2.0),
    sweep: None,
    in_key: true,
};

/// `--march-steps`: the march's samples before bisection.
pub static MARCH_STEPS: OptionSpec = OptionSpec {
    name: "march-steps",
    help: "Samples along the reflected ray before 6 bisection steps (--bump march).",
    kind: OptionKind::Count { min: 4, max: 1024 },
    default: ParamValue::Count(48),
    sweep: None,
    in_key: true,
};

/// `--texture-margin`: the engines' "extra FOV".
pub static TEXTURE_MARGIN: OptionSpec = OptionSpec {
    name: "texture-margin",
    help: "Pixels added around each mirror texture's screen footprint (within the screen), so \
           that lookups a bump moves outside the mirror still find what lies there.",
    kind: OptionKind::Count { min: 0, max: 4096 },
    default: ParamValue::Count(0),
    sweep: None,
    in_key: true,
};

/// The options above, for a method's option list.
pub const OPTIONS: [&OptionSpec; 5] = [
    &BUMP,
    &BUMP_STRENGTH,
    &PROXY_DISTANCE,
    &MARCH_STEPS,
    &TEXTURE_MARGIN,
];

/// The typed settings, as the shader reads them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BumpSettings {
    /// 0 flat, 1 distort, 2 distort-distance, 3 proxy, 4 march, 5 normals.
    pub mode: u32,
    pub strength: f32,
    pub proxy_distance: f32,
    pub march_steps: u32,
    pub margin: u32,
}

impl BumpSettings {
    pub fn from_params(p: &Params) -> Self {
        let mode = match p.choice(&BUMP) {
            "flat" => 0,
            "distort" => 1,
            "distort-distance" => 2,
            "proxy" => 3,
            "march" => 4,
            _ => 5,
        };
        BumpSettings {
            mode,
            strength: p.real(&BUMP_STRENGTH),
            proxy_distance: p.real(&PROXY_DISTANCE),
            march_steps: p.count(&MARCH_STEPS),
            margin: p.count(&TEXTURE_MARGIN),
        }
    }

    /// Whether mirror textures carry distances in their alpha (the march reads them).
    pub fn needs_distances(&self) -> bool {
        self.mode == 4
    }
}
