//! Issue 40: glTF 2.0 assets nobody here wrote — Debian's `assimp-testmodels`
//! (`scripts/install-system-deps.sh` installs it) — and the project's own textured asset
//! (`scenes/assets/textured_cube.gltf`, `scenes/textured_box.json`).
//!
//! - every real file loads, is placed in a mirror box by `mirrorbox import`'s
//!   `mirror_box_scene`, is seen in the truth, and every registered method draws it as the
//!   truth at its depth within bounds measured here (issue 50: before, only "finite and not
//!   one flat colour");
//! - every broken file is refused naming its glTF field;
//! - textured scenes: trace ↔ raster at the floor (the shading contract's "Textures").
//!
//! Where the corpus is missing the corpus tests fail, unless `MIRRORBOX_TEST_SKIP` names
//! `corpus` (`mirrorbox_testing`).

use crate::against_truth::Bounds;
use crate::methods::{error_against, settings, trace_depth};
use mirrorbox_raster::{Gpu, Method, render};
use mirrorbox_scene::Scene;
use mirrorbox_scene::load::parse_scene;
use std::path::Path;

const CORPUS: &str = "/usr/share/assimp/models/glTF2";

/// Real assets, with a note some must carry.
const REAL: [(&str, Option<&str>); 12] = [
    ("2CylinderEngine-glTF-Binary/2CylinderEngine.glb", None),
    ("BoxTextured-glTF/BoxTextured.gltf", None),
    ("BoxTextured-glTF-Binary/BoxTextured.glb", None),
    ("BoxTextured-glTF-Embedded/BoxTextured.gltf", None),
    (
        "BoxTextured-glTF-pbrSpecularGlossiness/BoxTextured.gltf",
        Some("KHR_materials_pbrSpecularGlossiness is not read"),
    ),
    ("BoxTexcoords-glTF/boxTexcoords.gltf", None),
    ("BoxBadNormals-glTF-Binary/BoxBadNormals.glb", None),
    ("cameras/Cameras.gltf", None),
    ("textureTransform/TextureTransformTest.gltf", None),
    ("ClearCoat-glTF/ClearCoatTest.gltf", Some("alphaMode")),
    (
        "glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf",
        Some("morph targets are not applied"),
    ),
    (
        "simple_skin/simple_skin.gltf",
        Some("skinning is not applied"),
    ),
];

/// Broken assets, with the glTF field and the words their refusal must carry.
const BROKEN: [(&str, &str); 17] = [
    (
        "BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb",
        "attributes[\"POSITION\"].min: is missing",
    ),
    (
        "IncorrectVertexArrays/Cube.gltf",
        "attributes[\"POSITION\"].min: is missing",
    ),
    (
        "IndexOutOfRange/IndexOutOfRange.gltf",
        "meshes[0].primitives[0].indices: element 0 is 255, out of range",
    ),
    (
        "IndexOutOfRange/AllIndicesOutOfRange.gltf",
        "meshes[0].primitives[0].indices: element 0 is 65535, out of range",
    ),
    (
        "MissingBin/BoxTextured.gltf",
        "buffers[0].uri: \"BoxTextured0.bin\"",
    ),
    (
        "RecursiveNodes/RecursiveNodes.gltf",
        "nodes[0].children: node 0 is its own ancestor",
    ),
    (
        "SchemaFailures/sceneWrongType.gltf",
        "scene: invalid type: string \"hello\"",
    ),
    (
        "TestNoRootNode/NoScene.gltf",
        "scene: refers to an item the file does not have",
    ),
    (
        "TestNoRootNode/SceneWithoutNodes.gltf",
        "scenes[0]: missing field `nodes`",
    ),
    (
        "BoxTextured-glTF-techniqueWebGL/BoxTextured.gltf",
        "extensionsRequired[0]: the file requires \"KHR_technique_webgl\"",
    ),
    (
        "wrongTypes/badArray.gltf",
        "meshes[0].primitives: invalid type",
    ),
    (
        "wrongTypes/badExtension.gltf",
        "baseColorTexture.extensions.KHR_texture_transform: invalid type",
    ),
    (
        "wrongTypes/badNumber.gltf",
        "materials[0].normalTexture.scale: invalid type",
    ),
    (
        "wrongTypes/badObject.gltf",
        "materials[0].pbrMetallicRoughness",
    ),
    ("wrongTypes/badString.gltf", "scenes[0].name: invalid type"),
    (
        "wrongTypes/badUint.gltf",
        "baseColorTexture.index: invalid type: integer `-1`",
    ),
    (
        "draco/2CylinderEngine.gltf",
        "requires \"KHR_draco_mesh_compression\"",
    ),
];

/// Whether the corpus is there; where not, the test fails, or returns where
/// `MIRRORBOX_TEST_SKIP` names `corpus` (`mirrorbox_testing`).
fn corpus_present() -> bool {
    mirrorbox_testing::require(
        mirrorbox_testing::CORPUS,
        Path::new(CORPUS).is_dir(),
        &format!("no {CORPUS}"),
    )
}

/// The scene file `mirrorbox import` writes for the asset at `rel`, `w × h` pixels.
fn imported_json(rel: &str, w: u32, h: u32) -> String {
    let path = Path::new(CORPUS).join(rel);
    mirrorbox_scene::import::mirror_box_scene(&path, &path.to_string_lossy(), None, w, h)
        .unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// The asset at `rel` in the mirror box `mirrorbox import` builds, `w × h` pixels.
fn imported(rel: &str, w: u32, h: u32) -> Scene {
    parse_scene(&imported_json(rel, w, h), Path::new("imported.json"))
        .unwrap_or_else(|e| panic!("{rel}: {e}"))
}

#[test]
fn every_gltf_of_the_corpus_loads_or_is_refused_naming_its_field() {
    if !corpus_present() {
        return;
    }
    for (rel, note) in REAL {
        let s = imported(rel, 32, 18);
        let notes = &s.geometry.obj_notes;
        match note {
            Some(n) => assert!(notes.iter().any(|x| x.contains(n)), "{rel}: {notes:?}"),
            None => assert!(notes.is_empty(), "{rel}: {notes:?}"),
        }
        // The asset's triangles are in, beside the box's floor and two mirrors.
        assert!(s.geometry.triangles.len() > 6, "{rel}");
    }
    for (rel, words) in BROKEN {
        let scene = serde_json::json!({
            "camera": { "position": [0, 1, 3], "look_at": [0, 0, 0], "fov_y_deg": 45, "width": 32, "height": 18 },
            "objects": [ { "type": "gltf", "path": format!("{CORPUS}/{rel}") } ]
        });
        let e = parse_scene(&scene.to_string(), Path::new("broken.json"))
            .err()
            .unwrap_or_else(|| panic!("{rel} loaded"))
            .to_string();
        assert!(
            e.contains("objects[0].path: glTF") && e.contains(words),
            "{rel}: {e}"
        );
    }
}

/// The size of the renders of every real asset.
const SIZE: (u32, u32) = (64, 36);

/// Each asset is seen: the truth with it differs from the truth of its box without it on at
/// least this share of the pixels. Measured (64×36, 2026-11-27): 16.1 % (the engine) to 53.2 %
/// (the boxes): `mirrorbox import` builds the box around the asset.
const SEEN_SHARE: f64 = 0.10;

/// The bounds of every method against the truth at its depth, measured on the 12 assets at
/// 64×36 (2026-11-27, lavapipe), the largest over the assets beside each. Exact methods:
/// at most 5 pixels of 2 304 off (0.22 %, the engine's thin CAD silhouettes: edge samples)
/// and FLIP ≤ 3.71e-3 (the engine; ≤ 4.03e-4 elsewhere), held to the exact methods'
/// criterion of 0.5 % and to 8e-3; the inexact ones 10 % (pixels off) and 20 % (FLIP) above
/// what they measured.
const BOUNDS: Bounds = Bounds {
    exact: (0.005, 8e-3),
    inexact: &[
        // depth 2; measured ≤ 6.77 % off, FLIP ≤ 3.04e-2.
        ("naive", 0.0745, 0.0365),
        ("auxiliary", 0.0745, 0.0365),
        // depth 1, exact there; measured ≤ 0.09 %, FLIP ≤ 2.82e-3.
        ("feedback", 0.005, 8e-3),
        // depth 1 and parallax; measured ≤ 31.73 %, FLIP ≤ 2.18e-1.
        ("cubemap", 0.349, 0.262),
        // depth 1, off-screen reflections missing; measured ≤ 30.56 %, FLIP ≤ 2.06e-1.
        ("ssr", 0.336, 0.247),
    ],
};

/// Each real asset in the mirror box `mirrorbox import` builds around it, at 64×36: its
/// truth is finite and shows it (at least [`SEEN_SHARE`] of the pixels differ from its box's
/// without it), and every registered method draws it as that truth at the method's depth
/// within [`BOUNDS`] — the engine (a real CAD mesh, 110 k triangles) included.
#[test]
fn every_real_gltf_traces_and_renders_with_every_method() {
    use crate::against_truth::{Truth, Without, check_every_method, every_render, pixels_off};
    if !corpus_present() {
        return;
    }
    let gpu = Gpu::new().unwrap();
    let n = (SIZE.0 * SIZE.1) as f64;
    let mut failures = Vec::new();
    for (rel, _) in REAL {
        let json = imported_json(rel, SIZE.0, SIZE.1);
        let s = parse_scene(&json, Path::new("imported.json")).unwrap();
        // The box alone: the asset's object taken out of the same scene file.
        let mut v: serde_json::Value = serde_json::from_str(&json).unwrap();
        v["objects"]
            .as_array_mut()
            .unwrap()
            .retain(|o| o["type"] != "gltf");
        let bare = parse_scene(&v.to_string(), Path::new("imported.json")).unwrap();
        let mut truth = Truth::new(&s);
        assert!(
            truth.at(8).pixels.iter().flatten().all(|c| c.is_finite()),
            "{rel}"
        );
        let mut bare_truth = Truth::new(&bare);
        let seen = pixels_off(truth.at(8), bare_truth.at(8)) as f64 / n;
        if seen < SEEN_SHARE {
            failures.push(format!(
                "{rel}: seen on {:.2} % of pixels, under {} %",
                100.0 * seen,
                100.0 * SEEN_SHARE
            ));
        }
        let bare_renders = every_render(&gpu, &bare, rel);
        let mut without = Without {
            renders: &bare_renders,
            truth: &mut bare_truth,
        };
        let (errors, failed) = check_every_method(&gpu, &s, &mut truth, rel, &BOUNDS, &mut without);
        println!("{rel}: seen on {:.1} % of pixels{errors}", 100.0 * seen);
        failures.extend(failed);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The contract's textures in both renderers: with the mirrors removed (the floor of every
/// comparison) the raster image is the tracer's to rounding — on the project's own textured
/// asset (base colour and emissive textures, a texture transform, mirrored-repeat and clamped
/// samplers, a node mirrored by a negative scale) and on the corpus's BoxTextured — and with
/// the mirrors, the exact methods match the truth at their depth as on untextured scenes.
#[test]
fn textured_scenes_agree_at_the_floor() {
    let gpu = Gpu::new().unwrap();
    let mut scenes = vec![("textured_box", {
        let mut s = mirrorbox_scene::load::bundled_scene("textured_box.json");
        s.camera = s.camera.with_size(160, 90);
        s
    })];
    if corpus_present() {
        scenes.push((
            "BoxTextured",
            imported("BoxTextured-glTF/BoxTextured.gltf", 160, 90),
        ));
    }
    // ray-query needs the adapter's ray queries (lavapipe has them): skipped only where they
    // are missing and MIRRORBOX_TEST_SKIP names `raytracing`; any other error fails.
    let ray_queries = mirrorbox_testing::require(
        mirrorbox_testing::RAYTRACING,
        gpu.features
            .contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY),
        &format!("{} has no ray queries", gpu.report.name),
    );
    for (name, s) in scenes {
        assert!(s.geometry.has_textures(), "{name}");
        let bare = s.without_mirrors();
        let raster = render(&gpu, &bare, &settings(Method::parse("naive").unwrap(), 1)).unwrap();
        let truth = trace_depth(&bare, 1);
        let (off, flip) = error_against(&truth, &raster.image);
        println!("{name} without mirrors: {off} pixels off by > 1e-3, FLIP {flip:.2e}");
        assert!(
            off * 1000 <= truth.pixels.len() && flip < 1e-4,
            "{name}: {off} off, FLIP {flip}"
        );
        for key in ["unrolled depth=16", "ray-query depth=16"] {
            if key.starts_with("ray-query") && !ray_queries {
                continue;
            }
            let method = Method::parse(key).unwrap();
            let out = render(&gpu, &s, &settings(method, 1))
                .unwrap_or_else(|e| panic!("{name} {key}: {e}"));
            let truth = trace_depth(&s, 16);
            let (off, flip) = error_against(&truth, &out.image);
            println!("{name} {key}: {off} pixels off by > 1e-3, FLIP {flip:.2e}");
            assert!(
                off * 200 <= truth.pixels.len() && flip < 1e-3,
                "{name} {key}: {off} off, FLIP {flip}"
            );
        }
    }
}

/// The scene fuzzer's mutations (`scene_fuzz::mutate`: extreme numbers, wrong types, deleted
/// and repeated nodes) applied to the glTF JSON of seed assets — the project's own (every
/// feature, embedded data) and the corpus's, valid and broken — each mutant written beside a
/// copy of its seed's files and loaded: refused with an error or loaded, never a panic (the
/// gltf crate's validator panicked on a POSITION accessor index past the accessors; found by
/// the CLI test, now refused first). Deterministic; `MIRRORBOX_FUZZ_MUTANTS` runs more, `MIRRORBOX_FUZZ_SEED` another sequence
/// (60 000 mutants of the default sequence and 40 000 of seed 7 ran clean).
#[test]
fn no_mutated_gltf_panics_the_loader() {
    use crate::scene_fuzz::{Rng, mutate};
    use mirrorbox_scene::gltf_asset::{CurvedMirrors, GltfOptions, load_gltf};
    let repo_asset =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/assets/textured_cube.gltf");
    let mut seeds = vec![repo_asset];
    if corpus_present() {
        for rel in [
            "BoxTextured-glTF-Embedded/BoxTextured.gltf",
            "textureTransform/TextureTransformTest.gltf",
            "cameras/Cameras.gltf",
            "simple_skin/simple_skin.gltf",
            "glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf",
            "RecursiveNodes/RecursiveNodes.gltf",
            "IndexOutOfRange/IndexOutOfRange.gltf",
            "IncorrectVertexArrays/Cube.gltf",
        ] {
            seeds.push(Path::new(CORPUS).join(rel));
        }
    }
    let mutants = crate::scene_fuzz::env_number("MIRRORBOX_FUZZ_MUTANTS", 600).max(1) as usize;
    let options = GltfOptions {
        scene: None,
        triangle_budget: 1 << 16,
        texel_budget: 1 << 20,
        transform: glam::Mat4::IDENTITY,
        curved_mirrors: CurvedMirrors::Refuse,
    };
    let seed = crate::scene_fuzz::env_number("MIRRORBOX_FUZZ_SEED", 0x6c7f_2024);
    let mut rng = Rng(seed);
    let (mut loaded, mut refused) = (0, 0);
    for (k, seed) in seeds.iter().enumerate() {
        let dir = tempfile::tempdir().unwrap();
        for entry in std::fs::read_dir(seed.parent().unwrap()).unwrap() {
            let from = entry.unwrap().path();
            if from.is_file() {
                std::fs::copy(&from, dir.path().join(from.file_name().unwrap())).unwrap();
            }
        }
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(seed).unwrap()).unwrap();
        let share = mutants / seeds.len() + usize::from(k < mutants % seeds.len());
        for i in 0..share {
            let mutant = mutate(&json, &mut rng);
            let path = dir.path().join("mutant.gltf");
            std::fs::write(&path, mutant.to_string()).unwrap();
            match std::panic::catch_unwind(|| load_gltf(&path, &options)) {
                Ok(Ok(_)) => loaded += 1,
                Ok(Err(_)) => refused += 1,
                Err(_) => {
                    let keep = Path::new(env!("CARGO_TARGET_TMPDIR")).join("gltf-fuzz-panic.gltf");
                    std::fs::write(&keep, mutant.to_string()).unwrap();
                    panic!(
                        "mutant {i} of {} panicked the loader; kept as {}",
                        seed.display(),
                        keep.display()
                    );
                }
            }
        }
    }
    println!("{loaded} mutants loaded, {refused} refused");
    assert!(
        loaded > 0 && refused > 0,
        "{loaded} loaded, {refused} refused"
    );
}
