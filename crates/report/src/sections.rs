//! The report sections of the experiments this crate writes (the experiment registry,
//! `mirrorbox-experiments`, names each experiment's): each takes the sweep's facts and records
//! and returns nothing where the records are not its experiment's.

use crate::document::Block;
use crate::{Record, SweepInfo};

/// The reproduction of the paper's Table 1 with the exact methods beside it
/// ([`crate::table1`]).
pub fn table1(info: &SweepInfo, records: &[Record]) -> Vec<Block> {
    crate::write::table1_section(info, records)
}

/// The exact methods' cost against the depth cap ([`crate::exact`]).
pub fn depth_scaling(info: &SweepInfo, records: &[Record]) -> Vec<Block> {
    let floor = records.iter().find(|r| r.kind == "floor");
    crate::write::depth_scaling(info, records, floor)
}

/// The symmetry methods' cost against the planes p ([`crate::symmetry`]).
pub fn symmetry_scaling(_: &SweepInfo, records: &[Record]) -> Vec<Block> {
    crate::write::symmetry_section(records)
}

/// Shadows and mirrored lights against the mirrored-light depth ([`crate::lighting`]).
pub fn lighting(_: &SweepInfo, records: &[Record]) -> Vec<Block> {
    crate::lighting::lighting_section(records)
}

/// The uneven mirrors' tricks against the tilt ([`crate::uneven`]).
pub fn uneven_mirrors(info: &SweepInfo, records: &[Record]) -> Vec<Block> {
    crate::uneven::uneven_section(records, &info.bump_methods)
}

/// Per-eye against shared mirror textures against the IPD ([`crate::stereo`]).
pub fn stereo(_: &SweepInfo, records: &[Record]) -> Vec<Block> {
    crate::stereo::stereo_section(records)
}

/// Screen-space and ray-query reflections beside the exact methods
/// ([`crate::engine_reflections`]).
pub fn engine_reflections(info: &SweepInfo, records: &[Record]) -> Vec<Block> {
    crate::engine_reflections::engine_reflections_section(records, &info.truth)
}
