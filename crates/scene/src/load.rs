//! Reading, checking and compiling a scene file into a [`Scene`].
//!
//! Syntax and type errors carry `file:line:column` and the field path where parsing stopped;
//! meaning errors carry the field path (`mirrors[1].normal`) and what is allowed. Nothing
//! here panics on any input.

use crate::bump::{
    MAX_AMPLITUDE_DEG, MAX_NORMAL_MAP_FILE_BYTES, MAX_NORMAL_MAP_SIDE, MAX_STRENGTH, MAX_TILING,
    MirrorBump, NormalMap, Ripple,
};
use crate::error::{FieldPath, SceneError};
use crate::format::{
    BumpDesc, CameraDesc, CurvedMirrorsDesc, LightDesc, MirrorDesc, ObjectDesc, Rgb, Scale,
    SceneFile, ShapeKind, SymmetryPlaneDesc, TransformDesc, Vec3f,
};
use crate::geometry::{Geometry, Surface};
use crate::gltf_asset;
use crate::light_images::{DEFAULT_MIN_THROUGHPUT, MAX_MIRRORED_LIGHTS};
use crate::limits::{
    MAX_COORDINATE, MAX_IMAGE_SIDE, MAX_OBJ_FILE_BYTES, MAX_PIXELS, MAX_SCENE_FILE_BYTES,
    MAX_TRIANGLES, MEMORY_PER_TRIANGLE, within_extent,
};
use crate::shading::{Lighting, PointLight};
use crate::symmetry::{self, MAX_SYMMETRY_PLANES, Symmetry, SymmetryPlane};
use crate::tessellate::{self, MAX_SPHERE_SUBDIVISIONS};
use crate::texture::MAX_TEXTURE_TEXELS;
use crate::{Camera, Mirror, Plane, Scene};
use glam::{EulerRot, Mat4, Quat, Vec3};
use std::path::{Path, PathBuf};

/// Largest interpupillary distance, scene units (eyes a scene unit apart are not a head).
const MAX_IPD: f32 = 1.0;

/// Defaults, documented in `docs/scene-format.md`.
pub mod defaults {
    pub const CAMERA_UP: [f32; 3] = [0.0, 1.0, 0.0];
    pub const EXPOSURE: f32 = 1.0;
    pub const MIRROR_REFLECTANCE: [f32; 3] = [0.9, 0.9, 0.9];
    pub const MIRROR_BACK_ALBEDO: [f32; 3] = [0.2, 0.2, 0.2];
    pub const ALBEDO: [f32; 3] = [0.8, 0.8, 0.8];
    pub const SPHERE_RADIUS: f32 = 1.0;
    pub const SPHERE_SUBDIVISIONS: u32 = 3;
    pub const BOX_SIZE: [f32; 3] = [1.0, 1.0, 1.0];
    pub const QUAD_SIZE: [f32; 2] = [1.0, 1.0];
}

/// A scene of this repository's `scenes/` folder by file name (`"mirror_box.json"`) — for
/// the workspace's own tests and benches: the path is this source tree's, fixed at compile
/// time. Panics if it does not load.
pub fn bundled_scene(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name);
    load_scene(&path).unwrap_or_else(|e| panic!("bundled scene {name}: {e}"))
}

/// Loads, checks and compiles the scene file at `path` (a regular file of at most
/// [`MAX_SCENE_FILE_BYTES`]).
pub fn load_scene(path: &Path) -> Result<Scene> {
    let text = mirrorbox_files::read_bounded_text(path, MAX_SCENE_FILE_BYTES, "scene file")
        .map_err(|e| SceneError::Read {
            file: path.to_path_buf(),
            message: e.message,
        })?;
    parse_scene(&text, path)
}

/// Parses scene JSON `text`; `path` names the file in messages and anchors relative OBJ paths.
pub fn parse_scene(text: &str, path: &Path) -> Result<Scene> {
    let syntax = |field: Option<String>, e: serde_json::Error| SceneError::Syntax {
        file: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        path: field.filter(|f| f != "."),
        message: finite_number_message(strip_position(&e.to_string())),
    };
    // Two mistakes serde would say in its own terms ("expected value", "expected struct
    // SceneFile"): a byte-order mark, and a document that is not one object.
    let problem = if text.starts_with('\u{feff}') {
        Some("the file starts with a UTF-8 byte-order mark: save it without one")
    } else if !text.trim_start().starts_with('{') && !text.trim().is_empty() {
        Some("a scene file is one JSON object, `{ \"camera\": …, \"objects\": … }`")
    } else {
        None
    };
    if let Some(message) = problem {
        return Err(SceneError::Syntax {
            file: path.to_path_buf(),
            line: 1,
            column: 1,
            path: None,
            message: message.into(),
        });
    }
    let mut de = serde_json::Deserializer::from_str(text);
    let file: SceneFile = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let field = e.path().to_string();
        syntax(Some(field), e.into_inner())
    })?;
    de.end().map_err(|e| syntax(None, e))?;
    Checker {
        file: path,
        normal_maps: Default::default(),
        gltf_images: Default::default(),
    }
    .compile(file)
}

/// What a number field that is not finite is told ([`Checker`]'s check of every number).
const NOT_FINITE: &str = "must be a finite number";

/// serde_json's "number out of range" (a literal such as `1e999`, or `1e39` for an f32 field:
/// its exact parse, `float_roundtrip`, refuses what its fast parse had made infinite) in the
/// words of the finite-number check that saw the infinity before.
fn finite_number_message(message: String) -> String {
    if message == "number out of range" {
        format!("{NOT_FINITE}, got one out of range")
    } else {
        message
    }
}

/// Mirror `mirror` appended to the scene's `mirrors` and its two front triangles to
/// `geometry` (its surface indexes it there).
fn push_mirror(geometry: &mut Geometry, mirrors: &mut Vec<Mirror>, mirror: Mirror) {
    let [a, b, c, d] = mirror.corners();
    geometry.push_part(
        mirror.name.clone(),
        Surface::Mirror {
            mirror: mirrors.len(),
            reflectance: mirror.reflectance,
            back_albedo: mirror.back_albedo,
        },
        vec![[a, b, c], [a, c, d]],
    );
    mirrors.push(mirror);
}

/// serde_json appends " at line L column C"; we print the position in front instead.
pub(crate) fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_string(),
        None => message.to_string(),
    }
}

struct Checker<'a> {
    file: &'a Path,
    /// Normal maps decoded so far, by the path they were read from: a map is read and decoded
    /// once per file however many mirrors use it (issue 51: 20 000 facets sharing one map
    /// took 18.6 s and 3.85 GB to `check`, the map decoded once per mirror). The mirrors
    /// share its texels (an `Arc`); the GPU atlas and the memory estimate count it once.
    normal_maps: std::cell::RefCell<std::collections::HashMap<PathBuf, DecodedMap>>,
    /// For each glTF file loaded so far (by resolved path), the scene texture each of its
    /// images became: a file instanced by many objects has its images read and decoded once
    /// (issue 51), the objects sharing the textures.
    gltf_images: std::cell::RefCell<std::collections::HashMap<PathBuf, Vec<Option<u32>>>>,
}

/// A decoded normal map: width, height and texels.
type DecodedMap = (u32, u32, std::sync::Arc<crate::bump::Texels>);

/// What glTF objects bring besides triangles: mirrors (with the object's field path),
/// point lights and cameras.
#[derive(Default)]
struct AssetExtras {
    mirrors: Vec<(FieldPath, Mirror)>,
    lights: Vec<PointLight>,
    /// Each glTF object's path (as the scene file writes it) and its cameras.
    cameras: Vec<(String, Vec<gltf_asset::AssetCamera>)>,
}

/// Where the camera is and looks, before it is checked: the file's fields or a glTF camera.
struct CameraFrame {
    position: Vec3f,
    look_at: Vec3f,
    up: Option<Vec3f>,
    fov_y_deg: f32,
}

type Result<T> = std::result::Result<T, SceneError>;

impl Checker<'_> {
    fn invalid(&self, path: &FieldPath, message: impl Into<String>) -> SceneError {
        SceneError::Invalid {
            file: self.file.to_path_buf(),
            path: path.to_string(),
            message: message.into(),
        }
    }

    /// A vertical field of view at `path`: finite and in (0, [`crate::limits::MAX_FOV_Y_DEG`]].
    fn fov(&self, path: &FieldPath, fov: f32) -> Result<f32> {
        let fov = self.finite(path, fov)?;
        if !crate::limits::fov_ok(fov) {
            return Err(self.invalid(
                path,
                format!(
                    "must be in (0, {}] degrees, got {fov}",
                    crate::limits::MAX_FOV_Y_DEG
                ),
            ));
        }
        Ok(fov)
    }

    fn finite(&self, path: &FieldPath, x: f32) -> Result<f32> {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.invalid(path, format!("{NOT_FINITE}, got {x}")))
        }
    }

    fn positive(&self, path: &FieldPath, x: f32) -> Result<f32> {
        let x = self.finite(path, x)?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.invalid(path, format!("must be greater than 0, got {x}")))
        }
    }

    fn vec3(&self, path: &FieldPath, v: Vec3f) -> Result<Vec3> {
        for (i, &c) in v.iter().enumerate() {
            self.finite(&path.index(i), c)?;
        }
        Ok(Vec3::from_array(v))
    }

    fn direction(&self, path: &FieldPath, v: Vec3f) -> Result<Vec3> {
        let v = self.vec3(path, v)?;
        v.try_normalize().ok_or_else(|| {
            self.invalid(
                path,
                format!("must be a non-zero direction, got {}", show(v)),
            )
        })
    }

    /// A point of the scene: finite and within [`MAX_COORDINATE`] on every axis.
    fn position(&self, path: &FieldPath, v: Vec3f) -> Result<Vec3> {
        let p = self.vec3(path, v)?;
        if !within_extent(p) {
            return Err(self.invalid(
                path,
                format!(
                    "must lie within the scene extent, every coordinate within ±{MAX_COORDINATE:e}, got {}",
                    show(p)
                ),
            ));
        }
        Ok(p)
    }

    /// Refuses a part of `adding` triangles that would take the scene past [`MAX_TRIANGLES`],
    /// before it is built.
    fn triangle_budget(&self, path: &FieldPath, have: usize, adding: u64) -> Result<()> {
        let total = have as u64 + adding;
        if total > MAX_TRIANGLES as u64 {
            return Err(self.invalid(
                path,
                format!(
                    "adds {adding} triangles, taking the scene to {total}; at most {MAX_TRIANGLES} are accepted \
                     (the scene would need about {} to trace, at most about {})",
                    mirrorbox_files::human_bytes(total.saturating_mul(MEMORY_PER_TRIANGLE)),
                    mirrorbox_files::human_bytes(MAX_TRIANGLES as u64 * MEMORY_PER_TRIANGLE)
                ),
            ));
        }
        Ok(())
    }

    /// RGB with every channel in `[lo, hi]`.
    fn rgb(
        &self,
        path: &FieldPath,
        v: Option<Rgb>,
        default: Rgb,
        lo: f32,
        hi: f32,
    ) -> Result<Vec3> {
        let v = v.unwrap_or(default);
        for (i, &c) in v.iter().enumerate() {
            let c = self.finite(&path.index(i), c)?;
            if !(lo..=hi).contains(&c) {
                let allowed = if hi.is_finite() {
                    format!("in [{lo}, {hi}]")
                } else {
                    format!("≥ {lo}")
                };
                return Err(self.invalid(&path.index(i), format!("must be {allowed}, got {c}")));
            }
        }
        Ok(Vec3::from_array(v))
    }

    fn reflectance(&self, path: &FieldPath, v: Option<Rgb>, default: Rgb) -> Result<Vec3> {
        self.rgb(path, v, default, 0.0, 1.0)
    }

    fn radiance(&self, path: &FieldPath, v: Option<Rgb>) -> Result<Vec3> {
        self.rgb(path, v, [0.0; 3], 0.0, f32::INFINITY)
    }

    fn compile(&self, file: SceneFile) -> Result<Scene> {
        let mut geometry = Geometry::default();
        let objects = FieldPath::root("objects");
        let mut assets = AssetExtras::default();
        for (i, object) in file.objects.iter().enumerate() {
            self.object(&objects.index(i), i, object, &mut geometry, &mut assets)?;
        }
        // After the objects: a glTF object may hold the camera.
        let frame = self.camera_frame(&FieldPath::root("camera"), &file.camera, &assets)?;
        let camera = self
            .camera(&FieldPath::root("camera"), &file.camera, &frame)
            .map_err(|e| gltf_camera_error(e, &file.camera))?;
        let planes = self.symmetry_planes(&file.symmetry_planes)?;
        let symmetry = if planes.is_empty() {
            None
        } else {
            // The mirrors' two triangles each come after the bake; leave room for them.
            let budget = MAX_TRIANGLES.saturating_sub(2 * file.mirrors.len());
            let plane_list: Vec<Plane> = planes.iter().map(|p| p.plane).collect();
            let baked =
                symmetry::split_and_mirror(&geometry, &plane_list, budget).map_err(|e| {
                    let field = FieldPath::root("symmetry_planes");
                    let field = match e.plane() {
                        Some(k) => field.index(k),
                        None => field,
                    };
                    self.invalid(&field, e.to_string())
                })?;
            let source = std::mem::replace(&mut geometry, baked);
            Some(Symmetry { planes, source })
        };
        let mut mirrors = Vec::with_capacity(file.mirrors.len());
        let mut bumps = Vec::with_capacity(file.mirrors.len());
        let mirror_paths = FieldPath::root("mirrors");
        for (i, desc) in file.mirrors.iter().enumerate() {
            let mirror_path = mirror_paths.index(i);
            self.triangle_budget(&mirror_path, geometry.triangles.len(), 2)?;
            let mirror = self.mirror(&mirror_path, i, desc)?;
            bumps.push(match &desc.bump {
                Some(b) => Some(self.bump(&mirror_path.field("bump"), b)?),
                None => None,
            });
            push_mirror(&mut geometry, &mut mirrors, mirror);
        }
        // Mirrors of glTF assets (docs/gltf.md), after the file's own.
        for (object_path, mirror) in assets.mirrors {
            self.triangle_budget(&object_path, geometry.triangles.len(), 2)?;
            bumps.push(None);
            push_mirror(&mut geometry, &mut mirrors, mirror);
        }
        let lights_path = FieldPath::root("lights");
        let mut lights = file
            .lights
            .iter()
            .enumerate()
            .map(|(i, l)| self.light(&lights_path.index(i), l))
            .collect::<Result<Vec<_>>>()?;
        lights.extend(assets.lights);
        let lighting_desc = file.lighting.as_ref();
        let mirrored_lights = lighting_desc.and_then(|l| l.mirrored_lights).unwrap_or(0);
        let mirrored_path = FieldPath::root("lighting").field("mirrored_lights");
        if mirrored_lights > MAX_MIRRORED_LIGHTS {
            return Err(self.invalid(
                &mirrored_path,
                format!(
                    "must be in [0, {MAX_MIRRORED_LIGHTS}] (mirrors between a light and a \
                     surface), got {mirrored_lights}"
                ),
            ));
        }
        if mirrored_lights > 0 && bumps.iter().any(Option::is_some) {
            return Err(self.invalid(
                &mirrored_path,
                "must be 0 in a scene with uneven mirrors (a bump): light images are defined \
                 for flat mirrors only (docs/shading.md)",
            ));
        }
        let camera_path = self.camera_path(
            &FieldPath::root("camera").field("path"),
            &file.camera,
            &camera,
        )?;
        let mut scene = Scene {
            source: self.file.to_path_buf(),
            camera,
            mirrors,
            stereo: self.stereo(
                &FieldPath::root("camera").field("stereo"),
                &file.camera,
                &frame,
            )?,
            camera_path,
            head: None,
            bumps,
            lighting: Lighting {
                lights,
                ambient: self.radiance(&FieldPath::root("ambient"), file.ambient)?,
                shadows: lighting_desc.and_then(|l| l.shadows).unwrap_or(false),
                mirrored_lights,
                images: Default::default(),
            },
            background: self.radiance(&FieldPath::root("background"), file.background)?,
            terminal: self.radiance(&FieldPath::root("terminal"), file.terminal)?,
            geometry,
            symmetry,
        };
        scene
            .enumerate_light_images(DEFAULT_MIN_THROUGHPUT)
            .map_err(|e| self.invalid(&mirrored_path, e.to_string()))?;
        Ok(scene)
    }

    /// Seed 001's planes, in file order: at most [`MAX_SYMMETRY_PLANES`], each through a point
    /// within the scene extent with a non-zero normal.
    fn symmetry_planes(&self, descs: &[SymmetryPlaneDesc]) -> Result<Vec<SymmetryPlane>> {
        let path = FieldPath::root("symmetry_planes");
        if descs.len() > MAX_SYMMETRY_PLANES {
            return Err(self.invalid(
                &path,
                format!(
                    "at most {MAX_SYMMETRY_PLANES} planes are accepted (each doubles the copies \
                     of the objects: 2^p), got {}",
                    descs.len()
                ),
            ));
        }
        descs
            .iter()
            .enumerate()
            .map(|(i, d)| {
                let path = path.index(i);
                let point = self.position(&path.field("point"), d.point)?;
                let normal = self.direction(&path.field("normal"), d.normal)?;
                Ok(SymmetryPlane {
                    name: d.name.clone().unwrap_or_else(|| format!("plane {i}")),
                    plane: Plane::from_point_normal(point, normal),
                })
            })
            .collect()
    }

    /// The camera's position, look-at point, up (if given) and field of view: the file's, or
    /// a glTF object's camera (`camera.gltf`, `camera.index`), never both.
    fn camera_frame(
        &self,
        path: &FieldPath,
        c: &CameraDesc,
        assets: &AssetExtras,
    ) -> Result<CameraFrame> {
        let Some(gltf) = &c.gltf else {
            if c.index.is_some() {
                return Err(self.invalid(
                    &path.field("index"),
                    "needs camera.gltf (the glTF object whose camera it numbers)",
                ));
            }
            let required = |field: &str| {
                self.invalid(
                    &path.field(field),
                    "is required (or camera.gltf and camera.index: a glTF object's camera)",
                )
            };
            return Ok(CameraFrame {
                position: c.position.ok_or_else(|| required("position"))?,
                look_at: c.look_at.ok_or_else(|| required("look_at"))?,
                up: c.up,
                fov_y_deg: c.fov_y_deg.ok_or_else(|| required("fov_y_deg"))?,
            });
        };
        for (field, given) in [
            ("position", c.position.is_some()),
            ("look_at", c.look_at.is_some()),
            ("up", c.up.is_some()),
            ("fov_y_deg", c.fov_y_deg.is_some()),
            ("path", c.path.is_some()),
        ] {
            if given {
                return Err(self.invalid(
                    &path.field(field),
                    "is not allowed with camera.gltf: the glTF camera places the view",
                ));
            }
        }
        let Some(cameras) = assets
            .cameras
            .iter()
            .find(|(p, _)| p == gltf)
            .map(|(_, c)| c)
        else {
            let paths: Vec<&str> = assets.cameras.iter().map(|(p, _)| p.as_str()).collect();
            return Err(self.invalid(
                &path.field("gltf"),
                format!("must be the path of one of the scene's gltf objects (they are: {paths:?}), got {gltf:?}"),
            ));
        };
        let index = c.index.unwrap_or(0);
        let Some(g) = cameras.get(index) else {
            return Err(self.invalid(
                &path.field("index"),
                format!(
                    "the asset places {} perspective cameras; camera {index} was asked for",
                    cameras.len()
                ),
            ));
        };
        Ok(CameraFrame {
            position: g.position.to_array(),
            look_at: (g.position + g.forward).to_array(),
            up: Some(g.up.to_array()),
            fov_y_deg: g.fov_y_deg,
        })
    }

    fn camera(&self, path: &FieldPath, c: &CameraDesc, frame: &CameraFrame) -> Result<Camera> {
        let position = self.position(&path.field("position"), frame.position)?;
        let look_at = self.position(&path.field("look_at"), frame.look_at)?;
        let forward = (look_at - position).try_normalize().ok_or_else(|| {
            self.invalid(&path.field("look_at"), "must differ from camera.position")
        })?;
        let up_path = path.field("up");
        let up = self.direction(&up_path, frame.up.unwrap_or(defaults::CAMERA_UP))?;
        if forward.cross(up).length() < 1e-4 {
            return Err(self.invalid(
                &up_path,
                "must not be parallel to the view direction (look_at − position)",
            ));
        }
        let fov = self.fov(&path.field("fov_y_deg"), frame.fov_y_deg)?;
        for (name, side) in [("width", c.width), ("height", c.height)] {
            if side == 0 || side > MAX_IMAGE_SIDE {
                return Err(self.invalid(
                    &path.field(name),
                    format!("must be in [1, {MAX_IMAGE_SIDE}] pixels, got {side}"),
                ));
            }
        }
        let pixels = u64::from(c.width) * u64::from(c.height);
        if pixels > MAX_PIXELS {
            return Err(self.invalid(
                &path.field("width"),
                format!(
                    "width × height must be at most {MAX_PIXELS} pixels (8192²), got {}×{} = {pixels}",
                    c.width, c.height
                ),
            ));
        }
        let exposure = self.positive(
            &path.field("exposure"),
            c.exposure.unwrap_or(defaults::EXPOSURE),
        )?;
        Ok(Camera {
            position,
            look_at,
            up,
            fov_y_deg: fov,
            width: c.width,
            height: c.height,
            exposure,
            shift_x: 0.0,
        })
    }

    /// `camera.path`: 1 to [`MAX_KEYS`](crate::camera_path::MAX_KEYS) keys, times finite
    /// and strictly increasing, each key a valid view (its own `up` and `fov_y_deg`, or the
    /// camera's).
    fn camera_path(
        &self,
        path: &FieldPath,
        c: &CameraDesc,
        camera: &Camera,
    ) -> Result<Option<crate::camera_path::CameraPath>> {
        use crate::camera_path::{CameraKey, CameraPath, MAX_KEYS};
        let Some(keys) = &c.path else {
            return Ok(None);
        };
        if keys.is_empty() || keys.len() > MAX_KEYS {
            return Err(self.invalid(
                path,
                format!("must hold 1 to {MAX_KEYS} keys, got {}", keys.len()),
            ));
        }
        let mut checked: Vec<CameraKey> = Vec::with_capacity(keys.len());
        for (i, k) in keys.iter().enumerate() {
            let at = path.index(i);
            let time_path = at.field("time");
            if !k.time.is_finite() || k.time.abs() > 1e9 {
                return Err(self.invalid(
                    &time_path,
                    format!(
                        "must be a finite number of seconds within ±1e9, got {}",
                        k.time
                    ),
                ));
            }
            if let Some(before) = checked.last()
                && k.time <= before.time
            {
                return Err(self.invalid(
                    &time_path,
                    format!(
                        "must be later than the key before it ({} s), got {} s",
                        before.time, k.time
                    ),
                ));
            }
            let position = self.position(&at.field("position"), k.position)?;
            let look_at = self.position(&at.field("look_at"), k.look_at)?;
            let forward = (look_at - position).try_normalize().ok_or_else(|| {
                self.invalid(&at.field("look_at"), "must differ from the key's position")
            })?;
            let up = match k.up {
                Some(up) => self.direction(&at.field("up"), up)?,
                None => camera.up,
            };
            if forward.cross(up).length() < 1e-4 {
                return Err(self.invalid(
                    &at.field("up"),
                    "must not be parallel to the key's view direction (look_at − position)",
                ));
            }
            let fov_y_deg = match k.fov_y_deg {
                Some(fov) => self.fov(&at.field("fov_y_deg"), fov)?,
                None => camera.fov_y_deg,
            };
            checked.push(CameraKey {
                time: k.time,
                position,
                look_at,
                up,
                fov_y_deg,
            });
        }
        Ok(Some(CameraPath::new(checked)))
    }

    fn mirror(&self, path: &FieldPath, index: usize, m: &MirrorDesc) -> Result<Mirror> {
        let center = self.position(&path.field("center"), m.center)?;
        let normal = self.direction(&path.field("normal"), m.normal)?;
        let up_path = path.field("up");
        let up = self.direction(&up_path, m.up)?;
        if normal.cross(up).length() < 1e-4 {
            return Err(self.invalid(&up_path, "must not be parallel to the mirror's normal"));
        }
        // Gram–Schmidt: keep the part of `up` in the mirror plane.
        let up = (up - normal * normal.dot(up)).normalize();
        let width = self.positive(&path.field("width"), m.width)?;
        let height = self.positive(&path.field("height"), m.height)?;
        let mirror = Mirror {
            name: m.name.clone().unwrap_or_else(|| format!("mirror {index}")),
            center,
            normal,
            up,
            width,
            height,
            reflectance: self.reflectance(
                &path.field("reflectance"),
                m.reflectance,
                defaults::MIRROR_REFLECTANCE,
            )?,
            back_albedo: self.reflectance(
                &path.field("back_albedo"),
                m.back_albedo,
                defaults::MIRROR_BACK_ALBEDO,
            )?,
        };
        if let Some(corner) = mirror.corners().into_iter().find(|c| !within_extent(*c)) {
            return Err(self.invalid(
                &path.field("width"),
                format!(
                    "puts the corner {} outside the scene extent: every coordinate must be within ±{MAX_COORDINATE:e}",
                    show(corner)
                ),
            ));
        }
        Ok(mirror)
    }

    /// `camera.stereo` (`crate::stereo`): an IPD in [0, [`MAX_IPD`]] scene units, a known
    /// convergence and a positive convergence distance.
    fn stereo(
        &self,
        path: &FieldPath,
        c: &CameraDesc,
        frame: &CameraFrame,
    ) -> Result<Option<crate::stereo::Stereo>> {
        use crate::stereo::{Convergence, Stereo};
        let Some(s) = &c.stereo else {
            return Ok(None);
        };
        let ipd = self.finite(&path.field("ipd"), s.ipd)?;
        if !(0.0..=MAX_IPD).contains(&ipd) {
            return Err(self.invalid(
                &path.field("ipd"),
                format!("must be in [0, {MAX_IPD}] scene units, got {ipd}"),
            ));
        }
        let convergence = match s.convergence.as_deref() {
            None | Some("off-axis") => Convergence::OffAxis,
            Some("parallel") => Convergence::Parallel,
            Some("toe-in") => Convergence::ToeIn,
            Some(other) => {
                return Err(self.invalid(
                    &path.field("convergence"),
                    format!("must be \"off-axis\", \"parallel\" or \"toe-in\", got \"{other}\""),
                ));
            }
        };
        let default = (Vec3::from_array(frame.look_at) - Vec3::from_array(frame.position)).length();
        let distance = self.positive(
            &path.field("convergence_distance"),
            s.convergence_distance.unwrap_or(default),
        )?;
        Ok(Some(Stereo {
            ipd,
            convergence,
            convergence_distance: distance,
        }))
    }

    /// `mirrors[i].bump` (`crate::bump`): each number in its range, the normal map read,
    /// bounded and decoded here.
    fn bump(&self, path: &FieldPath, b: &BumpDesc) -> Result<MirrorBump> {
        if b.ripple.is_none() && b.normal_map.is_none() {
            return Err(self.invalid(path, "needs a \"ripple\", a \"normal_map\" or both"));
        }
        let ripple = match &b.ripple {
            Some(r) => {
                let rp = path.field("ripple");
                let a = self.finite(&rp.field("amplitude_deg"), r.amplitude_deg)?;
                if !(0.0..MAX_AMPLITUDE_DEG).contains(&a) {
                    return Err(self.invalid(
                        &rp.field("amplitude_deg"),
                        format!("must be in [0, {MAX_AMPLITUDE_DEG}) degrees, got {a}"),
                    ));
                }
                let wavelength = self.positive(&rp.field("wavelength"), r.wavelength)?;
                let direction =
                    self.finite(&rp.field("direction_deg"), r.direction_deg.unwrap_or(0.0))?;
                let phase = self.finite(&rp.field("phase_deg"), r.phase_deg.unwrap_or(0.0))?;
                Some(Ripple {
                    amplitude: a.to_radians(),
                    wavelength,
                    direction: direction.to_radians(),
                    phase: phase.to_radians(),
                })
            }
            None => None,
        };
        let normal_map = match &b.normal_map {
            Some(m) => {
                let mp = path.field("normal_map");
                let tiling = m.tiling.unwrap_or([1.0, 1.0]);
                for (k, t) in tiling.into_iter().enumerate() {
                    let t = self.positive(&mp.field("tiling").index(k), t)?;
                    if t > MAX_TILING {
                        return Err(self.invalid(
                            &mp.field("tiling").index(k),
                            format!("must be in (0, {MAX_TILING}], got {t}"),
                        ));
                    }
                }
                let strength = self.finite(&mp.field("strength"), m.strength.unwrap_or(1.0))?;
                if !(0.0..=MAX_STRENGTH).contains(&strength) {
                    return Err(self.invalid(
                        &mp.field("strength"),
                        format!("must be in [0, {MAX_STRENGTH}], got {strength}"),
                    ));
                }
                let (resolved, (width, height, texels)) =
                    self.normal_map(&mp.field("path"), &m.path)?;
                Some(NormalMap {
                    path: m.path.clone(),
                    resolved,
                    width,
                    height,
                    texels,
                    tiling,
                    strength,
                })
            }
            None => None,
        };
        Ok(MirrorBump { ripple, normal_map })
    }

    /// [`Checker::normal_map_texels`] of `rel`, decoded once per resolved path
    /// ([`Checker::normal_maps`]).
    fn normal_map(&self, path: &FieldPath, rel: &str) -> Result<(PathBuf, DecodedMap)> {
        let resolved: PathBuf = self.file.parent().unwrap_or(Path::new(".")).join(rel);
        if let Some(map) = self.normal_maps.borrow().get(&resolved) {
            return Ok((resolved, map.clone()));
        }
        let (width, height, texels) = self.normal_map_texels(path, rel, &resolved)?;
        let map = (
            width,
            height,
            std::sync::Arc::new(crate::bump::Texels::new(texels)),
        );
        self.normal_maps
            .borrow_mut()
            .insert(resolved.clone(), map.clone());
        Ok((resolved, map))
    }

    /// A normal map PNG (`rel` as the scene wrote it, read from `resolved`, relative to the
    /// scene's folder): 8-bit RGB or RGBA (alpha ignored),
    /// at most [`MAX_NORMAL_MAP_SIDE`] texels a side (checked from the header, before
    /// decoding), every texel's blue above 127 (its normal points out of the mirror).
    fn normal_map_texels(
        &self,
        path: &FieldPath,
        rel: &str,
        resolved: &Path,
    ) -> Result<(u32, u32, Vec<[u8; 3]>)> {
        use image::ImageDecoder;
        let bad = |msg: String| {
            self.invalid(
                path,
                format!("\"{rel}\" (at {}): {msg}", resolved.display()),
            )
        };
        let bytes =
            mirrorbox_files::read_bounded(resolved, MAX_NORMAL_MAP_FILE_BYTES, "normal map")
                .map_err(|e| bad(e.message))?;
        let decoder = image::codecs::png::PngDecoder::new(std::io::Cursor::new(&bytes))
            .map_err(|e| bad(format!("not a readable PNG file ({e})")))?;
        let (w, h) = decoder.dimensions();
        if w == 0 || h == 0 || w > MAX_NORMAL_MAP_SIDE || h > MAX_NORMAL_MAP_SIDE {
            return Err(bad(format!(
                "is {w}×{h} texels; a normal map must be 1 to {MAX_NORMAL_MAP_SIDE} texels a side"
            )));
        }
        let color = decoder.color_type();
        let channels = match color {
            image::ColorType::Rgb8 => 3,
            image::ColorType::Rgba8 => 4,
            other => {
                return Err(bad(format!(
                    "has {other:?} texels; a normal map must be 8-bit RGB or RGBA"
                )));
            }
        };
        let mut raw = vec![0u8; decoder.total_bytes() as usize];
        decoder
            .read_image(&mut raw)
            .map_err(|e| bad(format!("cannot decode the PNG ({e})")))?;
        let texels: Vec<[u8; 3]> = raw
            .chunks_exact(channels)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        if let Some(k) = texels.iter().position(|t| t[2] <= 127) {
            let (x, y) = (k as u32 % w, k as u32 / w);
            return Err(bad(format!(
                "texel ({x}, {y}) has blue {} ≤ 127: its normal would point into the mirror \
                 (a tangent-space normal map's blue is above 127)",
                texels[k][2]
            )));
        }
        Ok((w, h, texels))
    }

    fn light(&self, path: &FieldPath, l: &LightDesc) -> Result<PointLight> {
        Ok(PointLight {
            position: self.position(&path.field("position"), l.position)?,
            intensity: self.radiance(&path.field("intensity"), Some(l.intensity))?,
        })
    }

    fn object(
        &self,
        path: &FieldPath,
        index: usize,
        o: &ObjectDesc,
        geometry: &mut Geometry,
        assets: &mut AssetExtras,
    ) -> Result<()> {
        let present = [
            ("size", o.size.is_some()),
            ("radius", o.radius.is_some()),
            ("subdivisions", o.subdivisions.is_some()),
            ("path", o.path.is_some()),
            ("scene", o.scene.is_some()),
            ("curved_mirrors", o.curved_mirrors.is_some()),
        ];
        let allowed = o.kind.allowed_fields();
        for (field, is_present) in present {
            if is_present && !allowed.contains(&field) {
                return Err(self.invalid(
                    &path.field(field),
                    format!(
                        "is not a field of a \"{}\" object (its shape fields: {})",
                        o.kind.name(),
                        allowed.join(", ")
                    ),
                ));
            }
        }
        let local = match o.kind {
            ShapeKind::Box => {
                let s = self.sizes(&path.field("size"), o.size.as_deref(), &defaults::BOX_SIZE)?;
                tessellate::cuboid(Vec3::new(s[0], s[1], s[2]))
            }
            ShapeKind::Quad => {
                let s = self.sizes(&path.field("size"), o.size.as_deref(), &defaults::QUAD_SIZE)?;
                tessellate::quad(s[0], s[1])
            }
            ShapeKind::Sphere => {
                let radius = self.positive(
                    &path.field("radius"),
                    o.radius.unwrap_or(defaults::SPHERE_RADIUS),
                )?;
                let level = o.subdivisions.unwrap_or(defaults::SPHERE_SUBDIVISIONS);
                if level > MAX_SPHERE_SUBDIVISIONS {
                    return Err(self.invalid(
                        &path.field("subdivisions"),
                        format!("must be in [0, {MAX_SPHERE_SUBDIVISIONS}] (20·4^s triangles), got {level}"),
                    ));
                }
                self.triangle_budget(path, geometry.triangles.len(), 20 << (2 * level))?;
                tessellate::icosphere(radius, level)
            }
            ShapeKind::Gltf => {
                for (field, given) in [
                    ("albedo", o.albedo.is_some()),
                    ("emission", o.emission.is_some()),
                ] {
                    if given {
                        return Err(self.invalid(
                            &path.field(field),
                            "is not a field of a \"gltf\" object: its materials give albedo and emission (docs/gltf.md)",
                        ));
                    }
                }
                return self.gltf(path, index, o, geometry, assets);
            }
            ShapeKind::Mesh => {
                let mesh_path = path.field("path");
                let rel = o
                    .path
                    .as_deref()
                    .ok_or_else(|| self.invalid(&mesh_path, "is required for a \"mesh\" object (an OBJ file, relative to the scene file)"))?;
                let (tris, notes) = self.obj(&mesh_path, rel, geometry.triangles.len())?;
                geometry
                    .obj_notes
                    .extend(notes.into_iter().map(|n| format!("{mesh_path}: {n}")));
                tris
            }
        };
        self.triangle_budget(path, geometry.triangles.len(), local.len() as u64)?;
        let transform_path = path.field("transform");
        let transform = self.transform(&transform_path, o.transform.as_ref())?;
        let flips = transform.determinant() < 0.0;
        let world: Vec<[Vec3; 3]> = local
            .into_iter()
            .map(|t| {
                let [a, b, c] = t.map(|p| transform.transform_point3(p));
                if flips { [a, c, b] } else { [a, b, c] }
            })
            .collect();
        if let Some(p) = world.iter().flatten().find(|p| !within_extent(**p)) {
            // The transform where there is one; else the object's own geometry is out.
            let (field, verb) = match o.transform {
                Some(_) => (&transform_path, "places"),
                None => (path, "has"),
            };
            return Err(self.invalid(
                field,
                format!(
                    "{verb} the vertex {} outside the scene extent: every coordinate must be within ±{MAX_COORDINATE:e}",
                    show(*p)
                ),
            ));
        }
        let surface = Surface::diffuse(
            self.reflectance(&path.field("albedo"), o.albedo, defaults::ALBEDO)?,
            self.radiance(&path.field("emission"), o.emission)?,
        );
        let name = o
            .name
            .clone()
            .unwrap_or_else(|| format!("{} {index}", o.kind.name()));
        geometry.push_part(name, surface, world);
        Ok(())
    }

    /// A glTF asset's parts into `geometry`, its mirrors and lights into `assets`.
    fn gltf(
        &self,
        path: &FieldPath,
        index: usize,
        o: &ObjectDesc,
        geometry: &mut Geometry,
        assets: &mut AssetExtras,
    ) -> Result<()> {
        let file_path = path.field("path");
        let rel = o.path.as_deref().ok_or_else(|| {
            self.invalid(&file_path, "is required for a \"gltf\" object (a .gltf or .glb file, relative to the scene file)")
        })?;
        let transform = self.transform(&path.field("transform"), o.transform.as_ref())?;
        let resolved: PathBuf = self.file.parent().unwrap_or(Path::new(".")).join(rel);
        let texels: u64 = geometry
            .textures
            .iter()
            .map(|t| u64::from(t.width) * u64::from(t.height))
            .sum();
        let options = gltf_asset::GltfOptions {
            scene: o.scene,
            triangle_budget: (MAX_TRIANGLES - geometry.triangles.len().min(MAX_TRIANGLES)) as u64,
            texel_budget: MAX_TEXTURE_TEXELS.saturating_sub(texels),
            transform,
            curved_mirrors: match o.curved_mirrors {
                Some(CurvedMirrorsDesc::Diffuse) => gltf_asset::CurvedMirrors::Diffuse,
                _ => gltf_asset::CurvedMirrors::Refuse,
            },
        };
        let known = self
            .gltf_images
            .borrow()
            .get(&resolved)
            .cloned()
            .unwrap_or_default();
        let texture_base = geometry.textures.len() as u32;
        let asset = gltf_asset::load_gltf_reusing(&resolved, &options, texture_base, &known)
            .map_err(|e| {
                let at = if resolved.to_string_lossy() == rel {
                    String::new()
                } else {
                    format!(" (at {})", resolved.display())
                };
                self.invalid(&file_path, format!("glTF \"{rel}\"{at}: {e}"))
            })?;
        geometry.textures.extend(asset.textures);
        self.gltf_images
            .borrow_mut()
            .insert(resolved.clone(), asset.texture_of_image);
        let object_name = o.name.clone().unwrap_or_else(|| format!("gltf {index}"));
        for part in asset.parts {
            let surface = part.surface;
            geometry.push_textured_part(
                format!("{object_name}: {}", part.name),
                surface,
                part.triangles,
                part.uvs,
            );
        }
        geometry
            .obj_notes
            .extend(asset.notes.into_iter().map(|n| format!("{file_path}: {n}")));
        assets
            .mirrors
            .extend(asset.mirrors.into_iter().map(|m| (path.clone(), m)));
        assets.lights.extend(asset.lights);
        assets.cameras.push((rel.to_string(), asset.cameras));
        Ok(())
    }

    /// Positive edge lengths, exactly as many as `default` has.
    fn sizes(&self, path: &FieldPath, given: Option<&[f32]>, default: &[f32]) -> Result<Vec<f32>> {
        let values = given.unwrap_or(default);
        if values.len() != default.len() {
            return Err(self.invalid(
                path,
                format!("must have {} numbers, got {}", default.len(), values.len()),
            ));
        }
        values
            .iter()
            .enumerate()
            .map(|(i, &x)| self.positive(&path.index(i), x))
            .collect()
    }

    /// `T · Rz · Ry · Rx · S` (scale, then rotate about x, y, z, then translate).
    fn transform(&self, path: &FieldPath, t: Option<&TransformDesc>) -> Result<Mat4> {
        let default = TransformDesc::default();
        let t = t.unwrap_or(&default);
        let translate = self.vec3(&path.field("translate"), t.translate.unwrap_or([0.0; 3]))?;
        let angles = self.vec3(&path.field("rotate_deg"), t.rotate_deg.unwrap_or([0.0; 3]))?;
        let scale_path = path.field("scale");
        let scale = match t.scale {
            None => Vec3::ONE,
            Some(Scale::Uniform(s)) => Vec3::splat(self.finite(&scale_path, s)?),
            Some(Scale::PerAxis(v)) => self.vec3(&scale_path, v)?,
        };
        if scale.cmpeq(Vec3::ZERO).any() {
            return Err(self.invalid(
                &scale_path,
                format!("must be non-zero on every axis, got {}", show(scale)),
            ));
        }
        let rotation = Quat::from_euler(
            EulerRot::ZYX,
            angles.z.to_radians(),
            angles.y.to_radians(),
            angles.x.to_radians(),
        );
        Ok(Mat4::from_scale_rotation_translation(
            scale, rotation, translate,
        ))
    }

    /// Triangles of an OBJ file, relative to the scene file's folder, and what loading it
    /// passed over ([`obj_text`]).
    fn obj(
        &self,
        path: &FieldPath,
        rel: &str,
        have: usize,
    ) -> Result<(Vec<[Vec3; 3]>, Vec<String>)> {
        let resolved: PathBuf = self.file.parent().unwrap_or(Path::new(".")).join(rel);
        let bytes = mirrorbox_files::read_bounded(&resolved, MAX_OBJ_FILE_BYTES, "OBJ file")
            .map_err(|e| {
                self.invalid(
                    path,
                    format!("\"{rel}\" (at {}): {}", resolved.display(), e.message),
                )
            })?;
        let (bytes, notes) = obj_text(&bytes)
            .map_err(|why| self.invalid(path, format!("OBJ file \"{rel}\": {why}")))?;
        self.triangle_budget(path, have, obj_triangle_count(&bytes))?;
        let models = parse_obj(&bytes).map_err(|(line, e)| {
            // The line itself, so that a user can see what the parser could not read.
            let text = |l: usize| {
                let t = String::from_utf8_lossy(bytes.split(|&b| b == b'\n').nth(l - 1)?);
                // Control characters (an escape sequence in a broken file) shown, not sent
                // to the terminal.
                let t: String = t
                    .trim()
                    .chars()
                    .take(60)
                    .map(|c| if c.is_control() { '\u{fffd}' } else { c })
                    .collect();
                (!t.is_empty()).then(|| format!(" (`{t}`)"))
            };
            let at = line
                .map(|l| format!(" at line {l}{}", text(l).unwrap_or_default()))
                .unwrap_or_default();
            self.invalid(path, format!("malformed OBJ file \"{rel}\"{at}: {e}"))
        })?;
        let mut tris = Vec::new();
        for model in &models {
            let m = &model.mesh;
            let vertex = |i: u32| {
                let i = i as usize * 3;
                Vec3::new(m.positions[i], m.positions[i + 1], m.positions[i + 2])
            };
            for f in m.indices.chunks_exact(3) {
                tris.push([vertex(f[0]), vertex(f[1]), vertex(f[2])]);
            }
        }
        if let Some(bad) = tris.iter().flatten().find(|p| !p.is_finite()) {
            // The line of the first `v` whose coordinates overflow f32 (`1e39`).
            let line = bytes
                .split(|&b| b == b'\n')
                .position(|l| {
                    let t = String::from_utf8_lossy(l);
                    let mut words = t.split_whitespace();
                    words.next() == Some("v")
                        && words
                            .take(3)
                            .any(|x| x.parse::<f32>().is_ok_and(|v| !v.is_finite()))
                })
                .map_or(String::new(), |i| format!(" at line {}", i + 1));
            return Err(self.invalid(
                path,
                format!(
                    "OBJ file \"{rel}\" has a non-finite vertex {}{line}: coordinates are \
                     finite 32-bit numbers (|x| below 3.4e38)",
                    show(*bad)
                ),
            ));
        }
        if tris.is_empty() {
            return Err(self.invalid(
                path,
                format!(
                    "OBJ file \"{rel}\" contains no faces (points and lines are not drawn; a \
                     mesh needs `f` statements)"
                ),
            ));
        }
        Ok((tris, notes))
    }
}

/// An OBJ file's bytes as the parser reads them, and what was passed over:
/// - UTF-16 text (a byte-order mark, as some exporters write) is decoded to UTF-8;
/// - bytes that are not UTF-8 (a material or group name in another encoding) become U+FFFD:
///   only names can hold them, and no name is read;
/// - material statements (`mtllib`, `usemtl`) are blanked, keeping the line count for error
///   positions: the scene gives each object its albedo, so a broken one (an empty name) must
///   not refuse the geometry; each broken one is noted.
fn obj_text(bytes: &[u8]) -> std::result::Result<(Vec<u8>, Vec<String>), String> {
    let mut notes = Vec::new();
    let utf16 = |big_endian: bool| -> std::result::Result<String, String> {
        let units = bytes[2..].chunks(2).map(|c| {
            let pair = [c[0], *c.get(1).unwrap_or(&0)];
            if big_endian {
                u16::from_be_bytes(pair)
            } else {
                u16::from_le_bytes(pair)
            }
        });
        char::decode_utf16(units)
            .collect::<std::result::Result<String, _>>()
            .map_err(|_| {
                "is UTF-16 text (it starts with a byte-order mark) that does not decode; save it \
                 as UTF-8 or ASCII"
                    .to_string()
            })
    };
    let text: String = match bytes {
        [0xFE, 0xFF, ..] => {
            notes.push("UTF-16 (big-endian) text, decoded".to_string());
            utf16(true)?
        }
        [0xFF, 0xFE, ..] => {
            notes.push("UTF-16 (little-endian) text, decoded".to_string());
            utf16(false)?
        }
        _ => {
            let text = String::from_utf8_lossy(bytes);
            if let std::borrow::Cow::Owned(_) = text {
                notes.push("bytes that are not UTF-8 (in names, which are not read)".to_string());
            }
            text.into_owned()
        }
    };
    let mut out = String::with_capacity(text.len());
    for (i, line) in text.split_inclusive('\n').enumerate() {
        let mut words = line.split_whitespace();
        let keyword = words.next();
        if matches!(keyword, Some("usemtl" | "mtllib")) {
            if words.next().is_none() {
                notes.push(format!(
                    "line {}: `{}` without a name, ignored",
                    i + 1,
                    keyword.unwrap_or_default()
                ));
            }
            if line.ends_with('\n') {
                out.push('\n');
            }
        } else {
            out.push_str(line);
        }
    }
    Ok((out.into_bytes(), notes))
}

fn obj_options() -> tobj::LoadOptions {
    tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    }
}

fn parse_obj_prefix(bytes: &[u8]) -> std::result::Result<Vec<tobj::Model>, tobj::LoadError> {
    let mut reader = std::io::BufReader::new(bytes);
    // Materials are not used (the scene gives albedo); a missing .mtl is not an error.
    tobj::load_obj_buf(&mut reader, &obj_options(), |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map(|(models, _materials)| models)
}

/// Parses an OBJ with tobj. tobj's errors carry no position, so on failure the first failing
/// line is found by bisecting over byte offsets, each extended to its line's end (parsing is
/// sequential: once a prefix fails, every longer one does) — no per-line table is built.
fn parse_obj(
    bytes: &[u8],
) -> std::result::Result<Vec<tobj::Model>, (Option<usize>, tobj::LoadError)> {
    let err = match parse_obj_prefix(bytes) {
        Ok(models) => return Ok(models),
        Err(e) => e,
    };
    // The end of the line holding byte `p - 1` (0 for the empty prefix).
    let line_end = |p: usize| -> usize {
        if p == 0 || bytes[p - 1] == b'\n' {
            p
        } else {
            bytes[p..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(bytes.len(), |i| p + i + 1)
        }
    };
    let fails = |p: usize| parse_obj_prefix(&bytes[..line_end(p)]).is_err();
    let (mut lo, mut hi) = (0usize, bytes.len()); // the whole file fails
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if fails(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    let end = line_end(lo);
    let line = (end > 0).then(|| 1 + bytes[..end - 1].iter().filter(|&&b| b == b'\n').count());
    Err((line, err))
}

/// Triangles the faces of an OBJ make once triangulated (k − 2 for a face of k vertices),
/// counted without parsing a number, so the scene's budget is checked before tobj allocates.
fn obj_triangle_count(bytes: &[u8]) -> u64 {
    bytes
        .split(|&b| b == b'\n')
        .filter_map(|line| {
            let mut tokens = line
                .split(|b| b.is_ascii_whitespace())
                .filter(|t| !t.is_empty());
            (tokens.next()? == b"f").then(|| tokens.count().saturating_sub(2) as u64)
        })
        .sum()
}

fn show(v: Vec3) -> String {
    format!("[{}, {}, {}]", v.x, v.y, v.z)
}

/// A problem of the camera's frame where a glTF object's camera gave it (`camera.gltf`): the
/// scene file has no `camera.position`, `look_at`, `up` or `fov_y_deg` to blame, so the
/// error names the field that chose the camera (`camera.index`, or `camera.gltf` where the
/// index is left at 0) and which of the camera's values is wrong.
fn gltf_camera_error(e: SceneError, camera: &CameraDesc) -> SceneError {
    let chosen_by = if camera.index.is_some() {
        "camera.index"
    } else {
        "camera.gltf"
    };
    match e {
        SceneError::Invalid {
            file,
            path,
            message,
        } if camera.gltf.is_some()
            && ["position", "look_at", "up", "fov_y_deg"]
                .iter()
                .any(|f| path == format!("camera.{f}")) =>
        {
            let value = path.trim_start_matches("camera.").to_string();
            SceneError::Invalid {
                file,
                path: chosen_by.into(),
                message: format!("the glTF camera's {value} (camera.gltf's asset): {message}"),
            }
        }
        e => e,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CAMERA: &str = r#""camera": { "position": [0, 1, 3], "look_at": [0, 1, 0], "fov_y_deg": 60, "width": 32, "height": 24 }"#;

    fn scene_with(rest: &str) -> Result<Scene> {
        parse_scene(&format!("{{ {CAMERA}{rest} }}"), Path::new("s.json"))
    }

    /// A byte-order mark and a document that is not one object are said in words, not in
    /// serde's ("expected value", "expected struct SceneFile with 9 elements").
    #[test]
    fn a_bom_or_a_document_that_is_not_an_object_is_said_in_words() {
        let good = format!("{{ {CAMERA} }}");
        for (text, says) in [
            (
                format!("\u{feff}{good}"),
                "s.json:1:1: the file starts with a UTF-8 byte-order mark",
            ),
            (
                "[]".to_string(),
                "s.json:1:1: a scene file is one JSON object",
            ),
            (
                "  \"camera\"".to_string(),
                "a scene file is one JSON object",
            ),
        ] {
            let e = parse_scene(&text, Path::new("s.json"))
                .unwrap_err()
                .to_string();
            assert!(e.contains(says), "{e}");
        }
        assert!(parse_scene(&good, Path::new("s.json")).is_ok());
    }

    fn refused(rest: &str) -> String {
        match scene_with(rest) {
            Ok(_) => panic!("accepted: {rest}"),
            Err(e) => e.to_string(),
        }
    }

    /// A normal map named by many mirrors is read and decoded once (issue 51): every mirror
    /// shares its texels; two files are two maps.
    #[test]
    fn a_normal_map_shared_by_many_mirrors_is_decoded_once() {
        let mirror = |x: f32, map: &str| {
            format!(
                r#"{{ "center": [{x}, 1, 0], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 0.5,
                     "height": 0.5, "bump": {{ "normal_map": {{ "path": "{map}" }} }} }}"#
            )
        };
        let mut mirrors: Vec<String> = (0..50)
            .map(|k| mirror(k as f32, "textures/hammered.png"))
            .collect();
        // The same file by another spelling of its path is another read (paths are not
        // canonicalised), but still the same image.
        mirrors.push(mirror(60.0, "textures/../textures/hammered.png"));
        let text = format!("{{ {CAMERA}, \"mirrors\": [{}] }}", mirrors.join(","));
        let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/shared.json");
        let scene = parse_scene(&text, &scenes).unwrap();
        let texels = |k: usize| {
            std::sync::Arc::clone(
                &scene.bumps[k]
                    .as_ref()
                    .unwrap()
                    .normal_map
                    .as_ref()
                    .unwrap()
                    .texels,
            )
        };
        assert!((1..50).all(|k| std::sync::Arc::ptr_eq(&texels(0), &texels(k))));
        assert!(!std::sync::Arc::ptr_eq(&texels(0), &texels(50)));
        assert_eq!(*texels(0), *texels(50));
    }

    /// OBJ text as the parser reads it: UTF-16 decoded, stray bytes replaced, material
    /// statements blanked with their lines kept, a nameless one noted.
    #[test]
    fn obj_text_passes_over_what_the_scene_never_reads() {
        let plain = b"v 0 0 0\nusemtl red\nmtllib a.mtl\nusemtl \nf 1 2 3\n";
        let (text, notes) = obj_text(plain).unwrap();
        assert_eq!(
            text, b"v 0 0 0\n\n\n\nf 1 2 3\n",
            "lines kept, statements blanked"
        );
        assert_eq!(notes, ["line 4: `usemtl` without a name, ignored"]);
        let mut be = vec![0xFE, 0xFF];
        let mut le = vec![0xFF, 0xFE];
        for u in "v 1 2 3\n".encode_utf16() {
            be.extend(u.to_be_bytes());
            le.extend(u.to_le_bytes());
        }
        assert_eq!(obj_text(&be).unwrap().0, b"v 1 2 3\n");
        assert_eq!(obj_text(&le).unwrap().0, b"v 1 2 3\n");
        let (text, notes) = obj_text(b"g caf\xe9\nv 0 0 0\n").unwrap();
        assert!(text.ends_with(b"v 0 0 0\n"));
        assert_eq!(notes.len(), 1, "{notes:?}");
        // An unpaired surrogate does not decode: refused with what to do.
        let e = obj_text(&[0xFE, 0xFF, 0xD8, 0x00]).unwrap_err();
        assert!(e.contains("save it as UTF-8"), "{e}");
    }

    #[test]
    fn a_camera_path_is_read_and_checked_key_by_key() {
        let with_path = |keys: &str| {
            parse_scene(
                &format!(
                    r#"{{ "camera": {{ "position": [0, 1, 3], "look_at": [0, 1, 0], "fov_y_deg": 60,
                    "width": 32, "height": 24, "path": [ {keys} ] }} }}"#
                ),
                Path::new("s.json"),
            )
        };
        let scene = with_path(
            r#"{ "time": 0, "position": [0, 1, 3], "look_at": [0, 1, 0] },
               { "time": 2, "position": [1, 1, 2], "look_at": [0, 1, 0], "fov_y_deg": 50 }"#,
        )
        .unwrap();
        let path = scene.camera_path.as_ref().unwrap();
        assert_eq!(path.keys().len(), 2);
        assert_eq!(path.keys()[0].fov_y_deg, 60.0, "default: the camera's");
        let at_end = scene.at_time(5.0).unwrap();
        assert_eq!(at_end.camera.position, glam::Vec3::new(1.0, 1.0, 2.0));
        assert_eq!(at_end.camera.fov_y_deg, 50.0);
        assert_eq!((at_end.camera.width, at_end.camera.height), (32, 24));
        // No path: any time is the scene itself.
        let still = scene_with("").unwrap();
        assert_eq!(still.at_time(3.0).unwrap().camera, still.camera);
        let key = |time: &str, extra: &str| {
            format!(r#"{{ "time": {time}, "position": [0, 1, 3], "look_at": [0, 1, 0]{extra} }}"#)
        };
        for (keys, words) in [
            (
                String::new(),
                "camera.path: must hold 1 to 10000 keys, got 0",
            ),
            (
                format!("{}, {}", key("1", ""), key("1", "")),
                "camera.path[1].time: must be later than the key before it (1 s), got 1 s",
            ),
            (
                key("1e12", ""),
                "camera.path[0].time: must be a finite number",
            ),
            (
                r#"{ "time": 0, "position": [0, 1, 3], "look_at": [0, 1, 3] }"#.to_string(),
                "camera.path[0].look_at: must differ from the key's position",
            ),
            (
                key("0", r#", "up": [0, 0, 1]"#),
                "camera.path[0].up: must not be parallel",
            ),
            (
                key("0", r#", "fov_y_deg": 180"#),
                "camera.path[0].fov_y_deg: must be in (0, 170]",
            ),
            (key("0", r#", "roll": 3"#), "roll"),
        ] {
            let e = with_path(&keys).unwrap_err().to_string();
            assert!(e.contains("s.json") && e.contains(words), "{keys}: {e}");
        }
    }

    #[test]
    fn a_stereo_camera_is_read_and_checked_field_by_field() {
        let stereo = |fields: &str| {
            parse_scene(
                &format!(
                    r#"{{ "camera": {{ "position": [0, 1, 3], "look_at": [0, 1, 0], "fov_y_deg": 60,
                    "width": 32, "height": 24, "stereo": {{ {fields} }} }} }}"#
                ),
                Path::new("s.json"),
            )
        };
        let s = stereo(r#""ipd": 0.064"#).unwrap().stereo.unwrap();
        assert_eq!(s.convergence, crate::stereo::Convergence::OffAxis);
        assert_eq!(
            s.convergence_distance, 3.0,
            "default: the distance to look_at"
        );
        let s = stereo(r#""ipd": 0.05, "convergence": "toe-in", "convergence_distance": 2"#)
            .unwrap()
            .stereo
            .unwrap();
        assert_eq!(
            (s.convergence, s.convergence_distance),
            (crate::stereo::Convergence::ToeIn, 2.0)
        );
        for (fields, words) in [
            (r#""ipd": -0.1"#, "camera.stereo.ipd"),
            (r#""ipd": 2"#, "[0, 1]"),
            (
                r#""ipd": 0.1, "convergence": "crossed""#,
                "camera.stereo.convergence",
            ),
            (
                r#""ipd": 0.1, "convergence_distance": 0"#,
                "camera.stereo.convergence_distance",
            ),
        ] {
            let e = stereo(fields).unwrap_err().to_string();
            assert!(e.contains(words), "{fields}: {e}");
        }
        assert!(scene_with("").unwrap().stereo.is_none());
    }

    #[test]
    fn positions_beyond_the_scene_extent_are_refused_with_their_field() {
        let e = refused(
            r#", "objects": [ { "type": "box", "transform": { "translate": [3.4e38, 0, 0] } } ]"#,
        );
        assert!(
            e.contains("objects[0].transform") && e.contains("scene extent"),
            "{e}"
        );
        let e =
            refused(r#", "objects": [ { "type": "sphere", "radius": 2e6, "subdivisions": 0 } ]"#);
        assert!(e.contains("objects[0]: has the vertex"), "{e}");
        let e = refused(
            r#", "mirrors": [ { "center": [0, 0, -2], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 3e6, "height": 1 } ]"#,
        );
        assert!(e.contains("mirrors[0].width"), "{e}");
        let e = refused(r#", "lights": [ { "position": [0, -1e7, 0], "intensity": [1, 1, 1] } ]"#);
        assert!(e.contains("lights[0].position"), "{e}");
        // At the limit is fine.
        scene_with(
            r#", "objects": [ { "type": "box", "transform": { "translate": [999999, 0, 0] } } ]"#,
        )
        .unwrap();
    }

    #[test]
    fn the_triangle_budget_is_checked_before_tessellating() {
        // 13 spheres at level 7 = 4 259 840 > 2²² triangles; the 13th is refused.
        let sphere = r#"{ "type": "sphere", "subdivisions": 7 }"#;
        let many = vec![sphere; 13].join(", ");
        let e = refused(&format!(r#", "objects": [ {many} ]"#));
        assert!(
            e.contains("objects[12]") && e.contains("at most 4194304") && e.contains("GiB"),
            "{e}"
        );
    }

    #[test]
    fn an_obj_path_to_a_device_or_folder_is_refused_without_reading() {
        let dir = std::env::temp_dir();
        for (path, kind) in [("/dev/zero", "character device"), (".", "folder")] {
            let text =
                format!(r#"{{ {CAMERA}, "objects": [ {{ "type": "mesh", "path": "{path}" }} ] }}"#);
            let e = parse_scene(&text, &dir.join("s.json"))
                .unwrap_err()
                .to_string();
            assert!(e.contains("objects[0].path") && e.contains(kind), "{e}");
        }
    }

    /// An overflowing vertex is named with its line and what is allowed; a broken line's
    /// control characters (an escape sequence) are not echoed to the terminal.
    #[test]
    fn a_broken_obj_line_is_named_safely() {
        let dir = tempfile::tempdir().unwrap();
        let scene = |obj: &str| {
            std::fs::write(dir.path().join("m.obj"), obj).unwrap();
            let text =
                format!(r#"{{ {CAMERA}, "objects": [ {{ "type": "mesh", "path": "m.obj" }} ] }}"#);
            parse_scene(&text, &dir.path().join("s.json"))
                .unwrap_err()
                .to_string()
        };
        let e = scene("v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n");
        assert!(
            e.contains("non-finite vertex") && e.contains("at line 2") && e.contains("3.4e38"),
            "{e}"
        );
        let e = scene("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \u{1b}[31m\u{7}\n");
        assert!(!e.chars().any(|c| c.is_control() && c != '\n'), "{e:?}");
    }

    #[test]
    fn an_obj_is_counted_against_the_budget_before_it_is_parsed() {
        let dir = tempfile::tempdir().unwrap();
        // One face of 4.2 M corners: 8 MB of text, 4.2 M triangles once triangulated.
        let mut obj = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
        obj.push_str(&" 1 2 3".repeat(1_400_000));
        std::fs::write(dir.path().join("fan.obj"), obj).unwrap();
        let text =
            format!(r#"{{ {CAMERA}, "objects": [ {{ "type": "mesh", "path": "fan.obj" }} ] }}"#);
        let e = parse_scene(&text, &dir.path().join("s.json"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("objects[0].path") && e.contains("adds 4199998 triangles"),
            "{e}"
        );
        assert_eq!(
            obj_triangle_count(b"f 1 2 3\nv 1 2 3\n  f 1 2 3 4 5\nf 1 2"),
            1 + 3
        );
    }

    /// A mesh vertex outside the scene extent is the transform's fault only where there is
    /// one: without, the object itself is named (it had named a `transform` the file lacks).
    #[test]
    fn a_far_vertex_names_the_transform_or_the_object() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("far.obj"),
            "v 0 0 0\nv 2e6 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        std::fs::write(
            dir.path().join("near.obj"),
            "v 0 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        for (object, says) in [
            (r#""path": "far.obj""#, "objects[0]: has the vertex"),
            (
                r#""path": "near.obj", "transform": {"scale": 1e6}"#,
                "objects[0].transform: places the vertex",
            ),
        ] {
            let text = format!(r#"{{ {CAMERA}, "objects": [ {{ "type": "mesh", {object} }} ] }}"#);
            let e = parse_scene(&text, &dir.path().join("s.json"))
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(says) && e.contains("outside the scene extent"),
                "{e}"
            );
        }
    }

    #[test]
    fn a_malformed_obj_line_is_found_by_bisection() {
        let good = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        for bad_line in 1..=4 {
            let mut lines: Vec<&[u8]> = good.split(|&b| b == b'\n').collect();
            lines[bad_line - 1] = b"v x y z";
            let text = lines.join(&b'\n');
            let (line, _) = parse_obj(&text).unwrap_err();
            assert_eq!(line, Some(bad_line), "{}", String::from_utf8_lossy(&text));
        }
    }

    #[test]
    fn a_scene_file_that_is_not_a_regular_file_is_refused() {
        let e = load_scene(Path::new("/dev/urandom"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("/dev/urandom") && e.contains("regular file"),
            "{e}"
        );
    }

    #[test]
    fn symmetry_planes_are_validated_with_their_field() {
        let plane = r#"{ "point": [0, 0, 0], "normal": [1, 0, 0] }"#;
        let cases = [
            (
                r#"{ "point": [0, 0, 0], "normal": [0, 0, 0] }"#,
                "symmetry_planes[0].normal: must be a non-zero direction",
            ),
            (
                r#"{ "point": [0, 2e6, 0], "normal": [0, 1, 0] }"#,
                "symmetry_planes[0].point: must lie within the scene extent",
            ),
            (
                r#"{ "point": [0, 0, 1e39], "normal": [0, 1, 0] }"#,
                "symmetry_planes[0].point[2]: must be a finite number",
            ),
            (
                r#"{ "point": [0, 0, 0], "normal": [1, 0, 0], "offset": 1 }"#,
                "symmetry_planes[0].offset: unknown field `offset`",
            ),
            (r#"{ "normal": [1, 0, 0] }"#, "missing field `point`"),
        ];
        for (desc, expected) in cases {
            let e = refused(&format!(r#", "symmetry_planes": [ {desc} ]"#));
            assert!(e.contains("s.json") && e.contains(expected), "{e}");
        }
        let seventeen = vec![plane; 17].join(", ");
        let e = refused(&format!(r#", "symmetry_planes": [ {seventeen} ]"#));
        assert!(
            e.contains("symmetry_planes: at most 16 planes") && e.contains("got 17"),
            "{e}"
        );
        let sixteen = vec![plane; 16].join(", ");
        scene_with(&format!(r#", "symmetry_planes": [ {sixteen} ]"#)).unwrap();
    }

    #[test]
    fn symmetry_planes_are_baked_into_the_geometry_in_order() {
        let objects = r#", "objects": [ { "type": "box", "transform": { "translate": [0.2, 0, 0] } } ],
            "mirrors": [ { "center": [0, 0, -3], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 2, "height": 2 } ]"#;
        let plain = scene_with(objects).unwrap();
        assert!(plain.symmetry.is_none());
        let empty = scene_with(&format!(r#"{objects}, "symmetry_planes": []"#)).unwrap();
        assert!(empty.symmetry.is_none());
        assert_eq!(empty.geometry, plain.geometry);
        let s = scene_with(&format!(
            r#"{objects}, "symmetry_planes": [ {{ "name": "x", "point": [0, 0, 0], "normal": [2, 0, 0] }},
                {{ "point": [0, 0.1, 0], "normal": [0, 1, 0] }} ]"#
        ))
        .unwrap();
        let symmetry = s.symmetry.as_ref().unwrap();
        assert_eq!(symmetry.planes[0].name, "x");
        assert_eq!(symmetry.planes[1].name, "plane 1");
        assert_eq!(symmetry.planes[0].plane.normal, Vec3::X);
        assert_eq!(symmetry.source.triangles, plain.geometry.triangles[..12]);
        let baked =
            symmetry::split_and_mirror(&symmetry.source, &symmetry.plane_list(), usize::MAX)
                .unwrap();
        let objects_end = baked.triangles.len();
        assert_eq!(s.geometry.triangles[..objects_end], baked.triangles[..]);
        // The mirror follows the baked objects, untouched.
        assert_eq!(
            s.geometry.triangles[objects_end..],
            plain.geometry.triangles[12..]
        );
        assert_eq!(s.geometry.mirror_triangle_count(), 2);
    }

    #[test]
    fn a_bake_past_the_triangle_budget_is_refused_naming_the_plane() {
        // 20 480 triangles, wholly in front of every plane: each doubles them, so plane 7
        // would take the bake to 2⁸ · 20 480 = 5 242 880 > 2²² (the mirror takes 2 more).
        // Plane k lies at −2·4^k on axis k mod 3, beyond everything earlier planes made.
        let planes: Vec<String> = (0..8)
            .map(|k| {
                let mut point = [0.0; 3];
                let mut normal = [0; 3];
                point[k % 3] = -2.0 * 4f32.powi(k as i32);
                normal[k % 3] = 1;
                format!(r#"{{ "point": {point:?}, "normal": {normal:?} }}"#)
            })
            .collect();
        let e = refused(&format!(
            r#", "objects": [ {{ "type": "sphere", "subdivisions": 5 }} ], "symmetry_planes": [ {} ]"#,
            planes.join(", ")
        ));
        assert!(
            e.contains("symmetry_planes[7]: after plane 7")
                && e.contains("5242880 triangles")
                && e.contains("4194304"),
            "{e}"
        );
    }

    /// A glTF file named by several objects has its images decoded once (issue 51): three
    /// instances of the textured cube hold the textures of one, and every instance's maps
    /// name those same textures (the scene texture numbers of the first), in range.
    #[test]
    fn a_gltf_file_instanced_many_times_decodes_its_images_once() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/scene.json");
        let scene = |objects: usize| {
            let objects: Vec<String> = (0..objects)
                .map(|i| {
                    format!(
                        r#"{{ "type": "gltf", "path": "assets/textured_cube.gltf",
                        "transform": {{ "translate": [{}, 0, 0] }} }}"#,
                        2 * i
                    )
                })
                .collect();
            parse_scene(
                &format!(
                    r#"{{ "camera": {{ "position": [0, 1, 5], "look_at": [0, 0, 0], "fov_y_deg": 50, "width": 32, "height": 18 }},
                    "objects": [ {} ] }}"#,
                    objects.join(",")
                ),
                &dir,
            )
            .unwrap()
        };
        let maps = |s: &Scene| -> Vec<u32> {
            s.geometry
                .surfaces
                .iter()
                .filter_map(|surface| match surface {
                    Surface::Diffuse { maps, .. } => Some(maps),
                    _ => None,
                })
                .flat_map(|m| [m.albedo, m.emission].into_iter().flatten())
                .map(|m| m.texture)
                .collect()
        };
        let (one, three) = (scene(1), scene(3));
        assert_eq!(one.geometry.textures.len(), 2, "the cube's two images");
        assert_eq!(three.geometry.textures.len(), one.geometry.textures.len());
        let (one_maps, three_maps) = (maps(&one), maps(&three));
        assert!(!one_maps.is_empty());
        assert_eq!(three_maps.len(), 3 * one_maps.len());
        for instance in three_maps.chunks(one_maps.len()) {
            assert_eq!(instance, one_maps.as_slice());
        }
    }

    /// `camera.gltf`: the scene camera is the asset's (the project's textured asset places one
    /// at (0.2, 1.3, 1.9), tilted 24° down, yfov 0.8 rad), through the object's transform;
    /// mixed with the file's own view fields, past the asset's cameras or naming no object,
    /// it is refused with its field.
    #[test]
    fn a_gltf_camera_can_be_the_scene_camera() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/scene.json");
        let scene = |camera: &str| {
            parse_scene(
                &format!(
                    r#"{{ "camera": {{ {camera}, "width": 64, "height": 36 }},
                    "objects": [ {{ "type": "gltf", "path": "assets/textured_cube.gltf",
                    "transform": {{ "translate": [1, 0, 0] }} }} ] }}"#
                ),
                &dir,
            )
        };
        let s = scene(r#""gltf": "assets/textured_cube.gltf", "index": 0"#).unwrap();
        let c = &s.camera;
        assert!(
            (c.position - Vec3::new(1.2, 1.3, 1.9)).length() < 1e-5,
            "{:?}",
            c.position
        );
        let forward = (c.look_at - c.position).normalize();
        assert!(
            (forward.y - (-24f32).to_radians().sin()).abs() < 1e-5,
            "{forward}"
        );
        assert!((c.fov_y_deg - 0.8f32.to_degrees()).abs() < 1e-4);
        for (camera, words) in [
            (
                r#""gltf": "assets/textured_cube.gltf", "index": 1"#,
                "camera.index: the asset places 1 perspective cameras",
            ),
            (
                r#""gltf": "other.glb""#,
                "camera.gltf: must be the path of one of the scene's gltf objects",
            ),
            (
                r#""gltf": "assets/textured_cube.gltf", "position": [0, 0, 0]"#,
                "camera.position: is not allowed with camera.gltf",
            ),
            (
                r#""look_at": [0, 0, 0], "fov_y_deg": 40"#,
                "camera.position: is required",
            ),
        ] {
            let e = scene(camera).err().unwrap().to_string();
            assert!(e.contains(words), "{camera}: {e}");
        }
        // A glTF camera outside the scene extent: the file has no camera.position to blame,
        // so the camera chosen is named, and its value.
        let tmp = tempfile::tempdir().unwrap();
        std::fs::write(
            tmp.path().join("far.gltf"),
            r#"{"asset": {"version": "2.0"}, "scenes": [{"nodes": [0, 1]}],
                "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 2e6]}],
                "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
                "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                               "min": [0, 0, 0], "max": [1, 1, 0]}],
                "bufferViews": [{"buffer": 0, "byteLength": 36}],
                "buffers": [{"uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA", "byteLength": 36}]}"#,
        )
        .unwrap();
        let e = parse_scene(
            r#"{ "camera": { "gltf": "far.gltf", "width": 64, "height": 36 },
                 "objects": [ { "type": "gltf", "path": "far.gltf" } ] }"#,
            &tmp.path().join("s.json"),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("camera.gltf: the glTF camera's position (camera.gltf's asset): must lie"),
            "{e}"
        );
    }

    #[test]
    fn an_empty_scene_loads() {
        let s = scene_with("").unwrap();
        assert!(s.geometry.triangles.is_empty() && s.mirrors.is_empty());
    }
}
