//! The obvhs ray tracer: mirrorbox's ground truth.
//!
//! - [`bvh`]: one obvhs hierarchy over all the scene's triangles, watertight triangle tests.
//! - [`whitted`]: the integrator that follows the shading contract to deep bounce counts.
//! - [`path`]: the physically based integrator, for comparison with Mitsuba's `path`.
//! - [`sampler`]: the shared sub-pixel grid, or stratified jitter.
//! - [`render`]: the parallel image loop and its statistics.

pub mod bvh;
pub mod mirror_bounce;
pub mod path;
pub mod render;
pub mod sampler;
pub mod watertight;
pub mod whitted;

pub use bvh::{BvhKind, Hit, SceneBvh};
pub use path::{PathSettings, PathTracer};
pub use render::{TraceOutput, TraceSettings, TraceStats, render};
pub use sampler::Sampling;
pub use whitted::{PathResult, Termination, Whitted, WhittedSettings};
