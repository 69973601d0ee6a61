// The hardware-clipped vertex stage of the methods that draw a mirror's world through the
// mirror's plane (crates/raster/src/methods/portal_stencil.rs, recursive_texture.rs and cubemap.rs),
// compiled only where the adapter has `clip_distances`: the module starts with
// `enable clip_distances;`, then shading.wgsl, mirror_plane_vertex.wgsl (`VertexOut`,
// `scene_vertex`) and the method's file.
// Clip distance 0 is the signed distance to the plane: the hardware clips what lies behind
// the mirror, so the method's plain fragment entry points need no discard.

struct ClippedVertexOut {
    @builtin(position) @invariant clip: vec4f,
    @builtin(clip_distances) clip_distances: array<f32, 1>,
    @location(0) world: vec3f,
    @location(1) @interpolate(flat) normal: vec3f,
    @location(2) @interpolate(flat) surface: u32,
    @location(3) plane_distance: f32,
    @location(8) uv: vec2f,
}

@vertex
fn vs_clip_distances(v: VertexIn) -> ClippedVertexOut {
    let o = scene_vertex(v);
    var out: ClippedVertexOut;
    out.clip = o.clip;
    out.clip_distances[0] = o.plane_distance;
    out.world = o.world;
    out.normal = o.normal;
    out.surface = o.surface;
    out.plane_distance = o.plane_distance;
    out.uv = o.uv;
    return out;
}
