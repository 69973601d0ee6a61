//! `--stereo-mirrors per-eye|shared` (issue 17, seed 002): in one eye's frame of a stereo
//! pair, render the mirror textures from that eye (seed 002's per-eye mirror cameras), or
//! take them from the head's centre — the shortcut many VR engines ship, one set of mirror
//! textures for both eyes, projected onto the mirror from the head: the reflection then
//! lies at the mirror's depth, "flat, like a TV screen". Only the texture methods have the
//! choice (the exact geometry methods draw every path from the eye).

use crate::method::{OptionKind, OptionSpec, ParamValue};

/// `--stereo-mirrors`.
pub static STEREO_MIRRORS: OptionSpec = OptionSpec {
    name: "stereo-mirrors",
    help: "In one eye of a stereo pair (render --stereo): mirror textures from that eye \
           (`per-eye`, seed 002) or from the head's centre, shared by both eyes (`shared`, the \
           shortcut: reflections at the mirror's depth).",
    kind: OptionKind::Choice {
        values: &["per-eye", "shared"],
    },
    default: ParamValue::Choice("per-eye"),
    sweep: None,
    in_key: true,
};
