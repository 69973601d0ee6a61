// Entry points of crates/raster/src/shadow_maps.rs: one layer of a shadow map, the distance
// from its light (or light image) to the nearest surface, per texel (docs/shading.md,
// "Shadow maps"). Stands alone: it reads the scene's vertices (VERTEX_LAYOUT) and nothing of
// the shading contract.
//
// A real light's six cube faces keep everything; a light image's layer looks through its last
// mirror and keeps only what lies on that mirror's front (`keep`), without the mirror itself
// (`skip_surface`): light through the mirror reaches nothing on its back.

struct ShadowView {
    clip_from_world: mat4x4f,
    // Fragments with dot(keep, (x, 1)) < 0 are dropped; (0, 0, 0, 1) keeps all.
    keep: vec4f,
    origin: vec3f,
    // A surface id not drawn (the image's mirror), or 0xffffffff.
    skip_surface: u32,
}

@group(0) @binding(0) var<uniform> shadow_view: ShadowView;

struct ShadowVertex {
    @location(0) position: vec3f,
    @location(1) normal: vec3f,
    @location(2) surface: u32,
}

struct ShadowOut {
    @builtin(position) clip: vec4f,
    @location(0) world: vec3f,
    @location(1) @interpolate(flat) surface: u32,
}

@vertex
fn vs_shadow(v: ShadowVertex) -> ShadowOut {
    var out: ShadowOut;
    out.clip = shadow_view.clip_from_world * vec4f(v.position, 1.0);
    out.world = v.position;
    out.surface = v.surface;
    return out;
}

@fragment
fn fs_shadow(in: ShadowOut) -> @location(0) vec4f {
    if (in.surface == shadow_view.skip_surface || dot(shadow_view.keep, vec4f(in.world, 1.0)) < 0.0) {
        discard;
    }
    // The distance in red; four channels so that half-float RGBA layers (GL) take it too.
    return vec4f(distance(in.world, shadow_view.origin), 0.0, 0.0, 1.0);
}
