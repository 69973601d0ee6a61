//! `mirrorbox info`: the wgpu adapter the raster commands would use.

use crate::Failure;
use mirrorbox_raster::{AdapterError, select_adapter};

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
        });
        println!("{value}");
    } else {
        println!("{r}");
    }
    Ok(())
}
