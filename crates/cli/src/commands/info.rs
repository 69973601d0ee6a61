//! `mirrorbox info`: the wgpu adapter the raster commands would use.

use crate::Failure;
use mirrorbox_raster::{AdapterError, ColorFormat, select_adapter};

#[derive(clap::Args)]
pub struct Args {
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    let selected = select_adapter().map_err(|e| match e {
        AdapterError::BadOverride { .. } => Failure::BadInput(e.to_string()),
        AdapterError::NoneFound { .. } => Failure::Other(e.to_string()),
    })?;
    let forced = ColorFormat::from_env().map_err(|value| {
        Failure::BadInput(mirrorbox_raster::RasterError::BadColorFormat { value }.to_string())
    })?;
    // The colour format `render` and `sweep` would use on this adapter (or why none fits).
    let color_format = ColorFormat::choose(&selected.adapter, forced);
    let r = &selected.report;
    if args.json {
        let value = serde_json::json!({
            "name": r.name,
            "backend": r.backend,
            "device_type": r.device_type,
            "driver": r.driver,
            "driver_info": r.driver_info,
            "timestamp_query": r.timestamp_query,
            "timestamp_query_inside_passes": r.timestamp_query_inside_passes,
            "clip_distances": r.clip_distances,
            "ray_query": r.ray_query,
            "mesa": mirrorbox_raster::mesa_version(&r.driver_info).map(|(a, b, c)| format!("{a}.{b}.{c}")),
            "shader_cache": r.shader_cache(),
            "warning": r.platform_warning(),
            "color_format": color_format.as_ref().ok().map(|f| f.name()),
            "color_format_error": color_format.as_ref().err(),
            "viewer": cfg!(feature = "viewer"),
        });
        println!("{value}");
    } else {
        println!("{r}");
        if let Some(warning) = r.platform_warning() {
            eprintln!("warning: {warning}");
        }
        match &color_format {
            Ok(f) => println!("colour targets:   {f}"),
            Err(why) => println!("colour targets:   none: {why}"),
        }
        // Whether `view` is in this binary (scripts/run.sh builds it without).
        println!(
            "viewer:           {}",
            if cfg!(feature = "viewer") {
                "built"
            } else {
                "not built (--no-default-features): `cargo build --release -p mirrorbox` builds it"
            }
        );
    }
    Ok(())
}
