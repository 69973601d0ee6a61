//! `mirrorbox render SCENE --method naive|auxiliary|portal|unrolled -o OUT.png`: the seed
//! paper's raster methods and the exact ones with wgpu, timed.

use super::{load, output_path, resize, unit_interval};
use crate::Failure;
use mirrorbox_image::{write_exr, write_png};
use mirrorbox_raster::plan::PlanError;
use mirrorbox_raster::{Gpu, Method, RasterError, RenderSettings, render};
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodName {
    /// The paper's Algorithm 1: recursive mirror textures, each mirror hidden in its own recursion.
    Naive,
    /// The paper's §3.1–3.2: n auxiliary mirrors (n + 2 in the queue), attenuation α^k.
    Auxiliary,
    /// Exact: stencil recursion over the reflection paths, one pass, cost linear in depth.
    Portal,
    /// Exact: every reflection path an instance of the scene, clipped to its cell; a handful of draws.
    Unrolled,
}

#[derive(clap::Args)]
pub struct Args {
    /// Scene file (JSON).
    scene: PathBuf,
    #[arg(long, value_enum, default_value_t = MethodName::Naive)]
    method: MethodName,
    /// Auxiliary mirrors (auxiliary method only).
    #[arg(long)]
    n: Option<u32>,
    /// Most mirrors along a reflection path (exact methods: portal, unrolled). Default 64.
    #[arg(long)]
    depth: Option<u32>,
    /// Exact methods: also prune paths whose portal covers fewer pixels² (at render
    /// resolution) though it may hold a pixel centre — lossy, for speed. Portals holding no
    /// pixel centre are always pruned (that changes no pixel).
    #[arg(long, default_value_t = 0.0)]
    min_portal_area: f32,
    /// Exact methods: prune paths whose attenuation falls below this (the tracer's --min-throughput).
    #[arg(long, default_value_t = 1e-4)]
    min_attenuation: f32,
    /// Unrolled method: clip every instance per fragment (discard) even where the adapter
    /// has hardware clip distances — to measure what they save.
    #[arg(long)]
    fragment_clipping: bool,
    /// Attenuation per reflection; also sets every mirror's reflectance (the truth to compare
    /// with is `trace --reflectance α`). In [0, 1]. Default: the scene's reflectances.
    #[arg(long)]
    alpha: Option<f32>,
    #[arg(long)]
    width: Option<u32>,
    #[arg(long)]
    height: Option<u32>,
    /// Supersampling factor s: renders at s× and box-filters down, the tracer's `--spp s²` grid.
    #[arg(long, default_value_t = 1)]
    ssaa: u32,
    /// Timed frames (after --warmup untimed ones).
    #[arg(long, default_value_t = 1)]
    frames: u32,
    #[arg(long, default_value_t = 2)]
    warmup: u32,
    /// Refuse, before any work, a configuration needing more scene passes per frame.
    #[arg(long, default_value_t = 5000)]
    max_passes: usize,
    /// Mirror texture resolution relative to the mirror's footprint on screen (1 = exact).
    #[arg(long, default_value_t = 1.0)]
    texture_scale: f32,
    /// Print one JSON object with timings, counts, adapter and parameters.
    #[arg(long)]
    json: bool,
    /// Output PNG (sRGB); the linear EXR is written beside it.
    #[arg(short, long)]
    output: PathBuf,
}

fn bad(message: String) -> Failure {
    Failure::BadInput(message)
}

pub fn run(args: &Args) -> Result<(), Failure> {
    if args.n.is_some() && args.method != MethodName::Auxiliary {
        return Err(bad("--n applies to --method auxiliary only".into()));
    }
    let exact = matches!(args.method, MethodName::Portal | MethodName::Unrolled);
    if args.depth.is_some() && !exact {
        return Err(bad(
            "--depth applies to --method portal or unrolled only".into()
        ));
    }
    if args.fragment_clipping && args.method != MethodName::Unrolled {
        return Err(bad(
            "--fragment-clipping applies to --method unrolled only".into()
        ));
    }
    let depth = match args.depth.unwrap_or(64) {
        d @ 1..=4096 => d,
        d => return Err(bad(format!("--depth must be in [1, 4096], got {d}"))),
    };
    let method = match args.method {
        MethodName::Naive => Method::Naive,
        MethodName::Auxiliary => Method::Auxiliary {
            n: args.n.unwrap_or(0),
        },
        MethodName::Portal => Method::Portal { depth },
        MethodName::Unrolled => Method::Unrolled { depth },
    };
    unit_interval("--min-attenuation", Some(args.min_attenuation))?;
    if !(args.min_portal_area >= 0.0 && args.min_portal_area.is_finite()) {
        return Err(bad(format!(
            "--min-portal-area must be ≥ 0, got {}",
            args.min_portal_area
        )));
    }
    unit_interval("--alpha", args.alpha)?;
    if !(1..=8).contains(&args.ssaa) {
        return Err(bad(format!("--ssaa must be in [1, 8], got {}", args.ssaa)));
    }
    if !(args.texture_scale > 0.0 && args.texture_scale <= 4.0) {
        return Err(bad(format!(
            "--texture-scale must be in (0, 4], got {}",
            args.texture_scale
        )));
    }
    if args.frames == 0 {
        return Err(bad("--frames must be at least 1".into()));
    }
    let png = output_path("-o", &args.output, "png")?;
    let mut scene = load(&args.scene)?;
    resize(&mut scene, args.width, args.height)?;
    if let Some(a) = args.alpha {
        scene.set_reflectance(glam::Vec3::splat(a));
    }
    let settings = RenderSettings {
        method,
        ssaa: args.ssaa,
        frames: args.frames,
        warmup: args.warmup,
        max_passes: args.max_passes,
        texture_scale: args.texture_scale,
        min_portal_area: args.min_portal_area,
        min_attenuation: args.min_attenuation,
        fragment_clipping: args.fragment_clipping,
    };
    // Plan the paper's recursion first: a refused configuration costs no GPU set-up. (The
    // exact methods have no such plan; their path enumeration happens inside `render`.)
    if method.depth_limit().is_none() {
        let (w, h) = (
            scene.camera.width * args.ssaa,
            scene.camera.height * args.ssaa,
        );
        mirrorbox_raster::plan::plan(&scene, method, w, h, args.max_passes)
            .map_err(plan_failure)?;
    }
    let gpu = Gpu::new().map_err(raster_failure)?;
    let out = render(&gpu, &scene, &settings).map_err(raster_failure)?;
    let exr = png.with_extension("exr");
    let method_text = method.to_string();
    for w in &out.warnings {
        eprintln!("warning: {w}");
    }
    let alpha = args
        .alpha
        .map_or("as in scene".to_string(), |a| a.to_string());
    let attributes = [
        ("mirrorbox.version", env!("CARGO_PKG_VERSION").to_string()),
        ("mirrorbox.scene", args.scene.display().to_string()),
        (
            "mirrorbox.scene_hash",
            format!("{:016x}", scene.content_hash()),
        ),
        ("mirrorbox.method", method_text.clone()),
        ("mirrorbox.alpha", alpha.clone()),
        ("mirrorbox.ssaa", args.ssaa.to_string()),
        ("mirrorbox.passes", out.stats.passes.to_string()),
        ("mirrorbox.adapter", gpu.report.name.clone()),
    ];
    let write_failed = |e: mirrorbox_image::ImageError| Failure::Other(e.to_string());
    write_exr(&exr, &out.image, &attributes).map_err(write_failed)?;
    write_png(&png, &out.image, scene.camera.exposure).map_err(write_failed)?;
    let s = &out.stats;
    let t = &out.timing;
    if args.json {
        let v = serde_json::json!({
            "scene": args.scene.display().to_string(),
            "scene_hash": format!("{:016x}", scene.content_hash()),
            "method": method.name(),
            "n": method.n(),
            "depth_limit": method.depth_limit(),
            "alpha": args.alpha,
            "width": scene.camera.width, "height": scene.camera.height, "ssaa": args.ssaa,
            "texture_scale": args.texture_scale, "frames": args.frames, "warmup": args.warmup,
            "ms_per_frame_median": t.median_ms(), "ms_per_frame_min": t.min_ms(),
            "frames_ms": t.frames_ms, "timing_source": t.source.name(),
            "passes": s.passes, "texture_renders": s.texture_renders, "draws": s.draws, "depth": s.depth,
            "triangles": s.triangles,
            "paths": s.paths.map(|c| serde_json::json!({
                "kept": c.kept, "pruned_empty": c.pruned_empty, "pruned_no_sample": c.pruned_no_sample,
                "pruned_small": c.pruned_small,
                "pruned_attenuation": c.pruned_attenuation, "capped": c.capped,
            })),
            "clipping": s.clipping.map(|c| c.name()),
            "warnings": out.warnings,
            "adapter": gpu.report.name, "backend": gpu.report.backend, "device_type": gpu.report.device_type,
            "outputs": [png.display().to_string(), exr.display().to_string()],
        });
        println!("{v}");
    } else {
        println!(
            "rendered {} with {method_text}, alpha {alpha}: {}x{}, ssaa {}; {} passes ({} texture renders, {} reflections deep), {} draws per frame",
            args.scene.display(),
            scene.camera.width,
            scene.camera.height,
            args.ssaa,
            s.passes,
            s.texture_renders,
            s.depth,
            s.draws
        );
        if let Some(c) = s.paths {
            println!(
                "  reflection paths: {} kept; pruned {} (empty {}, no pixel centre {}, under --min-portal-area {}, under --min-attenuation {}, past --depth {}); {} triangles submitted{}",
                c.kept,
                c.pruned(),
                c.pruned_empty,
                c.pruned_no_sample,
                c.pruned_small,
                c.pruned_attenuation,
                c.capped,
                s.triangles,
                s.clipping
                    .map_or(String::new(), |c| format!(", clipped by {}", c.name()))
            );
        }
        println!(
            "  {:.2} ms/frame median, {:.2} min over {} frames ({}) on {} ({}); wrote {}, {}",
            t.median_ms(),
            t.min_ms(),
            t.frames_ms.len(),
            t.source.name(),
            gpu.report.name,
            gpu.report.backend,
            png.display(),
            exr.display()
        );
    }
    Ok(())
}

fn plan_failure(e: PlanError) -> Failure {
    Failure::BadInput(e.to_string())
}

fn raster_failure(e: RasterError) -> Failure {
    match e {
        RasterError::Plan(p) => plan_failure(p),
        RasterError::Adapter(mirrorbox_raster::AdapterError::BadOverride { .. }) => {
            Failure::BadInput(e.to_string())
        }
        other => Failure::Other(other.to_string()),
    }
}
