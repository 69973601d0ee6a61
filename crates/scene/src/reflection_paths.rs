//! Reflection paths: every chain of mirrors the camera sees through, with its screen portal.
//!
//! From the camera, recurse through each visible mirror: facing the path's (virtual) eye, in
//! front of the path's last mirror, and inside the path's portal — the mirror's polygon is
//! clipped by the last mirror's plane, projected, clipped to the view and then to the
//! parent's portal (seed 001's pruning of invisible cells, made general). A path is pruned
//! when its portal is empty or holds no sample position (pixel centre at the render
//! resolution — the only points a rasterizer looks at, so this pruning changes no pixel),
//! optionally when it is smaller than `min_portal_area` pixels² (lossy, for speed), or when
//! the product of reflectances along it falls below `min_attenuation`, and capped at
//! `max_depth` mirrors.
//! Two parallel mirrors give chains; a mirror room branches, and pruning keeps it tractable.
//!
//! A portal says where a mirror *could* be seen; a nearer sibling mirror (another child of
//! the same path) may hide part of it — a small mirror in front of a large one. Each path
//! therefore also holds its *visible region*: its portal less what its siblings hide, cut into
//! convex pieces, inside its parent's visible region. Along the rays from the parent's eye
//! (a pixel's direction `d`), sibling X is met before sibling Y where
//! `d · (δ_Y(e)·n_X − δ_X(e)·n_Y) < 0` (δ the signed distances from the eye, n the normals):
//! a plane through the eye, i.e. a line on screen through the image of the two mirrors'
//! intersection. So the part of Y that X hides is convex (X's portal on X's side of that
//! line), and Y's visible region is Y's portal less a few convex polygons. Only the pixel
//! centres matter: a hidden part holding none changes no pixel and cuts nothing, so in scenes
//! without overlapping siblings every visible region is the portal itself.
//!
//! Views are composed in f64 (`view · R₁ · … · Rₖ`), so a 1000-reflection path is as exact as
//! a short one, and converted to f32 once.

use crate::Scene;
use crate::camera::pixel_to_ndc;
use crate::polygon::{area, bounds, clip_by, orientation, screen_footprint};
use crate::reflection::{Plane, ReflectedView};
use glam::{DMat3, DMat4, DVec3, Mat4, Vec2, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathLimits {
    /// Most mirrors along a path.
    pub max_depth: u32,
    /// Portals smaller than this (pixels²) are pruned, though they may hold a sample (lossy);
    /// 0 prunes only portals holding no sample, which is exact.
    pub min_portal_area: f32,
    /// Paths whose attenuation (largest channel) falls below this are pruned.
    pub min_attenuation: f32,
    /// Enumeration stops (and [`PathSet::truncated`] is set) beyond this many paths.
    pub max_paths: usize,
}

#[derive(Clone, Debug)]
pub struct ReflectionPath {
    /// Scene mirrors looked through, first mirror first (empty for the camera itself).
    pub mirrors: Vec<usize>,
    pub view: ReflectedView,
    /// The last mirror's plane (front kept): the near plane of this path's world.
    pub plane: Option<Plane>,
    /// Where the path's last mirror can be seen (convex polygon, image pixels): its footprint
    /// clipped to the parent's portal.
    pub portal: Vec<Vec2>,
    /// The part of `portal` really seen through the path, as convex pieces each holding a
    /// pixel centre: the portal inside the parent's visible region, less what nearer sibling
    /// mirrors hide (module docs). `[portal]` unless sibling portals overlap.
    pub visible: Vec<Vec<Vec2>>,
    /// Product of the reflectances along the path.
    pub attenuation: Vec3,
    pub parent: Option<usize>,
    pub children: Vec<usize>,
}

#[derive(Clone, Debug, Default)]
pub struct PathSet {
    /// `paths[0]` is the camera; children follow their parents.
    pub paths: Vec<ReflectionPath>,
    pub pruned_empty: usize,
    /// Non-empty portals holding no pixel centre.
    pub pruned_no_sample: usize,
    pub pruned_small: usize,
    pub pruned_attenuation: usize,
    pub capped: usize,
    /// Portals holding pixel centres only where nearer sibling mirrors hide them.
    pub pruned_hidden: usize,
    /// Kept paths whose visible region is not their whole portal (a nearer sibling mirror, of
    /// the path or of an ancestor, hides part of it).
    pub partly_hidden: usize,
    pub deepest: usize,
    /// More paths were visible than `max_paths` allowed: the set is incomplete.
    pub truncated: bool,
}

/// Drops vertices that (nearly) repeat their predecessor: clipping leaves such duplicates,
/// and a zero-length edge has no usable direction.
fn without_duplicates(poly: Vec<Vec2>) -> Vec<Vec2> {
    let mut out: Vec<Vec2> = Vec::with_capacity(poly.len());
    for p in poly {
        if out.last().is_none_or(|q| q.distance_squared(p) > 1e-8) {
            out.push(p);
        }
    }
    while out.len() > 1 && out[0].distance_squared(out[out.len() - 1]) <= 1e-8 {
        out.pop();
    }
    out
}

/// How far outside a region a pixel centre still counts as held by it, pixels: a rasterizer
/// snaps projected vertices to its sub-pixel grid (Vulkan's `subPixelPrecisionBits`, 8 on
/// lavapipe: up to 1/512 px per axis) and so may cover a sample that lies just outside the
/// exact region. Pruning a path whose region holds a sample only that closely would leave the
/// parent to draw the mirror there with the terminal radiance, where the truth goes on
/// (issue 50: `mirror_room` at depth 27, a pixel centre 10⁻⁵ px from a mirror's rim in one
/// world, covered by the snapped mirror, pruned by the plan). Keeping such a path costs a
/// draw and changes no pixel otherwise.
pub const SAMPLE_MARGIN: f32 = 1.0 / 128.0;

/// Whether convex polygon `poly` (pixels, any orientation) contains a pixel centre
/// `(i + ½, j + ½)`, edges included, or one within [`SAMPLE_MARGIN`] of it. Conservative: a
/// polygon whose bounding box spans more than 256 centres counts as holding one without
/// looking.
pub fn holds_a_sample(poly: &[Vec2]) -> bool {
    let (lo, hi) = bounds(poly);
    let (lo, hi) = (
        lo - Vec2::splat(SAMPLE_MARGIN),
        hi + Vec2::splat(SAMPLE_MARGIN),
    );
    // Centres c with lo ≤ c ≤ hi: i from ceil(lo − ½) to floor(hi − ½).
    let (i0, i1) = ((lo.x - 0.5).ceil(), (hi.x - 0.5).floor());
    let (j0, j1) = ((lo.y - 0.5).ceil(), (hi.y - 0.5).floor());
    if i1 < i0 || j1 < j0 {
        return false;
    }
    if (i1 - i0 + 1.0) * (j1 - j0 + 1.0) > 256.0 {
        return true;
    }
    let orientation = orientation(poly);
    let inside = |c: Vec2| {
        (0..poly.len()).all(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            orientation * (b - a).perp_dot(c - a) >= -SAMPLE_MARGIN * (b - a).length()
        })
    };
    let mut j = j0;
    while j <= j1 {
        let mut i = i0;
        while i <= i1 {
            if inside(Vec2::new(i + 0.5, j + 0.5)) {
                return true;
            }
            i += 1.0;
        }
        j += 1.0;
    }
    false
}

/// Whether convex polygon `poly` (pixels) contains a pixel centre `(i + ½, j + ½)`, edges
/// included — exactly, row by row: on each centre row the polygon is one interval.
pub fn holds_a_pixel_centre(poly: &[Vec2]) -> bool {
    if poly.len() < 3 {
        return false;
    }
    let (lo, hi) = bounds(poly);
    let mut y = (lo.y - 0.5).ceil() + 0.5;
    while y <= hi.y {
        let (mut x0, mut x1) = (f32::INFINITY, f32::NEG_INFINITY);
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            if (a.y - y) * (b.y - y) > 0.0 {
                continue; // the edge does not reach this row
            }
            let x = if a.y == b.y {
                x0 = x0.min(a.x.min(b.x));
                a.x.max(b.x)
            } else {
                a.x + (b.x - a.x) * (y - a.y) / (b.y - a.y)
            };
            x0 = x0.min(x);
            x1 = x1.max(x);
        }
        if (x0 - 0.5).ceil() <= (x1 - 0.5).floor() {
            return true;
        }
        y += 1.0;
    }
    false
}

/// Convex polygons `pieces` less convex polygon `hole`, as convex pieces holding pixel
/// centres. A piece whose overlap with the hole holds no centre is kept whole (cutting it
/// would change no pixel), as is one whose overlap is under 0.01 px² (rounding along an edge
/// the two share, as where two walls meet); any other is cut by the hole's edges in turn:
/// the part outside edge i and inside edges 0..i is kept.
pub fn subtract_convex(pieces: Vec<Vec<Vec2>>, hole: &[Vec2]) -> Vec<Vec<Vec2>> {
    let hole = without_duplicates(hole.to_vec());
    if hole.len() < 3 {
        return pieces;
    }
    let orientation = orientation(&hole);
    let mut out = Vec::with_capacity(pieces.len());
    for piece in pieces {
        let overlap = clip_convex(&piece, &hole);
        if overlap.len() < 3 || area(&overlap) <= 0.01 || !holds_a_pixel_centre(&overlap) {
            out.push(piece);
            continue;
        }
        let mut rest = piece;
        for i in 0..hole.len() {
            let (a, b) = (hole[i], hole[(i + 1) % hole.len()]);
            let edge = (b - a).normalize_or_zero();
            let inside = |p: Vec2| orientation * edge.perp_dot(p - a);
            let outside = without_duplicates(clip_by(&rest, |p| -inside(p)));
            if holds_a_pixel_centre(&outside) {
                out.push(outside);
            }
            rest = without_duplicates(clip_by(&rest, inside));
            if rest.len() < 3 {
                break;
            }
        }
    }
    out
}

/// Screen-space tests on the rays from one (virtual) eye, through `clip_from_world` (the
/// camera's projection times the path's view, f64).
struct EyeRays {
    eye: DVec3,
    /// `(M₃⁻¹)ᵀ`, M₃ = rows x, y, w and columns x, y, z of `clip_from_world`: a direction `d`
    /// from the eye has `(x_c, y_c, w_c) = M₃·d`, so `g·d` over the pixel at NDC `p` is
    /// `((M₃⁻¹)ᵀ g)·(p, 1)` up to the positive factor `w_c`.
    to_screen_line: DMat3,
    size: Vec2,
}

impl EyeRays {
    fn new(eye: DVec3, clip_from_world: DMat4, size: Vec2) -> Self {
        let m = clip_from_world;
        let m3 = DMat3::from_cols(
            DVec3::new(m.x_axis.x, m.x_axis.y, m.x_axis.w),
            DVec3::new(m.y_axis.x, m.y_axis.y, m.y_axis.w),
            DVec3::new(m.z_axis.x, m.z_axis.y, m.z_axis.w),
        );
        EyeRays {
            eye,
            to_screen_line: m3.inverse().transpose(),
            size,
        }
    }

    /// The part of `near`'s portal where its mirror (plane `near_plane`) is met before plane
    /// `far_plane` along the rays from the eye (both facing the eye): where
    /// `d · (δ_far·n_near − δ_near·n_far) < 0` (module docs).
    fn met_first(&self, near: &[Vec2], near_plane: &Plane, far_plane: &Plane) -> Vec<Vec2> {
        let distance = |p: &Plane| p.normal.as_dvec3().dot(self.eye) - p.offset as f64;
        let g = distance(far_plane) * near_plane.normal.as_dvec3()
            - distance(near_plane) * far_plane.normal.as_dvec3();
        let line = self.to_screen_line * g;
        let size = self.size;
        clip_by(near, |q| {
            let ndc = pixel_to_ndc(q, size).as_dvec2();
            -(line.x * ndc.x + line.y * ndc.y + line.z) as f32
        })
    }
}

/// Keeps the part of convex polygon `poly` inside convex polygon `clip` (any orientation).
pub fn clip_convex(poly: &[Vec2], clip: &[Vec2]) -> Vec<Vec2> {
    let clip = without_duplicates(clip.to_vec());
    let orientation = orientation(&clip);
    let mut out = poly.to_vec();
    for i in 0..clip.len() {
        if out.is_empty() {
            break;
        }
        let (a, b) = (clip[i], clip[(i + 1) % clip.len()]);
        let edge = (b - a).normalize_or_zero();
        out = clip_by(&out, |p| orientation * edge.perp_dot(p - a));
    }
    without_duplicates(out)
}

/// Enumerates the reflection paths of `scene` seen by its camera at `width × height` with
/// `projection` (the raster projection: its near plane bounds the root portal).
pub fn reflection_paths(
    scene: &Scene,
    width: u32,
    height: u32,
    projection: Mat4,
    limits: &PathLimits,
) -> PathSet {
    let camera = scene.camera.with_size(width, height);
    let size = Vec2::new(width as f32, height as f32);
    let screen = vec![
        Vec2::ZERO,
        Vec2::new(size.x, 0.0),
        size,
        Vec2::new(0.0, size.y),
    ];
    let mut set = PathSet::default();
    let root_view = camera.view().as_dmat4();
    set.paths.push(ReflectionPath {
        mirrors: Vec::new(),
        view: ReflectedView::direct(camera.view()),
        plane: None,
        visible: vec![screen.clone()],
        portal: screen,
        attenuation: Vec3::ONE,
        parent: None,
        children: Vec::new(),
    });
    // Exact (f64) views alongside the paths, and whether each path's visible region is its
    // whole portal.
    let mut views64 = vec![root_view];
    let mut whole = vec![true];
    let projection64 = projection.as_dmat4();
    let mut next = 0;
    while next < set.paths.len() {
        let parent = next;
        next += 1;
        let eye64 = views64[parent].inverse().transform_point3(DVec3::ZERO);
        let eye = eye64.as_vec3();
        let (clip_from_world, plane, portal, attenuation, depth) = {
            let p = &set.paths[parent];
            (
                projection * p.view.view,
                p.plane,
                p.portal.clone(),
                p.attenuation,
                p.mirrors.len(),
            )
        };
        // Every mirror seen from this path's eye, with its portal.
        let mut candidates: Vec<(usize, Plane, Vec<Vec2>)> = Vec::new();
        for (m, mirror) in scene.mirrors.iter().enumerate() {
            if set.paths[parent].mirrors.last() == Some(&m) {
                continue;
            }
            let mirror_plane = mirror.plane();
            if mirror_plane.signed_distance(eye) <= 0.0 {
                continue;
            }
            let mut poly = mirror.corners().to_vec();
            if let Some(pl) = plane {
                poly = clip_by(&poly, |p| pl.signed_distance(p));
            }
            let on_screen = screen_footprint(&poly, clip_from_world, size);
            let visible = if on_screen.len() >= 3 {
                clip_convex(&on_screen, &portal)
            } else {
                Vec::new()
            };
            if visible.len() < 3 || area(&visible) == 0.0 {
                set.pruned_empty += 1;
                continue;
            }
            candidates.push((m, mirror_plane, visible));
        }
        let rays = EyeRays::new(eye64, projection64 * views64[parent], size);
        for (c, (m, mirror_plane, visible)) in candidates.iter().enumerate() {
            let mirror = &scene.mirrors[*m];
            if !holds_a_sample(visible) {
                set.pruned_no_sample += 1;
                continue;
            }
            if area(visible) < limits.min_portal_area {
                set.pruned_small += 1;
                continue;
            }
            let att = attenuation * mirror.reflectance;
            if att.max_element() < limits.min_attenuation {
                set.pruned_attenuation += 1;
                continue;
            }
            if depth as u32 >= limits.max_depth {
                set.capped += 1;
                continue;
            }
            // The portal inside the parent's visible region, less what nearer siblings hide.
            let mut pieces: Vec<Vec<Vec2>> = if whole[parent] {
                vec![visible.clone()]
            } else {
                set.paths[parent]
                    .visible
                    .iter()
                    .map(|piece| clip_convex(visible, piece))
                    .filter(|piece| holds_a_pixel_centre(piece))
                    .collect()
            };
            if let [inside] = pieces.as_slice()
                && area(inside) >= area(visible) - 1e-4
            {
                pieces = vec![visible.clone()]; // the portal lies in one piece of the parent's
            }
            for (s, (_, sibling_plane, sibling_portal)) in candidates.iter().enumerate() {
                if s != c && !pieces.is_empty() {
                    let hidden = rays.met_first(sibling_portal, sibling_plane, mirror_plane);
                    pieces = subtract_convex(pieces, &hidden);
                }
            }
            if pieces.is_empty() {
                set.pruned_hidden += 1;
                continue;
            }
            if set.paths.len() >= limits.max_paths {
                set.truncated = true;
                return set;
            }
            let is_whole = pieces.len() == 1 && pieces[0] == *visible;
            set.partly_hidden += usize::from(!is_whole);
            let view64 = views64[parent] * mirror_plane.reflection_matrix_f64();
            let mut mirrors = set.paths[parent].mirrors.clone();
            mirrors.push(*m);
            let child = set.paths.len();
            set.deepest = set.deepest.max(mirrors.len());
            set.paths.push(ReflectionPath {
                mirrors,
                view: ReflectedView {
                    view: view64.as_mat4(),
                    depth: depth as u32 + 1,
                },
                plane: Some(*mirror_plane),
                portal: visible.clone(),
                visible: pieces,
                attenuation: att,
                parent: Some(parent),
                children: Vec::new(),
            });
            views64.push(view64);
            whole.push(is_whole);
            set.paths[parent].children.push(child);
        }
    }
    set
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::load::bundled_scene as scene;

    fn limits(max_depth: u32) -> PathLimits {
        PathLimits {
            max_depth,
            min_portal_area: 0.0,
            min_attenuation: 1e-4,
            max_paths: 100_000,
        }
    }

    fn run(s: &Scene, l: &PathLimits) -> PathSet {
        let cam = s.camera.with_size(160, 90);
        reflection_paths(s, 160, 90, cam.projection(0.01, 1e4), l)
    }

    #[test]
    fn parallel_mirrors_give_a_chain_cut_by_attenuation() {
        let s = scene("mirror_box.json");
        let set = run(&s, &limits(1000));
        // Reflectance 0.9: 0.9^k ≥ 1e-4 for k ≤ 87.
        assert_eq!(set.deepest, 87);
        assert_eq!(set.paths.len(), 1 + 87, "one chain");
        assert_eq!(set.pruned_attenuation, 1);
        for p in &set.paths[1..] {
            assert_eq!(set.paths[p.parent.unwrap()].children.len(), 1);
            // Alternating mirrors.
            assert!(p.mirrors.windows(2).all(|w| w[0] != w[1]));
        }
        let capped = run(&s, &limits(10));
        assert_eq!((capped.deepest, capped.capped), (10, 1));
    }

    #[test]
    fn portals_nest_and_views_stay_exact_deep_down() {
        let mut s = scene("mirror_box.json");
        s.set_reflectance(Vec3::ONE).unwrap();
        let set = run(&s, &limits(1000));
        for p in &set.paths[1..] {
            let parent = &set.paths[p.parent.unwrap()];
            assert!(area(&p.portal) <= area(&parent.portal) + 1e-3);
        }
        // Two parallel mirrors 4 apart: every two reflections move the virtual eye by +8 in
        // z. With R = 1 the chain ends only when its portal holds no pixel centre.
        let depth = set.deepest / 2 * 2;
        assert!(depth >= 100, "R = 1 reaches depth {}", set.deepest);
        let deep = set.paths.iter().find(|p| p.mirrors.len() == depth).unwrap();
        let expected = s.camera.position.z as f64 + 4.0 * depth as f64;
        let eye = deep.view.eye();
        assert!((eye.z as f64 - expected).abs() < 1e-2, "{eye}");
    }

    #[test]
    fn a_mirror_room_branches_and_pruning_keeps_it_tractable() {
        let s = scene("mirror_room.json");
        let set = run(
            &s,
            &PathLimits {
                max_depth: 64,
                min_portal_area: 1.0,
                min_attenuation: 1e-4,
                max_paths: 100_000,
            },
        );
        let branching = set.paths.iter().filter(|p| p.children.len() > 1).count();
        assert!(branching > 0, "the room branches");
        assert!(set.paths.len() < 20_000, "{} paths", set.paths.len());
        assert!(set.pruned_small + set.pruned_empty > 0);
        assert!(!set.truncated);
        let tight = run(
            &s,
            &PathLimits {
                max_depth: 64,
                min_portal_area: 1.0,
                min_attenuation: 1e-4,
                max_paths: 50,
            },
        );
        assert!(tight.truncated && tight.paths.len() == 50);
    }

    /// A clip polygon with a repeated vertex (as clipping produces) must not cut everything.
    #[test]
    fn repeated_vertices_do_not_empty_the_clip() {
        let a = [
            Vec2::new(0.0, 0.0),
            Vec2::new(2.0, 0.0),
            Vec2::new(2.0, 2.0),
            Vec2::new(0.0, 2.0),
        ];
        let with_repeat = [a[0], a[1], a[2], a[2] + Vec2::new(0.0, 4e-6), a[3]];
        assert!((area(&clip_convex(&a, &with_repeat)) - 4.0).abs() < 1e-4);
    }

    #[test]
    fn a_portal_holds_a_sample_only_around_a_pixel_centre() {
        let square = |c: Vec2, r: f32| {
            vec![
                c + Vec2::new(-r, -r),
                c + Vec2::new(r, -r),
                c + Vec2::new(r, r),
                c + Vec2::new(-r, r),
            ]
        };
        assert!(holds_a_sample(&square(Vec2::new(3.5, 7.5), 0.1)));
        // Area 0.64 px² between four centres: no sample.
        assert!(!holds_a_sample(&square(Vec2::new(4.0, 8.0), 0.4)));
        // Edges count; orientation does not matter.
        let mut edge = square(Vec2::new(3.5, 7.9), 0.4);
        assert!(holds_a_sample(&edge));
        edge.reverse();
        assert!(holds_a_sample(&edge));
        // A thin sliver between two rows of centres, 30 px long.
        let sliver = [
            Vec2::new(0.0, 2.1),
            Vec2::new(30.0, 2.1),
            Vec2::new(30.0, 2.4),
            Vec2::new(0.0, 2.4),
        ];
        assert!(!holds_a_sample(&sliver));
    }

    fn square(lo: Vec2, hi: Vec2) -> Vec<Vec2> {
        vec![lo, Vec2::new(hi.x, lo.y), hi, Vec2::new(lo.x, hi.y)]
    }

    #[test]
    fn the_exact_centre_test_agrees_with_the_shortcut_and_sees_thin_slivers() {
        for (c, r) in [(3.5, 0.1), (4.0, 0.4), (3.9, 0.4), (10.0, 0.6)] {
            let poly = square(Vec2::splat(c - r), Vec2::splat(c + r));
            assert_eq!(
                holds_a_pixel_centre(&poly),
                holds_a_sample(&poly),
                "{c} {r}"
            );
        }
        // A diagonal band 100 px long between the centres (y − x is an integer at every
        // centre, here in [0.1, 0.15]): the shortcut cannot tell, the row scan can.
        let band = [
            Vec2::new(0.0, 0.1),
            Vec2::new(100.0, 100.1),
            Vec2::new(100.0, 100.15),
            Vec2::new(0.0, 0.15),
        ];
        assert!(holds_a_sample(&band));
        assert!(!holds_a_pixel_centre(&band));
        let through_centres = band.map(|p| p + Vec2::new(0.0, 0.9)); // y − x in [1, 1.05]
        assert!(holds_a_pixel_centre(&through_centres));
    }

    #[test]
    fn subtracting_a_hole_leaves_convex_pieces_of_the_rest() {
        let big = square(Vec2::ZERO, Vec2::splat(20.0));
        let hole = square(Vec2::splat(5.0), Vec2::new(12.0, 9.0));
        let pieces = subtract_convex(vec![big.clone()], &hole);
        assert!(pieces.len() >= 2 && pieces.len() <= 4, "{pieces:?}");
        let total: f32 = pieces.iter().map(|p| area(p)).sum();
        assert!((total - (400.0 - 28.0)).abs() < 1e-3, "{total}");
        for (i, a) in pieces.iter().enumerate() {
            assert!(
                area(&clip_convex(a, &hole)) < 1e-4,
                "piece {i} overlaps the hole"
            );
            for b in &pieces[i + 1..] {
                assert!(area(&clip_convex(a, b)) < 1e-4, "pieces overlap");
            }
        }
        // A hole elsewhere, or one whose overlap holds no pixel centre, cuts nothing.
        let away = square(Vec2::splat(30.0), Vec2::splat(40.0));
        assert_eq!(subtract_convex(vec![big.clone()], &away), vec![big.clone()]);
        let between_centres = square(Vec2::new(5.6, 5.6), Vec2::new(6.4, 6.4));
        assert_eq!(
            subtract_convex(vec![big.clone()], &between_centres),
            vec![big]
        );
    }

    /// A small mirror in front of a large one, both facing the camera: the large mirror's
    /// visible region is its portal less the small mirror's, in convex pieces; the bundled
    /// scenes' siblings never hide each other, so their visible regions are their portals.
    #[test]
    fn a_nearer_sibling_mirror_cuts_the_visible_region_of_a_farther_one() {
        let text = r#"{
            "camera": { "position": [0, 1, 3], "look_at": [0, 1, -2], "fov_y_deg": 50, "width": 160, "height": 90 },
            "mirrors": [ { "center": [0, 1, -2], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 4, "height": 3 },
                         { "center": [0.2, 1, 0], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 0.6, "height": 0.6 } ]
        }"#;
        let s = crate::load::parse_scene(text, std::path::Path::new("overlap.json")).unwrap();
        let set = run(&s, &limits(1));
        assert_eq!(set.paths.len(), 3);
        let (large, small) = (&set.paths[1], &set.paths[2]);
        assert_eq!(
            (large.mirrors.as_slice(), small.mirrors.as_slice()),
            (&[0][..], &[1][..])
        );
        assert_eq!(small.visible, vec![small.portal.clone()]);
        assert!(large.visible.len() >= 2, "{:?}", large.visible);
        let seen: f32 = large.visible.iter().map(|p| area(p)).sum();
        let expected = area(&large.portal) - area(&clip_convex(&large.portal, &small.portal));
        assert!(
            (seen - expected).abs() < 1e-2 * expected,
            "{seen} vs {expected}"
        );
        assert_eq!(set.partly_hidden, 1);
        for name in ["mirror_box.json", "mirror_room.json", "tilted_pair.json"] {
            let set = run(&scene(name), &limits(16));
            assert_eq!((set.partly_hidden, set.pruned_hidden), (0, 0), "{name}");
            assert!(
                set.paths
                    .iter()
                    .all(|p| p.visible == vec![p.portal.clone()])
            );
        }
    }

    #[test]
    fn convex_clipping_keeps_the_overlap() {
        let a = [
            Vec2::new(0.0, 0.0),
            Vec2::new(2.0, 0.0),
            Vec2::new(2.0, 2.0),
            Vec2::new(0.0, 2.0),
        ];
        let b: Vec<Vec2> = a.iter().map(|p| *p + Vec2::splat(1.0)).rev().collect(); // clockwise
        assert!((area(&clip_convex(&a, &b)) - 1.0).abs() < 1e-6);
        let far: Vec<Vec2> = a.iter().map(|p| *p + Vec2::splat(5.0)).collect();
        assert!(clip_convex(&a, &far).is_empty());
    }
}
