//! glTF 2.0 assets (`.gltf` with its buffers and images, `.glb`, embedded data URIs) as a
//! scene object (`docs/gltf.md`). The JSON is parsed and validated by the `gltf` crate; its
//! buffers and images are read here, every size bounded before anything is allocated, and
//! every accessor checked against its buffer before a byte is read, so that a broken file is
//! refused naming the glTF field (`meshes[0].primitives[0].indices`), never a panic.
//!
//! What becomes what (the contract of `docs/shading.md`):
//! - every triangle primitive of the chosen scene's node tree, node transforms applied
//!   (strips and fans become triangles; points and lines are refused);
//! - its material's base colour factor × base colour texture (`TEXCOORD_n`, the sampler's
//!   wrap modes, `KHR_texture_transform`) is the diffuse albedo; emissive factor ×
//!   `KHR_materials_emissive_strength` × emissive texture is the emission;
//! - a primitive whose material is metallic 1 with roughness ≤ [`MIRROR_MAX_ROUGHNESS`] and
//!   whose triangles form one planar rectangle is a mirror (reflectance = the base colour
//!   factor); any other such primitive is refused, or kept diffuse when asked;
//! - `KHR_lights_punctual` point lights are point lights (intensity = colour × intensity,
//!   candela read as W/sr); spot and directional lights are refused;
//! - perspective cameras are listed, in node order, for the scene's `camera.gltf`.

use crate::limits::{MAX_COORDINATE, within_extent};
use crate::texture::{
    IDENTITY_TRANSFORM, MAX_TEXTURE_SIDE, SurfaceMaps, Texture, TextureMap, Wrap,
};
use crate::{Mirror, PointLight, Surface};
use glam::{Mat4, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use std::path::{Path, PathBuf};

/// Largest `.gltf`/`.glb` file, and largest buffer or image file it refers to.
pub const MAX_GLTF_FILE_BYTES: u64 = 256 << 20;
/// Largest sum of all buffers' and images' bytes of one asset.
pub const MAX_GLTF_TOTAL_BYTES: u64 = 512 << 20;
/// Deepest node nesting, and most node visits (a node may be instanced many times).
pub const MAX_NODE_DEPTH: usize = 256;
pub const MAX_NODE_VISITS: usize = 1 << 20;
/// The extensions read (any other may be used, but a file that requires one is refused).
pub const READ_EXTENSIONS: [&str; 3] = [
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_texture_transform",
];
/// A metallic material this smooth or smoother is a mirror.
pub const MIRROR_MAX_ROUGHNESS: f32 = 0.05;

/// What to do with a mirror-like primitive (metallic 1, smooth) that is not a planar
/// rectangle: the contract's mirrors are rectangles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CurvedMirrors {
    #[default]
    Refuse,
    /// Keep it as a diffuse surface of its base colour, with a note.
    Diffuse,
}

/// A refused asset: the glTF field path (empty for the file as a whole) and why.
#[derive(Debug, Clone, PartialEq)]
pub struct GltfError {
    pub field: String,
    pub message: String,
}

impl std::fmt::Display for GltfError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.field.is_empty() {
            f.write_str(&self.message)
        } else {
            write!(f, "{}: {}", self.field, self.message)
        }
    }
}

fn err(field: impl Into<String>, message: impl Into<String>) -> GltfError {
    GltfError {
        field: field.into(),
        message: message.into(),
    }
}

type Result<T> = std::result::Result<T, GltfError>;

/// One primitive instance, in the asset's coordinates with its node transforms applied.
pub struct AssetPart {
    pub name: String,
    pub surface: Surface,
    pub triangles: Vec<[Vec3; 3]>,
    pub uvs: Vec<[Vec2; 3]>,
}

/// A perspective camera placed by a node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AssetCamera {
    pub position: Vec3,
    pub forward: Vec3,
    pub up: Vec3,
    pub fov_y_deg: f32,
}

/// A loaded asset: diffuse parts (their [`Surface`]s' texture indices into `textures`),
/// mirrors, lights and cameras, and what loading passed over.
#[derive(Default)]
pub struct GltfAsset {
    pub parts: Vec<AssetPart>,
    pub textures: Vec<Texture>,
    pub mirrors: Vec<Mirror>,
    pub lights: Vec<PointLight>,
    pub cameras: Vec<AssetCamera>,
    pub notes: Vec<String>,
    /// `texture_of_image[i]`: the texture `images[i]` became, as the parts' maps number
    /// textures ([`load_gltf_reusing`]'s `texture_base` plus its place in `textures`, or the
    /// known texture it reused); `None` for an image no drawn material uses.
    pub texture_of_image: Vec<Option<u32>>,
}

/// What the caller allows.
#[derive(Clone, Copy, Debug)]
pub struct GltfOptions {
    /// The scene to load (`scenes[i]`); default: the file's `scene`, else its first.
    pub scene: Option<usize>,
    /// Most triangles the asset may add.
    pub triangle_budget: u64,
    /// Most texels its textures may add.
    pub texel_budget: u64,
    /// Applied to every position, light and camera (the scene object's `transform`).
    pub transform: Mat4,
    pub curved_mirrors: CurvedMirrors,
}

/// Loads the asset at `path` (see the module docs); its parts' maps number its own
/// `textures` from 0.
pub fn load_gltf(path: &Path, options: &GltfOptions) -> Result<GltfAsset> {
    load_gltf_reusing(path, options, 0, &[])
}

/// [`load_gltf`] for a scene that may already hold this file's images: `known[i]`, where
/// `Some`, is the scene texture `images[i]` was decoded into by an earlier object naming the
/// same file (it is not read, decoded or counted against the texel budget again: issue 51, a
/// file instanced by many objects is decoded once); a new image becomes scene texture
/// `texture_base + k`, `k` its place in the returned `textures`.
pub fn load_gltf_reusing(
    path: &Path,
    options: &GltfOptions,
    texture_base: u32,
    known: &[Option<u32>],
) -> Result<GltfAsset> {
    let bytes = mirrorbox_files::read_bounded(path, MAX_GLTF_FILE_BYTES, "glTF file")
        .map_err(|e| err("", e.message))?;
    let (json, blob) = if bytes.starts_with(b"glTF") {
        let glb = gltf::binary::Glb::from_slice(&bytes)
            .map_err(|e| err("", format!("not a readable binary glTF (.glb): {e}")))?;
        (glb.json.into_owned(), glb.bin.map(|b| b.into_owned()))
    } else {
        (bytes, None)
    };
    // serde_path_to_error: a wrong type is named by its field path, as the scene file's are.
    let mut de = serde_json::Deserializer::from_slice(&json);
    let root: gltf::json::Root = match serde_path_to_error::deserialize(&mut de) {
        Ok(root) => root,
        Err(e) => {
            // A file of another glTF version (1.0: its `scenes` and `accessors` objects, not
            // arrays) fails the 2.0 schema: named by its version, read from `asset` alone,
            // where that is what it is.
            if let Ok(VersionHead {
                asset:
                    Some(VersionFields {
                        version: Some(version),
                        min_version,
                    }),
            }) = serde_json::from_slice(&json)
            {
                check_version(&version, min_version.as_deref())?;
            }
            let field = e.path().to_string();
            let inner = e.into_inner();
            let message = format!(
                "{} (line {}, column {} of the JSON)",
                crate::load::strip_position(&inner.to_string()),
                inner.line(),
                inner.column()
            );
            return Err(err(
                if field == "." { String::new() } else { field },
                message,
            ));
        }
    };
    check_version(&root.asset.version, root.asset.min_version.as_deref())?;
    // An extension the file requires and mirrorbox does not read refuses it, named (before
    // the validation, which would report its consequences instead: a Draco mesh's missing
    // buffer views).
    if let Some((i, name)) = root
        .extensions_required
        .iter()
        .enumerate()
        .find(|(_, e)| !READ_EXTENSIONS.contains(&e.as_str()))
    {
        return Err(err(
            format!("extensionsRequired[{i}]"),
            format!(
                "the file requires \"{name}\", which mirrorbox does not read (it reads {})",
                READ_EXTENSIONS.join(", ")
            ),
        ));
    }
    // The gltf crate's validator indexes the POSITION accessor before checking that it exists
    // (gltf-json 1.4.1, mesh.rs:151): a reference past the accessors would panic there.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
            if let Some(index) = primitive.attributes.get(&position)
                && index.value() >= root.accessors.len()
            {
                return Err(err(
                    format!("meshes[{m}].primitives[{p}].attributes[\"POSITION\"]"),
                    format!(
                        "refers to accessor {}; the file has {}",
                        index.value(),
                        root.accessors.len()
                    ),
                ));
            }
        }
    }
    let document = gltf::Document::from_json(root).map_err(|e| match e {
        gltf::Error::Validation(list) => {
            let (field, why) = &list[0];
            let more = match list.len() {
                1 => String::new(),
                n => format!(" ({} more problems)", n - 1),
            };
            use gltf::json::validation::Error as V;
            let why = match why {
                V::Missing => "is missing: the glTF 2.0 specification requires it".to_string(),
                V::IndexOutOfBounds => "refers to an item the file does not have".to_string(),
                V::Invalid => "has a value the glTF 2.0 specification does not allow".to_string(),
                V::Unsupported => {
                    "names an extension mirrorbox does not read, and requires it".to_string()
                }
                other => other.to_string(),
            };
            err(field.to_string(), format!("{why}{more}"))
        }
        other => err("", other.to_string()),
    })?;
    // Extensions the file uses (not requires) that are not read: what they add is not drawn.
    let unread: Vec<&str> = document
        .extensions_used()
        .filter(|e| !READ_EXTENSIONS.contains(e))
        .collect();
    let base = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let mut reader = Reader {
        document: &document,
        base,
        blob,
        buffers: Vec::new(),
        total_bytes: 0,
        asset: GltfAsset::default(),
        texture_of_image: known.to_vec(),
        texture_base,
        texels: 0,
        options: *options,
        triangles: 0,
    };
    for name in unread {
        reader.note(format!(
            "extensionsUsed: {name} is not read (the core glTF material and geometry are drawn)"
        ));
    }
    reader.read_buffers()?;
    reader.read_scene()?;
    reader.asset.texture_of_image = reader.texture_of_image;
    Ok(reader.asset)
}

/// A glTF file's `asset.version` and `asset.minVersion` alone (every other field skipped
/// unparsed), read where the file fails the 2.0 schema.
#[derive(serde::Deserialize)]
struct VersionHead {
    asset: Option<VersionFields>,
}

#[derive(serde::Deserialize)]
struct VersionFields {
    version: Option<String>,
    #[serde(rename = "minVersion")]
    min_version: Option<String>,
}

/// The glTF versions read: 2.x, as the specification's "Versioning" asks of a 2.0 loader. An
/// asset whose `minVersion` is given loads only where that version is supported (2.0); one
/// without loads when its `version`'s major is 2, whatever its minor (a minor version adds
/// only what a 2.0 loader may ignore). Both are `<major>.<minor>`.
fn check_version(version: &str, min_version: Option<&str>) -> Result<()> {
    let parse = |field: &str, text: &str| -> Result<(u32, u32)> {
        text.split_once('.')
            .filter(|(m, n)| {
                !m.is_empty()
                    && !n.is_empty()
                    && m.bytes().chain(n.bytes()).all(|b| b.is_ascii_digit())
            })
            .and_then(|(m, n)| Some((m.parse().ok()?, n.parse().ok()?)))
            .ok_or_else(|| {
                err(
                    field,
                    format!("is \"{text}\"; a glTF version is <major>.<minor>, as \"2.0\""),
                )
            })
    };
    let (major, _) = parse("asset.version", version)?;
    if let Some(min) = min_version {
        if parse("asset.minVersion", min)? != (2, 0) {
            return Err(err(
                "asset.minVersion",
                format!("is \"{min}\": the asset needs glTF {min}; mirrorbox reads glTF 2.0"),
            ));
        }
    } else if major != 2 {
        return Err(err(
            "asset.version",
            format!(
                "is \"{version}\": mirrorbox reads glTF 2.x (glTF 1.0 files convert with \
                 gltf-pipeline)"
            ),
        ));
    }
    Ok(())
}

struct Reader<'a> {
    document: &'a gltf::Document,
    base: PathBuf,
    blob: Option<Vec<u8>>,
    buffers: Vec<Vec<u8>>,
    total_bytes: u64,
    asset: GltfAsset,
    /// `texture_of_image[i]`: the scene texture `images[i]` became, once decoded or known.
    texture_of_image: Vec<Option<u32>>,
    /// The scene texture number of `asset.textures[0]`.
    texture_base: u32,
    texels: u64,
    options: GltfOptions,
    triangles: u64,
}

impl Reader<'_> {
    /// The bytes behind a URI: a `data:` URI's payload, or a file named relative to the
    /// asset's folder as RFC 3986 resolves a relative reference against the asset's own
    /// location (`../shared/a.bin` reaches outside it, `/data/a.bin` is that absolute path):
    /// the reach of the scene file's own paths, which mirrorbox reads as given.
    fn uri_bytes(&mut self, field: &str, uri: &str, what: &str) -> Result<Vec<u8>> {
        let bytes = if let Some(rest) = uri.strip_prefix("data:") {
            let Some((header, payload)) = rest.split_once(',') else {
                return Err(err(field, "a data URI without a comma"));
            };
            if !header.ends_with(";base64") {
                return Err(err(
                    field,
                    "a data URI that is not base64 (only base64 data URIs are read)",
                ));
            }
            if payload.len() as u64 / 4 * 3 > MAX_GLTF_FILE_BYTES {
                return Err(err(
                    field,
                    format!("a data URI of over {} MiB", MAX_GLTF_FILE_BYTES >> 20),
                ));
            }
            use base64::Engine;
            base64::engine::general_purpose::STANDARD
                .decode(payload.trim_end())
                .map_err(|e| err(field, format!("a data URI that is not valid base64 ({e})")))?
        } else {
            let file = percent_decode(uri).ok_or_else(|| {
                err(
                    field,
                    format!("\"{uri}\" is not a valid URI (a bad %-escape)"),
                )
            })?;
            if file.contains("://") {
                return Err(err(
                    field,
                    format!("\"{uri}\": only files beside the asset and data URIs are read"),
                ));
            }
            let resolved = self.base.join(&file);
            mirrorbox_files::read_bounded(&resolved, MAX_GLTF_FILE_BYTES, what).map_err(|e| {
                err(
                    field,
                    format!("\"{uri}\" (at {}): {}", resolved.display(), e.message),
                )
            })?
        };
        self.total_bytes += bytes.len() as u64;
        if self.total_bytes > MAX_GLTF_TOTAL_BYTES {
            return Err(err(
                field,
                format!(
                    "the asset's buffers and images exceed {} MiB together",
                    MAX_GLTF_TOTAL_BYTES >> 20
                ),
            ));
        }
        Ok(bytes)
    }

    fn read_buffers(&mut self) -> Result<()> {
        for buffer in self.document.buffers() {
            let field = format!("buffers[{}]", buffer.index());
            let data = match buffer.source() {
                gltf::buffer::Source::Bin => self.blob.take().ok_or_else(|| {
                    err(format!("{field}.uri"), "is missing and the file has no binary chunk (a .glb's BIN) to stand for it")
                })?,
                gltf::buffer::Source::Uri(uri) => self.uri_bytes(&format!("{field}.uri"), uri, "glTF buffer")?,
            };
            if data.len() < buffer.length() {
                return Err(err(
                    format!("{field}.byteLength"),
                    format!(
                        "is {} but the data holds only {} bytes",
                        buffer.length(),
                        data.len()
                    ),
                ));
            }
            self.buffers.push(data);
        }
        Ok(())
    }

    /// The bytes of buffer view `view`, checked against its buffer.
    fn view_bytes(&self, view: &gltf::buffer::View) -> Result<&[u8]> {
        let field = format!("bufferViews[{}]", view.index());
        let data = &self.buffers[view.buffer().index()];
        let end = view.offset().checked_add(view.length());
        match end {
            Some(end) if end <= data.len() => Ok(&data[view.offset()..end]),
            _ => Err(err(
                field,
                format!(
                    "bytes {}..{} lie outside buffer {} ({} bytes)",
                    view.offset(),
                    view.offset().saturating_add(view.length()),
                    view.buffer().index(),
                    data.len()
                ),
            )),
        }
    }

    /// Accessor `a`'s elements as f32 components (normalized integers mapped to [0, 1] or
    /// [−1, 1] as glTF defines), checked against its view before reading; `field` names the
    /// attribute that uses it.
    fn components(&self, a: &gltf::Accessor, field: &str, dims: Dimensions) -> Result<Vec<f32>> {
        let here = format!("accessors[{}]", a.index());
        if a.dimensions() != dims {
            return Err(err(
                format!("{here}.type"),
                format!("is {:?}; {field} needs {dims:?}", a.dimensions()),
            ));
        }
        let n = dims.multiplicity();
        let bytes = self.element_bytes(a, field)?;
        let size = a.data_type().size();
        let mut out = Vec::with_capacity(a.count() * n);
        for element in bytes {
            for c in 0..n {
                let b = &element[c * size..(c + 1) * size];
                let v = match a.data_type() {
                    DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                    DataType::U8 if a.normalized() => f32::from(b[0]) / 255.0,
                    DataType::U16 if a.normalized() => {
                        f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0
                    }
                    DataType::I8 if a.normalized() => (f32::from(b[0] as i8) / 127.0).max(-1.0),
                    DataType::I16 if a.normalized() => {
                        (f32::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0)
                    }
                    other => {
                        return Err(err(
                            format!("{here}.componentType"),
                            format!(
                                "is {other:?}{}; {field} needs floats or normalized integers",
                                if a.normalized() {
                                    ""
                                } else {
                                    " (not normalized)"
                                }
                            ),
                        ));
                    }
                };
                out.push(v);
            }
        }
        Ok(out)
    }

    /// Accessor `a`'s elements as index values.
    fn indices(&self, a: &gltf::Accessor, field: &str) -> Result<Vec<u32>> {
        let here = format!("accessors[{}]", a.index());
        if a.dimensions() != Dimensions::Scalar {
            return Err(err(
                format!("{here}.type"),
                format!("is {:?}; {field} needs SCALAR", a.dimensions()),
            ));
        }
        let read = |b: &[u8]| match a.data_type() {
            DataType::U8 => Some(u32::from(b[0])),
            DataType::U16 => Some(u32::from(u16::from_le_bytes([b[0], b[1]]))),
            DataType::U32 => Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            _ => None,
        };
        // The elements checked against the buffer first: `count` is the file's word.
        let elements = self.element_bytes(a, field)?;
        let mut out = Vec::with_capacity(elements.len());
        for element in elements {
            out.push(read(element).ok_or_else(|| {
                err(
                    format!("{here}.componentType"),
                    format!(
                        "is {:?}; indices must be unsigned bytes, shorts or ints",
                        a.data_type()
                    ),
                )
            })?);
        }
        Ok(out)
    }

    /// Each element's bytes of accessor `a`, after checking that they all lie in its view.
    fn element_bytes(&self, a: &gltf::Accessor, field: &str) -> Result<Vec<&[u8]>> {
        let here = format!("accessors[{}]", a.index());
        if a.sparse().is_some() {
            return Err(err(
                format!("{here}.sparse"),
                format!("sparse accessors are not read ({field})"),
            ));
        }
        let Some(view) = a.view() else {
            return Err(err(
                format!("{here}.bufferView"),
                format!("is missing ({field} needs data)"),
            ));
        };
        let bytes = self.view_bytes(&view)?;
        let size = a.size();
        let stride = view.stride().unwrap_or(size);
        if stride < size {
            return Err(err(
                format!("bufferViews[{}].byteStride", view.index()),
                format!("is {stride}, less than the {size}-byte element of {here}"),
            ));
        }
        let count = a.count();
        // In u64 and checked: a byteOffset near 2^64 must not wrap past the bounds check.
        let first_end = match (a.offset() as u64).checked_add(size as u64) {
            Some(e) if e <= bytes.len() as u64 => e,
            _ => {
                return Err(err(
                    format!("{here}.byteOffset"),
                    format!(
                        "is {}: a {size}-byte element from there does not fit bufferView {} ({} bytes)",
                        a.offset(),
                        view.index(),
                        bytes.len()
                    ),
                ));
            }
        };
        let end = (count as u64).checked_sub(1).map_or(Some(0), |last| {
            last.checked_mul(stride as u64)
                .and_then(|x| x.checked_add(first_end))
        });
        match end {
            Some(end) if end <= bytes.len() as u64 => {}
            _ => {
                return Err(err(
                    format!("{here}.count"),
                    format!(
                        "{count} elements of {size} bytes every {stride} from byte {} do not fit bufferView {} ({} bytes)",
                        a.offset(),
                        view.index(),
                        bytes.len()
                    ),
                ));
            }
        }
        Ok((0..count)
            .map(|i| &bytes[a.offset() + i * stride..a.offset() + i * stride + size])
            .collect())
    }

    fn read_scene(&mut self) -> Result<()> {
        let doc = self.document;
        let scene = match self.options.scene {
            Some(i) => doc.scenes().nth(i).ok_or_else(|| {
                err(
                    "scenes",
                    format!("has {} scenes; scene {i} was asked for", doc.scenes().len()),
                )
            })?,
            None => doc
                .default_scene()
                .or_else(|| doc.scenes().next())
                .ok_or_else(|| {
                    err(
                        "scenes",
                        "the file has no scene: nothing says which nodes to draw",
                    )
                })?,
        };
        let mut visits = 0usize;
        // Depth-first with the path from the root, to refuse a cycle naming it.
        let mut stack: Vec<(gltf::Node, Mat4, Vec<usize>)> = scene
            .nodes()
            .map(|n| (n, self.options.transform, Vec::new()))
            .collect();
        stack.reverse();
        while let Some((node, parent, ancestors)) = stack.pop() {
            visits += 1;
            if visits > MAX_NODE_VISITS {
                return Err(err(
                    format!("scenes[{}]", scene.index()),
                    format!("instances more than {MAX_NODE_VISITS} nodes"),
                ));
            }
            let field = format!("nodes[{}]", node.index());
            if ancestors.contains(&node.index()) {
                return Err(err(
                    format!("{field}.children"),
                    format!(
                        "node {} is its own ancestor (a cycle: nodes {:?})",
                        node.index(),
                        ancestors
                    ),
                ));
            }
            if ancestors.len() >= MAX_NODE_DEPTH {
                return Err(err(
                    field,
                    format!("is nested deeper than {MAX_NODE_DEPTH} nodes"),
                ));
            }
            let local = Mat4::from_cols_array_2d(&node.transform().matrix());
            if !local.is_finite() {
                return Err(err(field, "has a transform that is not finite"));
            }
            let world = parent * local;
            if let Some(mesh) = node.mesh() {
                self.read_mesh(&node, &mesh, world)?;
            }
            if let Some(light) = node.light() {
                self.read_light(&node, &light, world)?;
            }
            if let Some(camera) = node.camera()
                && let gltf::camera::Projection::Perspective(p) = camera.projection()
            {
                let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
                let forward = world.transform_vector3(-Vec3::Z).normalize_or_zero();
                self.asset.cameras.push(AssetCamera {
                    position: world.transform_point3(Vec3::ZERO),
                    forward,
                    up,
                    fov_y_deg: p.yfov().to_degrees(),
                });
            }
            if node.skin().is_some() {
                self.note(format!(
                    "{field}.skin: skinning is not applied (the mesh is drawn in its bind pose)"
                ));
            }
            let mut path = ancestors;
            path.push(node.index());
            let children: Vec<_> = node.children().collect();
            for child in children.into_iter().rev() {
                stack.push((child, world, path.clone()));
            }
        }
        if self.asset.parts.is_empty() && self.asset.mirrors.is_empty() {
            return Err(err(
                format!("scenes[{}]", scene.index()),
                "draws no triangles (no node of it has a mesh with triangles)",
            ));
        }
        Ok(())
    }

    fn note(&mut self, note: String) {
        if !self.asset.notes.contains(&note) {
            self.asset.notes.push(note);
        }
    }

    fn read_light(
        &mut self,
        node: &gltf::Node,
        light: &gltf::khr_lights_punctual::Light,
        world: Mat4,
    ) -> Result<()> {
        use gltf::khr_lights_punctual::Kind;
        let field = format!("extensions.KHR_lights_punctual.lights[{}]", light.index());
        match light.kind() {
            Kind::Point => {}
            Kind::Spot { .. } => {
                return Err(err(
                    format!("{field}.type"),
                    "is \"spot\": the contract has point lights only (docs/shading.md); make it \"point\" or remove it",
                ));
            }
            Kind::Directional => {
                return Err(err(
                    format!("{field}.type"),
                    "is \"directional\": the contract has point lights only (docs/shading.md); make it \"point\" or remove it",
                ));
            }
        }
        let intensity = Vec3::from_array(light.color()) * light.intensity();
        if !intensity.is_finite() || intensity.min_element() < 0.0 {
            return Err(err(
                field,
                format!("has colour × intensity {intensity}: must be finite and ≥ 0"),
            ));
        }
        let position = world.transform_point3(Vec3::ZERO);
        if !within_extent(position) {
            return Err(err(
                format!("nodes[{}]", node.index()),
                format!("places its light outside the scene extent (±{MAX_COORDINATE:e})"),
            ));
        }
        self.asset.lights.push(PointLight {
            position,
            intensity,
        });
        Ok(())
    }

    fn read_mesh(&mut self, node: &gltf::Node, mesh: &gltf::Mesh, world: Mat4) -> Result<()> {
        let flips = world.determinant() < 0.0;
        for primitive in mesh.primitives() {
            let field = format!("meshes[{}].primitives[{}]", mesh.index(), primitive.index());
            use gltf::mesh::Mode;
            let mode = primitive.mode();
            if matches!(
                mode,
                Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip
            ) {
                return Err(err(
                    format!("{field}.mode"),
                    format!(
                        "is {mode:?}: points and lines are not drawn (triangles, strips and fans are)"
                    ),
                ));
            }
            if primitive.morph_targets().len() > 0 {
                self.note(format!(
                    "{field}.targets: morph targets are not applied (the base shape is drawn)"
                ));
            }
            let positions = primitive
                .get(&gltf::Semantic::Positions)
                .ok_or_else(|| err(format!("{field}.attributes"), "has no POSITION"))?;
            let vertex_count = positions.count();
            let index_count = primitive.indices().map_or(vertex_count, |a| a.count());
            let tris = match mode {
                Mode::Triangles => index_count / 3,
                _ => index_count.saturating_sub(2),
            } as u64;
            self.triangles += tris;
            if self.triangles > self.options.triangle_budget {
                return Err(err(
                    field,
                    format!(
                        "brings the asset to {} triangles, past the {} the scene may still hold",
                        self.triangles, self.options.triangle_budget
                    ),
                ));
            }
            let p = self.components(
                &positions,
                &format!("{field}.attributes.POSITION"),
                Dimensions::Vec3,
            )?;
            if let Some(k) = p.iter().position(|x| !x.is_finite()) {
                return Err(err(
                    format!("accessors[{}]", positions.index()),
                    format!("POSITION of vertex {} is not finite ({})", k / 3, p[k]),
                ));
            }
            let indices: Vec<u32> = match primitive.indices() {
                Some(a) => {
                    let list = self.indices(&a, &format!("{field}.indices"))?;
                    if let Some((k, i)) = list
                        .iter()
                        .enumerate()
                        .find(|(_, i)| **i as usize >= vertex_count)
                    {
                        return Err(err(
                            format!("{field}.indices"),
                            format!(
                                "element {k} is {i}, out of range: the primitive has {vertex_count} vertices"
                            ),
                        ));
                    }
                    list
                }
                None => (0..vertex_count as u32).collect(),
            };
            let corners: Vec<[u32; 3]> = match mode {
                Mode::Triangles => indices
                    .chunks_exact(3)
                    .map(|c| [c[0], c[1], c[2]])
                    .collect(),
                Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
                    .map(|k| {
                        if k % 2 == 0 {
                            [indices[k], indices[k + 1], indices[k + 2]]
                        } else {
                            [indices[k + 1], indices[k], indices[k + 2]]
                        }
                    })
                    .collect(),
                _ => (1..indices.len().saturating_sub(1))
                    .map(|k| [indices[0], indices[k], indices[k + 1]])
                    .collect(),
            };
            let material = primitive.material();
            let (surface, uv_set) = self.material(&material)?;
            let uv: Option<Vec<f32>> = match uv_set {
                None => None,
                Some(set) => {
                    let a = primitive
                        .get(&gltf::Semantic::TexCoords(set))
                        .ok_or_else(|| {
                            err(
                                format!("{field}.attributes"),
                                format!(
                                    "has no TEXCOORD_{set}, which its material's textures read"
                                ),
                            )
                        })?;
                    if a.count() != vertex_count {
                        return Err(err(
                            format!("accessors[{}].count", a.index()),
                            format!(
                                "is {}; TEXCOORD_{set} needs one per vertex ({vertex_count})",
                                a.count()
                            ),
                        ));
                    }
                    let values = self.components(
                        &a,
                        &format!("{field}.attributes.TEXCOORD_{set}"),
                        Dimensions::Vec2,
                    )?;
                    if values.iter().any(|x| !x.is_finite()) {
                        return Err(err(
                            format!("accessors[{}]", a.index()),
                            "has a texture coordinate that is not finite",
                        ));
                    }
                    Some(values)
                }
            };
            let position = |i: u32| {
                world.transform_point3(Vec3::new(
                    p[3 * i as usize],
                    p[3 * i as usize + 1],
                    p[3 * i as usize + 2],
                ))
            };
            let uv_of = |i: u32| {
                uv.as_ref().map_or(Vec2::ZERO, |t| {
                    Vec2::new(t[2 * i as usize], t[2 * i as usize + 1])
                })
            };
            let mut triangles = Vec::with_capacity(corners.len());
            let mut uvs = Vec::with_capacity(corners.len());
            for c in corners {
                let c = if flips { [c[0], c[2], c[1]] } else { c };
                let t = c.map(position);
                if let Some(bad) = t.iter().find(|v| !within_extent(**v)) {
                    return Err(err(
                        format!("nodes[{}]", node.index()),
                        format!(
                            "places a vertex of {field} at {bad}, outside the scene extent (±{MAX_COORDINATE:e})"
                        ),
                    ));
                }
                triangles.push(t);
                uvs.push(c.map(uv_of));
            }
            let name = format!(
                "{} {}",
                mesh.name().or(node.name()).unwrap_or("glTF mesh"),
                primitive.index()
            );
            if is_mirror_material(&material) {
                match rectangle(&triangles) {
                    Ok(m) => {
                        let factor = material.pbr_metallic_roughness().base_color_factor();
                        self.asset.mirrors.push(Mirror {
                            name,
                            reflectance: Vec3::new(factor[0], factor[1], factor[2]),
                            back_albedo: Vec3::from_array(
                                crate::load::defaults::MIRROR_BACK_ALBEDO,
                            ),
                            ..m
                        });
                        continue;
                    }
                    Err(why) if self.options.curved_mirrors == CurvedMirrors::Refuse => {
                        return Err(err(
                            field,
                            format!(
                                "its material {} is a mirror (metallic 1, roughness ≤ {MIRROR_MAX_ROUGHNESS}) but {why}: the contract's mirrors are planar rectangles (set the object's \"curved_mirrors\": \"diffuse\" to keep it diffuse)",
                                material_name(&material)
                            ),
                        ));
                    }
                    Err(why) => self.note(format!(
                        "{field}: a mirror-like material kept diffuse ({why})"
                    )),
                }
            }
            self.asset.parts.push(AssetPart {
                name,
                surface,
                triangles,
                uvs,
            });
        }
        Ok(())
    }

    /// The diffuse surface of `material`, and the texture-coordinate set its textures read.
    fn material(&mut self, material: &gltf::Material) -> Result<(Surface, Option<u32>)> {
        let field = match material.index() {
            Some(i) => format!("materials[{i}]"),
            None => "the default material".to_string(),
        };
        let pbr = material.pbr_metallic_roughness();
        let factor = pbr.base_color_factor();
        let albedo = Vec3::new(factor[0], factor[1], factor[2]);
        if !albedo.is_finite() || albedo.min_element() < 0.0 || albedo.max_element() > 1.0 {
            return Err(err(
                format!("{field}.pbrMetallicRoughness.baseColorFactor"),
                format!("is {albedo}: each channel must be in [0, 1]"),
            ));
        }
        let strength = material.emissive_strength().unwrap_or(1.0);
        let emission = Vec3::from_array(material.emissive_factor()) * strength;
        if !emission.is_finite() || emission.min_element() < 0.0 {
            return Err(err(
                format!("{field}.emissiveFactor"),
                format!("× emissive strength is {emission}: must be finite and ≥ 0"),
            ));
        }
        if material.alpha_mode() != gltf::material::AlphaMode::Opaque {
            self.note(format!(
                "{field}.alphaMode: {:?} is drawn opaque (the contract has no transparency)",
                material.alpha_mode()
            ));
        }
        let mut set: Option<u32> = None;
        let mut maps = SurfaceMaps::default();
        if let Some(info) = pbr.base_color_texture() {
            maps.albedo = Some(self.texture_map(
                &info,
                &format!("{field}.pbrMetallicRoughness.baseColorTexture"),
                &mut set,
            )?);
        }
        if let Some(info) = material.emissive_texture() {
            maps.emission =
                Some(self.texture_map(&info, &format!("{field}.emissiveTexture"), &mut set)?);
        }
        Ok((
            Surface::Diffuse {
                albedo,
                emission,
                maps,
            },
            set,
        ))
    }

    /// The map of a texture reference; `set` collects the texture-coordinate set (one per
    /// material: both renderers carry one set of coordinates per triangle).
    fn texture_map(
        &mut self,
        info: &gltf::texture::Info,
        field: &str,
        set: &mut Option<u32>,
    ) -> Result<TextureMap> {
        let transform = info.texture_transform();
        let coordinates = transform
            .as_ref()
            .and_then(|t| t.tex_coord())
            .unwrap_or(info.tex_coord());
        match *set {
            Some(s) if s != coordinates => {
                return Err(err(
                    format!("{field}.texCoord"),
                    format!(
                        "is {coordinates} where the material's other texture reads {s}: one set per material is supported"
                    ),
                ));
            }
            _ => *set = Some(coordinates),
        }
        let matrix = match &transform {
            None => IDENTITY_TRANSFORM,
            Some(t) => {
                // KHR_texture_transform: uv' = T·R·S·uv, R rotating by −rotation (its spec's matrix).
                let [ox, oy] = t.offset();
                let [sx, sy] = t.scale();
                let (s, c) = t.rotation().sin_cos();
                let m = [c * sx, s * sy, ox, -s * sx, c * sy, oy];
                if m.iter().any(|x| !x.is_finite()) {
                    return Err(err(
                        format!("{field}.extensions.KHR_texture_transform"),
                        "has a value that is not finite",
                    ));
                }
                m
            }
        };
        let texture = info.texture();
        let sampler = texture.sampler();
        let wrap = |w: gltf::texture::WrappingMode| match w {
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
            gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        };
        let image = texture.source();
        let index = self.image(&image)?;
        Ok(TextureMap {
            texture: index,
            wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
            transform: matrix,
        })
    }

    /// `images[i]` decoded (once) into the asset's textures.
    fn image(&mut self, image: &gltf::Image) -> Result<u32> {
        let i = image.index();
        if self.texture_of_image.len() <= i {
            self.texture_of_image.resize(i + 1, None);
        }
        if let Some(t) = self.texture_of_image[i] {
            return Ok(t);
        }
        let field = format!("images[{i}]");
        // From the JSON: the crate's `Image::source` unwraps a missing `uri` or `mimeType`.
        let json = &self.document.as_json().images[i];
        let bytes = match (&json.buffer_view, &json.uri) {
            (Some(v), _) => {
                let view = self.document.views().nth(v.value()).ok_or_else(|| {
                    err(
                        format!("{field}.bufferView"),
                        "refers to a buffer view the file does not have",
                    )
                })?;
                self.view_bytes(&view)?.to_vec()
            }
            (None, Some(uri)) => self.uri_bytes(&format!("{field}.uri"), uri, "glTF image")?,
            (None, None) => return Err(err(field, "has neither a uri nor a bufferView")),
        };
        let texture = decode_png(
            &bytes,
            MAX_TEXTURE_SIDE,
            self.options.texel_budget.saturating_sub(self.texels),
        )
        .map_err(|why| err(field.clone(), why))?;
        self.texels += u64::from(texture.width) * u64::from(texture.height);
        let name = match image.name() {
            Some(n) => format!("{field} ({n})"),
            None => field,
        };
        let index = self.texture_base + self.asset.textures.len() as u32;
        self.asset.textures.push(Texture { name, ..texture });
        self.texture_of_image[i] = Some(index);
        Ok(index)
    }
}

/// A PNG (any 8- or 16-bit colour type) as sRGB RGBA8 texels, refused past `max_side` a
/// side or `max_texels` texels before decoding.
pub fn decode_png(
    bytes: &[u8],
    max_side: u32,
    max_texels: u64,
) -> std::result::Result<Texture, String> {
    use image::ImageDecoder;
    if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        return Err("is a JPEG image: textures are read from PNG only (convert it to PNG)".into());
    }
    let decoder = image::codecs::png::PngDecoder::new(std::io::Cursor::new(bytes))
        .map_err(|e| format!("is not a readable PNG image ({e})"))?;
    let (w, h) = decoder.dimensions();
    if w == 0 || h == 0 || w > max_side || h > max_side {
        return Err(format!(
            "is {w}×{h} texels; a texture must be 1 to {max_side} texels a side"
        ));
    }
    if u64::from(w) * u64::from(h) > max_texels {
        return Err(format!(
            "is {w}×{h} texels, past the {max_texels} texels the scene's textures may still hold"
        ));
    }
    let image = image::DynamicImage::from_decoder(decoder)
        .map_err(|e| format!("cannot decode the PNG ({e})"))?;
    let rgba = image.to_rgba8();
    Ok(Texture {
        name: String::new(),
        width: w,
        height: h,
        texels: rgba.pixels().map(|p| p.0).collect(),
    })
}

fn material_name(material: &gltf::Material) -> String {
    match (material.index(), material.name()) {
        (Some(i), Some(n)) => format!("materials[{i}] (\"{n}\")"),
        (Some(i), None) => format!("materials[{i}]"),
        _ => "the default material".into(),
    }
}

fn is_mirror_material(material: &gltf::Material) -> bool {
    let pbr = material.pbr_metallic_roughness();
    pbr.metallic_factor() >= 1.0
        && pbr.roughness_factor() <= MIRROR_MAX_ROUGHNESS
        && pbr.metallic_roughness_texture().is_none()
}

/// The mirror whose front is the union of `triangles` (wound counter-clockwise, all facing
/// one way), if they form one planar rectangle; why not otherwise.
fn rectangle(triangles: &[[Vec3; 3]]) -> std::result::Result<Mirror, String> {
    let area = |t: &[Vec3; 3]| (t[1] - t[0]).cross(t[2] - t[0]);
    let total: Vec3 = triangles.iter().map(area).sum();
    let Some(normal) = total.try_normalize() else {
        return Err("its triangles have no area".into());
    };
    let points: Vec<Vec3> = triangles.iter().flatten().copied().collect();
    let scale = points
        .iter()
        .map(|p| (*p - points[0]).length())
        .fold(0.0, f32::max);
    let tolerance = 1e-4 * scale.max(1e-6);
    if points
        .iter()
        .any(|p| (*p - points[0]).dot(normal).abs() > tolerance)
    {
        return Err("its triangles are not in one plane".into());
    }
    if triangles.iter().any(|t| area(t).dot(normal) <= 0.0) {
        return Err("its triangles do not all face one way".into());
    }
    // A rectangle's bounding box is itself along one of its edges: try each edge's direction
    // (the first 64 triangles' edges) and keep the smallest box.
    let bounds = |a: Vec3| {
        let b = normal.cross(a);
        points.iter().fold(
            (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN)),
            |(lo, hi), p| {
                let q = Vec2::new(p.dot(a), p.dot(b));
                (lo.min(q), hi.max(q))
            },
        )
    };
    let (a, lo, hi) = triangles
        .iter()
        .take(64)
        .flat_map(|t| [t[1] - t[0], t[2] - t[1], t[0] - t[2]])
        .filter_map(|e| (e - normal * e.dot(normal)).try_normalize())
        .map(|a| {
            let (lo, hi) = bounds(a);
            (a, lo, hi)
        })
        .min_by(|x, y| {
            let area = |(_, lo, hi): &(Vec3, Vec2, Vec2)| (*hi - *lo).x * (*hi - *lo).y;
            area(x).total_cmp(&area(y))
        })
        .ok_or("its triangles have no edges")?;
    let b = normal.cross(a);
    let extent = hi - lo;
    // Twice the triangles' area is the cross products' length.
    let covered = 0.5 * total.length();
    if extent.min_element() <= 0.0
        || (covered - extent.x * extent.y).abs() > 1e-3 * extent.x * extent.y
    {
        return Err(format!(
            "its triangles cover {covered:.4} of the {:.4} of their bounding rectangle (not a rectangle)",
            extent.x * extent.y
        ));
    }
    let mid = (lo + hi) * 0.5;
    let offset = points[0].dot(normal);
    // `up` along b: right = up × normal = b × n = a.
    Ok(Mirror {
        name: String::new(),
        center: a * mid.x + b * mid.y + normal * offset,
        normal,
        up: b,
        width: extent.x,
        height: extent.y,
        reflectance: Vec3::ONE,
        back_albedo: Vec3::ZERO,
    })
}

/// A URI's %-escapes decoded (file names with spaces are written `%20`).
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Small budgets, the first scene, no transform.
    fn small_options() -> GltfOptions {
        GltfOptions {
            scene: None,
            triangle_budget: 1 << 10,
            texel_budget: 1 << 10,
            transform: Mat4::IDENTITY,
            curved_mirrors: CurvedMirrors::Refuse,
        }
    }

    /// A glTF of one triangle (three positions in a data URI), with `asset` as given and
    /// `accessor` (more fields of its POSITION accessor, each with a trailing comma).
    fn one_triangle(asset: &str, accessor: &str) -> String {
        format!(
            r#"{{"asset": {asset}, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
            "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}}}]}}],
            "accessors": [{{{accessor} "bufferView": 0, "componentType": 5126, "count": 3,
                            "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}}],
            "bufferViews": [{{"buffer": 0, "byteLength": 36}}],
            "buffers": [{{"uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA", "byteLength": 36}}]}}"#
        )
    }

    #[test]
    fn a_planar_rectangle_is_a_mirror_and_other_shapes_are_not() {
        let (p, q, r, s) = (
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        );
        let m = rectangle(&[[p, q, r], [p, r, s]]).unwrap();
        assert!((m.normal - Vec3::Z).length() < 1e-6);
        assert!((m.center - Vec3::new(1.0, 0.5, 0.0)).length() < 1e-6);
        assert!((m.width * m.height - 2.0).abs() < 1e-5);
        // The mirror's own corners span the same rectangle, front facing +z.
        let c = m.corners();
        assert!(((c[1] - c[0]).cross(c[2] - c[0])).dot(Vec3::Z) > 0.0);
        // A triangle alone is not a rectangle; a bent pair is not planar.
        assert!(
            rectangle(&[[p, q, r]])
                .unwrap_err()
                .contains("not a rectangle")
        );
        let bent = Vec3::new(0.0, 1.0, 0.5);
        assert!(
            rectangle(&[[p, q, r], [p, r, bent]])
                .unwrap_err()
                .contains("plane")
        );
    }

    /// glTF 2.x loads, whatever its minor version; another major, a `minVersion` above 2.0
    /// or a version not of the form `<major>.<minor>` is refused, naming the field.
    #[test]
    fn only_gltf_2_loads() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("v.gltf");
        let options = small_options();
        for (asset, refused) in [
            (r#"{"version": "2.0"}"#, None),
            (r#"{"version": "2.1"}"#, None),
            (r#"{"version": "2.0", "minVersion": "2.0"}"#, None),
            (r#"{"version": "3.0"}"#, Some("asset.version")),
            (r#"{"version": "1.0"}"#, Some("asset.version")),
            (r#"{"version": "2"}"#, Some("asset.version")),
            (r#"{"version": "two.0"}"#, Some("asset.version")),
            (
                r#"{"version": "2.1", "minVersion": "2.1"}"#,
                Some("asset.minVersion"),
            ),
            (
                r#"{"version": "2.0", "minVersion": "x"}"#,
                Some("asset.minVersion"),
            ),
        ] {
            std::fs::write(&path, one_triangle(asset, "")).unwrap();
            match (load_gltf(&path, &options), refused) {
                (Ok(_), None) => {}
                (Err(e), Some(field)) => {
                    let e = e.to_string();
                    assert!(e.contains(field) && e.contains("glTF"), "{asset}: {e}");
                }
                (r, _) => panic!("{asset}: {:?}", r.map(|_| "loaded")),
            }
        }
        // A glTF 1.0 file, whose top-level items are objects keyed by name, not arrays: its
        // version is read before the 2.0 schema would refuse its shape.
        std::fs::write(
            &path,
            r#"{"asset": {"version": "1.0"}, "scene": "main",
                "scenes": {"main": {"nodes": ["a"]}}, "nodes": {"a": {"meshes": []}}}"#,
        )
        .unwrap();
        let e = load_gltf(&path, &options)
            .err()
            .expect("refused")
            .to_string();
        assert!(
            e.contains("asset.version") && e.contains("gltf-pipeline"),
            "{e}"
        );
    }

    #[test]
    fn percent_escapes_decode_and_bad_ones_are_refused() {
        assert_eq!(
            percent_decode("my%20box.bin").as_deref(),
            Some("my box.bin")
        );
        assert_eq!(percent_decode("a%2"), None);
        assert_eq!(percent_decode("a%zz"), None);
    }

    /// An accessor's byteOffset near 2^64 is refused naming it: `offset + element size` had
    /// wrapped around in release builds, passed the bounds check and panicked on the slice.
    #[test]
    fn a_byte_offset_past_the_buffer_is_refused_not_wrapped() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("far.gltf");
        for (offset, field) in [
            (u64::MAX - 3, "accessors[0].byteOffset"),
            (36, "accessors[0].byteOffset"),
            (4, "accessors[0].count"),
        ] {
            std::fs::write(
                &path,
                one_triangle(
                    r#"{"version": "2.0"}"#,
                    &format!(r#""byteOffset": {offset},"#),
                ),
            )
            .unwrap();
            let options = small_options();
            let e = load_gltf(&path, &options).err().expect("refused");
            assert!(e.to_string().contains(field), "{offset}: {e}");
        }
    }
}
