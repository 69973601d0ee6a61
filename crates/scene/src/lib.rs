//! The scene model of mirrorbox and the math both renderers share.
//!
//! Data flows one way: a JSON scene file is parsed ([`format`]), checked and compiled
//! ([`load`]) into a [`Scene`], whose [`Scene::geometry`] is the *one* triangle list that both
//! the wgpu rasterizer and the obvhs tracer consume. The camera model ([`camera`]), plane
//! reflections and mirror cameras ([`reflection`]) and the shading contract ([`shading`]) are
//! implemented here once, so that an image difference between the renderers can only come
//! from the method being measured.
//!
//! Conventions (see `docs/scene-format.md` and `docs/shading.md`): right-handed world, y up,
//! lengths in scene units, angles in degrees in files and radians in code, linear RGB.

pub mod camera;
pub mod error;
pub mod format;
pub mod geometry;
pub mod load;
pub mod reflection;
pub mod shading;
pub mod tessellate;

pub use camera::{Camera, Ray, SubpixelGrid};
pub use error::SceneError;
pub use geometry::{Geometry, Surface, SurfaceId};
pub use load::load_scene;
pub use reflection::Plane;
pub use shading::{Lighting, PointLight};

use glam::Vec3;

/// A planar, rectangular, one-sided mirror (validated; `normal` and `up` are unit and
/// orthogonal). Its front side (towards `normal`) reflects `reflectance` of the incoming
/// radiance; its back side is a plain diffuse surface of albedo `back_albedo`.
#[derive(Clone, Debug, PartialEq)]
pub struct Mirror {
    pub name: String,
    pub center: Vec3,
    pub normal: Vec3,
    pub up: Vec3,
    pub width: f32,
    pub height: f32,
    pub reflectance: Vec3,
    pub back_albedo: Vec3,
}

impl Mirror {
    /// Unit vector along the mirror's width: `right = up × normal`, so that
    /// (right, up, normal) is a right-handed frame and the front face winds counter-clockwise.
    pub fn right(&self) -> Vec3 {
        self.up.cross(self.normal)
    }

    /// Corners counter-clockwise as seen from the front: bottom-left, bottom-right,
    /// top-right, top-left.
    pub fn corners(&self) -> [Vec3; 4] {
        let r = self.right() * (0.5 * self.width);
        let u = self.up * (0.5 * self.height);
        let c = self.center;
        [c - r - u, c + r - u, c + r + u, c - r + u]
    }

    /// The mirror's plane, oriented so that the front side has positive signed distance.
    pub fn plane(&self) -> Plane {
        Plane::from_point_normal(self.center, self.normal)
    }
}

/// A validated scene: what a scene file describes, with every number checked.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Where the scene was loaded from (used in messages and reports).
    pub source: std::path::PathBuf,
    pub camera: Camera,
    pub mirrors: Vec<Mirror>,
    pub lighting: Lighting,
    /// Radiance of a ray that leaves the scene.
    pub background: Vec3,
    /// Radiance a method shows on a mirror it can no longer follow (beyond its depth).
    pub terminal: Vec3,
    /// All triangles (objects and mirrors) with their surfaces: the single geometry both
    /// renderers consume.
    pub geometry: Geometry,
}

impl Scene {
    /// Replaces every mirror's reflectance (the harness sets it to the α being measured),
    /// keeping [`Scene::geometry`]'s surfaces in step.
    pub fn set_reflectance(&mut self, reflectance: Vec3) {
        for m in &mut self.mirrors {
            m.reflectance = reflectance;
        }
        self.geometry.set_mirror_reflectance(reflectance);
    }
}
