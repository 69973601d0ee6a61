//! Seed 001's symmetry cascade on the CPU: each copy's transform, its *cell* (the part of
//! the source space it keeps), and which copies can be left out of a frame.
//!
//! p ordered planes `n_i·x = o_i` make 2^p copies of the objects. Copy `b` (a bitmask) maps a
//! source point `x_0` through the cascade: for `i = 0 … p−1`, `d_i = n_i·x_i − o_i` (taken on
//! the point *already* moved by the earlier planes of `b`), then `x_{i+1} = x_i − 2 d_i n_i` if
//! bit `i` of `b` is set, else `x_{i+1} = x_i`. The copy keeps the point only where every
//! `d_i ≥ 0`. Each `x_i` is an affine function of `x_0`, so each condition is a half-space
//! of the source space — plane `i` pulled back through the reflections of `b` before it —
//! and the copy's cell is their intersection: a convex polyhedron. Bit `p−1` moves nothing
//! that a later plane tests, so copies `b` and `b ^ 2^(p−1)` share their cell.
//!
//! `symmetry-pruned` leaves out a copy whose cell holds no part of the objects' bounds (the
//! cell ∩ the bounds box is empty, up to f32: [`select_copies`]; three planes at 60° through
//! one line, the seed's six-pointed star, leave 6 of 8 copies) or whose image lies wholly
//! outside the view frustum. Cells are built by clipping the bounds box one half-space at a time down the
//! binary tree of bitmask prefixes, so an empty prefix prunes its whole subtree at once.

use glam::{DMat4, DVec3, DVec4, Mat4, Vec3};
use mirrorbox_scene::Plane;

/// Copies made by `planes` planes: 2^p.
pub fn copy_count(planes: usize) -> usize {
    1usize << planes
}

/// Whether copy `mask` reverses triangle winding: an odd number of reflections.
pub fn reverses_winding(mask: u32) -> bool {
    mask.count_ones() % 2 == 1
}

/// The affine map of copy `mask` (f64): `x_p = M·x_0`, the reflections of its set bits
/// applied in plane order (seed 001's `m = v − 2n(n·(v − o))` each).
pub fn copy_transform(planes: &[Plane], mask: u32) -> DMat4 {
    planes
        .iter()
        .enumerate()
        .filter(|(i, _)| mask >> i & 1 == 1)
        .fold(DMat4::IDENTITY, |m, (_, plane)| {
            plane.reflection_matrix_f64() * m
        })
}

/// The source point of final point `y` under copy `mask`: the reflections undone, last plane
/// first (each is its own inverse).
pub fn pull_back(planes: &[Plane], mask: u32, y: Vec3) -> Vec3 {
    let mut x = y.as_dvec3();
    for (i, plane) in planes.iter().enumerate().rev() {
        if mask >> i & 1 == 1 {
            x = plane.reflection_matrix_f64().transform_point3(x);
        }
    }
    x.as_vec3()
}

/// The copy whose image holds final point `y`, and the source point it came from: the cascade
/// unfolded, last plane first. Each stage keeps its input in front of its plane and puts the
/// reflected part behind it, so behind plane `i` (after undoing the later planes) means bit
/// `i` is set. A point on a plane goes to the unreflected side.
pub fn fold(planes: &[Plane], y: Vec3) -> (u32, Vec3) {
    let mut x = y.as_dvec3();
    let mut mask = 0u32;
    for (i, plane) in planes.iter().enumerate().rev() {
        let n = plane.normal.as_dvec3();
        let d = n.dot(x) - plane.offset as f64;
        if d < 0.0 {
            mask |= 1 << i;
            x -= 2.0 * d * n;
        }
    }
    (mask, x.as_vec3())
}

/// A half-space `normal·x − offset ≥ 0` (f64).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfSpace {
    pub normal: DVec3,
    pub offset: f64,
}

impl HalfSpace {
    pub fn distance(&self, x: DVec3) -> f64 {
        self.normal.dot(x) - self.offset
    }

    /// Plane `plane`'s front as a condition on the source point `x` of a copy whose earlier
    /// planes map `x` to `transform·x`: `n·(L·x + t) − o ≥ 0`, i.e. normal `Lᵀn`, offset
    /// `o − n·t`.
    pub fn pulled_back(plane: &Plane, transform: DMat4) -> HalfSpace {
        let n = plane.normal.as_dvec3();
        let linear = glam::DMat3::from_mat4(transform);
        HalfSpace {
            normal: linear.transpose() * n,
            offset: plane.offset as f64 - n.dot(transform.w_axis.truncate()),
        }
    }
}

/// A convex polyhedron as its faces (convex polygons; f64). The empty polyhedron is `None`
/// wherever one is returned.
#[derive(Clone, Debug, PartialEq)]
pub struct ConvexPolytope {
    faces: Vec<Vec<DVec3>>,
}

impl ConvexPolytope {
    /// The box `lo..hi` (may be flat: a quad's bounds).
    pub fn cuboid(lo: DVec3, hi: DVec3) -> ConvexPolytope {
        let c = |i: usize| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        };
        let faces = [
            [0, 2, 6, 4],
            [1, 5, 7, 3],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 1, 3, 2],
            [4, 6, 7, 5],
        ];
        ConvexPolytope {
            faces: faces
                .iter()
                .map(|f| f.iter().map(|&i| c(i)).collect())
                .collect(),
        }
    }

    /// Every vertex (each once per face it belongs to).
    pub fn vertices(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.faces.iter().flatten().copied()
    }

    /// The part where `h.distance(x) ≥ −slack` — the half-space widened by `slack` (shrunk
    /// where it is negative); `None` where nothing is left. Each face is
    /// clipped (Sutherland–Hodgman) and the cut closed by a cap face: the points on the
    /// plane, in angular order about their centroid.
    pub fn clip(&self, h: &HalfSpace, slack: f64) -> Option<ConvexPolytope> {
        let d = |x: DVec3| h.distance(x) + slack;
        let (mut lowest, mut highest) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in self.vertices() {
            lowest = lowest.min(d(v));
            highest = highest.max(d(v));
        }
        // Empty — or NaN, where nothing can be said to lie in it.
        if highest.is_nan() || highest < 0.0 {
            return None;
        }
        if lowest >= 0.0 {
            return Some(self.clone());
        }
        let mut faces = Vec::with_capacity(self.faces.len() + 1);
        let mut on_plane: Vec<DVec3> = Vec::new();
        for face in &self.faces {
            let mut out = Vec::with_capacity(face.len() + 1);
            for (k, &a) in face.iter().enumerate() {
                let b = face[(k + 1) % face.len()];
                let (da, db) = (d(a), d(b));
                if da >= 0.0 {
                    out.push(a);
                    if da == 0.0 {
                        on_plane.push(a);
                    }
                }
                if (da >= 0.0) != (db >= 0.0) {
                    let cut = a + (b - a) * (da / (da - db));
                    out.push(cut);
                    on_plane.push(cut);
                }
            }
            if out.len() >= 3 {
                faces.push(out);
            }
        }
        if let Some(cap) = convex_polygon_on_plane(&on_plane, h.normal) {
            faces.push(cap);
        }
        (!faces.is_empty()).then_some(ConvexPolytope { faces })
    }
}

/// The points (coplanar, on a plane with normal `normal`), deduplicated and ordered by angle
/// about their centroid; `None` for fewer than 3 distinct points.
fn convex_polygon_on_plane(points: &[DVec3], normal: DVec3) -> Option<Vec<DVec3>> {
    let scale = points
        .iter()
        .fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let tolerance = 1e-12 * scale.max(1.0);
    let mut distinct: Vec<DVec3> = Vec::new();
    for &p in points {
        if !distinct
            .iter()
            .any(|q| (*q - p).abs().max_element() <= tolerance)
        {
            distinct.push(p);
        }
    }
    if distinct.len() < 3 {
        return None;
    }
    let centroid = distinct.iter().copied().sum::<DVec3>() / distinct.len() as f64;
    let u = normal.any_orthonormal_vector();
    let v = normal.normalize().cross(u);
    distinct.sort_by(|a, b| {
        let angle = |p: &DVec3| (*p - centroid).dot(v).atan2((*p - centroid).dot(u));
        angle(a).total_cmp(&angle(b))
    });
    Some(distinct)
}

/// The copies a frame draws, and why the others were left out.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CopySelection {
    /// Bitmasks of the copies drawn, ascending.
    pub drawn: Vec<u32>,
    /// Copies whose cell holds no part of the objects' bounds.
    pub pruned_empty: usize,
    /// Copies whose image lies wholly outside the view frustum.
    pub pruned_outside_view: usize,
}

impl CopySelection {
    /// Every copy of `planes` planes, none pruned (`symmetry`).
    pub fn all(planes: usize) -> CopySelection {
        CopySelection {
            drawn: (0..copy_count(planes) as u32).collect(),
            ..Default::default()
        }
    }
}

/// The copies of `planes` whose cell meets the objects' `bounds` (source space; `None`: no
/// objects) and, with `clip_from_world` (the camera's projection · view), whose image is not
/// wholly outside the view frustum.
///
/// Exact up to f32, the precision the GPU runs the cascade in: with `s` = 10⁻⁶ of the
/// scene's size, a cell counts as empty when nothing of it is thicker than `s` — the bounds
/// grown by `2s`, every plane's half-space shrunk by `s`. A thinner cell can draw only
/// triangles lying exactly in it (the six-pointed star's two extra cells are half-planes
/// between two of its planes, zero thick), which f32 cannot put on either side of a plane
/// anyway; a quad lying in a plane still has its two copies, its bounds being grown first.
/// The frustum test is conservative: it uses the cell widened by `s` (bounds grown by `s`),
/// and a copy counts as outside only when every vertex of that cell's image lies beyond one
/// and the same frustum plane (the image is their convex hull).
pub fn select_copies(
    planes: &[Plane],
    bounds: Option<(Vec3, Vec3)>,
    clip_from_world: Option<Mat4>,
) -> CopySelection {
    let mut selection = CopySelection::default();
    let Some((lo, hi)) = bounds else {
        selection.pruned_empty = copy_count(planes.len());
        return selection;
    };
    let scale = planes
        .iter()
        .map(|p| p.offset.abs())
        .chain([lo.abs().max_element(), hi.abs().max_element(), 1.0])
        .fold(0.0f32, f32::max) as f64;
    let thickness = 1e-6 * scale;
    let walk = Walk {
        planes,
        thickness,
        clip_from_world: clip_from_world.map(|m| m.as_dmat4()),
    };
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let cell = Cell {
        inner: ConvexPolytope::cuboid(lo - 2.0 * thickness, hi + 2.0 * thickness),
        outer: ConvexPolytope::cuboid(lo - thickness, hi + thickness),
    };
    walk.visit(0, 0, DMat4::IDENTITY, cell, &mut selection);
    selection.drawn.sort_unstable();
    selection
}

/// A cell (∩ the objects' bounds) twice: `inner`, its part thicker than the tolerance (empty:
/// the copy draws nothing), and `outer`, widened by it (for the frustum test).
#[derive(Clone)]
struct Cell {
    inner: ConvexPolytope,
    outer: ConvexPolytope,
}

/// The depth-first walk of [`select_copies`] over bitmask prefixes.
struct Walk<'a> {
    planes: &'a [Plane],
    thickness: f64,
    clip_from_world: Option<DMat4>,
}

impl Walk<'_> {
    /// Prefix `mask` of bits `0..i`, mapping source points by `transform`, with `cell` the
    /// part of the bounds passing planes `0..i`.
    fn visit(
        &self,
        i: usize,
        mask: u32,
        transform: DMat4,
        cell: Cell,
        selection: &mut CopySelection,
    ) {
        let p = self.planes.len();
        if i == p {
            if self.outside_view(&cell.outer, transform) {
                selection.pruned_outside_view += 1;
            } else {
                selection.drawn.push(mask);
            }
            return;
        }
        let plane = &self.planes[i];
        let h = HalfSpace::pulled_back(plane, transform);
        let clipped = cell
            .inner
            .clip(&h, -self.thickness)
            .zip(cell.outer.clip(&h, self.thickness));
        let Some((inner, outer)) = clipped else {
            selection.pruned_empty += copy_count(p - i);
            return;
        };
        let cell = Cell { inner, outer };
        self.visit(i + 1, mask, transform, cell.clone(), selection);
        let reflected = plane.reflection_matrix_f64() * transform;
        self.visit(i + 1, mask | 1 << i, reflected, cell, selection);
    }

    /// Whether every vertex of the cell's image lies beyond one frustum plane: clip space
    /// `−w ≤ x ≤ w`, `−w ≤ y ≤ w`, `z ≤ w` (the near plane; infinite reversed Z has no far
    /// one).
    fn outside_view(&self, cell: &ConvexPolytope, transform: DMat4) -> bool {
        let Some(clip_from_world) = self.clip_from_world else {
            return false;
        };
        let m = clip_from_world * transform;
        let clip: Vec<DVec4> = cell.vertices().map(|v| m * v.extend(1.0)).collect();
        let tolerance = 1e-6 * clip.iter().fold(1.0f64, |a, c| a.max(c.w.abs()));
        let beyond = |f: fn(&DVec4) -> f64| clip.iter().all(|c| f(c) < -tolerance);
        beyond(|c| c.w - c.x)
            || beyond(|c| c.w + c.x)
            || beyond(|c| c.w - c.y)
            || beyond(|c| c.w + c.y)
            || beyond(|c| c.w - c.z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(point: Vec3, normal: Vec3) -> Plane {
        Plane::from_point_normal(point, normal)
    }

    /// Planes through the z axis with normals at `degrees` in the xy plane.
    fn through_z_axis(degrees: &[f32]) -> Vec<Plane> {
        degrees
            .iter()
            .map(|a| {
                let r = a.to_radians();
                plane(Vec3::ZERO, Vec3::new(r.cos(), r.sin(), 0.0))
            })
            .collect()
    }

    /// The copies that keep some point of a fine grid over `lo..hi`, by running the cascade
    /// on every point: the brute-force truth of which cells are empty.
    fn copies_keeping_grid_points(planes: &[Plane], lo: Vec3, hi: Vec3) -> Vec<u32> {
        let steps = 24;
        let mut kept = vec![false; copy_count(planes.len())];
        for i in 0..=steps {
            for j in 0..=steps {
                for k in 0..=steps {
                    let t = Vec3::new(i as f32, j as f32, k as f32) / steps as f32;
                    let x0 = lo + (hi - lo) * t;
                    for (mask, kept) in kept.iter_mut().enumerate() {
                        let mut x = x0;
                        let mut inside = true;
                        for (i, p) in planes.iter().enumerate() {
                            let d = p.signed_distance(x);
                            inside &= d >= 0.0;
                            if mask >> i & 1 == 1 {
                                x = p.reflect_point(x);
                            }
                        }
                        *kept |= inside;
                    }
                }
            }
        }
        (0..kept.len() as u32)
            .filter(|&m| kept[m as usize])
            .collect()
    }

    #[test]
    fn one_plane_keeps_both_copies_of_objects_in_front_and_none_of_objects_behind() {
        let planes = [plane(Vec3::ZERO, Vec3::X)];
        // In front: the copy as it is and its reflection — bit 0 moves nothing a later plane
        // tests, so both share the cell.
        let front = select_copies(
            &planes,
            Some((Vec3::new(1.0, 0.0, 0.0), Vec3::ONE * 2.0)),
            None,
        );
        assert_eq!(front.drawn, vec![0, 1]);
        // Behind: the cascade culls everything behind the plane, in both copies.
        let behind = select_copies(&planes, Some((-Vec3::ONE * 2.0, -Vec3::ONE)), None);
        assert_eq!(behind.drawn, Vec::<u32>::new());
        assert_eq!(behind.pruned_empty, 2);
        // Lying on the plane (a quad in it): kept, as the cascade keeps d = 0.
        let on = select_copies(
            &planes,
            Some((Vec3::new(0.0, -1.0, -1.0), Vec3::new(0.0, 1.0, 1.0))),
            None,
        );
        assert_eq!(on.drawn, vec![0, 1]);
    }

    /// Seed 001's six-pointed star: three planes through one line at 60° leave 6 of the 8
    /// copies (3 cells, each shared by a pair differing in the last bit), with objects
    /// around the line; the other two cells are half-planes (zero thick). The grid check
    /// agrees copy for copy (its points miss the line, where every copy keeps its point).
    #[test]
    fn the_star_keeps_six_copies_of_eight() {
        let planes = through_z_axis(&[0.0, 60.0, 120.0]);
        let (lo, hi) = (Vec3::new(-1.01, -0.97, -0.5), Vec3::new(0.99, 1.03, 0.5));
        let s = select_copies(&planes, Some((lo, hi)), None);
        assert_eq!(s.drawn, vec![0, 1, 3, 4, 5, 7]);
        assert_eq!(s.pruned_empty, 2);
        assert_eq!(s.drawn, copies_keeping_grid_points(&planes, lo, hi));
    }

    /// Random-looking planes and boxes: exactly the copies keeping a grid point have a
    /// non-empty cell (none of these cells is thinner than the grid's step).
    #[test]
    fn cells_match_the_brute_force_cascade() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut random = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f32 / (1u64 << 53) as f32 * 2.0 - 1.0
        };
        for case in 0..12 {
            let p = 2 + case % 4;
            let planes: Vec<Plane> = (0..p)
                .map(|_| {
                    let normal = Vec3::new(random(), random(), random());
                    plane(0.5 * Vec3::new(random(), random(), random()), normal)
                })
                .collect();
            let lo = Vec3::new(random(), random(), random()) - Vec3::ONE;
            let hi = lo + Vec3::new(1.0 + random(), 1.0 + random(), 1.0 + random());
            let s = select_copies(&planes, Some((lo, hi)), None);
            let truth = copies_keeping_grid_points(&planes, lo, hi);
            assert_eq!(s.drawn, truth, "case {case}");
            assert_eq!(s.drawn.len() + s.pruned_empty, copy_count(p));
        }
    }

    #[test]
    fn fold_inverts_every_copy() {
        let planes = vec![
            plane(Vec3::new(0.1, 0.0, 0.0), Vec3::new(1.0, 0.2, 0.0)),
            plane(Vec3::new(0.0, -0.2, 0.0), Vec3::new(0.3, 1.0, 0.1)),
            plane(Vec3::ZERO, Vec3::new(-0.2, 0.4, 1.0)),
        ];
        let x0 = Vec3::new(0.7, 0.5, 0.9);
        for mask in 0..8u32 {
            // Run the cascade; where the point survives, fold must give back mask and x0.
            let mut x = x0;
            let mut inside = true;
            for (i, p) in planes.iter().enumerate() {
                inside &= p.signed_distance(x) > 1e-3;
                if mask >> i & 1 == 1 {
                    x = p.reflect_point(x);
                }
            }
            let y = copy_transform(&planes, mask).as_mat4().transform_point3(x0);
            assert!((y - x).length() < 1e-5);
            assert!((pull_back(&planes, mask, y) - x0).length() < 1e-5);
            if inside {
                let (m, back) = fold(&planes, y);
                assert_eq!(m, mask);
                assert!((back - x0).length() < 1e-5);
            }
        }
    }

    /// Frustum pruning is conservative: a copy whose image reaches the view is never left
    /// out; one wholly behind the camera or beside the view is.
    #[test]
    fn copies_outside_the_view_are_pruned_and_only_those() {
        let camera = mirrorbox_scene::Camera {
            position: Vec3::new(3.0, 0.0, 0.0),
            look_at: Vec3::new(10.0, 0.0, 0.0),
            up: Vec3::Y,
            fov_y_deg: 40.0,
            width: 64,
            height: 48,
            exposure: 1.0,
            shift_x: 0.0,
        };
        let clip_from_world = crate::projection::camera_projection(&camera, 64, 48) * camera.view();
        // Objects at x in [5, 6]; the plane x = 0 puts the reflection at x in [−6, −5],
        // behind the camera looking towards +x.
        let planes = [plane(Vec3::ZERO, Vec3::X)];
        let bounds = Some((Vec3::new(5.0, -0.5, -0.5), Vec3::new(6.0, 0.5, 0.5)));
        let s = select_copies(&planes, bounds, Some(clip_from_world));
        assert_eq!(s.drawn, vec![0]);
        assert_eq!(s.pruned_outside_view, 1);
        // Looking back towards −x from x = 3: the objects are behind the camera, only the
        // reflection is in view.
        let back = mirrorbox_scene::Camera {
            look_at: Vec3::new(-10.0, 0.0, 0.0),
            ..camera
        };
        let clip_from_world = crate::projection::camera_projection(&back, 64, 48) * back.view();
        let s = select_copies(&planes, bounds, Some(clip_from_world));
        assert_eq!(s.drawn, vec![1]);
        // A box straddling the view's edge is kept.
        let straddling = Some((Vec3::new(5.0, 1.0, -0.5), Vec3::new(6.0, 20.0, 0.5)));
        let s = select_copies(&planes, straddling, Some(clip_from_world));
        assert_eq!(s.drawn, vec![1]);
    }

    #[test]
    fn clipping_a_cube_in_half_keeps_a_closed_half() {
        let cube = ConvexPolytope::cuboid(DVec3::ZERO, DVec3::ONE);
        let h = HalfSpace {
            normal: DVec3::new(1.0, 1.0, 0.0).normalize(),
            offset: 0.5f64.sqrt(),
        };
        let half = cube.clip(&h, 0.0).unwrap();
        // x + y ≥ 1: the z faces become triangles, x = 1 and y = 1 stay whole, x = 0 and
        // y = 0 shrink to an edge and go; the cap is a rectangle.
        assert_eq!(half.faces.len(), 5);
        assert!(half.vertices().all(|v| h.distance(v) >= -1e-12));
        let cap = half.faces.last().unwrap();
        assert_eq!(cap.len(), 4);
        assert!(
            cube.clip(
                &HalfSpace {
                    normal: DVec3::X,
                    offset: 2.0
                },
                0.0
            )
            .is_none()
        );
        assert_eq!(
            cube.clip(
                &HalfSpace {
                    normal: DVec3::X,
                    offset: -1.0
                },
                0.0
            ),
            Some(cube.clone())
        );
    }
}
