//! The wgpu rasterizer of mirrorbox.
//!
//! [`adapter`] chooses the adapter every raster method runs on — Vulkan first (Mesa's
//! lavapipe on a CPU-only machine), then GL through EGL (llvmpipe), `WGPU_BACKEND`
//! overriding — and reports what it can time and clip.

pub mod adapter;

pub use adapter::{AdapterError, AdapterReport, SelectedAdapter, select_adapter};
