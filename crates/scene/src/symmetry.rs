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
        uvs: Vec::with_capacity(total),
        textures: source.textures.clone(),
        surfaces: source.surfaces.clone(),
        parts: Vec::with_capacity(source.parts.len()),
        degenerate_dropped: source.degenerate_dropped,
        obj_notes: source.obj_notes.clone(),
    };
    let mut origins = Vec::with_capacity(total);
    for (part, pieces) in source.parts.iter().zip(by_part) {
        let start = baked.triangles.len();
        let textured = matches!(
            &source.surfaces[part.surface as usize],
            crate::Surface::Diffuse { maps, .. } if !maps.is_empty()
        );
        for piece in pieces {
            baked.triangles.push(piece.vertices);
            baked.surface_of.push(part.surface);
            baked.uvs.push(if textured {
                piece_uvs(source, planes, &piece)
            } else {
                [glam::Vec2::ZERO; 3]
            });
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

/// The texture coordinates of a baked piece's corners: each corner taken back to its source
/// triangle (the copy's reflections undone, the last plane's first) and interpolated there.
fn piece_uvs(source: &Geometry, planes: &[Plane], piece: &Piece) -> [glam::Vec2; 3] {
    let origin = piece.origin;
    piece.vertices.map(|v| {
        let mut x = v;
        for (k, plane) in planes.iter().enumerate().rev() {
            if origin.copy & (1 << k) != 0 {
                x = plane.reflect_point(x);
            }
        }
        source.uv_at(origin.source_triangle as usize, x)
    })
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Surface;
    use crate::tessellate;
    use std::collections::{BTreeMap, HashSet};

    fn diffuse() -> Surface {
        Surface::Diffuse {
            albedo: Vec3::splat(0.5),
            emission: Vec3::ZERO,
            maps: Default::default(),
        }
    }

    fn geometry(triangles: Vec<[Vec3; 3]>) -> Geometry {
        let mut g = Geometry::default();
        g.push_part("object".into(), diffuse(), triangles);
        g
    }

    /// A closed icosphere (320 triangles) off every plane's special positions.
    fn ball() -> Geometry {
        let offset = Vec3::new(0.31, 0.17, -0.23);
        geometry(
            tessellate::icosphere(1.0, 2)
                .into_iter()
                .map(|t| t.map(|v| v + offset))
                .collect(),
        )
    }

    fn plane(point: [f32; 3], normal: [f32; 3]) -> Plane {
        Plane::from_point_normal(Vec3::from_array(point), Vec3::from_array(normal))
    }

    fn area(t: &[Vec3; 3]) -> f32 {
        0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()
    }

    fn total_area(g: &Geometry) -> f64 {
        g.triangles.iter().map(|t| area(t) as f64).sum()
    }

    /// Ten planes in general position, each within 0.15 of the ball's centre (planes far
    /// from the objects soon leave nothing in front: seed 001's invisible spaces).
    fn scattered_planes() -> Vec<Plane> {
        let centre = Vec3::new(0.31, 0.17, -0.23);
        [
            ([0.1, 0.0, 0.0], [1.0, 0.2, -0.1]),
            ([0.0, 0.12, 0.1], [0.3, 1.0, 0.4]),
            ([-0.1, 0.0, 0.05], [-0.5, 0.1, 1.0]),
            ([0.0, -0.1, 0.0], [0.7, -0.6, 0.2]),
            ([0.05, 0.1, -0.1], [-0.2, 0.4, -0.9]),
            ([0.0, 0.0, 0.0], [0.9, 0.9, 0.1]),
            ([0.1, -0.1, 0.1], [-1.0, 0.3, 0.3]),
            ([-0.1, 0.05, 0.1], [0.1, -0.8, 0.6]),
            ([0.15, 0.0, -0.05], [0.6, 0.6, -0.5]),
            ([0.0, 0.08, 0.0], [-0.3, -0.2, -1.0]),
        ]
        .into_iter()
        .map(|(p, n)| Plane::from_point_normal(centre + Vec3::from_array(p), Vec3::from_array(n)))
        .collect()
    }

    #[test]
    fn no_planes_is_the_identity() {
        let g = ball();
        assert_eq!(split_and_mirror(&g, &[], usize::MAX).unwrap(), g);
    }

    #[test]
    fn one_plane_in_front_of_the_whole_mesh_doubles_it_with_reflected_normals() {
        let g = ball();
        let p = plane([0.0, 0.0, -2.0], [0.0, 0.2, 1.0]);
        assert!(
            g.triangles
                .iter()
                .flatten()
                .all(|v| p.signed_distance(*v) > 0.0)
        );
        let (baked, origins) = split_and_mirror_with_origins(&g, &[p], usize::MAX).unwrap();
        let n = g.triangles.len();
        assert_eq!(baked.triangles.len(), 2 * n);
        assert_eq!(
            &baked.triangles[..n],
            &g.triangles[..],
            "the front is kept as it is"
        );
        for i in 0..n {
            let m = baked.triangles[n + i];
            for (j, k) in [(0, 0), (1, 2), (2, 1)] {
                assert_eq!(m[j], p.reflect_point(g.triangles[i][k]));
            }
            let reflected_normal = p.reflect_vector(g.face_normal(i));
            assert!(baked.face_normal(n + i).abs_diff_eq(reflected_normal, 1e-5));
            assert_eq!(
                origins[n + i],
                CopyOrigin {
                    source_triangle: i as u32,
                    copy: 1
                }
            );
        }
        assert_eq!(baked.parts[0].triangles, 0..2 * n);
        assert_eq!(baked.surfaces, g.surfaces);
    }

    #[test]
    fn a_crossing_triangle_is_cut_not_dropped_and_its_area_doubles() {
        // A right triangle with legs 2 along x and y; the plane x = 0.5 (front x ≥ 0.5) keeps
        // the small triangle at the (2, 0) corner: legs 1.5 and 1.5, area 1.125.
        let t = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        ];
        let p = plane([0.5, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let baked = split_and_mirror(&geometry(vec![t]), &[p], usize::MAX).unwrap();
        assert_eq!(baked.triangles.len(), 2);
        assert!((total_area(&baked) - 2.0 * 1.125).abs() < 1e-6);
        // The other side (front x ≤ 0.5) keeps a quad: two triangles, area 2 − 1.125.
        let baked = split_and_mirror(&geometry(vec![t]), &[p.flipped()], usize::MAX).unwrap();
        assert_eq!(baked.triangles.len(), 4);
        assert!((total_area(&baked) - 2.0 * 0.875).abs() < 1e-6);
        // And a ball cut through: front area + its reflection = twice the front area.
        let g = ball();
        let p = plane([0.5, 0.0, 0.0], [1.0, 0.3, 0.0]);
        let baked = split_and_mirror(&g, &[p], usize::MAX).unwrap();
        let front: f64 = baked
            .triangles
            .iter()
            .filter(|t| t.iter().all(|v| p.signed_distance(*v) >= -1e-6))
            .map(|t| area(t) as f64)
            .sum();
        assert!((total_area(&baked) - 2.0 * front).abs() < 1e-5 * front);
        assert!(
            front < 0.5 * total_area(&g),
            "the plane cuts more than half away"
        );
    }

    /// Every baked triangle's face normal is its source triangle's normal reflected through
    /// the planes of its copy, in cascade order: no copy is wound backwards.
    #[test]
    fn every_copy_has_the_reflected_source_normal() {
        let g = ball();
        let planes = scattered_planes();
        let (baked, origins) = split_and_mirror_with_origins(&g, &planes, usize::MAX).unwrap();
        assert!(baked.triangles.len() > g.triangles.len());
        let mut copies = HashSet::new();
        for (i, origin) in origins.iter().enumerate() {
            let mut normal = g.face_normal(origin.source_triangle as usize);
            for (k, p) in planes.iter().enumerate() {
                if origin.copy & (1 << k) != 0 {
                    normal = p.reflect_vector(normal);
                }
            }
            let got = baked.face_normal(i);
            assert!(got.dot(normal) > 0.999, "triangle {i}: {got} vs {normal}");
            copies.insert(origin.copy);
        }
        assert!(copies.len() > 16, "only {} copies", copies.len());
    }

    /// Unfolds a baked triangle back through its copy's planes, last plane first. Returns,
    /// for each plane k, the triangle as it stood when plane k acted on it.
    fn unfold(t: [Vec3; 3], copy: u32, planes: &[Plane]) -> Vec<[Vec3; 3]> {
        let mut stages = vec![t; planes.len()];
        let mut t = t;
        for k in (0..planes.len()).rev() {
            if copy & (1 << k) != 0 {
                t = t.map(|v| planes[k].reflect_point(v));
            }
            stages[k] = t;
        }
        stages.push(t); // the source position
        stages
    }

    /// The cascade's invariant. "Nothing lies behind any plane" is false (a later plane moves
    /// copies behind earlier ones), and so is "symmetric about every plane". What holds:
    /// unfolding a baked triangle through the planes of its copy, last plane first, it lay in
    /// front of plane k when plane k acted on it (the seed's shader culls exactly there), and
    /// unfolded completely it lies inside its source triangle. After the last plane alone,
    /// the mesh is symmetric about it and no triangle crosses it.
    #[test]
    fn each_triangle_unfolds_in_front_of_every_plane_into_its_source() {
        let g = ball();
        let planes = scattered_planes();
        let (baked, origins) = split_and_mirror_with_origins(&g, &planes, usize::MAX).unwrap();
        let eps = 1e-5;
        let mut behind_an_earlier_plane = 0;
        for (t, origin) in baked.triangles.iter().zip(&origins) {
            let stages = unfold(*t, origin.copy, &planes);
            for (k, p) in planes.iter().enumerate() {
                for v in stages[k] {
                    assert!(
                        p.signed_distance(v) >= -eps,
                        "plane {k}: {}",
                        p.signed_distance(v)
                    );
                }
            }
            let s = g.triangles[origin.source_triangle as usize];
            let n = (s[1] - s[0]).cross(s[2] - s[0]);
            for v in stages[planes.len()] {
                assert!(
                    (v - s[0]).dot(n.normalize()).abs() < eps,
                    "off its source's plane"
                );
                for e in 0..3 {
                    let (a, b) = (s[e], s[(e + 1) % 3]);
                    let inside = (b - a).cross(v - a).dot(n) / n.length();
                    assert!(inside >= -eps, "outside its source triangle by {inside}");
                }
            }
            // Not reflected through plane 0, yet behind it: the naive invariant fails.
            if origin.copy & 1 == 0 && t.iter().any(|v| planes[0].signed_distance(*v) < -0.01) {
                behind_an_earlier_plane += 1;
            }
        }
        assert!(behind_an_earlier_plane > 0);
        // After the last plane: no triangle crosses it, and the mesh is its own mirror image.
        let last = planes[planes.len() - 1];
        let mut sides = [0, 0];
        for t in &baked.triangles {
            let d = t.map(|v| last.signed_distance(v));
            assert!(
                d.iter().all(|&x| x >= -eps) || d.iter().all(|&x| x <= eps),
                "{d:?}"
            );
            sides[(d.iter().sum::<f32>() < 0.0) as usize] += 1;
        }
        assert_eq!(sides[0], sides[1]);
    }

    /// A closed mesh stays closed: every edge of the result is shared, bit for bit, by a
    /// triangle traversing it the other way (cuts agree along shared edges, and the seam on a
    /// plane joins a piece to its own reflection without a crack).
    #[test]
    fn a_closed_mesh_stays_closed_bit_for_bit() {
        let key = |v: Vec3| v.to_array().map(f32::to_bits);
        for planes in [&scattered_planes()[..1], &scattered_planes()[..3]] {
            let baked = split_and_mirror(&ball(), planes, usize::MAX).unwrap();
            let edges: HashSet<_> = baked
                .triangles
                .iter()
                .flat_map(|t| (0..3).map(move |e| (key(t[e]), key(t[(e + 1) % 3]))))
                .collect();
            for (a, b) in &edges {
                assert!(
                    edges.contains(&(*b, *a)),
                    "open edge with {} planes",
                    planes.len()
                );
            }
        }
    }

    #[test]
    fn the_budget_is_refused_with_its_numbers_before_the_step_is_built() {
        let g = ball(); // 320 triangles, wholly in front of both planes: 640, then 1280.
        let planes = [
            plane([0.0, 0.0, -3.0], [0.0, 0.0, 1.0]),
            plane([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ];
        assert_eq!(
            split_and_mirror(&g, &planes, 1280).unwrap().triangles.len(),
            1280
        );
        let e = split_and_mirror(&g, &planes, 1279).unwrap_err();
        assert_eq!(
            e,
            SymmetryError::TooManyTriangles {
                plane: 1,
                triangles: 1280,
                budget: 1279
            }
        );
        let text = e.to_string();
        assert!(text.contains("after plane 1") && text.contains("1280") && text.contains("1279"));
        assert_eq!(
            split_and_mirror(&g, &planes, 639).unwrap_err().plane(),
            Some(0)
        );
    }

    #[test]
    fn a_reflection_outside_the_scene_extent_is_refused() {
        let g = geometry(vec![[Vec3::ZERO, Vec3::X, Vec3::Y]]);
        let far = plane([-6e5, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let e = split_and_mirror(&g, &[far], usize::MAX).unwrap_err();
        assert!(
            matches!(e, SymmetryError::OutsideExtent { plane: 0, .. }),
            "{e}"
        );
    }

    /// Per (source triangle, set of planes reflected through): the area and area-weighted
    /// centroid of what the bake made of it — independent of how the cut pieces are
    /// triangulated. `plane_ids[k]` names plane k of this order, so orders can be compared.
    fn pieces_by_copy(
        g: &Geometry,
        planes: &[Plane],
        plane_ids: &[u32],
    ) -> BTreeMap<(u32, u32), (f64, [f64; 3])> {
        let (baked, origins) = split_and_mirror_with_origins(g, planes, usize::MAX).unwrap();
        let mut out: BTreeMap<(u32, u32), (f64, [f64; 3])> = BTreeMap::new();
        for (t, o) in baked.triangles.iter().zip(origins) {
            let copy = (0..planes.len())
                .filter(|k| o.copy & (1 << k) != 0)
                .map(|k| 1 << plane_ids[k])
                .sum();
            let a = area(t) as f64;
            let c = ((t[0] + t[1] + t[2]) / 3.0).as_dvec3() * a;
            let e = out
                .entry((o.source_triangle, copy))
                .or_insert((0.0, [0.0; 3]));
            e.0 += a;
            for i in 0..3 {
                e.1[i] += c[i];
            }
        }
        out
    }

    fn same_pieces(
        a: &BTreeMap<(u32, u32), (f64, [f64; 3])>,
        b: &BTreeMap<(u32, u32), (f64, [f64; 3])>,
    ) -> bool {
        a.len() == b.len()
            && a.iter().all(|(k, (area, c))| {
                b.get(k).is_some_and(|(area2, c2)| {
                    (area - area2).abs() < 1e-6 && (0..3).all(|i| (c[i] - c2[i]).abs() < 1e-6)
                })
            })
    }

    #[test]
    fn perpendicular_planes_commute_and_others_do_not() {
        let g = ball();
        let x = plane([0.2, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let y = plane([0.0, 0.4, 0.0], [0.0, -1.0, 0.0]);
        let z = plane([0.0, 0.0, 0.1], [0.0, 0.0, 1.0]);
        let xyz = pieces_by_copy(&g, &[x, y, z], &[0, 1, 2]);
        assert!(same_pieces(
            &xyz,
            &pieces_by_copy(&g, &[z, x, y], &[2, 0, 1])
        ));
        assert!(same_pieces(
            &xyz,
            &pieces_by_copy(&g, &[y, z, x], &[1, 2, 0])
        ));
        // Two planes through one line at 60°: the two orders give different meshes.
        let a = plane([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let b = plane([0.0, 0.0, 0.0], [0.5, 0.0, 0.75f32.sqrt()]);
        let ab = pieces_by_copy(&g, &[a, b], &[0, 1]);
        let ba = pieces_by_copy(&g, &[b, a], &[1, 0]);
        assert!(!same_pieces(&ab, &ba));
    }

    /// The seed's six-pointed star: three planes through one line at 60° to each other.
    /// Seed 001 says they make "6 spaces instead of 8". The cascade, with each normal the
    /// previous one turned by +60° about the common line, gives exactly 6 non-empty copies:
    /// after two planes the four copies tile the full turn in wedges of 120° (copy 00),
    /// 60° (10), 120° (01) and 60° (11); the third plane's front half-space (180°) meets
    /// copy 01's wedge in a single ray only, so copy 01 and its reflection 011 are empty
    /// (written here first plane first; as bit masks, bit k = plane k: 0b010 and 0b110).
    /// The count depends on which way the normals face: every sign choice is checked.
    #[test]
    fn the_six_pointed_star_has_six_non_empty_copies_or_four_with_normals_120_degrees_apart() {
        // A big slab across the common line (the y axis), so every non-empty cell holds some.
        let slab = geometry(tessellate::cuboid(Vec3::new(4.0, 0.5, 4.0)));
        let normal = |deg: f32| {
            let r = deg.to_radians();
            [r.cos(), 0.0, r.sin()]
        };
        for signs in 0..8u32 {
            let planes: Vec<Plane> = (0..3)
                .map(|k| {
                    let flip = if signs & (1 << k) != 0 { 180.0 } else { 0.0 };
                    plane([0.0; 3], normal(60.0 * k as f32 + flip))
                })
                .collect();
            let (baked, origins) =
                split_and_mirror_with_origins(&slab, &planes, usize::MAX).unwrap();
            let mut area_by_copy: BTreeMap<u32, f64> = BTreeMap::new();
            for (t, o) in baked.triangles.iter().zip(&origins) {
                *area_by_copy.entry(o.copy).or_default() += area(t) as f64;
            }
            let non_empty: Vec<u32> = area_by_copy
                .iter()
                .filter(|(_, a)| **a > 1e-3)
                .map(|(c, _)| *c)
                .collect();
            // Normals 60° apart (signs 000, and 111, 001, 110 which flip the same wedge):
            // 6 copies. Normals 120° apart (the others): the three front half-spaces share
            // only the common line, and 4 copies remain. Never 8.
            let expected = match signs {
                0b000 | 0b111 | 0b001 | 0b110 => 6,
                _ => 4,
            };
            assert_eq!(
                non_empty.len(),
                expected,
                "signs {signs:03b}: copies {non_empty:?}"
            );
            if signs == 0 {
                assert_eq!(non_empty, vec![0b000, 0b001, 0b011, 0b100, 0b101, 0b111]);
            }
        }
    }

    /// Copies of the bake with a positive area: the cells the objects reach.
    fn non_empty_copies(symmetry: &Symmetry) -> Vec<u32> {
        let (baked, origins) =
            split_and_mirror_with_origins(&symmetry.source, &symmetry.plane_list(), usize::MAX)
                .unwrap();
        let mut area_by_copy: BTreeMap<u32, f64> = BTreeMap::new();
        for (t, o) in baked.triangles.iter().zip(&origins) {
            *area_by_copy.entry(o.copy).or_default() += area(t) as f64;
        }
        area_by_copy
            .into_iter()
            .filter(|(_, a)| *a > 1e-6)
            .map(|(c, _)| c)
            .collect()
    }

    /// `scenes/symmetry_star.json` is the 60°-step star: its floor covers the common line, so
    /// the objects reach all 6 non-empty cells of the cascade (not 2³ = 8; see above).
    #[test]
    fn the_bundled_star_reaches_six_of_eight_copies() {
        let scene = crate::load::bundled_scene("symmetry_star.json");
        let symmetry = scene.symmetry.as_ref().unwrap();
        assert_eq!(symmetry.copy_count(), 8);
        assert_eq!(
            non_empty_copies(symmetry),
            vec![0b000, 0b001, 0b011, 0b100, 0b101, 0b111]
        );
        // Three perpendicular planes through the objects: every octant is reached.
        let cube = crate::load::bundled_scene("symmetry_cube.json");
        assert_eq!(non_empty_copies(cube.symmetry.as_ref().unwrap()).len(), 8);
        // Ten scattered planes: far fewer than 2¹⁰ cells are reached, and the bake stays small.
        let many = crate::load::bundled_scene("symmetry_many.json");
        let reached = non_empty_copies(many.symmetry.as_ref().unwrap()).len();
        assert!((16..1024).contains(&reached), "{reached}");
        assert!(many.geometry.triangles.len() < 200_000);
    }
}
