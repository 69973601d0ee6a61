//! Convex polygon clipping (Sutherland–Hodgman), shared by the raster methods: which part of
//! a mirror a camera can see, and where on screen (its footprint).

use glam::{Vec2, Vec3, Vec4};

/// Keeps the part of convex polygon `poly` where `distance(p) ≥ 0` (one clipping plane), in
/// the precision of the distances (`f32`, or `f64` where far light images need it).
pub fn clip_by<P, S>(poly: &[P], distance: impl Fn(P) -> S) -> Vec<P>
where
    P: Copy + std::ops::Add<Output = P> + std::ops::Sub<Output = P> + std::ops::Mul<S, Output = P>,
    S: Copy + Default + PartialOrd + std::ops::Sub<Output = S> + std::ops::Div<Output = S>,
{
    let zero = S::default();
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        let (da, db) = (distance(a), distance(b));
        if da >= zero {
            out.push(a);
        }
        if (da >= zero) != (db >= zero) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

/// Clips a world-space polygon, transformed by `clip_from_world`, to the view volume
/// `−w ≤ x, y ≤ w`, `0 ≤ z ≤ w` (WebGPU clip space) and returns the visible part's vertices in
/// continuous image coordinates (pixel convention of [`crate::camera`]) for an image of
/// `size` pixels. Empty when nothing is visible.
pub fn screen_footprint(world: &[Vec3], clip_from_world: glam::Mat4, size: Vec2) -> Vec<Vec2> {
    let mut poly: Vec<Vec4> = world
        .iter()
        .map(|p| clip_from_world * p.extend(1.0))
        .collect();
    let planes: [fn(Vec4) -> f32; 6] = [
        |c| c.w + c.x,
        |c| c.w - c.x,
        |c| c.w + c.y,
        |c| c.w - c.y,
        |c| c.z,
        |c| c.w - c.z,
    ];
    for plane in planes {
        if poly.is_empty() {
            break;
        }
        poly = clip_by(&poly, plane);
    }
    poly.iter()
        .filter(|c| c.w > 0.0)
        .map(|c| crate::camera::ndc_to_pixel(Vec2::new(c.x / c.w, c.y / c.w), size))
        .collect()
}

/// Twice the signed area (shoelace): positive for counter-clockwise in a y-up frame.
fn twice_signed_area(poly: &[Vec2]) -> f32 {
    (0..poly.len())
        .map(|i| poly[i].perp_dot(poly[(i + 1) % poly.len()]))
        .sum()
}

/// Area of a polygon by the shoelace formula (absolute value).
pub fn area(poly: &[Vec2]) -> f32 {
    0.5 * twice_signed_area(poly).abs()
}

/// +1 or −1 by the polygon's winding (the sign of its signed area): multiplying an edge's
/// `(b − a) × (p − a)` by it makes the inside positive whatever the orientation.
pub fn orientation(poly: &[Vec2]) -> f32 {
    twice_signed_area(poly).signum()
}

/// The bounding rectangle (min, max) of a polygon.
pub fn bounds(poly: &[Vec2]) -> (Vec2, Vec2) {
    poly.iter().fold(
        (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
        |(a, b), q| (a.min(*q), b.max(*q)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_a_square_in_half() {
        let square = [
            Vec2::new(0.0, 0.0),
            Vec2::new(2.0, 0.0),
            Vec2::new(2.0, 2.0),
            Vec2::new(0.0, 2.0),
        ];
        let half = clip_by(&square, |p| 1.0 - p.x);
        assert!((area(&half) - 2.0).abs() < 1e-6);
        assert!(clip_by(&square, |p| -1.0 - p.x).is_empty());
        assert_eq!(clip_by(&square, |p| p.x + 5.0).len(), 4);
    }

    #[test]
    fn footprint_of_a_quad_in_front_and_behind() {
        let cam = crate::Camera {
            position: Vec3::new(0.0, 0.0, 5.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 90.0,
            width: 100,
            height: 100,
            exposure: 1.0,
            shift_x: 0.0,
        };
        let m = cam.projection(0.1, 100.0) * cam.view();
        // A 2×2 quad at distance 5 with a 90° field of view spans 2/10 of the image height.
        let quad = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ];
        let fp = screen_footprint(&quad, m, Vec2::splat(100.0));
        assert!((area(&fp) - 400.0).abs() < 0.1, "{}", area(&fp));
        // Behind the camera: nothing.
        let behind: Vec<Vec3> = quad.iter().map(|p| *p + Vec3::Z * 10.0).collect();
        assert!(screen_footprint(&behind, m, Vec2::splat(100.0)).is_empty());
        // Much larger than the view: clipped to the whole image.
        let big: Vec<Vec3> = quad.iter().map(|p| *p * 100.0).collect();
        assert!((area(&screen_footprint(&big, m, Vec2::splat(100.0))) - 10000.0).abs() < 1.0);
    }
}
