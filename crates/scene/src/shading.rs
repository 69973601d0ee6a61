//! The shading contract (`docs/shading.md`), implemented once on the CPU. The tracer calls
//! it directly and the WGSL shaders are tested against it.
//!
//! Radiance is linear RGB. A diffuse surface seen from direction `ω_o` returns
//!
//! `L = E·[front] + ρ/π · Σᵢ Iᵢ·max(0, n·lᵢ)/rᵢ² + ρ·A`
//!
//! with `n` the face normal turned towards the viewer (diffuse is two-sided), `E` the
//! emission (front side only), `ρ` the albedo, `Iᵢ` the point lights' intensities (W/sr) at
//! distance `rᵢ` in unit direction `lᵢ`, and `A` the ambient term. There are no shadows. A
//! mirror's front returns its reflectance times the radiance along the reflected ray.

use crate::geometry::Surface;
use glam::Vec3;

/// An isotropic point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    pub position: Vec3,
    /// Radiant intensity per channel, W/sr.
    pub intensity: Vec3,
}

/// Everything that lights a diffuse surface.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lighting {
    pub lights: Vec<PointLight>,
    pub ambient: Vec3,
}

/// Squared distance below which a light is considered to touch the surface and ignored
/// (its 1/r² would be unbounded).
pub const MIN_LIGHT_DISTANCE_SQUARED: f32 = 1e-8;

impl Lighting {
    /// Radiance leaving a diffuse point `p` towards the viewer.
    ///
    /// `face_normal` is the triangle's front normal, `to_viewer` the unit direction from `p`
    /// back towards the viewer (−ray direction).
    pub fn diffuse_radiance(
        &self,
        p: Vec3,
        face_normal: Vec3,
        to_viewer: Vec3,
        albedo: Vec3,
        emission: Vec3,
    ) -> Vec3 {
        let front = face_normal.dot(to_viewer) >= 0.0;
        let n = if front { face_normal } else { -face_normal };
        let mut irradiance = Vec3::ZERO;
        for light in &self.lights {
            let to_light = light.position - p;
            let r2 = to_light.length_squared();
            if r2 < MIN_LIGHT_DISTANCE_SQUARED {
                continue;
            }
            let cos = n.dot(to_light) / r2.sqrt();
            if cos > 0.0 {
                irradiance += light.intensity * (cos / r2);
            }
        }
        let emitted = if front { emission } else { Vec3::ZERO };
        emitted + albedo * (irradiance * std::f32::consts::FRAC_1_PI + self.ambient)
    }
}

/// What happens where a ray meets a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Interaction {
    /// Shade with [`Lighting::diffuse_radiance`].
    Diffuse { albedo: Vec3, emission: Vec3 },
    /// Follow the perfect reflection, multiplying by `reflectance`.
    Reflect { reflectance: Vec3 },
}

/// The contract's rule for each surface: a mirror reflects on its front side only and is a
/// plain diffuse surface (no emission) on its back side.
pub fn interaction(surface: &Surface, front_facing: bool) -> Interaction {
    match *surface {
        Surface::Diffuse { albedo, emission } => Interaction::Diffuse { albedo, emission },
        Surface::Mirror { reflectance, .. } if front_facing => Interaction::Reflect { reflectance },
        Surface::Mirror { back_albedo, .. } => Interaction::Diffuse {
            albedo: back_albedo,
            emission: Vec3::ZERO,
        },
    }
}

/// Perfect specular reflection of direction `d` about unit normal `n`: `d − 2(d·n)n`.
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * d.dot(n) * n
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    fn one_light(position: Vec3, intensity: f32) -> Lighting {
        Lighting {
            lights: vec![PointLight {
                position,
                intensity: Vec3::splat(intensity),
            }],
            ambient: Vec3::ZERO,
        }
    }

    #[test]
    fn lambert_with_inverse_square_falloff() {
        // Light 2 units straight above: E = I/r² = 10/4; L = ρ/π·E.
        let l = one_light(Vec3::new(0.0, 2.0, 0.0), 10.0);
        let rho = Vec3::new(0.5, 0.25, 1.0);
        let out = l.diffuse_radiance(Vec3::ZERO, Vec3::Y, Vec3::Y, rho, Vec3::ZERO);
        assert!(out.abs_diff_eq(rho * (2.5 / PI), 1e-6));
        // At 60° incidence the cosine halves it.
        let p = Vec3::new(-2.0 * 3f32.sqrt(), 0.0, 0.0); // light at distance 4, 60° off normal
        let out = l.diffuse_radiance(p, Vec3::Y, Vec3::Y, rho, Vec3::ZERO);
        assert!(
            out.abs_diff_eq(rho * (10.0 * 0.5 / 16.0 / PI), 1e-6),
            "{out}"
        );
    }

    #[test]
    fn two_sided_diffuse_but_one_sided_emission() {
        let mut l = one_light(Vec3::new(0.0, -1.0, 0.0), 1.0);
        l.ambient = Vec3::splat(0.1);
        let e = Vec3::splat(3.0);
        let rho = Vec3::splat(0.5);
        // Viewer and light below a surface whose front faces up: lit as the back, no emission.
        let below = l.diffuse_radiance(Vec3::ZERO, Vec3::Y, -Vec3::Y, rho, e);
        assert!(below.abs_diff_eq(rho * (1.0 / PI + 0.1), 1e-6));
        // Viewer above, light below: only emission and ambient.
        let above = l.diffuse_radiance(Vec3::ZERO, Vec3::Y, Vec3::Y, rho, e);
        assert!(above.abs_diff_eq(e + rho * 0.1, 1e-6));
    }

    #[test]
    fn mirror_back_is_diffuse() {
        let s = Surface::Mirror {
            mirror: 0,
            reflectance: Vec3::splat(0.9),
            back_albedo: Vec3::splat(0.2),
        };
        assert_eq!(
            interaction(&s, true),
            Interaction::Reflect {
                reflectance: Vec3::splat(0.9)
            }
        );
        assert_eq!(
            interaction(&s, false),
            Interaction::Diffuse {
                albedo: Vec3::splat(0.2),
                emission: Vec3::ZERO
            }
        );
    }

    #[test]
    fn reflection_of_a_direction() {
        let d = Vec3::new(1.0, -1.0, 0.0).normalize();
        assert!(reflect(d, Vec3::Y).abs_diff_eq(Vec3::new(1.0, 1.0, 0.0).normalize(), 1e-6));
    }
}
