//! The exact methods' (`portal`, `unrolled`) options, and the path limits they give
//! ([`crate::exact_paths`] plans the paths).

use crate::exact_paths::MAX_PATHS;
use crate::method::{OptionKind, OptionSpec, ParamValue, Params, SweepAxis};
use mirrorbox_scene::reflection_paths::PathLimits;

/// `--depth`: most mirrors along a reflection path.
/// The depths `mirrorbox advise` times first for an exact method (issue 55): powers of two,
/// then bisection between the last within budget and the first over it.
pub const DEPTHS_COARSE: &[u32] = &[1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024];

pub static DEPTH: OptionSpec = OptionSpec {
    name: "depth",
    help: "Most mirrors along a reflection path.",
    kind: OptionKind::Count { min: 1, max: 4096 },
    default: ParamValue::Count(64),
    sweep: Some(SweepAxis {
        default: "1,2,4,8,16,32,64",
        range_example: "1..8",
        list_example: "1,4,16,64",
        noun: "depths",
    }),
    in_key: true,
};

/// `--min-portal-area`: lossy pruning of small portals.
pub static MIN_PORTAL_AREA: OptionSpec = OptionSpec {
    name: "min-portal-area",
    help: "Also prune paths whose portal covers fewer pixels² (at render resolution) though it \
           may hold a pixel centre — lossy, for speed. Portals holding no pixel centre are \
           always pruned (that changes no pixel).",
    kind: OptionKind::Real {
        min: 0.0,
        min_open: false,
        max: None,
    },
    default: ParamValue::Real(0.0),
    sweep: None,
    in_key: true,
};

/// `--min-attenuation`: the tracer's `--min-throughput`.
pub static MIN_ATTENUATION: OptionSpec = OptionSpec {
    name: "min-attenuation",
    help: "Prune paths whose attenuation falls below this (the tracer's --min-throughput).",
    kind: OptionKind::Real {
        min: 0.0,
        min_open: false,
        max: Some(1.0),
    },
    default: ParamValue::Real(1e-4),
    sweep: None,
    in_key: true,
};

/// The path limits of an exact method's parameters.
pub fn limits(p: &Params) -> PathLimits {
    PathLimits {
        max_depth: p.count(&DEPTH),
        min_portal_area: p.real(&MIN_PORTAL_AREA),
        min_attenuation: p.real(&MIN_ATTENUATION),
        max_paths: MAX_PATHS,
    }
}
