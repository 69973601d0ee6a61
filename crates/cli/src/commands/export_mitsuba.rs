//! `mirrorbox export-mitsuba SCENE -o DIR/scene.xml`: the scene as Mitsuba 3 XML.

use super::{grid_side, load, output_path, unit_interval};
use crate::Failure;
use mirrorbox_mitsuba::{ExportSettings, export};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Scene file (JSON).
    scene: PathBuf,
    /// Output XML; meshes go to meshes/ beside it, with mirrorbox.json (what Mitsuba cannot express).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    size: super::SizeArgs,
    /// Samples per pixel (a perfect square: Mitsuba's stratified grid; unjittered for whitted, where it is ours; a second sensor samples independently for path).
    #[arg(long, default_value_t = 16)]
    spp: u32,
    /// α: override every mirror's reflectance, in [0, 1]. `--reflectance` is the same flag.
    #[arg(
        long = "alpha",
        visible_alias = "reflectance",
        allow_negative_numbers = true
    )]
    reflectance: Option<f32>,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    grid_side(args.spp)?;
    unit_interval("--alpha", args.reflectance)?;
    // One rule for every command: the folder an output goes into must exist (a typo never
    // silently creates folders); the export creates only its own `meshes/` inside it.
    let xml = output_path("-o", &args.output, "xml")?;
    let mut scene = load(&args.scene)?;
    args.size.apply(&mut scene)?;
    if let Some(r) = args.reflectance {
        scene
            .set_reflectance(glam::Vec3::splat(r))
            .map_err(|e| super::light_budget(&scene, "--reflectance", e))?;
    }
    let written = export(&scene, &xml, ExportSettings { spp: args.spp }).map_err(|e| {
        if e.refused {
            // The part's name says which object; the scene file says where it is.
            Failure::BadInput(format!("{}: {e}", args.scene.display()))
        } else {
            Failure::Other(e.to_string())
        }
    })?;
    println!(
        "exported {} to {} ({} files)",
        args.scene.display(),
        xml.display(),
        written.len()
    );
    // Said, not only recorded: a comparison with `trace` differs by these.
    for left_out in mirrorbox_mitsuba::not_exported(&scene) {
        println!("  not exported: {left_out}");
    }
    Ok(())
}
