//! Symmetry planes (seed 001, "Rendering symmetry") and the exact split-and-mirror bake that
//! is their ground truth.
//!
//! Seed 001 applies p planes to the objects **in order**, a cascade: for plane k, keep what
//! lies in front of it (signed distance `n·x − offset ≥ 0`) and add the reflection of that
//! part, `m = x − 2n(n·x − offset)`, behind it; plane k+1 then acts on everything plane k
//! produced. A point of the result is therefore one of 2^p copies, named by the bit mask of the
//! planes it was reflected through. The seed's shader draws the whole mesh 2^p times and culls
//! each copy per fragment; its article suggests baking the same result once on the CPU for many
//! planes. [`split_and_mirror`] is that bake, exact: triangles crossing a plane are cut (a
//! triangle becomes one or two), not dropped.
//!
//! The cascade is not the reflection group the planes generate: the result depends on the
//! order of the planes, and a plane's own symmetry survives only until a later plane cuts it.
//! For mutually perpendicular planes the reflections commute and the cascade equals the group
//! (and a physical corner of mirrors). Lighting is not mirrored: a copy is lit by the scene's
//! real lights with its reflected normal, as in the seed's shader (`docs/scene-format.md`).

use crate::geometry::{Geometry, Part, is_degenerate};
use crate::limits::{MAX_COORDINATE, MEMORY_PER_TRIANGLE, within_extent};
use crate::reflection::Plane;
use glam::Vec3;

/// Most symmetry planes a scene may have: 2^16 copies is already far beyond what any method
/// here draws per copy; the seed's demo allows 10.
pub const MAX_SYMMETRY_PLANES: usize = 16;

/// One symmetry plane of a scene. `plane.normal` is unit; the front is `n·x − offset ≥ 0`.
#[derive(Clone, Debug, PartialEq)]
pub struct SymmetryPlane {
    pub name: String,
    pub plane: Plane,
}

/// A scene's symmetry planes and what they act on.
#[derive(Clone, Debug, PartialEq)]
pub struct Symmetry {
    /// File order = cascade order (at least one plane).
    pub planes: Vec<SymmetryPlane>,
    /// The objects' triangles BEFORE the planes (objects only, no mirrors): what the raster
    /// `symmetry` method draws 2^p times. [`crate::Scene::geometry`] holds the baked result.
    pub source: Geometry,
}

impl Symmetry {
    /// The planes alone, in cascade order.
    pub fn plane_list(&self) -> Vec<Plane> {
        self.planes.iter().map(|p| p.plane).collect()
    }

    /// 2^p: how many copies the seed's method draws.
    pub fn copy_count(&self) -> u64 {
        1u64 << self.planes.len()
    }
}

/// Where a triangle of the baked mesh comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CopyOrigin {
    /// Index into the source geometry's `triangles`: the baked triangle is part of this one,
    /// moved by the copy's reflections.
    pub source_triangle: u32,
    /// Bit k is set when the triangle was reflected through plane k: the same bit mask the
    /// seed's shader takes per copy.
    pub copy: u32,
}

/// Why a bake was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SymmetryError {
    #[error(
        "after plane {plane} the split-and-mirror mesh would hold {triangles} triangles, more than \
         the {budget} the scene has room for (it would need about {}); use fewer planes, planes \
         that cut more of the objects away, or objects with fewer triangles",
        mirrorbox_files::human_bytes(triangles.saturating_mul(MEMORY_PER_TRIANGLE))
    )]
    TooManyTriangles {
        /// Index of the plane whose step would exceed the budget.
        plane: usize,
        triangles: u64,
        budget: usize,
    },
    #[error(
        "plane {plane} reflects a vertex to [{}, {}, {}], outside the scene extent: every \
         coordinate must be within ±{MAX_COORDINATE:e}",
        reflected.x, reflected.y, reflected.z
    )]
    OutsideExtent { plane: usize, reflected: Vec3 },
    #[error("asked for the first {asked} symmetry planes, the scene has {have}")]
    NotThatManyPlanes { asked: usize, have: usize },
}

impl SymmetryError {
    /// The plane a refusal is about, if any (for the field path `symmetry_planes[k]`).
    pub fn plane(&self) -> Option<usize> {
        match self {
            SymmetryError::TooManyTriangles { plane, .. }
            | SymmetryError::OutsideExtent { plane, .. } => Some(*plane),
            SymmetryError::NotThatManyPlanes { .. } => None,
        }
    }
}

/// Seed 001's cascade, exact, on the CPU; see [`split_and_mirror_with_origins`].
pub fn split_and_mirror(
    source: &Geometry,
    planes: &[Plane],
    max_triangles: usize,
) -> Result<Geometry, SymmetryError> {
    split_and_mirror_with_origins(source, planes, max_triangles).map(|(g, _)| g)
}

/// A triangle during the cascade.
#[derive(Clone, Copy)]
struct Piece {
    vertices: [Vec3; 3],
    part: u32,
    origin: CopyOrigin,
}

/// Seed 001's cascade, exact: for each plane in order, every triangle is clipped to the plane's
/// front half-space `n·x − offset ≥ 0` (a crossing triangle is cut into one or two; one wholly
/// behind is dropped), and the front part gets its reflection `m = x − 2n(n·x − offset)`
/// appended, wound `[m₀, m₂, m₁]` so that its face normal is the reflected normal
/// `n_f − 2n(n·n_f)` (a reflection alone would reverse the winding).
///
/// Also returns, per baked triangle, where it came from. With no planes the result is `source`
/// itself. Every part keeps its name and surface and holds all copies of its triangles (in
/// cascade order: at each plane the kept fronts, then their reflections). Cut slivers of
/// (near) zero area are discarded (they cover nothing); `degenerate_dropped` stays the source's.
///
/// Watertight seams: a vertex a cut creates lies on the plane by construction, so its
/// reflection is taken to be itself (bit-identical, no crack between a piece and its mirror
/// image), and an edge shared by two triangles is cut at bit-identical points (the
/// intersection is computed from the edge's endpoints in a fixed order).
///
/// Refuses, before allocating past it, a step that would hold more than `max_triangles`
/// triangles (every step is held in memory, so every step is bounded, not only the last), and
/// a reflected vertex outside the scene extent.
pub fn split_and_mirror_with_origins(
    source: &Geometry,
    planes: &[Plane],
    max_triangles: usize,
) -> Result<(Geometry, Vec<CopyOrigin>), SymmetryError> {
    let mut pieces: Vec<Piece> = Vec::with_capacity(source.triangles.len());
    for (p, part) in source.parts.iter().enumerate() {
        for i in part.triangles.clone() {
            pieces.push(Piece {
                vertices: source.triangles[i],
                part: p as u32,
                origin: CopyOrigin {
                    source_triangle: i as u32,
                    copy: 0,
                },
            });
        }
    }
    for (k, plane) in planes.iter().enumerate() {
        pieces = split_and_mirror_step(&pieces, plane, k, max_triangles)?;
    }
    // Group by part (stable: cascade order within a part).
    let mut by_part: Vec<Vec<Piece>> = vec![Vec::new(); source.parts.len()];
    for piece in pieces {
        by_part[piece.part as usize].push(piece);
    }
    let total: usize = by_part.iter().map(Vec::len).sum();
    let mut baked = Geometry {
        triangles: Vec::with_capacity(total),
        surface_of: Vec::with_capacity(total),
        surfaces: source.surfaces.clone(),
        parts: Vec::with_capacity(source.parts.len()),
        degenerate_dropped: source.degenerate_dropped,
    };
    let mut origins = Vec::with_capacity(total);
    for (part, pieces) in source.parts.iter().zip(by_part) {
        let start = baked.triangles.len();
        for piece in pieces {
            baked.triangles.push(piece.vertices);
            baked.surface_of.push(part.surface);
            origins.push(piece.origin);
        }
        baked.parts.push(Part {
            name: part.name.clone(),
            surface: part.surface,
            triangles: start..baked.triangles.len(),
        });
    }
    Ok((baked, origins))
}

/// A vertex of a clipped polygon; `on_plane` when the cut created it.
#[derive(Clone, Copy)]
struct ClipVertex {
    position: Vec3,
    on_plane: bool,
}

/// One plane of the cascade: the front parts of `pieces`, then their reflections.
fn split_and_mirror_step(
    pieces: &[Piece],
    plane: &Plane,
    k: usize,
    max_triangles: usize,
) -> Result<Vec<Piece>, SymmetryError> {
    // Count first, so the budget is checked before anything is allocated.
    let front_count: u64 = pieces
        .iter()
        .map(|p| {
            let kept = p
                .vertices
                .iter()
                .filter(|v| plane.signed_distance(**v) >= 0.0)
                .count();
            // A triangle with 1 vertex in front stays a triangle, with 2 becomes a quad (two).
            match kept {
                0 => 0,
                1 | 3 => 1,
                _ => 2,
            }
        })
        .sum();
    let total = 2 * front_count;
    if total > max_triangles as u64 {
        return Err(SymmetryError::TooManyTriangles {
            plane: k,
            triangles: total,
            budget: max_triangles,
        });
    }
    let mut front: Vec<(Piece, [bool; 3])> = Vec::with_capacity(front_count as usize);
    let mut polygon: Vec<ClipVertex> = Vec::with_capacity(4);
    for piece in pieces {
        clip_triangle(&piece.vertices, plane, &mut polygon);
        // Fan: a triangle or a convex quad, wound as the original.
        for j in 1..polygon.len().saturating_sub(1) {
            let corners = [polygon[0], polygon[j], polygon[j + 1]];
            let vertices = corners.map(|c| c.position);
            if is_degenerate(&vertices) {
                continue;
            }
            front.push((Piece { vertices, ..*piece }, corners.map(|c| c.on_plane)));
        }
    }
    let mut out = Vec::with_capacity(2 * front.len());
    out.extend(front.iter().map(|(p, _)| *p));
    for (piece, on_plane) in &front {
        let mut m = [Vec3::ZERO; 3];
        for i in 0..3 {
            m[i] = if on_plane[i] {
                piece.vertices[i]
            } else {
                plane.reflect_point(piece.vertices[i])
            };
            if !within_extent(m[i]) {
                return Err(SymmetryError::OutsideExtent {
                    plane: k,
                    reflected: m[i],
                });
            }
        }
        out.push(Piece {
            vertices: [m[0], m[2], m[1]],
            part: piece.part,
            origin: CopyOrigin {
                copy: piece.origin.copy | (1 << k),
                ..piece.origin
            },
        });
    }
    Ok(out)
}

/// Sutherland–Hodgman against one plane: the part of triangle `t` with `n·x − offset ≥ 0`, in
/// `out` (cleared; 0, 3 or 4 vertices, in `t`'s winding). A vertex exactly on the plane counts
/// as in front and creates no extra crossing, so no duplicate vertices arise.
fn clip_triangle(t: &[Vec3; 3], plane: &Plane, out: &mut Vec<ClipVertex>) {
    out.clear();
    let d = t.map(|v| plane.signed_distance(v));
    for i in 0..3 {
        let j = (i + 1) % 3;
        if d[i] >= 0.0 {
            out.push(ClipVertex {
                position: t[i],
                on_plane: false,
            });
        }
        if (d[i] > 0.0 && d[j] < 0.0) || (d[i] < 0.0 && d[j] > 0.0) {
            out.push(ClipVertex {
                position: edge_crossing(t[i], d[i], t[j], d[j]),
                on_plane: true,
            });
        }
    }
    if out.len() < 3 {
        out.clear();
    }
}

/// Where the edge `a b` (signed distances `da`, `db` of opposite signs) meets the plane,
/// computed from the endpoint that is smaller by bits, so both triangles sharing the edge get
/// the same point whichever way they traverse it.
fn edge_crossing(a: Vec3, da: f32, b: Vec3, db: f32) -> Vec3 {
    let key = |v: Vec3| v.to_array().map(f32::to_bits);
    let ((a, da), (b, db)) = if key(a) <= key(b) {
        ((a, da), (b, db))
    } else {
        ((b, db), (a, da))
    };
    a + (b - a) * (da / (da - db))
}
