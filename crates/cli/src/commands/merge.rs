//! `mirrorbox merge OUT DIR...` (issue 20): the shards of one sweep (`sweep --shard I/N`) joined
//! into one sweep folder with its reports (`mirrorbox_harness::merge`).

use crate::Failure;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The merged sweep's folder (created inside an existing folder).
    out: PathBuf,
    /// The shards' folders, every shard of the sweep once.
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    let command = std::env::args().collect::<Vec<_>>().join(" ");
    let merged = mirrorbox_harness::merge::merge(
        &args.out,
        &args.dirs,
        &command,
        &mirrorbox_experiments::sections(),
    )?;
    println!(
        "merged {} shards, {} points, into {}; devices: {}",
        merged.shards,
        merged.points,
        args.out.join("report.md").display(),
        merged.devices.join("; ")
    );
    if merged.devices.len() > 1 {
        eprintln!(
            "note: the shards ran on {} devices: error figures merge freely, timings compare only \
             within one device (report.md lists which shard ran where)",
            merged.devices.len()
        );
    }
    Ok(())
}
