//! What every method plans from, on the CPU, before any GPU work: the lowest floor of the
//! rasterizer, importing nothing of the crate above itself (`tests::floors`). The seed
//! paper's recursion ([`recursion`], re-exported here: [`plan`], [`Plan`], [`PlanError`]),
//! the exact methods' reflection paths ([`exact_paths`]), footprints against portals
//! ([`culling`]), seed 001's symmetry cells ([`symmetry_cells`]), the shadow maps' CPU half
//! ([`shadow_plan`]), the one projection (infinite reversed Z, [`projection`]) and the
//! memory estimate every plan is checked against before a byte is allocated ([`memory`]).

pub mod culling;
pub mod exact_paths;
pub mod memory;
pub mod projection;
mod recursion;
pub mod shadow_plan;
pub mod symmetry_cells;

pub use recursion::*;
