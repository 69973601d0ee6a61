//! The obvhs ray tracer: mirrorbox's ground truth.
//!
//! - [`bvh`]: one obvhs hierarchy over all the scene's triangles, watertight triangle tests;
//!   [`bvh::packet`]: the packet kernel (a pixel's rays through a binary BVH together).
//! - [`integrator`]: the [`Integrator`] trait and its implementations, chosen by
//!   [`IntegratorSettings`]:
//!   - [`whitted`]: the integrator that follows the shading contract to deep bounce counts;
//!   - [`path`]: the physically based integrator, for comparison with Mitsuba's `path`.
//! - [`hit_point`]: a diffuse hit's point re-solved on its triangle's plane in f64.
//! - [`sampler`]: the shared sub-pixel grid, or stratified jitter.
//! - [`render`](mod@render): the parallel image loop and its statistics.
//! - [`ab_switch`]: a switch for timing two forms of a change inside one process.

pub mod ab_switch;
pub mod bvh;
pub mod cpu_features;
pub mod hit_point;
pub mod integrator;
pub mod mirror_bounce;
pub mod mirror_mask;
pub mod render;
pub mod sampler;
pub mod watertight;

pub use bvh::{BvhKind, Hit, SceneBvh};
pub use integrator::{Integrator, IntegratorSettings, PathResult, Termination, path, whitted};
pub use mirror_mask::{mirror_mask, reflections_off_screen};
pub use path::{PathSettings, PathTracer};
pub use render::{TraceOutput, TraceSettings, TraceStats, render, render_while};
pub use sampler::Sampling;
pub use whitted::{Whitted, WhittedSettings};
