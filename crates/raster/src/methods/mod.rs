//! The raster methods, one file each, and the one table of them.
//!
//! To add a method: its file here (a `MethodEntry` static and the `RasterMethod` it
//! configures), its WGSL in `shaders/`, one `mod` line and one row below, its golden image,
//! a paragraph in `docs/methods.md` — see `CONTRIBUTING.md`.

pub mod cubemap;
pub mod feedback;
pub mod portal_stencil;
pub mod ray_query;
pub mod recursive_texture;
pub mod screen_space_reflections;
pub mod symmetry;
pub mod symmetry_baked;
pub mod symmetry_pruned;
pub mod unrolled;

use crate::method::MethodEntry;

/// Every raster method mirrorbox knows, in the order the CLI lists them.
pub static METHODS: &[&MethodEntry] = &[
    &recursive_texture::NAIVE,
    &recursive_texture::AUXILIARY,
    &recursive_texture::PATH_TEXTURES,
    &feedback::FEEDBACK,
    &cubemap::CUBEMAP,
    &screen_space_reflections::SSR,
    &portal_stencil::PORTAL,
    &unrolled::UNROLLED,
    &ray_query::RAY_QUERY,
    &symmetry::SYMMETRY,
    &symmetry_pruned::SYMMETRY_PRUNED,
    &symmetry_baked::SYMMETRY_BAKED,
];

/// Every adapter feature a registered method needs or can use.
pub fn wanted_features() -> wgpu::Features {
    METHODS.iter().fold(wgpu::Features::empty(), |f, e| {
        f | e.optional_features | e.required_features
    })
}
