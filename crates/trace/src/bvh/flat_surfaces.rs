//! Flat surfaces: the sets of triangles on one plane that a ray leaving any of them cannot
//! meet again, so that a query skips the whole set instead of only the triangle it leaves
//! (issue 56).
//!
//! - **Each mirror** is one: flat surface `m` is mirror `m`'s triangles, so a mirror's index
//!   is its flat surface (what the integrators pass for the mirror a ray leaves).
//! - **Each plane's diffuse triangles** are another, numbered after the mirrors: the two
//!   triangles of a quad, a box's face, every triangle of a tiled floor.
//!
//! A ray leaving a point of plane `P` in a direction off it meets `P` only at its origin, so
//! a hit on another triangle of `P` can only be a self-intersection: at a distance of the
//! rounding of the origin over the direction's cosine to the plane (about 10⁻⁷ of the scene
//! over that cosine). Skipping the plane's triangles answers as an exact tracer would. Before,
//! a `path` ray leaving one floor triangle entered the leaf of the floor's other triangle on
//! almost every query: 1.54 M of `mirror_box`'s 3.34 M leaf visits (640×360, 16 spp, one
//! render), 2.52 M of `mirror_room`'s 7.44 M.
//!
//! **Which triangles share a plane.** Vertices are f32, so the triangles of one modelled plane
//! agree only up to rounding: two triangles share one when their unit normals are parallel
//! (either orientation) within 10⁻⁶ rad and each one's corners lie within
//! [`PLANE_TOLERANCE`] × their largest coordinate of the other's plane (f64 arithmetic).
//! Each plane is tested against its first triangle only (no chains of near planes drifting
//! apart). Candidates are found through a grid of the planes' normals and offsets, at most
//! [`PLANES_PER_CELL`] per cell (a finely tessellated curved mesh puts many planes in one
//! cell; without the cap its grouping would be quadratic). A plane that straddles a grid
//! boundary, or finds its cell full, becomes a flat surface of its own there: a skip missed,
//! never one too many.
//!
//! **Cost.** One pass over the triangles, before the hierarchy is built (so its working
//! memory is gone when the build's peak comes): per plane a triangle index and a link, per
//! grid cell one hash entry of a word and two indices — under 30 bytes per triangle where
//! every triangle is a plane of its own, the result 4.

use glam::DVec3;
use mirrorbox_scene::{Geometry, Surface};
use std::collections::HashMap;

/// How far off a plane, relative to the largest coordinate of the two triangles, a corner
/// may be and still be on it: 16 f32 roundings. (A quad rotated by −90° in f32 has its
/// corners about 10⁻⁷ off the plane of its triangles.)
const PLANE_TOLERANCE: f64 = 16.0 * f32::EPSILON as f64;

/// `1 − |cos|` of the largest angle between two normals of one plane (10⁻⁶ rad).
const NORMAL_TOLERANCE: f64 = 5e-13;

/// Cells per unit of the grid that finds candidate planes (normal components and offsets).
const GRID: f64 = 4096.0;

/// Planes a grid cell holds; a triangle is compared with at most these.
const PLANES_PER_CELL: usize = 8;

/// The direction a plane's normal is turned towards for its grid cell: (1, √2, √3), which no
/// normal with small integer components is perpendicular to (where a normal is nearly
/// perpendicular, two triangles of its plane may fall in two cells: a skip missed). A rule such
/// as "the largest component positive" would split a wall at 45° whenever rounding tips which
/// of its two equal components is largest.
const ORIENTATION: DVec3 = DVec3::new(1.0, std::f64::consts::SQRT_2, 1.732_050_807_568_877_2);

/// No next plane in a cell.
const END: u32 = u32::MAX;

/// A triangle's plane: its unit normal (zero for a triangle without area), its corners, and
/// the largest coordinate of its corners (at least the smallest positive f64).
struct Plane {
    n: DVec3,
    corners: [DVec3; 3],
    scale: f64,
}

impl Plane {
    fn of(geometry: &Geometry, triangle: usize) -> Self {
        let corners = geometry.triangles[triangle].map(|p| p.as_dvec3());
        let n = (corners[1] - corners[0])
            .cross(corners[2] - corners[0])
            .normalize_or_zero();
        let scale = corners
            .iter()
            .map(|p| p.abs().max_element())
            .fold(f64::MIN_POSITIVE, f64::max);
        Plane { n, corners, scale }
    }

    /// Whether `other` lies on this plane and this on `other`'s, within the tolerances (never
    /// for a triangle without area).
    fn holds(&self, other: &Plane) -> bool {
        let tolerance = PLANE_TOLERANCE * self.scale.max(other.scale);
        let on = |a: &Plane, b: &Plane| {
            b.corners
                .iter()
                .all(|p| a.n.dot(*p - a.corners[0]).abs() <= tolerance)
        };
        self.n.dot(other.n).abs() >= 1.0 - NORMAL_TOLERANCE && on(self, other) && on(other, self)
    }

    /// The grid cell of the plane: its normal oriented along [`ORIENTATION`], and its offset
    /// along that normal, each quantised, hashed into one word (two cells that share a word
    /// only share their candidates: [`Plane::holds`] decides).
    fn cell(&self) -> u64 {
        let n = if self.n.dot(ORIENTATION) < 0.0 {
            -self.n
        } else {
            self.n
        };
        let q = |x: f64| (x * GRID).round() as i64 as u64;
        [q(n.x), q(n.y), q(n.z), q(n.dot(self.corners[0]))]
            .into_iter()
            .fold(0u64, |h, v| {
                (h.rotate_left(5) ^ v).wrapping_mul(0x517c_c1b7_2722_0a95)
            })
    }
}

/// Per triangle of `geometry`, its flat surface: mirror `m`'s triangles `m`; a diffuse
/// triangle the number of mirrors plus its plane's index (in order of first appearance).
pub(super) fn flat_surfaces(geometry: &Geometry) -> Vec<u32> {
    let mirrors = geometry
        .surfaces
        .iter()
        .filter_map(|s| match s {
            Surface::Mirror { mirror, .. } => Some(*mirror as u32 + 1),
            Surface::Diffuse { .. } => None,
        })
        .max()
        .unwrap_or(0);
    // Per plane (numbered as the flat surfaces after the mirrors): its first triangle, and
    // the next plane of its grid cell.
    let mut first: Vec<u32> = Vec::new();
    let mut next: Vec<u32> = Vec::new();
    // Per grid cell: its first plane and how many it holds.
    let mut cells: HashMap<u64, (u32, u32)> = HashMap::new();
    (0..geometry.triangles.len())
        .map(|i| match geometry.surface(i) {
            Surface::Mirror { mirror, .. } => *mirror as u32,
            Surface::Diffuse { .. } => {
                let plane = Plane::of(geometry, i);
                let new = first.len() as u32;
                let cell = cells.entry(plane.cell()).or_insert((END, 0));
                let mut candidate = cell.0;
                while candidate != END {
                    let other = Plane::of(geometry, first[candidate as usize] as usize);
                    if other.holds(&plane) {
                        return mirrors + candidate;
                    }
                    candidate = next[candidate as usize];
                }
                first.push(i as u32);
                next.push(END);
                if (cell.1 as usize) < PLANES_PER_CELL {
                    next[new as usize] = cell.0;
                    *cell = (new, cell.1 + 1);
                }
                mirrors + new
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_scene::load::parse_scene;

    fn scene_geometry(json: &str) -> Geometry {
        parse_scene(json, std::path::Path::new("flat_surfaces.json"))
            .expect("a valid scene")
            .geometry
    }

    /// The flat surfaces of a scene with two mirrors, a rotated floor quad, a wall at 45°, a
    /// rotated box, a second quad 10⁻⁵ above the floor (parallel, not on its plane) and a
    /// sphere: each mirror's triangles are that mirror; the floor's two triangles share one
    /// flat surface, as do the wall's, the quad above the floor has its own; each face of the
    /// box is one, the opposite faces apart; no sphere triangle shares one with a triangle of
    /// another object.
    #[test]
    fn the_triangles_of_one_plane_share_a_flat_surface() {
        let geometry = scene_geometry(
            r#"{
              "camera": { "position": [0, 1, 3], "look_at": [0, 0.5, 0], "fov_y_deg": 60,
                          "width": 16, "height": 16 },
              "mirrors": [
                { "center": [0, 1.5, -2], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 4, "height": 3 },
                { "center": [0, 1.5, 2], "normal": [0, 0, -1], "up": [0, 1, 0], "width": 4, "height": 3 }
              ],
              "objects": [
                { "type": "quad", "name": "floor", "size": [4, 4],
                  "transform": { "rotate_deg": [-90, 0, 0] } },
                { "type": "quad", "name": "wall", "size": [1, 1],
                  "transform": { "translate": [0, 1, 1], "rotate_deg": [0, -45, 0] } },
                { "type": "quad", "name": "above", "size": [1, 1],
                  "transform": { "translate": [0, 0.00001, 0], "rotate_deg": [-90, 0, 0] } },
                { "type": "box", "name": "box", "size": [0.8, 0.8, 0.8],
                  "transform": { "translate": [-0.7, 0.4, -0.3], "rotate_deg": [0, 30, 0] } },
                { "type": "sphere", "name": "sphere", "radius": 0.5,
                  "transform": { "translate": [0.8, 0.5, 0.4] } }
              ],
              "lights": [ { "position": [0, 2.8, 0], "intensity": [15, 15, 15] } ]
            }"#,
        );
        let flat = flat_surfaces(&geometry);
        let part = |name: &str| {
            let p = geometry
                .parts
                .iter()
                .find(|p| p.name == name)
                .unwrap_or_else(|| panic!("a part named {name}"));
            p.triangles.clone()
        };
        for (i, &f) in flat.iter().enumerate() {
            if let Surface::Mirror { mirror, .. } = geometry.surface(i) {
                assert_eq!(f, *mirror as u32, "mirror triangle {i}");
            } else {
                assert!(f >= 2, "diffuse triangle {i} after the mirrors: {f}");
            }
        }
        let floor = part("floor");
        assert_eq!(floor.len(), 2);
        assert_eq!(
            flat[floor.start],
            flat[floor.start + 1],
            "the floor's two triangles"
        );
        let wall = part("wall");
        assert_eq!(flat[wall.start], flat[wall.start + 1], "a wall at 45°");
        let above = part("above");
        assert_eq!(flat[above.start], flat[above.start + 1]);
        assert_ne!(
            flat[above.start], flat[floor.start],
            "a parallel quad 10⁻⁵ above"
        );
        let cube = part("box");
        assert_eq!(cube.len(), 12);
        let faces: Vec<u32> = cube.clone().map(|i| flat[i]).collect();
        let mut distinct = faces.clone();
        distinct.sort_unstable();
        distinct.dedup();
        assert_eq!(distinct.len(), 6, "one flat surface per face: {faces:?}");
        for i in cube.clone() {
            assert_eq!(faces.iter().filter(|&&f| f == flat[i]).count(), 2);
        }
        let sphere = part("sphere");
        for i in sphere.clone() {
            let others = (0..flat.len()).filter(|j| !sphere.contains(j));
            assert!(
                others.into_iter().all(|j| flat[j] != flat[i]),
                "sphere triangle {i}"
            );
        }
    }
}
