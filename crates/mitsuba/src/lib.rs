//! Mitsuba 3 export: the same scene as Mitsuba XML, so our ground truth can be checked
//! against the reference renderer of the field (`tools/mitsuba/`, `docs/mitsuba.md`).
//!
//! Mapping (each choice is what makes Mitsuba compute our shading contract):
//! - camera → `perspective` with `fov_axis = "y"` (Mitsuba's default axis is x) and a
//!   `lookat`; film `hdrfilm`, float32 RGB, **box** filter (the default is Gaussian); two
//!   sensors alike but for their sampler: the first `stratified` without jitter, whose s²
//!   samples are exactly our s×s sub-pixel grid (`whitted`), the second `independent`
//!   (`path`: an unbiased estimate; the unjittered grid is a biased quadrature of every
//!   random dimension);
//! - every part (object or mirror) → its own OBJ beside the XML holding *our* triangles, the
//!   coordinates written as the shortest text that round-trips to the same f32, loaded with
//!   `face_normals = true`;
//! - diffuse → `twosided` `diffuse` (our diffuse is two-sided); emission → an `area`
//!   emitter (one-sided, like ours);
//! - mirror → `twosided` with a `conductor` (`material = none`: reflects exactly
//!   `specular_reflectance` at every angle) in front and a `diffuse` of the back albedo behind;
//! - an uneven mirror (a `bump`) → its OBJ with texture coordinates and the `conductor`
//!   wrapped in a `normalmap` BSDF reading an EXR beside the meshes: for a normal map, its
//!   texels decoded and scaled by the strength, `(s·m.x, s·m.y, m.z)`, stored as
//!   `(n + 1)/2` (Mitsuba computes `2·texel − 1` and normalizes after bilinear filtering,
//!   as the contract does, so the export is exact) and tiled by the bitmap's `to_uv`; a
//!   ripple is baked into a map of 48 texels per wavelength at the texel centres over the
//!   whole mirror, clamped at its edges (bilinear between them: an approximation of
//!   relative size ~(π/48)²/2);
//! - a textured diffuse part (`docs/shading.md`, "Textures") → its OBJ with texture
//!   coordinates `(u, 1 − v)` (Mitsuba's OBJ loader turns them back into glTF's `(u, v)`,
//!   row 0 at `v = 0`), and a `bitmap` per texture: an EXR beside the meshes holding the
//!   factor × the sRGB-decoded texels (linear, so Mitsuba's bilinear filter blends the same
//!   numbers as the contract's), `filter_type = bilinear`, the wrap mode, and the map's
//!   transform as `to_uv` (a 4×4 matrix: Mitsuba reads a 2D translation from its 4th
//!   column); both renderers' lookups are then the same arithmetic;
//! - point light → `point` (intensity in W/sr); background → `constant` emitter.
//!
//! What Mitsuba cannot express — the ambient term, the terminal radiance and the exposure —
//! goes into `mirrorbox.json` beside the XML, which the Whitted integrator in
//! `tools/mitsuba/render.py` reads (Mitsuba's own `path` cannot use it: see the docs).

use glam::Vec3;
use mirrorbox_files::{FileError, StagedFiles};
use mirrorbox_scene::{Scene, Surface};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Export settings that are not part of the scene.
#[derive(Clone, Copy, Debug)]
pub struct ExportSettings {
    /// Samples per pixel; a perfect square (the stratified grid).
    pub spp: u32,
}

/// Texels per ripple wavelength in a baked normal map.
const RIPPLE_TEXELS_PER_WAVELENGTH: f32 = 48.0;

/// The normal map Mitsuba's `normalmap` reads for an uneven mirror (texels `(n + 1)/2`, row 0
/// at the mirror's top) and its tiling: a normal map alone exactly (its texels scaled by
/// the strength, tiled by `to_uv`), anything with a ripple baked at the texel centres of
/// [`RIPPLE_TEXELS_PER_WAVELENGTH`] per wavelength (at most 4096 a side).
fn normal_texture(
    m: &mirrorbox_scene::Mirror,
    b: &mirrorbox_scene::bump::MirrorBump,
) -> (mirrorbox_image::RgbImage, [f32; 2]) {
    let encode = |n: glam::DVec3| {
        [
            (n.x as f32 + 1.0) / 2.0,
            (n.y as f32 + 1.0) / 2.0,
            (n.z as f32 + 1.0) / 2.0,
        ]
    };
    match (&b.ripple, &b.normal_map) {
        (None, Some(map)) => {
            let image = mirrorbox_image::RgbImage::from_fn(map.width, map.height, |x, y| {
                let t = map.texels[(y * map.width + x) as usize];
                let d = |c: u8| f64::from(c) * 2.0 / 255.0 - 1.0;
                let s = f64::from(map.strength);
                encode(glam::DVec3::new(s * d(t[0]), s * d(t[1]), d(t[2])))
            });
            (image, map.tiling)
        }
        (Some(r), _) => {
            let side = |len: f32| {
                ((len / r.wavelength * RIPPLE_TEXELS_PER_WAVELENGTH).ceil() as u32).clamp(2, 4096)
            };
            let (w, h) = (side(m.width), side(m.height));
            let image = mirrorbox_image::RgbImage::from_fn(w, h, |x, y| {
                let u = ((f64::from(x) + 0.5) / f64::from(w) - 0.5) * f64::from(m.width);
                let v = (0.5 - (f64::from(y) + 0.5) / f64::from(h)) * f64::from(m.height);
                encode(b.tangent_normal(u, v, f64::from(m.width), f64::from(m.height)))
            });
            (image, [1.0, 1.0])
        }
        (None, None) => (
            mirrorbox_image::RgbImage::from_fn(1, 1, |_, _| [0.5, 0.5, 1.0]),
            [1.0, 1.0],
        ),
    }
}

fn rgb(v: Vec3) -> String {
    format!("{}, {}, {}", v.x, v.y, v.z)
}

/// Writes `xml_path` and its meshes (under `meshes/` beside it) and `mirrorbox.json`;
/// returns every file written. Every file is staged under a temporary name and renamed into
/// place once all are written: a scene refused part-way (a texture Mitsuba cannot wrap)
/// leaves no file, and no `meshes/` folder that the export made.
pub fn export(
    scene: &Scene,
    xml_path: &Path,
    settings: ExportSettings,
) -> Result<Vec<PathBuf>, FileError> {
    let dir = mirrorbox_files::folder_of(xml_path);
    refuse_another_export(dir, xml_path)?;
    let mesh_dir = dir.join("meshes");
    let made_mesh_dir = !mesh_dir.is_dir();
    std::fs::create_dir_all(&mesh_dir).map_err(|e| FileError {
        path: mesh_dir.clone(),
        message: format!("cannot create the folder: {e}"),
        // A file of its name is the user's to move (exit 2), not a failure.
        refused: mesh_dir.exists(),
    })?;
    let mut staged = StagedFiles::new();
    let result = match export_staged(scene, xml_path, &mesh_dir, settings, &mut staged) {
        Ok(()) => staged.commit(),
        Err(e) => {
            drop(staged); // removes what it staged
            Err(e)
        }
    };
    if result.is_err() && made_mesh_dir {
        // Empty by now: the staged files went with their temporary names.
        let _ = std::fs::remove_dir(&mesh_dir);
    }
    result
}

fn export_staged(
    scene: &Scene,
    xml_path: &Path,
    mesh_dir: &Path,
    settings: ExportSettings,
    staged: &mut StagedFiles,
) -> Result<(), FileError> {
    let dir = mirrorbox_files::folder_of(xml_path);
    let cam = &scene.camera;
    let mut xml = String::new();
    let _ = writeln!(xml, "<?xml version=\"1.0\" encoding=\"utf-8\"?>");
    let _ = writeln!(
        xml,
        "<!-- Exported by mirrorbox {} from {} (scene hash {:016x}).\n     \
         Ambient, terminal radiance and exposure are in mirrorbox.json; see docs/mitsuba.md. -->",
        env!("CARGO_PKG_VERSION"),
        scene.source.display(),
        scene.content_hash()
    );
    let _ = writeln!(xml, "<scene version=\"3.0.0\">");
    let _ = writeln!(xml, "  <default name=\"spp\" value=\"{}\"/>", settings.spp);
    let _ = writeln!(xml, "  <default name=\"max_depth\" value=\"66\"/>");
    let _ = writeln!(
        xml,
        "  <integrator type=\"path\">\n    <integer name=\"max_depth\" value=\"$max_depth\"/>\n    \
         <integer name=\"rr_depth\" value=\"100000\"/>\n  </integrator>"
    );
    // Two sensors, one camera. The first (Mitsuba's default, `whitted`'s) samples our
    // sub-pixel grid unjittered, sample for sample. The second (render.py's `path`) samples
    // independently: the unjittered stratified sampler gives every random dimension its
    // strata's centres, a fixed quadrature whose error does not average out (`mirror_room`'s
    // image mean 0.12 % low, docs/mitsuba.md); of the unbiased samplers the independent one
    // measured the cheaper (×1.12 the unjittered time, jittered ×1.15).
    for (comment, sampler) in [
        (
            "whitted: our sub-pixel grid",
            "<sampler type=\"stratified\">\n      <integer name=\"sample_count\" value=\"$spp\"/>\n      \
             <boolean name=\"jitter\" value=\"false\"/>\n    </sampler>",
        ),
        (
            "path: unbiased samples",
            "<sampler type=\"independent\">\n      <integer name=\"sample_count\" value=\"$spp\"/>\n    \
             </sampler>",
        ),
    ] {
        let _ = writeln!(
            xml,
            "  <!-- {comment} -->\n  <sensor type=\"perspective\">\n    <string name=\"fov_axis\" value=\"y\"/>\n    \
             <float name=\"fov\" value=\"{}\"/>\n    <float name=\"near_clip\" value=\"0.0001\"/>\n    \
             <float name=\"far_clip\" value=\"1000000\"/>\n    <transform name=\"to_world\">\n      \
             <lookat origin=\"{}\" target=\"{}\" up=\"{}\"/>\n    </transform>\n    \
             {sampler}\n    <film type=\"hdrfilm\">\n      \
             <integer name=\"width\" value=\"{}\"/>\n      <integer name=\"height\" value=\"{}\"/>\n      \
             <string name=\"pixel_format\" value=\"rgb\"/>\n      \
             <string name=\"component_format\" value=\"float32\"/>\n      <rfilter type=\"box\"/>\n    \
             </film>\n  </sensor>",
            cam.fov_y_deg,
            rgb(cam.position),
            rgb(cam.look_at),
            rgb(cam.up),
            cam.width,
            cam.height
        );
    }
    let _ = writeln!(
        xml,
        "  <emitter type=\"constant\">\n    <rgb name=\"radiance\" value=\"{}\"/>\n  </emitter>",
        rgb(scene.background)
    );
    for light in &scene.lighting.lights {
        let _ = writeln!(
            xml,
            "  <emitter type=\"point\">\n    <point name=\"position\" value=\"{}\"/>\n    \
             <rgb name=\"intensity\" value=\"{}\"/>\n  </emitter>",
            rgb(light.position),
            rgb(light.intensity)
        );
    }
    let g = &scene.geometry;
    for (i, part) in g.parts.iter().enumerate() {
        if part.triangles.is_empty() {
            continue;
        }
        let file = format!("{i:03}_{}.obj", slug(&part.name));
        let mut obj = format!(
            "# {} ({} triangles), exported by mirrorbox\n",
            part.name,
            part.triangles.len()
        );
        let bumped = match &g.surfaces[part.surface as usize] {
            Surface::Mirror { mirror, .. } => scene.bumps[*mirror]
                .as_ref()
                .map(|b| (&scene.mirrors[*mirror], b)),
            Surface::Diffuse { .. } => None,
        };
        let textured = matches!(&g.surfaces[part.surface as usize], Surface::Diffuse { maps, .. } if !maps.is_empty());
        for (k, t) in g.triangles[part.triangles.clone()].iter().enumerate() {
            let uv = g.uvs[part.triangles.start + k];
            for (c, v) in t.iter().enumerate() {
                let _ = writeln!(obj, "v {} {} {}", v.x, v.y, v.z);
                if textured {
                    let _ = writeln!(obj, "vt {} {}", uv[c].x, 1.0 - uv[c].y);
                }
                if let Some((m, _)) = bumped {
                    // OBJ's v grows upwards: (u/width + ½, v/height + ½).
                    let d = *v - m.center;
                    let _ = writeln!(
                        obj,
                        "vt {} {}",
                        d.dot(m.right()) / m.width + 0.5,
                        d.dot(m.up) / m.height + 0.5
                    );
                }
            }
        }
        for k in 0..part.triangles.len() {
            let (a, b, c) = (3 * k + 1, 3 * k + 2, 3 * k + 3);
            if bumped.is_some() || textured {
                let _ = writeln!(obj, "f {a}/{a} {b}/{b} {c}/{c}");
            } else {
                let _ = writeln!(obj, "f {a} {b} {c}");
            }
        }
        stage_bytes(staged, &mesh_dir.join(&file), obj.as_bytes())?;
        let colour = |name: &str, what: &str, factor: Vec3, map, staged: &mut StagedFiles| {
            colour_xml(
                g,
                mesh_dir,
                (i, &part.name),
                (name, what),
                factor,
                map,
                staged,
            )
        };
        let bsdf = match &g.surfaces[part.surface as usize] {
            Surface::Diffuse { albedo, maps, .. } => format!(
                "    <bsdf type=\"twosided\">\n      <bsdf type=\"diffuse\">\n        \
                 {}\n      </bsdf>\n    </bsdf>",
                colour("reflectance", "albedo", *albedo, maps.albedo, staged)?
            ),
            Surface::Mirror {
                reflectance,
                back_albedo,
                ..
            } => {
                let conductor = format!(
                    "<bsdf type=\"conductor\">\n        \
                     <string name=\"material\" value=\"none\"/>\n        \
                     <rgb name=\"specular_reflectance\" value=\"{}\"/>\n      </bsdf>",
                    rgb(*reflectance)
                );
                let front = match bumped {
                    None => conductor,
                    Some((m, b)) => {
                        let name = format!("{i:03}_{}_normals.exr", slug(&part.name));
                        let path = mesh_dir.join(&name);
                        let (image, tiling) = normal_texture(m, b);
                        // A ripple is baked over the whole mirror once: its edges must not
                        // blend with the opposite edge's texels (a normal map tiles).
                        let wrap = if b.ripple.is_some() {
                            "clamp"
                        } else {
                            "repeat"
                        };
                        stage_exr(staged, &path, &image)?;
                        format!(
                            "<bsdf type=\"normalmap\">\n        \
                             <texture name=\"normalmap\" type=\"bitmap\">\n          \
                             <string name=\"filename\" value=\"meshes/{name}\"/>\n          \
                             <boolean name=\"raw\" value=\"true\"/>\n          \
                             <string name=\"filter_type\" value=\"bilinear\"/>\n          \
                             <string name=\"wrap_mode\" value=\"{wrap}\"/>\n          \
                             <transform name=\"to_uv\"><scale x=\"{}\" y=\"{}\"/></transform>\n        \
                             </texture>\n        {conductor}\n      </bsdf>",
                            tiling[0], tiling[1]
                        )
                    }
                };
                format!(
                    "    <bsdf type=\"twosided\">\n      {front}\n      \
                     <bsdf type=\"diffuse\">\n        <rgb name=\"reflectance\" value=\"{}\"/>\n      </bsdf>\n    </bsdf>",
                    rgb(*back_albedo)
                )
            }
        };
        let emitter = match &g.surfaces[part.surface as usize] {
            Surface::Diffuse { emission, maps, .. } if *emission != Vec3::ZERO => format!(
                "\n    <emitter type=\"area\">\n      {}\n    </emitter>",
                colour("radiance", "emission", *emission, maps.emission, staged)?
            ),
            _ => String::new(),
        };
        let _ = writeln!(
            xml,
            "  <!-- {} -->\n  <shape type=\"obj\">\n    <string name=\"filename\" value=\"meshes/{file}\"/>\n    \
             <boolean name=\"face_normals\" value=\"true\"/>\n{bsdf}{emitter}\n  </shape>",
            xml_comment(&part.name)
        );
    }
    let _ = writeln!(xml, "</scene>");
    let sidecar = serde_json::json!({
        // The XML this sidecar belongs to: render.py refuses another's.
        "xml": xml_name(xml_path),
        "scene": scene.source.display().to_string(),
        "scene_hash": format!("{:016x}", scene.content_hash()),
        "ambient": scene.lighting.ambient.to_array(),
        "background": scene.background.to_array(),
        "terminal": scene.terminal.to_array(),
        "exposure": cam.exposure,
        "width": cam.width,
        "height": cam.height,
        "spp": settings.spp,
        "not_exported": not_exported(scene),
    });
    stage_bytes(
        staged,
        &dir.join("mirrorbox.json"),
        format!("{sidecar:#}\n").as_bytes(),
    )?;
    stage_bytes(staged, xml_path, xml.as_bytes())
}

/// The XML's file name, as the sidecar records it.
fn xml_name(xml_path: &Path) -> String {
    xml_path
        .file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into_owned())
}

/// One export per folder: its `mirrorbox.json` and `meshes/` have fixed names, so a second
/// XML written beside another would take the first one's sidecar and meshes (the first then
/// rendered the second's scene, unsaid). Replacing the same XML is allowed.
fn refuse_another_export(dir: &Path, xml_path: &Path) -> Result<(), FileError> {
    let sidecar = dir.join("mirrorbox.json");
    if !sidecar.exists() {
        return Ok(());
    }
    // Bounded (a sidecar is a few hundred bytes), and a folder or FIFO of its name refused
    // here, before any mesh is written.
    let text = mirrorbox_files::read_bounded_text(&sidecar, 1 << 20, "an export's mirrorbox.json")?;
    let other = serde_json::from_str::<serde_json::Value>(&text)
        .ok()
        .and_then(|v| v.get("xml").and_then(|x| x.as_str()).map(String::from));
    match other {
        Some(other) if other == xml_name(xml_path) => Ok(()),
        // An export from before the sidecar named its XML: which one is not known.
        None if dir.join("meshes").is_dir() && !xml_path.is_file() => Err(FileError {
            path: sidecar,
            message: "this folder holds another export (its mirrorbox.json and meshes/ \
                      would be replaced): give each export a folder of its own"
                .into(),
            refused: true,
        }),
        None => Ok(()),
        Some(other) => Err(FileError {
            path: sidecar,
            message: format!(
                "this folder holds the export of {other} (its mirrorbox.json and meshes/ \
                 would be replaced): give each export a folder of its own"
            ),
            refused: true,
        }),
    }
}

fn stage_bytes(staged: &mut StagedFiles, path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    staged.stage_with(path, |tmp| {
        std::fs::write(tmp, bytes).map_err(|e| e.to_string())
    })
}

fn stage_exr(
    staged: &mut StagedFiles,
    path: &Path,
    image: &mirrorbox_image::RgbImage,
) -> Result<(), FileError> {
    mirrorbox_image::stage_exr(staged, path, image, &[]).map_err(|e| FileError {
        path: path.to_path_buf(),
        message: e.to_string(),
        refused: false,
    })
}

/// What the scene has that the export leaves out (Mitsuba's scene, and `render.py`'s
/// integrators, have no counterpart), one phrase each: the export renders one still view lit
/// directly, so a comparison with `trace` on such a scene differs by these. Recorded in
/// `mirrorbox.json` and said by `export-mitsuba`.
pub fn not_exported(scene: &Scene) -> Vec<String> {
    let mut out = Vec::new();
    if scene.stereo.is_some() {
        out.push("camera.stereo (the head's view is exported)".to_string());
    }
    if scene.camera_path.is_some() {
        out.push("camera.path (the still camera is exported)".to_string());
    }
    if scene.lighting.shadows {
        out.push("lighting.shadows (render.py's whitted lights without shadows)".to_string());
    }
    if scene.lighting.mirrored_lights > 0 {
        out.push(format!(
            "lighting.mirrored_lights {} (image-source lighting, docs/mitsuba.md)",
            scene.lighting.mirrored_lights
        ));
    }
    out
}

/// A factor as `<rgb>`, or the factor × its texture as a `bitmap` reading an EXR written
/// beside the meshes (`part`: the part's index and name; `name`: the BSDF's or emitter's
/// parameter; `what`: the file's suffix).
fn colour_xml(
    g: &mirrorbox_scene::Geometry,
    mesh_dir: &Path,
    part: (usize, &str),
    (name, what): (&str, &str),
    factor: Vec3,
    map: Option<mirrorbox_scene::texture::TextureMap>,
    staged: &mut StagedFiles,
) -> Result<String, FileError> {
    let Some(m) = map else {
        return Ok(format!("<rgb name=\"{name}\" value=\"{}\"/>", rgb(factor)));
    };
    let wrap = mitsuba_wrap(&m, part.1)?;
    let file = format!("{:03}_{}_{what}.exr", part.0, slug(part.1));
    bitmap_exr(
        &g.textures[m.texture as usize],
        factor,
        &mesh_dir.join(&file),
        staged,
    )?;
    // Mitsuba's OBJ loader turns `vt` (u, 1 − v) back into (u, v) and its bitmap reads row 0
    // at v = 0, so the contract's transform applies as it is. `to_uv` is a 2D transform
    // extracted from a 4×4 matrix: its translation is read from the 4th column (a 3×3 matrix
    // in the XML loses it), hence the 16 values.
    let k = m.transform;
    Ok(format!(
        "<texture name=\"{name}\" type=\"bitmap\">\n          \
         <string name=\"filename\" value=\"meshes/{file}\"/>\n          \
         <string name=\"filter_type\" value=\"bilinear\"/>\n          \
         <string name=\"wrap_mode\" value=\"{wrap}\"/>\n          \
         <transform name=\"to_uv\"><matrix value=\"{} {} 0 {} {} {} 0 {} 0 0 1 0 0 0 0 1\"/></transform>\n        \
         </texture>",
        k[0], k[1], k[2], k[3], k[4], k[5]
    ))
}

/// A texture as Mitsuba reads it: `factor` × each texel decoded from sRGB, in linear f32.
fn bitmap_exr(
    texture: &mirrorbox_scene::texture::Texture,
    factor: Vec3,
    path: &Path,
    staged: &mut StagedFiles,
) -> Result<(), FileError> {
    use mirrorbox_scene::texture::srgb_to_linear;
    let image = mirrorbox_image::RgbImage::from_fn(texture.width, texture.height, |x, y| {
        let t = texture.texels[(y * texture.width + x) as usize];
        [
            factor.x * srgb_to_linear(t[0]),
            factor.y * srgb_to_linear(t[1]),
            factor.z * srgb_to_linear(t[2]),
        ]
    });
    stage_exr(staged, path, &image)
}

/// Mitsuba's bitmap has one wrap mode for both axes: a map whose axes differ is refused.
fn mitsuba_wrap(
    m: &mirrorbox_scene::texture::TextureMap,
    part: &str,
) -> Result<&'static str, FileError> {
    use mirrorbox_scene::texture::Wrap;
    let name = |w: Wrap| match w {
        Wrap::Repeat => "repeat",
        Wrap::ClampToEdge => "clamp",
        Wrap::MirroredRepeat => "mirror",
    };
    if m.wrap[0] != m.wrap[1] {
        return Err(FileError {
            path: PathBuf::from(part),
            message: format!(
                "a texture wraps {} along u and {} along v (its sampler's wrapS and wrapT): \
                 Mitsuba's bitmap has one wrap mode for both",
                name(m.wrap[0]),
                name(m.wrap[1])
            ),
            refused: true,
        });
    }
    Ok(name(m.wrap[0]))
}

fn slug(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect();
    s.trim_matches('_').chars().take(40).collect()
}

fn xml_comment(s: &str) -> String {
    s.replace("--", "- -")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What the export leaves out is named: nothing for a plain scene; the lit scene's
    /// shadows and mirrored lights, the walk's camera path, the stereo scene's rig.
    #[test]
    fn what_the_export_leaves_out_is_named() {
        let named = |file: &str| not_exported(&mirrorbox_scene::load::bundled_scene(file));
        assert!(named("mirror_box.json").is_empty());
        let lit = named("mirror_box_lit.json");
        assert!(
            lit.len() == 2 && lit[0].starts_with("lighting.shadows") && lit[1].contains(" 8 "),
            "{lit:?}"
        );
        assert!(named("mirror_box_walk.json")[0].starts_with("camera.path"));
        assert!(named("stereo_box.json")[0].starts_with("camera.stereo"));
    }

    #[test]
    fn exported_meshes_hold_exactly_our_triangles() {
        let scene = mirrorbox_scene::load::bundled_scene("single_mirror.json");
        let dir = tempfile::tempdir().unwrap();
        let xml = dir.path().join("scene.xml");
        let files = export(&scene, &xml, ExportSettings { spp: 4 }).unwrap();
        assert_eq!(files.len(), scene.geometry.parts.len() + 2);
        // Read every OBJ back (in part order) and compare bit for bit.
        let mut triangles = Vec::new();
        for f in files
            .iter()
            .filter(|f| f.extension().is_some_and(|e| e == "obj"))
        {
            let text = std::fs::read_to_string(f).unwrap();
            let v: Vec<Vec3> = text
                .lines()
                .filter_map(|l| l.strip_prefix("v "))
                .map(|l| {
                    let c: Vec<f32> = l.split(' ').map(|x| x.parse().unwrap()).collect();
                    Vec3::new(c[0], c[1], c[2])
                })
                .collect();
            triangles.extend(v.chunks(3).map(|c| [c[0], c[1], c[2]]));
        }
        assert_eq!(triangles, scene.geometry.triangles);
        let text = std::fs::read_to_string(&xml).unwrap();
        assert!(text.contains("<string name=\"fov_axis\" value=\"y\"/>"));
        assert!(text.contains("<rfilter type=\"box\"/>"));
        assert!(text.contains("<string name=\"component_format\" value=\"float32\"/>"));
        assert!(text.contains("<string name=\"material\" value=\"none\"/>"));
        assert_eq!(
            text.matches("<shape type=\"obj\">").count(),
            scene.geometry.parts.len()
        );
        // No temporary files are left.
        assert!(
            std::fs::read_dir(dir.path().join("meshes"))
                .unwrap()
                .all(|e| { !e.unwrap().path().to_string_lossy().ends_with(".tmp") })
        );
    }

    /// A second XML in a folder that holds an export is refused, naming the first (both
    /// share `mirrorbox.json` and `meshes/`: the first had rendered the second's scene); the
    /// same XML again replaces it.
    #[test]
    fn a_folder_holds_one_export() {
        let scene = mirrorbox_scene::load::bundled_scene("single_mirror.json");
        let dir = tempfile::tempdir().unwrap();
        let settings = || ExportSettings { spp: 4 };
        export(&scene, &dir.path().join("a.xml"), settings()).unwrap();
        export(&scene, &dir.path().join("a.xml"), settings()).expect("the same XML again");
        let e = export(&scene, &dir.path().join("b.xml"), settings()).unwrap_err();
        assert!(
            e.refused && e.to_string().contains("the export of a.xml"),
            "{e}"
        );
        assert!(!dir.path().join("b.xml").exists());
    }

    /// A ripple is baked over the whole mirror once, so its map is clamped at the edges; a
    /// scene's normal map tiles (`repeat`, as the contract's lookup wraps it).
    #[test]
    fn a_baked_ripple_is_clamped_and_a_normal_map_repeats() {
        for (file, wrap) in [
            ("bumpy_pair.json", "clamp"),
            ("bumpy_single.json", "repeat"),
        ] {
            let scene = mirrorbox_scene::load::bundled_scene(file);
            let dir = tempfile::tempdir().unwrap();
            let xml = dir.path().join("scene.xml");
            export(&scene, &xml, ExportSettings { spp: 4 }).unwrap();
            let text = std::fs::read_to_string(&xml).unwrap();
            let normalmaps = text.matches("<bsdf type=\"normalmap\">").count();
            let wraps = format!("<string name=\"wrap_mode\" value=\"{wrap}\"/>");
            assert!(normalmaps > 0, "{file}");
            assert_eq!(text.matches(&wraps).count(), normalmaps, "{file}: {text}");
        }
    }

    /// A folder where the export writes its sidecar is refused (exit 2) before any mesh is
    /// written: the meshes had been left without their XML.
    #[test]
    fn a_folder_in_the_sidecars_place_is_refused_leaving_nothing() {
        let scene = mirrorbox_scene::load::bundled_scene("single_mirror.json");
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("mirrorbox.json")).unwrap();
        let e = export(&scene, &dir.path().join("x.xml"), ExportSettings { spp: 4 }).unwrap_err();
        assert!(e.refused, "{e}");
        assert!(!dir.path().join("meshes").exists() && !dir.path().join("x.xml").exists());
    }

    /// Two sensors of one camera: the first samples our grid unjittered (`whitted`), the
    /// second independently (`path`, unbiased).
    #[test]
    fn whitted_and_path_each_have_their_sensor() {
        let scene = mirrorbox_scene::load::bundled_scene("single_mirror.json");
        let dir = tempfile::tempdir().unwrap();
        let xml = dir.path().join("scene.xml");
        export(&scene, &xml, ExportSettings { spp: 4 }).unwrap();
        let text = std::fs::read_to_string(&xml).unwrap();
        assert_eq!(text.matches("<sensor type=\"perspective\">").count(), 2);
        let (first, second) = (
            text.find("<sampler type=\"stratified\">").unwrap(),
            text.find("<sampler type=\"independent\">").unwrap(),
        );
        assert!(first < second);
        assert!(text.contains("<boolean name=\"jitter\" value=\"false\"/>"));
    }
}
