//! The planning of a frame's reflection paths ([`mirrorbox_scene::reflection_paths`]) on
//! the CPU, before any GPU work, which the exact methods (`portal`, `unrolled`) share — a
//! frame with too many paths is refused there. Their options are
//! [`crate::exact_options`]'s.

use crate::plan::PlanError;
use glam::Mat4;
use mirrorbox_scene::Scene;
use mirrorbox_scene::reflection_paths::{PathLimits, PathSet, reflection_paths};

/// Most reflection paths an exact method draws per frame (memory and time bound).
pub const MAX_PATHS: usize = 200_000;

/// A frame's reflection paths at render resolution, with the projection they were
/// enumerated with.
pub struct PlannedPaths {
    pub paths: PathSet,
    pub width: u32,
    pub height: u32,
    /// The camera's projection ([`crate::projection::camera_projection`]).
    pub projection: Mat4,
}

/// Enumerates the reflection paths of `scene` at `width × height`.
pub fn plan_paths(
    scene: &Scene,
    width: u32,
    height: u32,
    limits: &PathLimits,
) -> Result<PlannedPaths, PlanError> {
    let projection = crate::projection::camera_projection(&scene.camera, width, height);
    let paths = reflection_paths(scene, width, height, projection, limits);
    if paths.truncated {
        return Err(PlanError::TooManyPaths { limit: MAX_PATHS });
    }
    Ok(PlannedPaths {
        paths,
        width,
        height,
        projection,
    })
}

/// Host bytes a path set holds: each path's record, mirror list, portal, visible pieces and
/// children (a memory estimate's "the reflection paths", [`crate::memory`]).
pub fn paths_host_bytes(paths: &PathSet) -> u64 {
    use mirrorbox_scene::reflection_paths::ReflectionPath;
    let vec2 = std::mem::size_of::<glam::Vec2>();
    let vec_header = std::mem::size_of::<Vec<u8>>();
    paths
        .paths
        .iter()
        .map(|p| {
            std::mem::size_of::<ReflectionPath>()
                + 8 * (p.mirrors.len() + p.children.len())
                + vec2 * p.portal.len()
                + p.visible
                    .iter()
                    .map(|v| vec_header + vec2 * v.len())
                    .sum::<usize>()
        })
        .sum::<usize>() as u64
}

/// The paths' part of a memory estimate: their records on the host.
pub fn paths_memory(e: &mut crate::memory::MemoryEstimate, paths: &PathSet) {
    e.host(
        "the reflection paths",
        "--depth, or raise --min-portal-area or --min-attenuation",
        paths_host_bytes(paths),
    );
}
