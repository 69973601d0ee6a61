//! `mirrorbox render SCENE --method METHOD [its options] -o OUT.png`: one raster method of
//! the registry (`mirrorbox_raster::METHODS`) with wgpu, timed.

use super::method_flags::{RenderOptions, method_value_parser};
use super::stereo::eye_path;
use super::{check_outputs, load, output_path, unit_interval};
use crate::Failure;
use mirrorbox_files::with_stem_suffix;
use mirrorbox_image::{StagedFiles, stage_exr, stage_png, stage_png_bytes};
use mirrorbox_raster::methods::recursive_texture::TEXTURE_SCALE;
use mirrorbox_raster::{FrameHistory, Gpu, RenderSettings, plan_frame, render_planned_after};
use mirrorbox_scene::stereo::Eye;
use std::cell::RefCell;
use std::path::PathBuf;

#[derive(clap::Args, Clone)]
pub struct Args {
    /// Scene file (JSON).
    scene: PathBuf,
    /// The raster method (the registry's table; its options are the flags below).
    #[arg(long, default_value = "naive", value_parser = method_value_parser())]
    method: String,
    #[command(flatten)]
    options: RenderOptions,
    /// α: attenuation per reflection; sets every mirror's reflectance (the truth to compare
    /// with is `trace --alpha α`). In [0, 1]. Default: the scene's reflectances.
    /// `--reflectance` is the same flag.
    #[arg(long, visible_alias = "reflectance", allow_negative_numbers = true)]
    alpha: Option<f32>,
    #[command(flatten)]
    size: super::SizeArgs,
    #[command(flatten)]
    time: super::TimeArgs,
    /// Supersampling factor s, 1..8: renders at s× and box-filters down, the tracer's
    /// `--spp s²` grid.
    #[arg(long, default_value_t = 1)]
    ssaa: u32,
    /// Timed frames, 1..10000 (after --warmup untimed ones).
    #[arg(long, default_value_t = 1)]
    frames: u32,
    /// Untimed frames rendered first (driver caches, pipeline compilation), 0..1000.
    #[arg(long, default_value_t = 2)]
    warmup: u32,
    /// Print one JSON object with timings, counts, adapter and parameters.
    #[arg(long)]
    json: bool,
    /// Output PNG (sRGB); the linear EXR is written beside it.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    stereo: super::stereo::StereoArgs,
    #[command(flatten)]
    memory: super::MemoryBudgetArgs,
}

fn bad(message: String) -> Failure {
    Failure::BadInput(message)
}

/// One frame, or with `--sequence` one frame per time step (each written whole before the
/// next starts; frame k into OUT_k). A sequence opens the adapter once, and a stateful
/// method (`feedback`) continues each frame from the one before, as in an engine.
pub fn run(args: &Args) -> Result<(), Failure> {
    let carry = RefCell::new(Carry::default());
    let scene = std::cell::OnceCell::new();
    args.time.run(
        args,
        |args, time, suffix| Args {
            time,
            output: mirrorbox_files::with_stem_suffix(&args.output, suffix),
            ..args.clone()
        },
        |frame| {
            check_frame_outputs(frame)?;
            super::check_frame_time(frame.time, &frame.scene, &scene)
        },
        |args| run_frame(args, &mut carry.borrow_mut()),
    )
}

/// What a sequence's frame hands the next: the adapter and a stateful method's history.
#[derive(Default)]
struct Carry {
    gpu: Option<Gpu>,
    history: Option<FrameHistory>,
}

/// Checks a frame's outputs (`-o`, its EXR and a stereo pair's pictures): their folders
/// exist, none is a folder, no two are one file. Returns `-o`.
fn check_frame_outputs(args: &Args) -> Result<PathBuf, Failure> {
    let png = output_path("-o", &args.output, "png")?;
    let exr = png.with_extension("exr");
    let eyes: Vec<Option<Eye>> = if args.stereo.asked() {
        Eye::BOTH.map(Some).to_vec()
    } else {
        vec![None]
    };
    let mut outputs = Vec::new();
    for eye in &eyes {
        outputs.push(("-o", eye_path(&png, *eye)));
        outputs.push(("-o (its EXR)", eye_path(&exr, *eye)));
    }
    if args.stereo.asked() {
        outputs.push(("-o (side by side)", with_stem_suffix(&png, "sbs")));
        outputs.push(("-o (anaglyph)", with_stem_suffix(&png, "anaglyph")));
    }
    check_outputs(&outputs)?;
    Ok(png)
}

fn run_frame(args: &Args, carry: &mut Carry) -> Result<(), Failure> {
    let entry = mirrorbox_raster::registry::find(&args.method)
        .ok_or_else(|| bad(format!("unknown method {:?}", args.method)))?;
    let method = args.options.0.configure(entry)?;
    // A stereo pair's option on one view would change nothing: said, not ignored.
    if !args.stereo.asked()
        && method
            .params()
            .get(&mirrorbox_raster::stereo_mirrors::STEREO_MIRRORS)
            == Some(mirrorbox_raster::ParamValue::Choice("shared"))
    {
        return Err(bad(
            "--stereo-mirrors shared: an option of a stereo pair (--stereo or --ipd); this \
             render is of one view, where it would change nothing"
                .into(),
        ));
    }
    unit_interval("--alpha", args.alpha)?;
    let png = check_frame_outputs(args)?;
    let exr = png.with_extension("exr");
    let mut scene = args.time.apply(load(&args.scene)?)?;
    let rig = args.stereo.rig(&scene)?;
    args.size.apply(&mut scene)?;
    if let Some(a) = args.alpha {
        scene
            .set_reflectance(glam::Vec3::splat(a))
            .map_err(|e| super::light_budget(&scene, "--alpha", e))?;
    }
    let settings = RenderSettings {
        method: method.clone(),
        ssaa: args.ssaa,
        frames: args.frames,
        warmup: args.warmup,
    };
    let alpha = args
        .alpha
        .map_or("as in scene".to_string(), |a| a.to_string());
    let views = super::stereo::views(&scene, rig);
    // Plan first: a refused configuration costs no GPU set-up. A stereo pair is one frame
    // (both eyes, timed together: mirrorbox_raster::stereo_pair).
    let planned = match &views[..] {
        [(_, left), (_, right)] => Err(mirrorbox_raster::stereo_pair::plan_pair(
            [left, right],
            &settings,
        )?),
        _ => Ok(plan_frame(&views[0].1, &settings)?),
    };
    // A stateful method continues from the previous frame of a sequence: its carried
    // textures count in this frame's memory.
    let planned = planned.map(|mut one| {
        if let Some(history) = carry.history.take() {
            one.continue_from(history);
        }
        one
    });
    // Refused above --memory-budget before the adapter is opened.
    let budget = args.memory.memory_budget;
    let estimate = match &planned {
        Ok(one) => one.check_memory(&views[0].1, &settings, budget)?,
        Err(pair) => pair.check_memory([&views[0].1, &views[1].1], &settings, budget)?,
    };
    if carry.gpu.is_none() {
        carry.gpu = Some(Gpu::new()?);
    }
    let gpu = carry.gpu.as_ref().expect("the adapter was just opened");
    // One view (Ok), or a stereo pair (Err) with each eye's scene.
    let mut out = match planned {
        Ok(one) => render_planned_after(gpu, &views[0].1, one, &settings, None)?,
        Err(pair) => mirrorbox_raster::stereo_pair::render_pair(
            gpu,
            [&views[0].1, &views[1].1],
            pair,
            &settings,
        )?,
    };
    carry.history = out.history.take();
    for w in &out.warnings {
        eprintln!("warning: {w}");
    }
    let write_failed = |e: mirrorbox_image::ImageError| Failure::Other(e.to_string());
    let mut staged = StagedFiles::new();
    let images = [Some(&out.image), out.right_eye.as_ref()];
    let mut written = Vec::new();
    for ((eye, view), image) in views.iter().zip(images.into_iter().flatten()) {
        let mut attributes = vec![
            ("mirrorbox.version", env!("CARGO_PKG_VERSION").to_string()),
            ("mirrorbox.scene", args.scene.display().to_string()),
            (
                "mirrorbox.scene_hash",
                format!("{:016x}", view.content_hash()),
            ),
            ("mirrorbox.exposure", view.camera.exposure.to_string()),
            ("mirrorbox.method", method.to_string()),
            ("mirrorbox.alpha", alpha.clone()),
            ("mirrorbox.ssaa", args.ssaa.to_string()),
            ("mirrorbox.passes", out.stats.passes.to_string()),
            ("mirrorbox.adapter", gpu.report.name.clone()),
            (
                "mirrorbox.color_format",
                out.color_format.name().to_string(),
            ),
        ];
        if let Some(e) = eye {
            attributes.push(("mirrorbox.eye", e.name().to_string()));
        }
        attributes.extend(args.time.attribute());
        let (png, exr) = (eye_path(&png, *eye), eye_path(&exr, *eye));
        stage_exr(&mut staged, &exr, image, &attributes).map_err(write_failed)?;
        stage_png(&mut staged, &png, image, view.camera.exposure).map_err(write_failed)?;
        written.extend([png, exr]);
    }
    if let Some(right) = &out.right_eye {
        let e = scene.camera.exposure;
        let (a, b) = (out.image.to_srgb8(e), right.to_srgb8(e));
        let (w, h) = (scene.camera.width, scene.camera.height);
        let sbs = mirrorbox_image::stereo::side_by_side(&a, &b, w, h);
        let ana = mirrorbox_image::stereo::anaglyph(&a, &b);
        for (suffix, w, bytes) in [("sbs", 2 * w, &sbs), ("anaglyph", w, &ana)] {
            let path = with_stem_suffix(&png, suffix);
            stage_png_bytes(&mut staged, &path, w, h, bytes).map_err(write_failed)?;
            written.push(path);
        }
    }
    staged.commit().map_err(|e| Failure::Other(e.to_string()))?;
    summary(
        args,
        &method,
        &views[0].1,
        &out,
        gpu,
        &written,
        &alpha,
        rig.is_some(),
        &estimate,
    );
    Ok(())
}

/// Prints the frame's summary (one JSON object with --json); a stereo pair's counts and
/// times are both eyes' (`scene`: the left eye's).
#[allow(clippy::too_many_arguments)]
fn summary(
    args: &Args,
    method: &mirrorbox_raster::Method,
    scene: &mirrorbox_scene::Scene,
    out: &mirrorbox_raster::RenderOutput,
    gpu: &Gpu,
    written: &[std::path::PathBuf],
    alpha: &str,
    stereo: bool,
    estimate: &mirrorbox_raster::MemoryEstimate,
) {
    // This process's peak resident memory so far (VmHWM), next to the plan's estimate.
    let peak_rss = mirrorbox_harness::peak_memory_bytes();
    let method_text = method.to_string();
    let s = &out.stats;
    let t = &out.timing;
    if args.json {
        let v = serde_json::json!({
            "scene": args.scene.display().to_string(),
            // The camera path's time of this view (`--time`, or this frame's), if given.
            "time": args.time.time,
            "stereo_pair": stereo,
            "scene_hash": format!("{:016x}", scene.content_hash()),
            "method": method.name(),
            "key": method.key(),
            "params": method.entry().options.iter()
                .map(|o| (o.name.to_string(), param_json(method.params().get(o))))
                .collect::<serde_json::Map<_, _>>(),
            "texture_scale": param_json(method.params().get(&TEXTURE_SCALE)),
            "n": method.count_of("n"),
            "depth_limit": method.count_of("depth"),
            "alpha": args.alpha,
            "width": scene.camera.width, "height": scene.camera.height, "ssaa": args.ssaa,
            "frames": args.frames, "warmup": args.warmup,
            "ms_per_frame_median": t.median_ms(), "ms_per_frame_min": t.min_ms(),
            "frames_ms": t.frames_ms, "timing_source": t.source.name(),
            "encode_ms": t.encode_ms,
            "gpu_buffer_bytes": out.gpu_memory.buffer_bytes, "gpu_texture_bytes": out.gpu_memory.texture_bytes,
            "memory_estimate": {
                "gpu_bytes": estimate.gpu_bytes, "host_bytes": estimate.host_bytes,
                "budget_bytes": args.memory.memory_budget,
            },
            "peak_rss_bytes": peak_rss,
            "passes": s.passes, "texture_renders": s.texture_renders, "draws": s.draws, "depth": s.depth,
            "triangles": s.triangles,
            "paths": s.paths.map(|c| serde_json::json!({
                "kept": c.kept, "pruned_empty": c.pruned_empty, "pruned_no_sample": c.pruned_no_sample,
                "pruned_small": c.pruned_small,
                "pruned_attenuation": c.pruned_attenuation, "capped": c.capped,
                "pruned_hidden": c.pruned_hidden, "partly_hidden": c.partly_hidden,
            })),
            "copies": s.copies.map(|c| serde_json::json!({
                "planes": c.planes, "total": c.total, "drawn": c.drawn,
                "pruned_empty": c.pruned_empty, "pruned_outside_view": c.pruned_outside_view,
                "culled_parts": c.culled_parts, "parts": c.parts,
            })),
            "bake_ms": out.bake_ms,
            "clipping": s.clipping.name(),
            "depth_format": format!("{:?}", s.depth_format),
            "warnings": out.warnings,
            "adapter": gpu.report.name, "backend": gpu.report.backend, "device_type": gpu.report.device_type,
            "color_format": out.color_format.name(),
            "outputs": written.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
        });
        println!("{v}");
    } else {
        if stereo {
            println!("stereo pair (both eyes in one frame; counts and times are the pair's):");
        }
        println!(
            "rendered {} with {method_text}, alpha {alpha}: {}x{}, ssaa {}; {} ({}, {} reflections deep), {} per frame; depth {:?}, mirrors clipped by {}",
            args.scene.display(),
            scene.camera.width,
            scene.camera.height,
            args.ssaa,
            crate::count(s.passes, "pass"),
            crate::count(s.texture_renders, "texture render"),
            s.depth,
            crate::count(s.draws, "draw"),
            s.depth_format,
            s.clipping.name()
        );
        if let Some(c) = s.paths {
            println!(
                "  reflection paths: {} kept ({} partly hidden by a nearer sibling mirror); pruned {} (empty {}, no pixel centre {}, under --min-portal-area {}, under --min-attenuation {}, past --depth {}, hidden by nearer siblings {}); {} triangles submitted",
                c.kept,
                c.partly_hidden,
                c.pruned(),
                c.pruned_empty,
                c.pruned_no_sample,
                c.pruned_small,
                c.pruned_attenuation,
                c.capped,
                c.pruned_hidden,
                s.triangles,
            );
        }
        if let Some(c) = s.copies {
            println!(
                "  symmetry: {} planes, {} of {} copies drawn (pruned: {} with an empty cell, {} outside the view); {} of {} object parts drawn with back-face culling; {} triangles submitted",
                c.planes,
                c.drawn,
                c.total,
                c.pruned_empty,
                c.pruned_outside_view,
                c.culled_parts,
                c.parts,
                s.triangles,
            );
        }
        if let Some(ms) = out.bake_ms {
            let what = if method.name() == "ray-query" {
                "acceleration structures (a BLAS per mesh, a TLAS) built on the device"
            } else {
                "split-and-mirror bake on the CPU while planning"
            };
            println!("  {what}: {ms:.2} ms (not in the frame time)");
        }
        println!(
            "  memory: estimate {estimate} (budget {}); peak resident {}",
            mirrorbox_raster::memory::format_bytes(args.memory.memory_budget),
            peak_rss.map_or("unknown".into(), mirrorbox_raster::memory::format_bytes)
        );
        println!(
            "  {:.2} ms/frame median, {:.2} ms the least, over {} ({}); CPU encode+submit {:.2} ms median; GPU memory {}; on {} ({}, {} targets); wrote {}",
            t.median_ms(),
            t.min_ms(),
            crate::count(t.frames_ms.len(), "frame"),
            t.source.name(),
            mirrorbox_report::stats::median(&t.encode_ms),
            // wgpu's GL backend keeps no allocation counters: its 0 is no measurement.
            if gpu.report.backend == "gl" {
                "not counted by the GL backend".to_string()
            } else {
                format!(
                    "{} in buffers, {} in textures",
                    mirrorbox_files::human_bytes(out.gpu_memory.buffer_bytes),
                    mirrorbox_files::human_bytes(out.gpu_memory.texture_bytes)
                )
            },
            gpu.report.name,
            gpu.report.backend,
            out.color_format,
            written
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
}

/// A parameter value as JSON (`null` where the method has no such option).
fn param_json(value: Option<mirrorbox_raster::ParamValue>) -> serde_json::Value {
    use mirrorbox_raster::ParamValue;
    match value {
        Some(ParamValue::Count(c)) => serde_json::json!(c),
        Some(ParamValue::Real(r)) => serde_json::json!(r),
        Some(ParamValue::Switch(s)) => serde_json::json!(s),
        Some(ParamValue::Choice(c)) => serde_json::json!(c),
        None => serde_json::Value::Null,
    }
}
