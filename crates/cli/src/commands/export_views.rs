//! `mirrorbox export-views SCENE -o DIR`: the exchange's way out (issue 53,
//! `docs/exchange.md`): the scene as glTF, its views (cameras in every convention a client
//! needs, the contract's rules) and their truths with and without mirrors, for any renderer
//! to draw and `mirrorbox score` to judge.

use super::unit_interval;
use crate::Failure;
use mirrorbox_harness::exchange::{ExportSettings, check_views, export_views, read_view_list};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Scene file (JSON).
    scene: PathBuf,
    /// Output folder (its parent must exist): scene.gltf, scene.bin, textures/, scene.json,
    /// views.json, truth/. An earlier export there is replaced.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    size: super::TruthSizeArgs,
    /// Sub-pixel grid side s: each truth pixel is the mean of s × s samples, 1..8.
    #[arg(long, default_value_t = 1)]
    ssaa: u32,
    /// α: every mirror's reflectance, in [0, 1] (a sweep's α); default: the scene's.
    /// `--reflectance` is the same flag.
    #[arg(long, visible_alias = "reflectance", allow_negative_numbers = true)]
    alpha: Option<f32>,
    /// A view list (JSON: {"views": [{"name", "position", "look_at", "up"?, "fov_y_deg"?}]}),
    /// e.g. a camera path; default: the scene's camera, named "camera".
    #[arg(long)]
    views: Option<PathBuf>,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    super::ssaa(args.ssaa)?;
    unit_interval("--alpha", args.alpha)?;
    let views = match &args.views {
        Some(path) => {
            let views = read_view_list(path).map_err(Failure::from)?;
            // Against the scene too, naming the file, before any truth is traced.
            check_views(path, &views, &super::load(&args.scene)?).map_err(Failure::from)?;
            views
        }
        None => Vec::new(),
    };
    let settings = ExportSettings {
        width: args.size.width,
        height: args.size.height,
        ssaa: args.ssaa,
        alpha: args.alpha,
        views,
    };
    let started = std::time::Instant::now();
    let done = export_views(&args.scene, &args.output, &settings).map_err(Failure::from)?;
    println!(
        "exported {} to {} in {:.1} s: {} view(s), {} truths traced ({} files)",
        args.scene.display(),
        args.output.display(),
        started.elapsed().as_secs_f64(),
        done.views,
        done.truths_traced,
        done.files
    );
    println!(
        "next: draw each view of {0}/views.json from {0}/scene.gltf into RUN/<client>/<variant>/<view>.exr, then mirrorbox score {0} RUN -o OUT",
        args.output.display()
    );
    Ok(())
}
