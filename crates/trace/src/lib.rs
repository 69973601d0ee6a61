//! The obvhs ray tracer: mirrorbox's ground truth.
//!
//! This crate owns the acceleration structure over the scene's single triangle list
//! ([`SceneBvh`]); integrators build on its closest-hit query.

pub mod bvh;

pub use bvh::{Hit, SceneBvh};
