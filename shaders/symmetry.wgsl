// Entry points of crates/raster/src/methods/symmetry.rs (and symmetry_pruned.rs,
// symmetry_baked.rs): seed 001's symmetry planes. Prepended with shading.wgsl;
// symmetry_clip_distances.wgsl adds the hardware-clipped vertex stage where the adapter has
// clip distances.
//
// Copy `mask` of a vertex, the seed's cascade: x_0 = the source vertex; for plane i = 0..p−1
// in order, d_i = n_i·x_i − offset_i (on the position already moved by the earlier planes),
// then x_{i+1} = x_i − 2 d_i n_i if bit i of the mask is set, else x_i; the normal is
// reflected with the position. The copy keeps only what has every d_i ≥ 0: each d_i is affine
// in the source position, so clipping at d_i = 0 (clip distances) or discarding fragments with
// an interpolated d_i < 0 is exact. An odd number of reflections reverses the winding: the
// method draws even and odd copies apart, with opposite front faces.

const MAX_SYMMETRY_PLANES: u32 = 16u;

struct SymmetryFrame {
    clip_from_world: mat4x4f,
    // The camera (shading's viewer): copies are lit and seen in the real world.
    eye: vec3f,
    plane_count: u32,
    // Plane i as (n_i, −offset_i): dot(planes[i], vec4f(x, 1)) is d_i.
    planes: array<vec4f, 16>,
}

// One copy's record for `--symmetry-draws per-copy` (the seed's uniform per draw).
struct CopyRecord {
    mask: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(1) @binding(0) var<uniform> symmetry: SymmetryFrame;
// Instanced draws: instance i draws copy masks[i] (each draw's first_instance starts its
// winding group).
@group(1) @binding(1) var<storage, read> masks: array<u32>;
@group(1) @binding(2) var<uniform> copy_record: CopyRecord;

// A source vertex moved into one copy, with its distances to the planes (1 past the last).
struct CopiedVertex {
    position: vec3f,
    normal: vec3f,
    d0: vec4f,
    d1: vec4f,
    d2: vec4f,
    d3: vec4f,
}

fn copy_vertex(position: vec3f, normal: vec3f, mask: u32) -> CopiedVertex {
    var x = position;
    var n = normal;
    var d = array<f32, 16>(1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0);
    for (var i = 0u; i < min(symmetry.plane_count, MAX_SYMMETRY_PLANES); i++) {
        let plane = symmetry.planes[i];
        let di = dot(plane.xyz, x) + plane.w;
        d[i] = di;
        if (((mask >> i) & 1u) == 1u) {
            x = x - 2.0 * di * plane.xyz;
            n = n - 2.0 * dot(plane.xyz, n) * plane.xyz;
        }
    }
    var out: CopiedVertex;
    out.position = x;
    out.normal = n;
    out.d0 = vec4f(d[0], d[1], d[2], d[3]);
    out.d1 = vec4f(d[4], d[5], d[6], d[7]);
    out.d2 = vec4f(d[8], d[9], d[10], d[11]);
    out.d3 = vec4f(d[12], d[13], d[14], d[15]);
    return out;
}

// The fragment-discard stage: every distance interpolated (perspective-correct, hence exact
// for these affine functions) and tested per fragment.
struct CopyOut {
    @builtin(position) @invariant clip: vec4f,
    @location(0) world: vec3f,
    @location(1) @interpolate(flat) normal: vec3f,
    @location(2) @interpolate(flat) surface: u32,
    @location(3) @interpolate(flat) copy: u32,
    @location(4) d0: vec4f,
    @location(5) d1: vec4f,
    @location(6) d2: vec4f,
    @location(7) d3: vec4f,
    @location(8) uv: vec2f,
}

fn copy_out(v: VertexIn, mask: u32) -> CopyOut {
    let c = copy_vertex(v.position, v.normal, mask);
    var out: CopyOut;
    out.clip = symmetry.clip_from_world * vec4f(c.position, 1.0);
    out.world = c.position;
    out.normal = c.normal;
    out.surface = v.surface;
    out.copy = mask;
    out.uv = v.uv;
    out.d0 = c.d0;
    out.d1 = c.d1;
    out.d2 = c.d2;
    out.d3 = c.d3;
    return out;
}

@vertex
fn vs_instanced(v: VertexIn, @builtin(instance_index) instance: u32) -> CopyOut {
    return copy_out(v, masks[instance]);
}

@vertex
fn vs_per_copy(v: VertexIn) -> CopyOut {
    return copy_out(v, copy_record.mask);
}

fn behind_a_plane(in: CopyOut) -> bool {
    return any(in.d0 < vec4f(0.0)) || any(in.d1 < vec4f(0.0)) || any(in.d2 < vec4f(0.0))
        || any(in.d3 < vec4f(0.0));
}

fn object_colour(world: vec3f, normal: vec3f, surface: u32, uv: vec2f) -> vec4f {
    let s = surfaces[surface];
    return vec4f(diffuse_radiance(world, normal, normalize(symmetry.eye - world), surface_albedo(s, uv), surface_emission(s, uv)), 1.0);
}

// The debug output of `--copy-ids`: which copy a pixel shows, as copy mask + 1 (0: none).
fn copy_id_colour(mask: u32) -> vec4f {
    return vec4f(f32(mask + 1u), 0.0, 0.0, 1.0);
}

@fragment
fn fs_object_discard(in: CopyOut) -> @location(0) vec4f {
    if (behind_a_plane(in)) {
        discard;
    }
    return object_colour(in.world, in.normal, in.surface, in.uv);
}

@fragment
fn fs_copy_id_discard(in: CopyOut) -> @location(0) vec4f {
    if (behind_a_plane(in)) {
        discard;
    }
    return copy_id_colour(in.copy);
}

// Scene mirrors and the baked mesh: drawn as they are, once.
alias UnmovedOut = SceneVertexOut;

@vertex
fn vs_unmoved(v: VertexIn) -> UnmovedOut {
    return scene_vertex_through(v, symmetry.clip_from_world);
}

// The symmetry methods follow no mirror (reflection depth 0): a mirror's front shows the
// terminal radiance, as every method shows a mirror it cannot follow; its back is diffuse.
@fragment
fn fs_mirror(in: UnmovedOut) -> @location(0) vec4f {
    let s = surfaces[in.surface];
    if (dot(in.normal, symmetry.eye - in.world) > 0.0) {
        return vec4f(frame.terminal, 1.0);
    }
    return vec4f(diffuse_radiance(in.world, in.normal, normalize(symmetry.eye - in.world), s.back_albedo, vec3f(0.0)), 1.0);
}

@fragment
fn fs_mirror_copy_id(in: UnmovedOut) -> @location(0) vec4f {
    return vec4f(0.0, 0.0, 0.0, 1.0);
}

@fragment
fn fs_unmoved_object(in: UnmovedOut) -> @location(0) vec4f {
    return object_colour(in.world, in.normal, in.surface, in.uv);
}

// The baked mesh under `--copy-ids`: each vertex carries the copy its triangle came from
// (the bake's record, a second vertex buffer).
struct BakedCopyOut {
    @builtin(position) @invariant clip: vec4f,
    @location(0) @interpolate(flat) copy: u32,
}

@vertex
fn vs_baked_copy_id(v: VertexIn, @location(3) copy: u32) -> BakedCopyOut {
    var out: BakedCopyOut;
    out.clip = symmetry.clip_from_world * vec4f(v.position, 1.0);
    out.copy = copy;
    return out;
}

@fragment
fn fs_baked_copy_id(in: BakedCopyOut) -> @location(0) vec4f {
    return copy_id_colour(in.copy);
}
