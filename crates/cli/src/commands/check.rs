//! `mirrorbox check SCENE...`: load and validate each scene; one line per scene.

use crate::{Failure, count};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Scene files (JSON, see docs/scene-format.md).
    #[arg(required = true)]
    scenes: Vec<PathBuf>,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    let mut failed = 0;
    for path in &args.scenes {
        match super::load(path) {
            Ok(scene) => {
                let g = &scene.geometry;
                let dropped = match g.degenerate_dropped {
                    0 => String::new(),
                    n => format!(", {n} degenerate triangles dropped"),
                };
                let symmetry = match &scene.symmetry {
                    None => String::new(),
                    Some(s) => format!(
                        ", {} (objects: {} before the bake, 2^p = {} copies)",
                        count(s.planes.len(), "symmetry plane"),
                        count(s.source.triangles.len(), "triangle"),
                        s.copy_count()
                    ),
                };
                let camera_path = match &scene.camera_path {
                    None => String::new(),
                    Some(p) => {
                        let (t0, t1) = p.span();
                        format!(
                            ", a camera path of {} over {t0}–{t1} s",
                            count(p.keys().len(), "key")
                        )
                    }
                };
                println!(
                    "{}: ok: {}, {} ({} on mirrors), {}, {}x{}{dropped}{symmetry}{camera_path}",
                    path.display(),
                    count(scene.mirrors.len(), "mirror"),
                    count(g.triangles.len(), "triangle"),
                    g.mirror_triangle_count(),
                    count(scene.lighting.lights.len(), "light"),
                    scene.camera.width,
                    scene.camera.height,
                );
                for note in &g.obj_notes {
                    println!("  note: {note}");
                }
            }
            Err(e) => {
                eprintln!("error: {}", e.message());
                failed += 1;
            }
        }
    }
    match failed {
        0 => Ok(()),
        n => Err(Failure::BadInput(format!(
            "{n} of {} scene files failed to load",
            args.scenes.len()
        ))),
    }
}
