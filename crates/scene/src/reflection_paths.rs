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
//! Views are composed in f64 (`view · R₁ · … · Rₖ`), so a 1000-reflection path is as exact as
//! a short one, and converted to f32 once.

use crate::Scene;
use crate::polygon::{area, bounds, clip_by, orientation, screen_footprint};
use crate::reflection::{Plane, ReflectedView};
use glam::{DVec3, Mat4, Vec2, Vec3};

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
    /// Visible screen region (convex polygon, image pixels).
    pub portal: Vec<Vec2>,
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

/// Whether convex polygon `poly` (pixels, any orientation) contains a pixel centre
/// `(i + ½, j + ½)`, edges included. Conservative: a polygon whose bounding box spans more
/// than 256 centres counts as holding one without looking.
pub fn holds_a_sample(poly: &[Vec2]) -> bool {
    let (lo, hi) = bounds(poly);
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
            orientation * (b - a).perp_dot(c - a) >= 0.0
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
        portal: screen,
        attenuation: Vec3::ONE,
        parent: None,
        children: Vec::new(),
    });
    // Exact (f64) views alongside the paths.
    let mut views64 = vec![root_view];
    let mut next = 0;
    while next < set.paths.len() {
        let parent = next;
        next += 1;
        let (eye, clip_from_world, plane, portal, attenuation, depth) = {
            let p = &set.paths[parent];
            let eye = views64[parent]
                .inverse()
                .transform_point3(DVec3::ZERO)
                .as_vec3();
            (
                eye,
                projection * p.view.view,
                p.plane,
                p.portal.clone(),
                p.attenuation,
                p.mirrors.len(),
            )
        };
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
            if !holds_a_sample(&visible) {
                set.pruned_no_sample += 1;
                continue;
            }
            if area(&visible) < limits.min_portal_area {
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
            if set.paths.len() >= limits.max_paths {
                set.truncated = true;
                return set;
            }
            let view64 = views64[parent] * mirror_plane.reflection_matrix_f64();
            let mut mirrors = set.paths[parent].mirrors.clone();
            mirrors.push(m);
            let child = set.paths.len();
            set.deepest = set.deepest.max(mirrors.len());
            set.paths.push(ReflectionPath {
                mirrors,
                view: ReflectedView {
                    view: view64.as_mat4(),
                    depth: depth as u32 + 1,
                },
                plane: Some(mirror_plane),
                portal: visible,
                attenuation: att,
                parent: Some(parent),
                children: Vec::new(),
            });
            views64.push(view64);
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
        s.set_reflectance(Vec3::ONE);
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
