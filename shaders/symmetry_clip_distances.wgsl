// The clip-distance vertex stage of crates/raster/src/methods/symmetry.rs (and
// symmetry_pruned.rs), compiled only where the adapter has `clip_distances` (the module starts
// with `enable clip_distances;`, then shading.wgsl and symmetry.wgsl) and used for at most 8
// planes: clip distance i is d_i, the hardware clips each copy to its cell, so the fragment
// stage needs no discard and keeps early depth.

struct ClippedCopyOut {
    @builtin(position) @invariant clip: vec4f,
    @builtin(clip_distances) clip_distances: array<f32, 8>,
    @location(0) world: vec3f,
    @location(1) @interpolate(flat) normal: vec3f,
    @location(2) @interpolate(flat) surface: u32,
    @location(3) @interpolate(flat) copy: u32,
    @location(8) uv: vec2f,
}

struct ClippedCopyIn {
    @builtin(position) @invariant clip: vec4f,
    @location(0) world: vec3f,
    @location(1) @interpolate(flat) normal: vec3f,
    @location(2) @interpolate(flat) surface: u32,
    @location(3) @interpolate(flat) copy: u32,
    @location(8) uv: vec2f,
}

fn clipped_copy_out(v: VertexIn, mask: u32) -> ClippedCopyOut {
    let c = copy_vertex(v.position, v.normal, mask);
    var out: ClippedCopyOut;
    out.clip = symmetry.clip_from_world * vec4f(c.position, 1.0);
    // Planes past the count have distance 1 (copy_vertex).
    out.clip_distances = array<f32, 8>(c.d0.x, c.d0.y, c.d0.z, c.d0.w, c.d1.x, c.d1.y, c.d1.z, c.d1.w);
    out.world = c.position;
    out.normal = c.normal;
    out.surface = v.surface;
    out.copy = mask;
    out.uv = v.uv;
    return out;
}

@vertex
fn vs_instanced_clipped(v: VertexIn, @builtin(instance_index) instance: u32) -> ClippedCopyOut {
    return clipped_copy_out(v, masks[instance]);
}

@vertex
fn vs_per_copy_clipped(v: VertexIn) -> ClippedCopyOut {
    return clipped_copy_out(v, copy_record.mask);
}

@fragment
fn fs_object_clipped(in: ClippedCopyIn) -> @location(0) vec4f {
    return object_colour(in.world, in.normal, in.surface, in.uv);
}

@fragment
fn fs_copy_id_clipped(in: ClippedCopyIn) -> @location(0) vec4f {
    return copy_id_colour(in.copy);
}
