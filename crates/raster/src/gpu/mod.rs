//! The wgpu layer, the floor above [`crate::plan`]: the adapter (Vulkan, then GL;
//! `WGPU_BACKEND` overrides), the device, its errors and its caches ([`device`]), colour
//! formats (RGBA32F, else RGBA16F; `MIRRORBOX_COLOR_FORMAT` forces one), render targets,
//! the scene-pipeline builder and uniform arena ([`pipeline`]), layouts and pipelines made
//! once per device ([`state_cache`]), the SSAA resolve, GPU timestamps ([`timing`]),
//! readback, the viewer's display tone map, the camera rays of the ray-query methods, and
//! all WGSL composition ([`wgsl`]). It imports [`crate::plan`] and nothing above itself
//! (the methods and what they share): `tests::floors`.

pub mod adapter;
pub mod camera_rays;
pub mod color_format;
mod device;
pub mod display_tone_map;
pub mod pipeline;
pub mod readback;
pub mod resolve;
pub mod state_cache;
pub mod targets;
pub mod timing;
pub mod wgsl;

pub use device::*;
