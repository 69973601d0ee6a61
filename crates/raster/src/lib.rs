//! The wgpu rasterizer of mirrorbox.
//!
//! - [`adapter`]: the one adapter rule (Vulkan, then GL; `WGPU_BACKEND` overrides).
//! - [`plan`]: the seed paper's recursion (naive and auxiliary), planned on the CPU.

pub mod adapter;
pub mod plan;

pub use adapter::{AdapterError, AdapterReport, SelectedAdapter, select_adapter};
