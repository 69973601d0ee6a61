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

pub mod bump;
pub mod camera;
pub mod camera_path;
pub mod error;
pub mod format;
pub mod geometry;
pub mod gltf_asset;
pub mod gltf_export;
pub mod hash;
pub mod import;
pub mod lanes;
pub mod light_images;
pub mod limits;
pub mod load;
pub mod polygon;
pub mod reflection;
pub mod reflection_paths;
pub mod shading;
pub mod stereo;
pub mod symmetry;
pub mod tessellate;
pub mod texture;

pub use camera::{Camera, Ray, SubpixelGrid};
pub use error::SceneError;
pub use geometry::{Geometry, Surface, SurfaceId};
pub use load::load_scene;
pub use reflection::Plane;
pub use shading::{Lighting, PointLight};
pub use symmetry::{Symmetry, SymmetryPlane};

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

    /// The mirror's plane in f64: unit normal `n` and offset `n·center` (plane-exact deep
    /// bounces and far light images).
    pub fn plane_f64(&self) -> (glam::DVec3, f64) {
        let n = self.normal.as_dvec3().normalize();
        (n, n.dot(self.center.as_dvec3()))
    }

    /// The mirror's plane, oriented so that the front side has positive signed distance.
    pub fn plane(&self) -> Plane {
        Plane::from_point_normal(self.center, self.normal)
    }

    /// Whether the mirror lies in `plane` (every corner within 1e-5 scene units of it): a
    /// pass through that plane's mirror does not draw it, it is the portal itself.
    pub fn lies_in(&self, plane: &Plane) -> bool {
        self.corners()
            .iter()
            .all(|c| plane.signed_distance(*c).abs() < 1e-5)
    }
}

/// A validated scene: what a scene file describes, with every number checked.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Where the scene was loaded from (used in messages and reports).
    pub source: std::path::PathBuf,
    pub camera: Camera,
    pub mirrors: Vec<Mirror>,
    /// The camera's stereo rig (`camera.stereo`), if any: [`Scene::eye`] gives each eye.
    pub stereo: Option<stereo::Stereo>,
    /// Keyframes of a moving camera (`camera.path`), if any: [`Scene::at_time`] places the
    /// camera on it. `camera` stays the file's still view.
    pub camera_path: Option<camera_path::CameraPath>,
    /// In one eye's scene ([`Scene::eye`]): the head's camera, which a method sharing its
    /// mirrors between the eyes renders them from (`--stereo-mirrors shared`).
    pub head: Option<Camera>,
    /// Per mirror, its uneven shading normal ([`bump`]); `None`: flat.
    pub bumps: Vec<Option<bump::MirrorBump>>,
    pub lighting: Lighting,
    /// Radiance of a ray that leaves the scene.
    pub background: Vec3,
    /// Radiance a method shows on a mirror it can no longer follow (beyond its depth).
    pub terminal: Vec3,
    /// All triangles (objects and mirrors) with their surfaces: the single geometry both
    /// renderers consume. With symmetry planes, the objects here are already split and
    /// mirrored ([`symmetry::split_and_mirror`]); the mirrors follow them, untouched.
    pub geometry: Geometry,
    /// Seed 001's symmetry planes and the objects before them; `None` when the file has no
    /// `symmetry_planes` (or an empty list).
    pub symmetry: Option<Symmetry>,
}

impl Scene {
    /// The same scene with its mirrors removed (their triangles included): what every method
    /// renders identically, so comparing raster and trace on it measures the floor of the
    /// comparison — rasterization and arithmetic, no mirror effect.
    pub fn without_mirrors(&self) -> Scene {
        let mut geometry = self.geometry.empty_like();
        for part in &self.geometry.parts {
            let surface = &self.geometry.surfaces[part.surface as usize];
            if matches!(surface, Surface::Diffuse { .. }) {
                geometry.push_textured_part(
                    part.name.clone(),
                    surface.clone(),
                    self.geometry.triangles[part.triangles.clone()].to_vec(),
                    self.geometry.uvs[part.triangles.clone()].to_vec(),
                );
            }
        }
        let mut lighting = self.lighting.clone();
        // No mirror, no light image (their beams would still light points).
        lighting.images = light_images::LightImages {
            min_throughput: lighting.images.min_throughput,
            ..Default::default()
        };
        Scene {
            mirrors: Vec::new(),
            bumps: Vec::new(),
            geometry,
            lighting,
            ..self.clone()
        }
    }

    /// Overrides the camera's image size (`--width`, `--height`), each side and the area
    /// checked as everywhere else ([`limits::image_size`]).
    pub fn resize(
        &mut self,
        width: Option<u32>,
        height: Option<u32>,
    ) -> Result<(), limits::SettingError> {
        // The camera's own size is valid, so any error names the flag that was given.
        let (w, h) = limits::image_size(
            width.unwrap_or(self.camera.width),
            height.unwrap_or(self.camera.height),
        )?;
        self.camera = self.camera.with_size(w, h);
        Ok(())
    }

    /// The same scene keeping only its first `planes` symmetry planes, the objects baked again
    /// (`planes = 0` gives the scene without symmetry, `symmetry: None`). The mirrors, their
    /// current reflectance and everything else are kept. A sweep over p uses it.
    pub fn with_symmetry_planes(&self, planes: usize) -> Result<Scene, symmetry::SymmetryError> {
        let have = self.symmetry.as_ref().map_or(0, |s| s.planes.len());
        if planes > have {
            return Err(symmetry::SymmetryError::NotThatManyPlanes {
                asked: planes,
                have,
            });
        }
        let Some(sym) = &self.symmetry else {
            return Ok(self.clone());
        };
        let kept = &sym.planes[..planes];
        let mirror_parts: Vec<_> = self
            .geometry
            .parts
            .iter()
            .filter(|part| {
                matches!(
                    self.geometry.surfaces[part.surface as usize],
                    Surface::Mirror { .. }
                )
            })
            .collect();
        let mirror_triangles: usize = mirror_parts.iter().map(|p| p.triangles.len()).sum();
        let plane_list: Vec<Plane> = kept.iter().map(|p| p.plane).collect();
        let mut geometry = symmetry::split_and_mirror(
            &sym.source,
            &plane_list,
            limits::MAX_TRIANGLES.saturating_sub(mirror_triangles),
        )?;
        for part in mirror_parts {
            geometry.push_part(
                part.name.clone(),
                self.geometry.surfaces[part.surface as usize].clone(),
                self.geometry.triangles[part.triangles.clone()].to_vec(),
            );
        }
        geometry.degenerate_dropped = self.geometry.degenerate_dropped;
        geometry.obj_notes = self.geometry.obj_notes.clone();
        Ok(Scene {
            geometry,
            symmetry: (planes > 0).then(|| Symmetry {
                planes: kept.to_vec(),
                source: sym.source.clone(),
            }),
            ..self.clone()
        })
    }

    /// Replaces every mirror's reflectance (the harness sets it to the α being measured),
    /// keeping [`Scene::geometry`]'s surfaces and the light images in step. A higher
    /// reflectance keeps more light images and may exceed their budget (never without
    /// `lighting.mirrored_lights`).
    pub fn set_reflectance(
        &mut self,
        reflectance: Vec3,
    ) -> Result<(), light_images::TooManyLightImages> {
        for m in &mut self.mirrors {
            m.reflectance = reflectance;
        }
        self.geometry.set_mirror_reflectance(reflectance);
        if self.lighting.mirrored_lights > 0 {
            self.enumerate_light_images(self.lighting.images.min_throughput)?;
        }
        Ok(())
    }

    /// Sets the steepest tilt of every uneven mirror to `degrees` ([`bump::MirrorBump::set_amplitude`]:
    /// the ripples' amplitude, the normal maps' strength); flat mirrors stay flat.
    pub fn set_bump_amplitude(&mut self, degrees: f32) {
        for b in self.bumps.iter_mut().flatten() {
            b.set_amplitude(degrees);
        }
    }

    /// The rig the scene's stereo renders use at interpupillary distance `ipd`: the camera's
    /// own `stereo` with that IPD, or else an off-axis rig converging at `look_at`.
    pub fn stereo_rig(&self, ipd: f32) -> stereo::Stereo {
        match self.stereo {
            Some(rig) => stereo::Stereo { ipd, ..rig },
            None => stereo::Stereo {
                ipd,
                convergence: stereo::Convergence::OffAxis,
                convergence_distance: (self.camera.look_at - self.camera.position).length(),
            },
        }
    }

    /// The albedo of the diffuse object named `name` (a marker a measurement looks for).
    pub fn albedo_of(&self, name: &str) -> Option<Vec3> {
        self.geometry.parts.iter().find_map(|p| {
            match (&self.geometry.surfaces[p.surface as usize], p.name == name) {
                (Surface::Diffuse { albedo, .. }, true) => Some(*albedo),
                _ => None,
            }
        })
    }

    /// The scene at `time` seconds along its camera path: the camera placed by the path (its
    /// size, exposure and stereo rig kept). A scene without a path is still: any time gives
    /// the scene itself.
    pub fn at_time(&self, time: f64) -> Result<Scene, camera_path::DegenerateView> {
        let Some(path) = &self.camera_path else {
            return Ok(self.clone());
        };
        Ok(Scene {
            camera: path.camera_at(&self.camera, time)?,
            ..self.clone()
        })
    }

    /// The camera [`Scene::at_time`] would place, without copying the scene: what a check
    /// of many frames' times needs.
    pub fn camera_at_time(&self, time: f64) -> Result<Camera, camera_path::DegenerateView> {
        match &self.camera_path {
            None => Ok(self.camera.clone()),
            Some(path) => path.camera_at(&self.camera, time),
        }
    }

    /// The scene seen by one eye of `stereo` (the scene's own rig, or another): its camera
    /// replaced by that eye's ([`stereo::Stereo::eye`]), no rig left.
    pub fn eye(&self, stereo: &stereo::Stereo, eye: stereo::Eye) -> Scene {
        Scene {
            camera: stereo.eye(&self.camera, eye),
            stereo: None,
            head: Some(self.camera.clone()),
            ..self.clone()
        }
    }

    /// Whether any mirror is uneven.
    pub fn has_bumps(&self) -> bool {
        self.bumps.iter().any(Option::is_some)
    }

    /// (Re)computes [`Lighting::images`] for chains of at most `lighting.mirrored_lights`
    /// mirrors, pruning chains dimmer than `min_throughput` (the tracer's `--min-throughput`;
    /// loading uses [`light_images::DEFAULT_MIN_THROUGHPUT`]).
    pub fn enumerate_light_images(
        &mut self,
        min_throughput: f32,
    ) -> Result<(), light_images::TooManyLightImages> {
        self.lighting.images = light_images::light_images(
            self,
            &self.lighting.lights,
            self.lighting.mirrored_lights,
            min_throughput,
        )?;
        Ok(())
    }
}

impl Scene {
    /// A 64-bit FNV-1a hash of everything that affects an image (camera, mirrors, lighting,
    /// background, terminal, triangles and surfaces, symmetry planes; not the file path). Floats enter through
    /// their exact shortest round-trip text, so equal hashes mean equal inputs. Used to label
    /// outputs and as the key of cached ground truths.
    pub fn content_hash(&self) -> u64 {
        use std::fmt::Write;
        let mut h = hash::Fnv1a::new();
        let g = &self.geometry;
        let _ = write!(
            h,
            "{:?}{:?}Lighting {{ lights: {:?}, ambient: {:?} }}{:?}{:?}{:?}{:?}{:?}",
            self.camera,
            self.mirrors,
            self.lighting.lights,
            self.lighting.ambient,
            self.background,
            self.terminal,
            g.triangles,
            g.surface_of,
            g.surfaces
        );
        // Scenes without planes keep the hash they had before planes existed (cached truths);
        // a plane's name changes no image.
        if let Some(symmetry) = &self.symmetry {
            let _ = write!(h, "symmetry{:?}", symmetry.plane_list());
        }
        // Likewise mono cameras.
        if let Some(s) = &self.stereo {
            let _ = write!(h, "stereo{s:?}");
        }
        if let Some(c) = &self.head {
            let _ = write!(h, "head{c:?}");
        }
        // Likewise scenes whose mirrors are all flat.
        if self.bumps.iter().any(Option::is_some) {
            let _ = write!(h, "bumps{:?}", self.bumps);
        }
        // Likewise scenes with the default lighting (no shadows, no mirrored lights). The
        // images follow from the rest, but their pruning threshold does not.
        let l = &self.lighting;
        if l.shadows || l.mirrored_lights > 0 {
            let _ = write!(
                h,
                "lighting{} {} {:?}",
                l.shadows, l.mirrored_lights, l.images.min_throughput
            );
        }
        h.finish()
    }
}

/// Helpers of the crate's unit tests.
#[cfg(test)]
pub(crate) mod test_support {
    /// A fixed sequence of floats in `[0, 1)` (xorshift64 from `seed`, its top 24 bits).
    pub fn unit_floats(mut state: u64) -> impl FnMut() -> f32 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn content_hash_tracks_what_affects_the_image() {
        let text = r#"{ "camera": { "position": [0, 1, 3], "look_at": [0, 1, 0], "fov_y_deg": 60,
            "width": 32, "height": 24 },
            "mirrors": [ { "center": [0, 1, -2], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 4, "height": 3 } ] }"#;
        let a = load::parse_scene(text, std::path::Path::new("a.json")).unwrap();
        let b = load::parse_scene(text, std::path::Path::new("elsewhere/b.json")).unwrap();
        assert_eq!(
            a.content_hash(),
            b.content_hash(),
            "the path must not matter"
        );
        let mut c = a.clone();
        c.set_reflectance(Vec3::splat(0.7)).unwrap();
        assert_ne!(a.content_hash(), c.content_hash());
        let mut d = a.clone();
        d.camera = d.camera.with_size(33, 24);
        assert_ne!(a.content_hash(), d.content_hash());
    }

    const WITH_PLANES: &str = r#"{ "camera": { "position": [0, 1, 3], "look_at": [0, 1, 0], "fov_y_deg": 60,
        "width": 32, "height": 24 },
        "mirrors": [ { "center": [0, 1, -2], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 4, "height": 3 } ],
        "objects": [ { "type": "sphere", "subdivisions": 1, "transform": { "translate": [0.3, 1, 0.2] } } ],
        "symmetry_planes": [ { "point": [0, 1, 0], "normal": [1, 0, 0] },
                             { "point": [0, 1.1, 0], "normal": [0.2, 1, 0] } ] }"#;

    fn without_field(text: &str) -> Scene {
        let mut value: serde_json::Value = serde_json::from_str(text).unwrap();
        value.as_object_mut().unwrap().remove("symmetry_planes");
        load::parse_scene(&value.to_string(), std::path::Path::new("a.json")).unwrap()
    }

    #[test]
    fn symmetry_planes_enter_the_hash_and_survive_without_mirrors() {
        let a = load::parse_scene(WITH_PLANES, std::path::Path::new("a.json")).unwrap();
        let plain = without_field(WITH_PLANES);
        assert_ne!(a.content_hash(), plain.content_hash());
        // Same baked triangles, other planes: still a different hash.
        let mut b = a.clone();
        b.symmetry.as_mut().unwrap().planes[0].name = "renamed".into();
        assert_eq!(
            a.content_hash(),
            b.content_hash(),
            "a name changes no image"
        );
        b.symmetry.as_mut().unwrap().planes[0].plane.offset += 1.0;
        assert_ne!(a.content_hash(), b.content_hash());
        let bare = a.without_mirrors();
        assert_eq!(bare.symmetry, a.symmetry);
        assert_eq!(bare.geometry.mirror_triangle_count(), 0);
        assert_eq!(
            bare.geometry.triangles[..],
            a.geometry.triangles[..a.geometry.triangles.len() - 2]
        );
    }

    #[test]
    fn with_symmetry_planes_rebakes_the_first_p_planes() {
        let mut a = load::parse_scene(WITH_PLANES, std::path::Path::new("a.json")).unwrap();
        a.set_reflectance(Vec3::splat(0.7)).unwrap();
        let all = a.with_symmetry_planes(2).unwrap();
        assert_eq!(all.geometry, a.geometry);
        assert_eq!(all.symmetry, a.symmetry);
        let none = a.with_symmetry_planes(0).unwrap();
        let mut plain = without_field(WITH_PLANES);
        plain.set_reflectance(Vec3::splat(0.7)).unwrap();
        assert!(none.symmetry.is_none());
        assert_eq!(none.geometry, plain.geometry);
        assert_eq!(none.content_hash(), plain.content_hash());
        let one = a.with_symmetry_planes(1).unwrap();
        let symmetry = one.symmetry.as_ref().unwrap();
        assert_eq!(
            symmetry.planes[..],
            a.symmetry.as_ref().unwrap().planes[..1]
        );
        let baked =
            symmetry::split_and_mirror(&symmetry.source, &symmetry.plane_list(), usize::MAX)
                .unwrap();
        assert_eq!(
            one.geometry.triangles[..baked.triangles.len()],
            baked.triangles[..]
        );
        assert_eq!(one.geometry.mirror_triangle_count(), 2);
        assert!(matches!(
            a.with_symmetry_planes(3),
            Err(symmetry::SymmetryError::NotThatManyPlanes { asked: 3, have: 2 })
        ));
        assert!(plain.with_symmetry_planes(1).is_err());
        assert_eq!(
            plain.with_symmetry_planes(0).unwrap().geometry,
            plain.geometry
        );
    }
}
