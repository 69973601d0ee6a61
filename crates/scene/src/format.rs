//! The scene file as written on disk (JSON). Field-by-field documentation with units and
//! defaults: `docs/scene-format.md`. Unknown fields are rejected everywhere, so a typo never
//! silently falls back to a default. Numbers are read here and checked in [`crate::load`].

use serde::Deserialize;

pub type Rgb = [f32; 3];
pub type Vec3f = [f32; 3];

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub camera: CameraDesc,
    #[serde(default)]
    pub mirrors: Vec<MirrorDesc>,
    #[serde(default)]
    pub objects: Vec<ObjectDesc>,
    #[serde(default)]
    pub lights: Vec<LightDesc>,
    #[serde(default)]
    pub ambient: Option<Rgb>,
    /// Shadows and mirrored light sources (opt-in; absent: neither).
    #[serde(default)]
    pub lighting: Option<LightingDesc>,
    #[serde(default)]
    pub background: Option<Rgb>,
    #[serde(default)]
    pub terminal: Option<Rgb>,
    /// Seed 001's symmetry planes, applied to the objects in this order.
    #[serde(default)]
    pub symmetry_planes: Vec<SymmetryPlaneDesc>,
}

/// One symmetry plane: through `point`, front side towards `normal`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SymmetryPlaneDesc {
    #[serde(default)]
    pub name: Option<String>,
    pub point: Vec3f,
    pub normal: Vec3f,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Required unless `gltf` places the camera.
    #[serde(default)]
    pub position: Option<Vec3f>,
    #[serde(default)]
    pub look_at: Option<Vec3f>,
    #[serde(default)]
    pub up: Option<Vec3f>,
    #[serde(default)]
    pub fov_y_deg: Option<f32>,
    /// A glTF asset's camera as the scene camera: the `path` of one of the scene's `gltf`
    /// objects, and `index`, the number of its perspective camera in node order.
    #[serde(default)]
    pub gltf: Option<String>,
    #[serde(default)]
    pub index: Option<usize>,
    pub width: u32,
    pub height: u32,
    #[serde(default)]
    pub exposure: Option<f32>,
    /// Two eyes instead of one (`crate::stereo`).
    #[serde(default)]
    pub stereo: Option<StereoDesc>,
    /// Keyframes of a moving camera (`crate::camera_path`).
    #[serde(default)]
    pub path: Option<Vec<CameraKeyDesc>>,
}

/// One key of `camera.path`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraKeyDesc {
    /// Seconds.
    pub time: f64,
    pub position: Vec3f,
    pub look_at: Vec3f,
    /// Default: the camera's `up`.
    #[serde(default)]
    pub up: Option<Vec3f>,
    /// Default: the camera's `fov_y_deg`.
    #[serde(default)]
    pub fov_y_deg: Option<f32>,
}

/// `camera.stereo`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StereoDesc {
    /// Interpupillary distance, scene units.
    pub ipd: f32,
    /// `off-axis` (default), `parallel` or `toe-in`.
    #[serde(default)]
    pub convergence: Option<String>,
    /// Default: the distance from `position` to `look_at`.
    #[serde(default)]
    pub convergence_distance: Option<f32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MirrorDesc {
    #[serde(default)]
    pub name: Option<String>,
    pub center: Vec3f,
    pub normal: Vec3f,
    pub up: Vec3f,
    pub width: f32,
    pub height: f32,
    #[serde(default)]
    pub reflectance: Option<Rgb>,
    #[serde(default)]
    pub back_albedo: Option<Rgb>,
    /// An uneven mirror's shading normal (`crate::bump`); absent: flat.
    #[serde(default)]
    pub bump: Option<BumpDesc>,
}

/// `mirrors[i].bump`: a ripple and/or a normal map (at least one).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BumpDesc {
    #[serde(default)]
    pub ripple: Option<RippleDesc>,
    #[serde(default)]
    pub normal_map: Option<NormalMapDesc>,
}

/// A sinusoidal tilt of the normal (`crate::bump`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RippleDesc {
    /// Largest tilt of the normal, degrees in [0, 90).
    pub amplitude_deg: f32,
    /// Scene units.
    pub wavelength: f32,
    /// Direction of travel in the mirror's plane, degrees from its right axis towards up.
    #[serde(default)]
    pub direction_deg: Option<f32>,
    #[serde(default)]
    pub phase_deg: Option<f32>,
}

/// A tangent-space normal map PNG (8-bit RGB or RGBA; green = +up).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NormalMapDesc {
    /// Relative to the scene file's folder.
    pub path: String,
    /// Repeats across the mirror's width and height (default [1, 1]).
    #[serde(default)]
    pub tiling: Option<[f32; 2]>,
    /// Scales the tangential components (default 1).
    #[serde(default)]
    pub strength: Option<f32>,
}

/// The kind of an object's shape (the `type` field).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeKind {
    Box,
    Sphere,
    Quad,
    Mesh,
    Gltf,
}

impl ShapeKind {
    /// The shape-specific fields this kind accepts (all others are refused).
    pub fn allowed_fields(self) -> &'static [&'static str] {
        match self {
            ShapeKind::Box => &["size"],
            ShapeKind::Sphere => &["radius", "subdivisions"],
            ShapeKind::Quad => &["size"],
            ShapeKind::Mesh => &["path"],
            ShapeKind::Gltf => &["path", "scene", "curved_mirrors"],
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Box => "box",
            ShapeKind::Sphere => "sphere",
            ShapeKind::Quad => "quad",
            ShapeKind::Mesh => "mesh",
            ShapeKind::Gltf => "gltf",
        }
    }
}

/// One object. The shape parameters are flat optional fields (rather than a tagged enum) so
/// that every error keeps its exact field path and line; [`crate::load`] refuses fields
/// that do not belong to the object's `type`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDesc {
    #[serde(rename = "type")]
    pub kind: ShapeKind,
    #[serde(default)]
    pub name: Option<String>,
    /// box: [x, y, z] edge lengths; quad: [width, height].
    #[serde(default)]
    pub size: Option<Vec<f32>>,
    #[serde(default)]
    pub radius: Option<f32>,
    #[serde(default)]
    pub subdivisions: Option<u32>,
    #[serde(default)]
    pub path: Option<String>,
    /// gltf: which of the file's scenes (default: its `scene`, else the first).
    #[serde(default)]
    pub scene: Option<usize>,
    /// gltf: what a mirror-like primitive that is not a planar rectangle becomes.
    #[serde(default)]
    pub curved_mirrors: Option<CurvedMirrorsDesc>,
    #[serde(default)]
    pub transform: Option<TransformDesc>,
    #[serde(default)]
    pub albedo: Option<Rgb>,
    #[serde(default)]
    pub emission: Option<Rgb>,
}

/// `curved_mirrors` of a glTF object (`docs/gltf.md`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CurvedMirrorsDesc {
    Refuse,
    Diffuse,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransformDesc {
    #[serde(default)]
    pub translate: Option<Vec3f>,
    /// Euler angles in degrees, applied about x, then y, then z (R = Rz·Ry·Rx).
    #[serde(default)]
    pub rotate_deg: Option<Vec3f>,
    #[serde(default)]
    pub scale: Option<Scale>,
}

/// A uniform (`2.0`) or per-axis (`[1, 2, 1]`) scale.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(untagged, expecting = "must be a number or an array of 3 numbers")]
pub enum Scale {
    Uniform(f32),
    PerAxis(Vec3f),
}

/// How light reaches diffuse surfaces beyond the contract's default (`docs/shading.md`).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightingDesc {
    /// Straight legs from a surface to a light must be unoccluded.
    #[serde(default)]
    pub shadows: Option<bool>,
    /// Most mirrors between a light and a surface (0: light reaches surfaces only directly).
    #[serde(default)]
    pub mirrored_lights: Option<u32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightDesc {
    pub position: Vec3f,
    /// Radiant intensity in W/sr per RGB channel.
    pub intensity: Rgb,
}
