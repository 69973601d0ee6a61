//! A scene as glTF 2.0 (issue 53, the exchange's way out): what another renderer loads with
//! its own glTF loader to draw the same view. The inverse of [`crate::gltf_asset`]'s reading,
//! in the same conventions (`docs/gltf.md`), so that loading the file back gives the same
//! triangles, surfaces, mirrors and lights:
//! - every part of the scene's geometry is one node with one mesh of one primitive,
//!   unindexed, with its **face** normals (the contract shades with them) and its texture
//!   coordinates where its surface is textured; every material is double-sided (the
//!   contract's diffuse is two-sided);
//! - a diffuse surface: base colour factor = albedo (× base colour texture), metallic 0,
//!   roughness 1; emissive factor × `KHR_materials_emissive_strength` = emission;
//! - a mirror: its rectangle, metallic 1, roughness 0, base colour factor = reflectance, and
//!   `extras.mirrorbox_mirror` = {index, name, reflectance, back_albedo} for tools that read
//!   extras;
//! - point lights as `KHR_lights_punctual` (colour × intensity = the contract's W/sr, read as
//!   candela: glTF's Lambert `ρ/π · I·cos/r²` is the contract's);
//! - the camera as a perspective camera node (glTF cameras look down −Z);
//! - the scene's `extras.mirrorbox`: ambient, background, terminal, exposure — what glTF
//!   has no field for.

use crate::texture::{IDENTITY_TRANSFORM, TextureMap, Wrap};
use crate::{Scene, Surface};
use glam::{Mat3, Quat, Vec3};
use serde_json::{Value, json};

/// The files of an exported scene: `scene.gltf`'s JSON, its buffer (`scene.bin`) and its
/// images (`textures/<n>.png`, names relative to the glTF file).
pub struct GltfFiles {
    pub json: String,
    pub bin: Vec<u8>,
    pub images: Vec<(String, Vec<u8>)>,
}

/// Name of the buffer file the JSON refers to.
pub const BIN_NAME: &str = "scene.bin";

/// Why a scene cannot be written as glTF.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("{0}")]
    Unsupported(String),
    #[error("cannot encode texture {name} as PNG: {message}")]
    Png { name: String, message: String },
}

/// Near and far planes for a client's depth buffer: `near` a thousandth of the scene's
/// extent, `far` a hundred extents (a chain of ~100 reflections of the scene stays inside).
pub fn clip_planes(scene: &Scene) -> (f32, f32) {
    let (lo, hi) = scene.geometry.triangles.iter().flatten().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let extent = (hi - lo).length().max(1e-3);
    (extent * 1e-3, extent * 100.0)
}

/// The camera's orthonormal frame: right, true up, forward (`crate::camera`'s convention).
pub fn camera_frame(scene: &Scene) -> (Vec3, Vec3, Vec3) {
    let c = &scene.camera;
    let forward = (c.look_at - c.position).normalize();
    let right = forward.cross(c.up).normalize();
    (right, right.cross(forward), forward)
}

/// The glTF files of `scene` (see the module docs). Refused: stereo cameras and uneven
/// mirrors (not in the exchange), a texture transform with shear (not expressible by
/// `KHR_texture_transform`).
pub fn export(scene: &Scene) -> Result<GltfFiles, ExportError> {
    if scene.stereo.is_some() {
        return Err(ExportError::Unsupported(
            "a stereo camera is not in the exchange (a view has no field for an off-axis eye's \
             shifted image); a parallel or toe-in eye can be a view: export the scene without \
             `camera.stereo`, with --views giving each eye's position and look-at"
                .into(),
        ));
    }
    if scene.bumps.iter().any(Option::is_some) {
        return Err(ExportError::Unsupported(
            "uneven mirrors (a mirror's bump) are not in the exchange".into(),
        ));
    }
    let g = &scene.geometry;
    let mut bin: Vec<u8> = Vec::new();
    let mut buffer_views = Vec::new();
    let mut accessors = Vec::new();
    // One bufferView and accessor per attribute of a part: floats, so every offset is a
    // multiple of 4.
    let mut push_floats = |values: &[f32], components: usize, kind: &str, bounds: bool| {
        let offset = bin.len();
        for v in values {
            bin.extend_from_slice(&v.to_le_bytes());
        }
        buffer_views.push(json!({
            "buffer": 0, "byteOffset": offset, "byteLength": values.len() * 4
        }));
        let mut accessor = json!({
            "bufferView": buffer_views.len() - 1,
            "componentType": 5126,
            "count": values.len() / components,
            "type": kind,
        });
        if bounds {
            let mut lo = vec![f32::MAX; components];
            let mut hi = vec![f32::MIN; components];
            for chunk in values.chunks(components) {
                for (i, v) in chunk.iter().enumerate() {
                    lo[i] = lo[i].min(*v);
                    hi[i] = hi[i].max(*v);
                }
            }
            accessor["min"] = json!(lo);
            accessor["max"] = json!(hi);
        }
        accessors.push(accessor);
        accessors.len() - 1
    };
    let mut textures = TextureTable::default();
    let mut materials: Vec<Value> = Vec::new();
    let mut material_of_surface: Vec<Option<usize>> = vec![None; g.surfaces.len()];
    let mut meshes = Vec::new();
    let mut nodes = Vec::new();
    for part in &g.parts {
        let surface_id = part.surface as usize;
        let surface = &g.surfaces[surface_id];
        let material = match material_of_surface[surface_id] {
            Some(m) => m,
            None => {
                materials.push(material(scene, surface, &mut textures)?);
                material_of_surface[surface_id] = Some(materials.len() - 1);
                materials.len() - 1
            }
        };
        let tris = &g.triangles[part.triangles.clone()];
        let mut positions = Vec::with_capacity(tris.len() * 9);
        let mut normals = Vec::with_capacity(tris.len() * 9);
        for t in tris {
            let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
            for v in t {
                positions.extend_from_slice(&v.to_array());
                normals.extend_from_slice(&n.to_array());
            }
        }
        let mut attributes = json!({
            "POSITION": push_floats(&positions, 3, "VEC3", true),
            "NORMAL": push_floats(&normals, 3, "VEC3", false),
        });
        if matches!(surface, Surface::Diffuse { maps, .. } if !maps.is_empty()) {
            let uvs: Vec<f32> = g.uvs[part.triangles.clone()]
                .iter()
                .flatten()
                .flat_map(|uv| uv.to_array())
                .collect();
            attributes["TEXCOORD_0"] = json!(push_floats(&uvs, 2, "VEC2", false));
        }
        meshes.push(json!({
            "name": part.name,
            "primitives": [{ "attributes": attributes, "material": material, "mode": 4 }],
        }));
        nodes.push(json!({ "name": part.name, "mesh": meshes.len() - 1 }));
    }
    let mut lights = Vec::new();
    for (i, l) in scene.lighting.lights.iter().enumerate() {
        let intensity = l.intensity.max_element();
        let color = if intensity > 0.0 {
            l.intensity / intensity
        } else {
            Vec3::ONE
        };
        lights.push(json!({
            "type": "point", "name": format!("light {i}"),
            "color": color.to_array(), "intensity": intensity,
        }));
        nodes.push(json!({
            "name": format!("light {i}"),
            "translation": l.position.to_array(),
            "extensions": { "KHR_lights_punctual": { "light": i } },
        }));
    }
    let (right, up, forward) = camera_frame(scene);
    let rotation = Quat::from_mat3(&Mat3::from_cols(right, up, -forward)).normalize();
    let (near, far) = clip_planes(scene);
    let c = &scene.camera;
    nodes.push(json!({
        "name": "camera",
        "camera": 0,
        "translation": c.position.to_array(),
        "rotation": rotation.to_array(),
    }));
    let mut extensions_used = vec!["KHR_materials_emissive_strength"];
    if !lights.is_empty() {
        extensions_used.push("KHR_lights_punctual");
    }
    if textures.transformed {
        extensions_used.push("KHR_texture_transform");
    }
    let mut doc = json!({
        "asset": { "version": "2.0", "generator": format!("mirrorbox {} export-views", env!("CARGO_PKG_VERSION")) },
        "extensionsUsed": extensions_used,
        "scene": 0,
        "scenes": [{
            "name": scene.source.display().to_string(),
            "nodes": (0..nodes.len()).collect::<Vec<_>>(),
            "extras": { "mirrorbox": {
                "ambient": scene.lighting.ambient.to_array(),
                "background": scene.background.to_array(),
                "terminal": scene.terminal.to_array(),
                "exposure": c.exposure,
            }},
        }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{
            "type": "perspective",
            "perspective": {
                "yfov": c.fov_y_deg.to_radians(),
                "aspectRatio": c.width as f32 / c.height as f32,
                "znear": near, "zfar": far,
            },
        }],
        "buffers": [{ "uri": BIN_NAME, "byteLength": bin.len() }],
        "bufferViews": buffer_views,
        "accessors": accessors,
    });
    if !lights.is_empty() {
        doc["extensions"] = json!({ "KHR_lights_punctual": { "lights": lights } });
    }
    let mut images = Vec::new();
    if !textures.used.is_empty() {
        let mut image_list = Vec::new();
        for (n, &t) in textures.images.iter().enumerate() {
            let name = format!("textures/{n}.png");
            images.push((name.clone(), png(&g.textures[t as usize])?));
            image_list.push(json!({ "uri": name }));
        }
        doc["images"] = json!(image_list);
        doc["samplers"] = json!(
            textures
                .samplers
                .iter()
                .map(|w| json!({
                    "magFilter": 9729, "minFilter": 9729,
                    "wrapS": wrap_code(w[0]), "wrapT": wrap_code(w[1]),
                }))
                .collect::<Vec<_>>()
        );
        doc["textures"] = json!(
            textures
                .used
                .iter()
                .map(|(image, sampler)| json!({ "source": image, "sampler": sampler }))
                .collect::<Vec<_>>()
        );
    }
    let json = serde_json::to_string_pretty(&doc).expect("a JSON value serialises");
    Ok(GltfFiles { json, bin, images })
}

/// The glTF images, samplers and textures the materials use, each once.
#[derive(Default)]
struct TextureTable {
    /// Scene texture index of each glTF image.
    images: Vec<u32>,
    /// Wrap modes of each sampler.
    samplers: Vec<[Wrap; 2]>,
    /// (image, sampler) of each glTF texture.
    used: Vec<(usize, usize)>,
    /// Some map has a transform other than the identity.
    transformed: bool,
}

impl TextureTable {
    /// The textureInfo of `map`: its glTF texture, and its transform as
    /// `KHR_texture_transform` where it is not the identity.
    fn info(&mut self, map: &TextureMap) -> Result<Value, ExportError> {
        let image = index_of(&mut self.images, map.texture);
        let sampler = index_of(&mut self.samplers, map.wrap);
        let texture = index_of(&mut self.used, (image, sampler));
        let mut info = json!({ "index": texture, "texCoord": 0 });
        if map.transform != IDENTITY_TRANSFORM {
            self.transformed = true;
            info["extensions"] = json!({ "KHR_texture_transform": trs(&map.transform)? });
        }
        Ok(info)
    }
}

fn index_of<T: PartialEq>(list: &mut Vec<T>, item: T) -> usize {
    match list.iter().position(|x| *x == item) {
        Some(i) => i,
        None => {
            list.push(item);
            list.len() - 1
        }
    }
}

/// `KHR_texture_transform`'s offset, rotation and scale of a 2×3 matrix `T·R·S`
/// (`[[sx·cos r, sy·sin r, tx], [−sx·sin r, sy·cos r, ty]]`), checked by composing it again.
fn trs(m: &[f32; 6]) -> Result<Value, ExportError> {
    let [a, b, c, d, e, f] = m.map(f64::from);
    let sx = a.hypot(d);
    let r = (-d).atan2(a);
    let sy = b * r.sin() + e * r.cos();
    let again = [
        sx * r.cos(),
        sy * r.sin(),
        c,
        -sx * r.sin(),
        sy * r.cos(),
        f,
    ];
    let scale = [a, b, d, e].iter().fold(1.0f64, |s, v| s.max(v.abs()));
    if again
        .iter()
        .zip([a, b, c, d, e, f])
        .any(|(x, y)| (x - y).abs() > 1e-6 * scale)
    {
        return Err(ExportError::Unsupported(format!(
            "a texture transform {m:?} has shear, which KHR_texture_transform cannot express"
        )));
    }
    Ok(json!({ "offset": [c, f], "rotation": r, "scale": [sx, sy] }))
}

fn wrap_code(w: Wrap) -> u32 {
    match w {
        Wrap::Repeat => 10497,
        Wrap::ClampToEdge => 33071,
        Wrap::MirroredRepeat => 33648,
    }
}

fn material(
    scene: &Scene,
    surface: &Surface,
    textures: &mut TextureTable,
) -> Result<Value, ExportError> {
    Ok(match surface {
        Surface::Diffuse {
            albedo,
            emission,
            maps,
        } => {
            let mut pbr = json!({
                "baseColorFactor": [albedo.x, albedo.y, albedo.z, 1.0],
                "metallicFactor": 0.0, "roughnessFactor": 1.0,
            });
            if let Some(m) = &maps.albedo {
                pbr["baseColorTexture"] = textures.info(m)?;
            }
            // An emission above 1 is a factor ≤ 1 times a power of two: both exact in binary,
            // so the reader's product gives the emission back bit for bit.
            let brightest = emission.max_element();
            let strength = if brightest > 1.0 {
                2f32.powi(brightest.log2().ceil() as i32)
            } else {
                1.0
            };
            let mut material = json!({
                "name": "diffuse",
                "pbrMetallicRoughness": pbr,
                "doubleSided": true,
            });
            if brightest > 0.0 {
                material["emissiveFactor"] = json!((*emission / strength).to_array());
                if strength > 1.0 {
                    material["extensions"] = json!({
                        "KHR_materials_emissive_strength": { "emissiveStrength": strength }
                    });
                }
            }
            if let Some(m) = &maps.emission {
                if brightest == 0.0 {
                    material["emissiveFactor"] = json!([0.0, 0.0, 0.0]);
                }
                material["emissiveTexture"] = textures.info(m)?;
            }
            material
        }
        Surface::Mirror {
            mirror,
            reflectance,
            back_albedo,
        } => {
            let name = scene.mirrors.get(*mirror).map_or("", |m| m.name.as_str());
            json!({
                "name": format!("mirror {name}"),
                "pbrMetallicRoughness": {
                    "baseColorFactor": [reflectance.x, reflectance.y, reflectance.z, 1.0],
                    "metallicFactor": 1.0, "roughnessFactor": 0.0,
                },
                "doubleSided": true,
                "extras": { "mirrorbox_mirror": {
                    "index": mirror, "name": name,
                    "reflectance": reflectance.to_array(),
                    "back_albedo": back_albedo.to_array(),
                }},
            })
        }
    })
}

/// A texture's texels as an 8-bit RGBA PNG (the bytes as they were read: sRGB-encoded).
fn png(t: &crate::texture::Texture) -> Result<Vec<u8>, ExportError> {
    let mut out = Vec::new();
    let bytes: Vec<u8> = t.texels.iter().flatten().copied().collect();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut out),
        &bytes,
        t.width,
        t.height,
        image::ExtendedColorType::Rgba8,
    )
    .map_err(|e| ExportError::Png {
        name: t.name.clone(),
        message: e.to_string(),
    })?;
    Ok(out)
}

/// A mirrorbox scene file whose only object is the exported `gltf` (a path relative to the
/// scene file) and whose camera, ambient, background, terminal and lighting options are
/// `scene`'s: loading it gives `scene` back through the glTF reader (the exchange's round
/// trip, tested by tracing both).
pub fn scene_file(scene: &Scene, gltf: &str) -> String {
    let c = &scene.camera;
    let l = &scene.lighting;
    let doc = json!({
        "camera": {
            "position": c.position.to_array(), "look_at": c.look_at.to_array(),
            "up": c.up.to_array(), "fov_y_deg": c.fov_y_deg,
            "width": c.width, "height": c.height, "exposure": c.exposure,
        },
        "objects": [{ "type": "gltf", "path": gltf }],
        "ambient": l.ambient.to_array(),
        "lighting": { "shadows": l.shadows, "mirrored_lights": l.mirrored_lights },
        "background": scene.background.to_array(),
        "terminal": scene.terminal.to_array(),
    });
    serde_json::to_string_pretty(&doc).expect("a JSON value serialises")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn root() -> &'static Path {
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
    }

    /// Writes `scene`'s export into `dir` and loads it back through the glTF reader.
    fn round_trip(scene: &Scene, dir: &Path) -> Scene {
        let files = export(scene).unwrap();
        std::fs::write(dir.join("scene.gltf"), &files.json).unwrap();
        std::fs::write(dir.join(BIN_NAME), &files.bin).unwrap();
        for (name, bytes) in &files.images {
            let p = dir.join(name);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, bytes).unwrap();
        }
        let text = scene_file(scene, "scene.gltf");
        crate::load::parse_scene(&text, &dir.join("scene.json")).unwrap()
    }

    /// Every triangle with its surface, as text, sorted: the same multiset on both sides
    /// (mirrors may come in another order).
    fn triangles(s: &Scene) -> Vec<String> {
        let g = &s.geometry;
        let mut out: Vec<String> = (0..g.triangles.len())
            .map(|i| {
                let surface = match &g.surfaces[g.surface_of[i] as usize] {
                    Surface::Mirror { reflectance, .. } => format!("mirror {reflectance}"),
                    Surface::Diffuse {
                        albedo,
                        emission,
                        maps,
                    } => format!(
                        "diffuse {albedo} {emission} {:?} {:?} uv {:?}",
                        maps.albedo
                            .as_ref()
                            .map(|m| (m.wrap, m.transform.map(|x| (x * 1e4).round()))),
                        maps.emission.as_ref().map(|m| m.wrap),
                        g.uvs[i]
                    ),
                };
                let mut corners = g.triangles[i].map(|v| format!("{:.4?}", v.to_array()));
                corners.sort();
                format!("{corners:?} {surface}")
            })
            .collect();
        out.sort();
        out
    }

    #[test]
    fn an_exported_scene_loads_back_with_the_same_triangles_surfaces_and_lights() {
        for name in [
            "mirror_box_lit.json",
            "textured_box.json",
            "mirror_room.json",
        ] {
            let scene = crate::load::load_scene(&root().join("scenes").join(name)).unwrap();
            let dir = tempfile::tempdir().unwrap();
            let back = round_trip(&scene, dir.path());
            let (a, b) = (triangles(&back), triangles(&scene));
            assert_eq!(a.len(), b.len(), "{name}");
            for (x, y) in a.iter().zip(&b) {
                assert_eq!(x, y, "{name}");
            }
            assert_eq!(back.mirrors.len(), scene.mirrors.len(), "{name}");
            assert_eq!(back.lighting.lights, scene.lighting.lights, "{name}");
            assert_eq!(back.lighting.ambient, scene.lighting.ambient, "{name}");
            assert_eq!(back.geometry.textures.len(), scene.geometry.textures.len());
            for (a, b) in back.geometry.textures.iter().zip(&scene.geometry.textures) {
                assert_eq!(a.texels, b.texels, "{name}");
            }
        }
    }

    #[test]
    fn a_sheared_texture_transform_is_refused_and_a_rotation_is_kept() {
        let (s, r) = (0.5f32, 0.3f32);
        let rotated = [
            2.0 * r.cos(),
            s * r.sin(),
            0.25,
            -2.0 * r.sin(),
            s * r.cos(),
            0.5,
        ];
        let v = trs(&rotated).unwrap();
        assert!((v["rotation"].as_f64().unwrap() - 0.3).abs() < 1e-6, "{v}");
        assert!((v["scale"][1].as_f64().unwrap() - 0.5).abs() < 1e-6, "{v}");
        assert!(trs(&[1.0, 0.5, 0.0, 0.0, 1.0, 0.0]).is_err());
    }
}
