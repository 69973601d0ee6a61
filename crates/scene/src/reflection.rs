//! Plane reflections and reflected ("mirror") cameras.
//!
//! Seed 001 reflects a vertex `v` through the plane with point `o` and unit normal `n`:
//! `m = v − 2n(n·(v − o))`. As a 4×4 affine matrix that is
//! `R = [[I − 2nnᵀ, 2(n·o)n], [0, 1]]`: an involution (`R·R = I`) with determinant −1, so it
//! flips handedness — triangle winding reverses after an odd number of reflections.
//!
//! Seed 002's mirror camera is the camera reflected in the mirror plane; rendering the world
//! through `view · R` shows exactly what the real camera sees in the mirror (the image is
//! not flipped, the winding is). Reflections compose on the right: looking through mirror 1
//! and then (in it) mirror 2 is `view · R₁ · R₂`.

use glam::{DMat3, DMat4, Mat4, Vec3, Vec4};

/// An oriented plane `{x : normal·x = offset}`; the front side has positive signed distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub normal: Vec3,
    pub offset: f32,
}

impl Plane {
    /// The plane through `point` with normal `normal` (normalized here; must be non-zero).
    pub fn from_point_normal(point: Vec3, normal: Vec3) -> Plane {
        let normal = normal.normalize();
        Plane {
            normal,
            offset: normal.dot(point),
        }
    }

    pub fn signed_distance(&self, p: Vec3) -> f32 {
        self.normal.dot(p) - self.offset
    }

    /// `m = p − 2n(n·p − offset)` (seed 001).
    pub fn reflect_point(&self, p: Vec3) -> Vec3 {
        p - 2.0 * self.signed_distance(p) * self.normal
    }

    /// Reflection of a direction (or normal): `v − 2n(n·v)`.
    pub fn reflect_vector(&self, v: Vec3) -> Vec3 {
        v - 2.0 * self.normal.dot(v) * self.normal
    }

    /// The reflection as an affine matrix `[[I − 2nnᵀ, 2·offset·n], [0, 1]]`.
    pub fn reflection_matrix(&self) -> Mat4 {
        self.reflection_matrix_f64().as_mat4()
    }

    /// [`Plane::reflection_matrix`] in f64, for composing long chains of reflections without
    /// accumulating rounding (a 1000-reflection view stays exact to f64).
    pub fn reflection_matrix_f64(&self) -> DMat4 {
        let n = self.normal.as_dvec3();
        let linear = DMat3::IDENTITY - 2.0 * DMat3::from_cols(n * n.x, n * n.y, n * n.z);
        let mut m = DMat4::from_mat3(linear);
        m.w_axis = (2.0 * self.offset as f64 * n).extend(1.0);
        m
    }

    /// Plane coefficients `(n, −offset)`: `dot(coeffs, (p, 1))` is the signed distance.
    pub fn coefficients(&self) -> Vec4 {
        self.normal.extend(-self.offset)
    }

    /// The same plane, facing the other way.
    pub fn flipped(&self) -> Plane {
        Plane {
            normal: -self.normal,
            offset: -self.offset,
        }
    }

    /// Coefficients of this (world-space) plane in the space of `transform` (e.g. a view
    /// matrix): a plane transforms with the inverse transpose, `C' = (M⁻¹)ᵀ C`.
    pub fn coefficients_in(&self, transform: Mat4) -> Vec4 {
        transform.inverse().transpose() * self.coefficients()
    }
}

/// A view through zero or more mirrors: the real camera's view matrix composed with the
/// reflections of the mirrors it looks through, first mirror first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReflectedView {
    /// World → view transform: `view · R₁ · … · Rₖ`.
    pub view: Mat4,
    /// Number of reflections composed so far.
    pub depth: u32,
}

impl ReflectedView {
    pub fn direct(view: Mat4) -> Self {
        ReflectedView { view, depth: 0 }
    }

    /// Looks further through a mirror lying in `plane` (a world-space plane of the scene,
    /// as it is; the composition takes care of where the previous mirrors show it).
    pub fn through(&self, plane: &Plane) -> Self {
        ReflectedView {
            view: self.view * plane.reflection_matrix(),
            depth: self.depth + 1,
        }
    }

    /// True when an odd number of reflections reversed the triangle winding.
    pub fn flips_winding(&self) -> bool {
        self.depth % 2 == 1
    }

    /// The virtual eye in world space: where the mirror camera sits behind the mirrors.
    pub fn eye(&self) -> Vec3 {
        self.view.inverse().transform_point3(Vec3::ZERO)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;

    fn planes() -> Vec<Plane> {
        vec![
            Plane::from_point_normal(Vec3::new(0.0, 0.0, -2.0), Vec3::Z),
            Plane::from_point_normal(Vec3::new(0.0, 1.5, 2.0), Vec3::new(0.0349, 0.0, -0.9994)),
            Plane::from_point_normal(Vec3::new(1.0, -2.0, 3.0), Vec3::new(1.0, 2.0, -0.5)),
        ]
    }

    #[test]
    fn reflection_is_an_involution_with_determinant_minus_one_fixing_the_plane() {
        for plane in planes() {
            let r = plane.reflection_matrix();
            assert!(
                (r * r).abs_diff_eq(Mat4::IDENTITY, 1e-5),
                "R·R ≠ I for {plane:?}"
            );
            assert!((r.determinant() + 1.0).abs() < 1e-5);
            // Points of the plane are fixed.
            let t = plane.normal.any_orthonormal_vector();
            let b = plane.normal.cross(t);
            for (u, v) in [(0.0, 0.0), (1.5, -2.0), (-7.0, 3.25)] {
                let p = plane.normal * plane.offset + t * u + b * v;
                assert!(r.transform_point3(p).abs_diff_eq(p, 1e-5));
            }
            // Matrix and formula agree; the normal direction is negated.
            let q = Vec3::new(0.3, -1.2, 4.0);
            assert!(
                r.transform_point3(q)
                    .abs_diff_eq(plane.reflect_point(q), 1e-5)
            );
            assert!(
                (plane.signed_distance(plane.reflect_point(q)) + plane.signed_distance(q)).abs()
                    < 1e-5
            );
            assert!(
                plane
                    .reflect_vector(plane.normal)
                    .abs_diff_eq(-plane.normal, 1e-6)
            );
        }
    }

    fn camera() -> Camera {
        Camera {
            position: Vec3::new(0.6, 1.6, 1.5),
            look_at: Vec3::new(-0.3, 1.3, -2.0),
            up: Vec3::Y,
            fov_y_deg: 60.0,
            width: 80,
            height: 60,
            exposure: 1.0,
            shift_x: 0.0,
        }
    }

    /// The defining property of the mirror camera: a point seen in the mirror (real camera
    /// ray → mirror → reflected ray → point) projects, through `view · R`, to the pixel of
    /// that ray.
    #[test]
    fn mirror_camera_sees_reflected_points_at_the_pixel_of_the_real_ray() {
        let cam = camera();
        let mirror = Plane::from_point_normal(Vec3::new(0.0, 0.0, -2.0), Vec3::Z);
        let through = ReflectedView::direct(cam.view()).through(&mirror);
        assert!(through.flips_winding());
        let eye = mirror.reflect_point(cam.position);
        assert!(through.eye().abs_diff_eq(eye, 1e-4));
        let proj = cam.projection(0.01, 100.0);
        for (px, py) in [(40.0, 30.0), (10.5, 50.25), (70.0, 5.0)] {
            let ray = cam.primary_ray(px, py);
            let t = -mirror.signed_distance(ray.origin) / mirror.normal.dot(ray.dir);
            assert!(t > 0.0);
            let hit = ray.at(t);
            let reflected_dir = mirror.reflect_vector(ray.dir);
            let p = hit + reflected_dir * 2.5;
            let clip = proj * through.view * p.extend(1.0);
            let ndc = clip.truncate().truncate() / clip.w;
            let pixel = crate::camera::ndc_to_pixel(ndc, cam.size());
            assert!(pixel.abs_diff_eq(glam::Vec2::new(px, py), 1e-3), "{pixel}");
        }
    }

    #[test]
    fn two_reflections_restore_winding_and_compose_in_order() {
        let cam = camera();
        let m1 = Plane::from_point_normal(Vec3::new(0.0, 0.0, -2.0), Vec3::Z);
        let m2 = Plane::from_point_normal(Vec3::new(0.0, 0.0, 2.0), -Vec3::Z);
        let v = ReflectedView::direct(cam.view()).through(&m1).through(&m2);
        assert!(!v.flips_winding());
        // The view shows p where R₁(R₂(p)) is: p mirrored in M₂, and that picture in M₁.
        let p = Vec3::new(0.3, 0.7, 0.5);
        let shown = m1.reflect_point(m2.reflect_point(p));
        assert!(
            v.view
                .transform_point3(p)
                .abs_diff_eq(cam.view().transform_point3(shown), 1e-4)
        );
        // Two parallel mirrors 4 apart compose to a translation by 2·4 = 8 (from M₁ to M₂):
        // the virtual eye is R₂(R₁(eye)).
        let eye = v.eye();
        assert!(eye.abs_diff_eq(cam.position + Vec3::Z * 8.0, 1e-4), "{eye}");
    }
}
