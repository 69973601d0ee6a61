//! `mirrorbox import ASSET.glb -o scene.json`: a glTF asset in a mirror box sized to its
//! bounds (`mirrorbox_scene::import`), written as a scene file ready for `trace`, `render`,
//! `sweep` and `view`; the written scene is loaded back before the command succeeds.

use super::output_path;
use crate::Failure;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The glTF 2.0 asset (.gltf with its files, or .glb).
    asset: PathBuf,
    /// The scene file to write (JSON); the asset is referred to relative to it when it lies
    /// in the same folder or below, else by its absolute path.
    #[arg(short, long)]
    output: PathBuf,
    /// Which of the asset's scenes (default: its `scene`, else the first).
    #[arg(long)]
    scene: Option<usize>,
    /// Image width of the scene's camera, in pixels.
    #[arg(long, default_value_t = 640)]
    width: u32,
    /// Image height of the scene's camera, in pixels.
    #[arg(long, default_value_t = 360)]
    height: u32,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    let out = output_path("-o", &args.output, "json")?;
    mirrorbox_scene::limits::image_size(args.width, args.height)
        .map_err(|e| Failure::BadInput(e.to_string()))?;
    let asset = std::fs::canonicalize(&args.asset).map_err(|e| {
        Failure::BadInput(format!(
            "{}: cannot read the asset: {e}",
            args.asset.display()
        ))
    })?;
    let folder = std::fs::canonicalize(mirrorbox_files::folder_of(&out))
        .map_err(|e| Failure::BadInput(format!("{}: {e}", out.display())))?;
    let reference = match asset.strip_prefix(&folder) {
        Ok(rel) => rel.to_string_lossy().into_owned(),
        Err(_) => asset.to_string_lossy().into_owned(),
    };
    let scene = mirrorbox_scene::import::mirror_box_scene(
        &asset,
        &reference,
        args.scene,
        args.width,
        args.height,
    )
    .map_err(|e| Failure::BadInput(format!("{}: {e}", args.asset.display())))?;
    let text = scene;
    // Checked before it is written: a scene this command writes always loads.
    let loaded = mirrorbox_scene::load::parse_scene(&text, &out)
        .map_err(|e| Failure::Other(format!("the imported scene does not load: {e}")))?;
    mirrorbox_files::write_atomically(&out, text.as_bytes())
        .map_err(|e| Failure::Other(e.to_string()))?;
    let g = &loaded.geometry;
    println!(
        "wrote {}: {} in a mirror box ({}, {}, {}, {})",
        out.display(),
        args.asset.display(),
        crate::count(g.triangles.len(), "triangle"),
        crate::count(g.textures.len(), "texture"),
        crate::count(loaded.mirrors.len(), "mirror"),
        crate::count(loaded.lighting.lights.len(), "light")
    );
    for note in &g.obj_notes {
        println!("  note: {note}");
    }
    println!(
        "next: mirrorbox trace {0} -o truth.exr; mirrorbox render {0} --method unrolled -o unrolled.png",
        out.display()
    );
    Ok(())
}
