//! The scene crate's reflection paths (what the exact raster methods draw) against the
//! tracer: the mirrors a traced ray meets must be a kept path, in order, and every kept
//! path must be met by the ray through its portal.

use glam::Vec2;
use mirrorbox_scene::load::parse_scene;
use mirrorbox_scene::reflection_paths::{PathLimits, PathSet, reflection_paths};
use mirrorbox_scene::{Scene, polygon::area};
use mirrorbox_trace::{SceneBvh, Whitted, WhittedSettings};
use std::path::Path;

const DEPTH: u32 = 6;

/// The mirror room with its objects removed, so that nothing but mirrors can stop a ray
/// (portals know nothing of occluders).
fn bare_room(width: u32, height: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mirror_room.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    v["objects"] = serde_json::json!([]);
    v["camera"]["width"] = width.into();
    v["camera"]["height"] = height.into();
    parse_scene(&v.to_string(), &path).unwrap()
}

fn paths(s: &Scene) -> PathSet {
    let (w, h) = (s.camera.width, s.camera.height);
    let limits = PathLimits {
        max_depth: DEPTH,
        min_portal_area: 0.0,
        min_attenuation: 0.0,
        max_paths: 100_000,
    };
    reflection_paths(s, w, h, s.camera.projection(0.01, 1e4), &limits)
}

/// The mirrors (in order, at most `DEPTH`) that the ray through image position `p` meets.
fn traced_mirrors(s: &Scene, whitted: &Whitted, p: Vec2) -> Vec<usize> {
    let mut seen = Vec::new();
    whitted.trace(s.camera.primary_ray(p.x, p.y), |_, _, m| seen.push(m));
    seen
}

fn whitted_for(s: &Scene) -> (SceneBvh, WhittedSettings) {
    let settings = WhittedSettings {
        max_depth: DEPTH,
        min_throughput: 0.0,
    };
    (SceneBvh::build(&s.geometry), settings)
}

/// Whether the convex polygon `poly` (either winding) holds `p`, or lies within `tolerance`
/// of it.
fn holds(poly: &[Vec2], p: Vec2, tolerance: f32) -> bool {
    let edges = || poly.iter().zip(poly.iter().cycle().skip(1));
    let area: f32 = edges().map(|(a, b)| a.perp_dot(*b)).sum();
    poly.len() >= 3
        && edges().all(|(a, b)| {
            let edge = *b - *a;
            area.signum() * edge.perp_dot(p - *a) / edge.length().max(f32::MIN_POSITIVE)
                >= -tolerance
        })
}

/// Every pixel centre's traced mirror sequence is a kept path whose portal holds the pixel:
/// no path the rasterizer needs is missing.
#[test]
fn every_traced_mirror_sequence_is_a_kept_path() {
    let s = bare_room(64, 36);
    let set = paths(&s);
    let (bvh, settings) = whitted_for(&s);
    let whitted = Whitted::new(&s, &bvh, settings);
    let mut checked = 0;
    for y in 0..s.camera.height {
        for x in 0..s.camera.width {
            let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let seen = traced_mirrors(&s, &whitted, centre);
            let found = set.paths.iter().find(|p| p.mirrors == seen);
            let Some(path) = found else {
                panic!("pixel ({x}, {y}) meets mirrors {seen:?}, which no kept path follows");
            };
            // Its portal holds the pixel centre, within a hundredth of a pixel (the
            // portal's corners are projected in f32).
            assert!(
                path.mirrors.is_empty() || holds(&path.portal, centre, 0.01),
                "pixel ({x}, {y}): the path {seen:?}'s portal {:?} does not hold it",
                path.portal
            );
            checked += usize::from(!seen.is_empty());
        }
    }
    assert!(checked > 1000, "most pixels see a mirror: {checked}");
}

/// The ray through a point well inside a kept path's portal meets that path's mirrors first.
#[test]
fn the_ray_through_a_portal_follows_its_path() {
    let s = bare_room(160, 90);
    let set = paths(&s);
    let (bvh, settings) = whitted_for(&s);
    let whitted = Whitted::new(&s, &bvh, settings);
    let mut checked = 0;
    for p in set.paths.iter().skip(1) {
        if area(&p.portal) < 4.0 {
            continue; // its centroid may lie within rounding of an edge
        }
        let centroid = p.portal.iter().copied().sum::<Vec2>() / p.portal.len() as f32;
        let seen = traced_mirrors(&s, &whitted, centroid);
        assert!(
            seen.starts_with(&p.mirrors),
            "portal of {:?} (centroid {centroid}) traced as {seen:?}",
            p.mirrors
        );
        checked += 1;
    }
    assert!(checked > 50, "{checked} paths checked");
}

/// Signed distance (pixels) of `c` inside convex polygon `poly`: positive inside.
fn inside_by(poly: &[Vec2], c: Vec2) -> f32 {
    let o = mirrorbox_scene::polygon::orientation(poly);
    (0..poly.len())
        .map(|k| {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            o * (b - a).normalize().perp_dot(c - a)
        })
        .fold(f32::INFINITY, f32::min)
}

/// Where a nearer mirror hides part of a sibling's portal (a small mirror before a large one,
/// and one tilted across it), the visible regions partition the pixel centres by the mirrors
/// the traced ray meets: a centre well inside (0.01 px) a path's visible piece meets that
/// path's mirrors first, and every centre's traced sequence is a kept path whose visible
/// region holds it (up to 0.01 px).
#[test]
fn visible_regions_follow_the_traced_mirrors_where_siblings_overlap() {
    let text = serde_json::json!({
        "camera": { "position": [0.1, 1.2, 3], "look_at": [0, 1.2, -2], "fov_y_deg": 50, "width": 96, "height": 54 },
        "mirrors": [ { "center": [0, 1.5, -2], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 4, "height": 3 },
                     { "center": [0, 1.2, -0.5], "normal": [0, 1, 1], "up": [0, 1, -1], "width": 0.9, "height": 0.9 },
                     { "center": [0.9, 1.0, -1.0], "normal": [-0.6, 0, 1], "up": [0, 1, 0], "width": 0.8, "height": 1.2 } ]
    });
    let s = parse_scene(&text.to_string(), Path::new("overlap.json")).unwrap();
    let set = paths(&s);
    assert!(set.partly_hidden > 0, "the scene has overlapping siblings");
    let (bvh, settings) = whitted_for(&s);
    let whitted = Whitted::new(&s, &bvh, settings);
    let mut checked = 0;
    for y in 0..s.camera.height {
        for x in 0..s.camera.width {
            let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let seen = traced_mirrors(&s, &whitted, centre);
            for p in &set.paths[1..] {
                let depth = p.visible.iter().map(|piece| inside_by(piece, centre));
                let depth = depth.fold(f32::NEG_INFINITY, f32::max);
                if depth > 0.01 {
                    assert!(
                        seen.starts_with(&p.mirrors),
                        "pixel ({x}, {y}) lies in the visible region of {:?} but meets {seen:?}",
                        p.mirrors
                    );
                    checked += 1;
                }
                if p.mirrors == seen {
                    assert!(
                        depth >= -0.01,
                        "pixel ({x}, {y}) meets {seen:?} outside its visible region"
                    );
                }
            }
            if !seen.is_empty() {
                assert!(
                    set.paths.iter().any(|p| p.mirrors == seen),
                    "pixel ({x}, {y}): {seen:?}"
                );
            }
        }
    }
    assert!(checked > 500, "{checked} centres checked");
}
