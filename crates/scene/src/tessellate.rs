//! Shapes turned into triangles, in object space, counter-clockwise seen from outside.
//! Tessellation happens once, at load; both renderers get the same triangles.

use glam::Vec3;

/// An axis-aligned box centred at the origin with edge lengths `size`: 12 triangles.
pub fn cuboid(size: Vec3) -> Vec<[Vec3; 3]> {
    let h = size * 0.5;
    // For each face: outward axis, and two in-plane axes (u, v) with u × v = outward.
    let faces = [
        (Vec3::X, Vec3::Y, Vec3::Z),
        (Vec3::NEG_X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::Z, Vec3::X),
        (Vec3::NEG_Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (Vec3::NEG_Z, Vec3::Y, Vec3::X),
    ];
    let mut tris = Vec::with_capacity(12);
    for (n, u, v) in faces {
        let c = n * h;
        let (u, v) = (u * h, v * h);
        let q = [c - u - v, c + u - v, c + u + v, c - u + v];
        tris.push([q[0], q[1], q[2]]);
        tris.push([q[0], q[2], q[3]]);
    }
    tris
}

/// A `width × height` rectangle in the xy plane centred at the origin, facing +z (the
/// orientation of Mitsuba's `rectangle`): 2 triangles.
pub fn quad(width: f32, height: f32) -> Vec<[Vec3; 3]> {
    let (x, y) = (0.5 * width, 0.5 * height);
    let q = [
        Vec3::new(-x, -y, 0.0),
        Vec3::new(x, -y, 0.0),
        Vec3::new(x, y, 0.0),
        Vec3::new(-x, y, 0.0),
    ];
    vec![[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
}

/// Highest sphere subdivision level accepted (20·4⁷ = 327 680 triangles).
pub const MAX_SPHERE_SUBDIVISIONS: u32 = 7;

/// An icosphere of `radius`: the icosahedron with each triangle split into four
/// `subdivisions` times, new vertices pushed onto the sphere; 20·4^subdivisions triangles.
pub fn icosphere(radius: f32, subdivisions: u32) -> Vec<[Vec3; 3]> {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let v = [
        Vec3::new(-1.0, t, 0.0),
        Vec3::new(1.0, t, 0.0),
        Vec3::new(-1.0, -t, 0.0),
        Vec3::new(1.0, -t, 0.0),
        Vec3::new(0.0, -1.0, t),
        Vec3::new(0.0, 1.0, t),
        Vec3::new(0.0, -1.0, -t),
        Vec3::new(0.0, 1.0, -t),
        Vec3::new(t, 0.0, -1.0),
        Vec3::new(t, 0.0, 1.0),
        Vec3::new(-t, 0.0, -1.0),
        Vec3::new(-t, 0.0, 1.0),
    ]
    .map(Vec3::normalize);
    const FACES: [[usize; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut tris: Vec<[Vec3; 3]> = FACES.iter().map(|f| f.map(|i| v[i])).collect();
    for _ in 0..subdivisions {
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let ab = (a + b).normalize();
            let bc = (b + c).normalize();
            let ca = (c + a).normalize();
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        tris = next;
    }
    for t in &mut tris {
        *t = t.map(|p| p * radius);
    }
    tris
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Signed volume by the divergence theorem: positive iff every face winds outward.
    fn signed_volume(tris: &[[Vec3; 3]]) -> f32 {
        tris.iter().map(|[a, b, c]| a.dot(b.cross(*c)) / 6.0).sum()
    }

    #[test]
    fn cuboid_is_closed_outward_and_has_the_right_volume() {
        let t = cuboid(Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(t.len(), 12);
        assert!((signed_volume(&t) - 6.0).abs() < 1e-5);
        for [a, b, c] in &t {
            let n = (*b - *a).cross(*c - *a).normalize();
            let centroid = (*a + *b + *c) / 3.0;
            assert!(n.dot(centroid) > 0.0, "face wound inward");
        }
    }

    #[test]
    fn icosphere_counts_and_volume_converge() {
        for s in 0..4 {
            let t = icosphere(2.0, s);
            assert_eq!(t.len(), 20 * 4usize.pow(s));
            for p in t.iter().flatten() {
                assert!((p.length() - 2.0).abs() < 1e-5);
            }
            assert!(signed_volume(&t) > 0.0);
        }
        let v = signed_volume(&icosphere(1.0, 5));
        let exact = 4.0 / 3.0 * std::f32::consts::PI;
        assert!((v - exact).abs() / exact < 2e-3, "volume {v}");
    }

    #[test]
    fn quad_faces_plus_z() {
        for [a, b, c] in quad(2.0, 1.0) {
            assert_eq!((b - a).cross(c - a).normalize(), Vec3::Z);
        }
    }
}
