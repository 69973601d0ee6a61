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
//! apart); candidates are found through a grid of the planes' normals and offsets, and a
//! plane that straddles a grid boundary is split into two flat surfaces there: a skip missed,
//! never one too many.

use glam::{DVec3, Vec3};
use mirrorbox_scene::{Geometry, Surface};
use std::collections::HashMap;

/// How far off a plane, relative to the largest coordinate of the two triangles, a corner
/// may be and still be on it: 16 f32 roundings. (A quad rotated by −90° in f32 has its
/// corners about 10⁻⁷ off the plane of its triangles.)
const PLANE_TOLERANCE: f64 = 16.0 * f32::EPSILON as f64;

/// `1 − cos` of the largest angle between two normals of one plane (10⁻⁶ rad).
const NORMAL_TOLERANCE: f64 = 5e-13;

/// Cells per unit of the grid that finds candidate planes (normal components and offsets).
const GRID: f64 = 4096.0;

/// A triangle's plane: its unit normal (largest component positive), a corner, its corners.
struct Plane {
    n: DVec3,
    corners: [DVec3; 3],
    /// The largest coordinate of its corners (at least a tiny positive number).
    scale: f64,
}

impl Plane {
    fn of(triangle: &[Vec3; 3]) -> Self {
        let corners = triangle.map(|p| p.as_dvec3());
        let mut n = (corners[1] - corners[0])
            .cross(corners[2] - corners[0])
            .normalize_or_zero();
        if n[n.abs().max_position()] < 0.0 {
            n = -n;
        }
        let scale = corners
            .iter()
            .map(|p| p.abs().max_element())
            .fold(f64::MIN_POSITIVE, f64::max);
        Plane { n, corners, scale }
    }

    /// Whether `other` lies on this plane (and this on `other`'s), within the tolerances.
    fn holds(&self, other: &Plane) -> bool {
        let tolerance = PLANE_TOLERANCE * self.scale.max(other.scale);
        let on = |a: &Plane, b: &Plane| {
            b.corners
                .iter()
                .all(|p| a.n.dot(*p - a.corners[0]).abs() <= tolerance)
        };
        self.n.dot(other.n) >= 1.0 - NORMAL_TOLERANCE && on(self, other) && on(other, self)
    }

    fn cell(&self) -> [i64; 4] {
        let q = |x: f64| (x * GRID).round() as i64;
        let offset = self.n.dot(self.corners[0]);
        [q(self.n.x), q(self.n.y), q(self.n.z), q(offset)]
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
    let mut planes: Vec<Plane> = Vec::new();
    let mut cells: HashMap<[i64; 4], Vec<u32>> = HashMap::new();
    geometry
        .triangles
        .iter()
        .enumerate()
        .map(|(i, t)| match geometry.surface(i) {
            Surface::Mirror { mirror, .. } => *mirror as u32,
            Surface::Diffuse { .. } => {
                let plane = Plane::of(t);
                let cell = cells.entry(plane.cell()).or_default();
                let index = match cell.iter().find(|&&p| planes[p as usize].holds(&plane)) {
                    Some(&p) => p,
                    None => {
                        planes.push(plane);
                        cell.push(planes.len() as u32 - 1);
                        planes.len() as u32 - 1
                    }
                };
                mirrors + index
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

    /// The flat surfaces of a scene with two mirrors, a rotated floor quad, a rotated box, a
    /// second quad 10⁻³ above the floor (parallel, not on its plane) and a sphere: each
    /// mirror's triangles are that mirror; the floor's two triangles share one flat surface,
    /// the quad above the floor has its own; each face of the box is one, the opposite faces
    /// apart; no sphere triangle shares one with a triangle of another object.
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
