// The clip-distance vertex stage of crates/raster/src/methods/unrolled.rs, compiled only where the
// adapter has `clip_distances` (the module starts with `enable clip_distances;`, then
// shading.wgsl and unrolled.wgsl). Distance 0 is the last mirror's plane, 1..=7 the piece's
// edges; the hardware clips, so the fragment stage needs no discard and keeps early depth.

const CLIP_EDGES: u32 = 7u;

struct ClippedOut {
    @builtin(position) clip: vec4f,
    @builtin(clip_distances) clip_distances: array<f32, 8>,
    @location(0) world: vec3f,
    @location(1) @interpolate(flat) normal: vec3f,
    @location(2) @interpolate(flat) surface: u32,
    @location(3) @interpolate(flat) piece: u32,
    @location(8) uv: vec2f,
}

struct ClippedIn {
    @builtin(position) clip: vec4f,
    @location(0) world: vec3f,
    @location(1) @interpolate(flat) normal: vec3f,
    @location(2) @interpolate(flat) surface: u32,
    @location(3) @interpolate(flat) piece: u32,
    @location(8) uv: vec2f,
}

@vertex
fn vs_clipped(v: VertexIn, @builtin(instance_index) instance: u32) -> ClippedOut {
    let id = ids[instance];
    let p = pieces[id];
    var out: ClippedOut;
    out.clip = p.clip_from_world * vec4f(v.position, 1.0);
    out.clip_distances[0] = dot(p.plane, vec4f(v.position, 1.0));
    for (var i = 0u; i < CLIP_EDGES; i++) {
        var d = 1.0;
        if (i < p.edge_count) {
            d = dot(edges[p.edge_first + i].xyz, out.clip.xyw);
        }
        out.clip_distances[i + 1u] = d;
    }
    out.world = v.position;
    out.normal = v.normal;
    out.surface = v.surface;
    out.piece = id;
    out.uv = v.uv;
    return out;
}

@fragment
fn fs_object_clipped(in: ClippedIn) -> @location(0) vec4f {
    return object_colour(in.piece, in.world, in.normal, in.surface, in.uv);
}

@fragment
fn fs_mirror_clipped(in: ClippedIn) -> @location(0) vec4f {
    return mirror_colour(in.piece, in.world, in.normal, in.surface);
}
