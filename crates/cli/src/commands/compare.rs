//! `mirrorbox compare REF TEST`: every metric of TEST against the reference REF.

use super::output_path;
use crate::Failure;
use mirrorbox_image::metrics::{FLIP_PIXELS_PER_DEGREE, Metrics, compare, flip_map};
use mirrorbox_image::{colormap, read_image, write_png_bytes};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Reference image (the truth): EXR (linear) or PNG (sRGB).
    reference: PathBuf,
    /// Test image of the same size.
    test: PathBuf,
    /// Exposure of the tone mapping for PSNR, SSIM and FLIP. Default: the scene camera's
    /// exposure that `trace` and `render` record in their EXRs (`mirrorbox.exposure`), else 1.
    #[arg(long)]
    exposure: Option<f32>,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
    /// Write the FLIP error map as a heat-map PNG.
    #[arg(long, value_name = "OUT.png")]
    heatmap: Option<PathBuf>,
    /// Refuse images whose comparison would need more host memory than SIZE (about 112 bytes
    /// a pixel: 1.9 GB at 4096²), before reading them: 2G, 512M, 1.5GB or plain bytes (K, M,
    /// G, T are powers of 1024), 1M..1T.
    #[arg(
        long = "memory-budget",
        value_name = "SIZE",
        default_value = "2G",
        value_parser = super::parse_memory_budget
    )]
    memory_budget: u64,
}

/// Refuses a comparison of images of `(width, height)` above `budget` bytes, naming what it
/// would need: an 8192² pair had needed 7 GB, and been killed.
fn check_compare_memory((width, height): (u32, u32), budget: u64) -> Result<(), Failure> {
    let need = mirrorbox_image::metrics::compare_bytes(width, height);
    if need > budget {
        let gb = |b: u64| b as f64 / 1e9;
        return Err(Failure::BadInput(format!(
            "comparing {width}×{height} images needs about {:.1} GB of memory ({} bytes a \
             pixel, FLIP's filters most of it), above --memory-budget ({:.1} GB): raise it or \
             compare crops",
            gb(need),
            mirrorbox_image::metrics::COMPARE_BYTES_PER_PIXEL,
            gb(budget)
        )));
    }
    Ok(())
}

/// Metrics as JSON (an infinite PSNR, for identical images, is `null`).
pub fn metrics_json(m: &Metrics) -> serde_json::Value {
    serde_json::json!({
        "rmse": m.rmse, "relmse": m.relmse, "smape": m.smape, "max_abs": m.max_abs,
        "psnr": m.psnr.is_finite().then_some(m.psnr), "ssim": m.ssim,
        "flip_mean": m.flip_mean, "flip_p95": m.flip_p95, "flip_p99": m.flip_p99,
        "flip_ppd": FLIP_PIXELS_PER_DEGREE,
    })
}

/// What `trace` and `render` record in their EXRs that a comparison needs, read once per
/// image (a PNG records nothing: it is already exposed and encoded).
#[derive(Clone, Default)]
struct Recorded {
    /// The samples per pixel: `mirrorbox.spp` (trace), or `mirrorbox.ssaa` s as s² (render).
    spp: Option<u64>,
    /// The scene camera's exposure, `mirrorbox.exposure`.
    exposure: Option<f32>,
    /// The content hash of the scene drawn (`mirrorbox.scene_hash`: its reflectances and
    /// `--alpha` included, its cut depth not).
    scene_hash: Option<String>,
    /// An image of something other than radiance (`mirrorbox.aov`: `bounces`, trace's mean
    /// bounce counts).
    aov: Option<String>,
}

fn recorded(path: &std::path::Path) -> Recorded {
    let Ok(attributes) = mirrorbox_image::read_exr_attributes(path) else {
        return Recorded::default();
    };
    let value = |key: &str| {
        attributes
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    };
    let count = |key: &str| value(key).and_then(|v| v.parse::<u64>().ok());
    Recorded {
        spp: count("mirrorbox.spp")
            .or_else(|| count("mirrorbox.ssaa").and_then(|s| s.checked_mul(s))),
        exposure: value("mirrorbox.exposure")
            .and_then(|v| v.parse::<f32>().ok())
            .filter(|e| *e > 0.0 && e.is_finite()),
        scene_hash: value("mirrorbox.scene_hash").map(String::from),
        aov: value("mirrorbox.aov").map(String::from),
    }
}

/// The tone mapping's exposure: `--exposure`, else the one both images record, else 1. Images
/// recording different exposures, or one recording an exposure other than 1 beside one that
/// records none, are refused without `--exposure`: no one value fits both.
fn exposure(args: &Args, reference: &Recorded, test: &Recorded) -> Result<f32, Failure> {
    if let Some(e) = args.exposure {
        if !(e > 0.0 && e.is_finite()) {
            return Err(Failure::BadInput(format!(
                "--exposure must be a positive number, got {e}"
            )));
        }
        return Ok(e);
    }
    let (r, t) = (reference.exposure, test.exposure);
    match (r, t) {
        (Some(a), Some(b)) if a == b => Ok(a),
        (None, None) => Ok(1.0),
        (Some(a), None) | (None, Some(a)) if a == 1.0 => Ok(1.0),
        _ => {
            let said = |p: &std::path::Path, e: Option<f32>| {
                e.map_or(format!("{} records no exposure", p.display()), |e| {
                    format!("{} was made with exposure {e}", p.display())
                })
            };
            Err(Failure::BadInput(format!(
                "{} and {}: give --exposure",
                said(&args.reference, r),
                said(&args.test, t)
            )))
        }
    }
}

/// Refuses images sampled on different sub-pixel grids: a 4×4 box average and a pixel-centre
/// sample differ wherever the image curves, and that difference would be read as the
/// method's error (the shading contract: never from mismatched sampling).
fn check_same_grid(args: &Args, reference: &Recorded, test: &Recorded) -> Result<(), Failure> {
    match (reference.spp, test.spp) {
        (Some(a), Some(b)) if a != b => Err(Failure::BadInput(format!(
            "{} was taken with {a} samples per pixel and {} with {b}: compare images of the \
             same sub-pixel grid (trace --spp s² against render --ssaa s)",
            args.reference.display(),
            args.test.display()
        ))),
        _ => Ok(()),
    }
}

/// A warning where both images record the scene they show and the scenes differ (another
/// scene file, or the same at another `--alpha`): the numbers are then not one method's
/// error. A warning, not a refusal: comparing two scenes on purpose is allowed.
fn scenes_warning(args: &Args, reference: &Recorded, test: &Recorded) -> Option<String> {
    match (&reference.scene_hash, &test.scene_hash) {
        (Some(a), Some(b)) if a != b => Some(format!(
            "warning: {} and {} show different scenes (scene hashes {a} and {b}: another scene \
             file, or its mirrors at another reflectance, --alpha): the difference is not only \
             the method's",
            args.reference.display(),
            args.test.display()
        )),
        _ => None,
    }
}

pub fn run(args: &Args) -> Result<(), Failure> {
    let (reference, test) = (recorded(&args.reference), recorded(&args.test));
    // A bounce map carries its radiance image's keys (scene, spp, exposure): it had been
    // scored as an image of the scene.
    for (path, r) in [(&args.reference, &reference), (&args.test, &test)] {
        if let Some(aov) = &r.aov {
            return Err(Failure::BadInput(format!(
                "{}: holds trace's {aov} (mirrorbox.aov), not radiance: compare images of the \
                 scene",
                path.display()
            )));
        }
    }
    let exposure = exposure(args, &reference, &test)?;
    if let Some(w) = scenes_warning(args, &reference, &test) {
        eprintln!("{w}");
    }
    let heatmap = args
        .heatmap
        .as_deref()
        .map(|p| output_path("--heatmap", p, "png"))
        .transpose()?;
    if let Some(h) = &heatmap {
        // The heat map must not overwrite an image being compared (the two inputs may be
        // one file: an image against itself is a valid, if empty, comparison).
        for (flag, input) in [("REFERENCE", &args.reference), ("TEST", &args.test)] {
            if mirrorbox_files::in_resolved_folder(h) == mirrorbox_files::in_resolved_folder(input)
            {
                return Err(Failure::BadInput(format!(
                    "{}: --heatmap would overwrite {flag}, an image being compared; give it \
                     another name",
                    h.display()
                )));
            }
        }
    }
    // The sizes first (headers only): their memory is checked before a pixel is read.
    for p in [&args.reference, &args.test] {
        let size = mirrorbox_image::image_size(p).map_err(|e| Failure::BadInput(e.to_string()))?;
        check_compare_memory(size, args.memory_budget)?;
    }
    // A NaN, infinite or negative pixel makes the metrics NaN (and hides in `max |d|`).
    let read = |p: &PathBuf| {
        let image = read_image(p).map_err(|e| Failure::BadInput(e.to_string()))?;
        match image.radiance_problem() {
            Some(problem) => Err(Failure::BadInput(format!("{}: {problem}", p.display()))),
            None => Ok(image),
        }
    };
    let (r, t) = (read(&args.reference)?, read(&args.test)?);
    let m = compare(&r, &t, exposure).map_err(|e| {
        Failure::BadInput(format!(
            "{} vs {}: {e}",
            args.reference.display(),
            args.test.display()
        ))
    })?;
    check_same_grid(args, &reference, &test)?;
    if let Some(path) = &heatmap {
        let map = flip_map(
            &r.to_srgb8(exposure),
            &t.to_srgb8(exposure),
            r.width,
            r.height,
        );
        let bytes: Vec<u8> = map.iter().flat_map(|&v| colormap::heat(v)).collect();
        write_png_bytes(path, r.width, r.height, &bytes)
            .map_err(|e| Failure::Other(e.to_string()))?;
    }
    if args.json {
        let mut v = metrics_json(&m);
        v["exposure"] = serde_json::json!(exposure);
        println!("{v}");
    } else {
        println!(
            "{} vs {} ({}x{}, over the whole image):",
            args.test.display(),
            args.reference.display(),
            r.width,
            r.height
        );
        println!(
            "  linear:  RMSE {:.4e}  relMSE {:.4e}  SMAPE {:.4e}  max |d| {:.4e}",
            m.rmse, m.relmse, m.smape, m.max_abs
        );
        println!(
            "  sRGB:    PSNR {:.2} dB  SSIM {:.6}  FLIP mean {:.4e} p95 {:.4e} p99 {:.4e} ({} px/deg; exposure {exposure})",
            m.psnr, m.ssim, m.flip_mean, m.flip_p95, m.flip_p99, FLIP_PIXELS_PER_DEGREE
        );
        if let Some(path) = &heatmap {
            println!("  wrote the FLIP map {}", path.display());
        }
    }
    Ok(())
}
