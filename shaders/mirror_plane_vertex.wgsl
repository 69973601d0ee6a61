// The vertex stage of the methods that draw a mirror's world through the mirror's plane
// (crates/raster/src/methods/portal_stencil.rs, recursive_texture.rs and cubemap.rs): it
// follows shading.wgsl, and the method's own file provides the view it draws,
// `view_clip_from_world()` and `view_plane()` (the plane in scene space, front positive, that
// its world lies in front of; (0, 0, 0, 1) for the camera's).

struct VertexOut {
    // Invariant: a mirror marked in a stencil pass must meet the depth its world pass wrote.
    @builtin(position) @invariant clip: vec4f,
    @location(0) world: vec3f,
    @location(1) @interpolate(flat) normal: vec3f,
    @location(2) @interpolate(flat) surface: u32,
    // Signed distance to the view's mirror plane (scene units).
    @location(3) plane_distance: f32,
    @location(8) uv: vec2f,
}

fn scene_vertex(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = view_clip_from_world() * vec4f(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.surface = v.surface;
    out.uv = v.uv;
    out.plane_distance = dot(view_plane(), vec4f(v.position, 1.0));
    return out;
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    return scene_vertex(v);
}
