// Entry points of crates/raster/src/methods/portal_stencil.rs: exact mirrors by stencil recursion.
// Each reflection path draws its world where the stencil holds its value, in front of its last
// mirror, attenuated by the product of the reflectances along it. Prepended with
// shading.wgsl and mirror_plane_vertex.wgsl; followed by mirror_plane_fragments.wgsl, and by
// mirror_plane_clip_distances.wgsl where the adapter has clip
// distances (vs_clip_distances with fs_object / fs_mirror / fs_none), else the plane is
// tested per fragment (vs_main with the *_discard entry points).

struct Path {
    clip_from_world: mat4x4f,
    eye: vec3f,
    _pad0: f32,
    attenuation: vec3f,
    _pad1: f32,
    // The path's last mirror plane in scene space, front positive ((0, 0, 0, 1) for the
    // camera): its world is what lies in front of it.
    plane: vec4f,
}

@group(1) @binding(0) var<uniform> path: Path;

// The path's view and its last mirror plane (mirror_plane_vertex.wgsl's hooks).
fn view_clip_from_world() -> mat4x4f {
    return path.clip_from_world;
}

fn view_plane() -> vec4f {
    return path.plane;
}

fn shade(in: VertexOut, albedo: vec3f, emission: vec3f) -> vec3f {
    return path.attenuation * diffuse_radiance(in.world, in.normal, normalize(path.eye - in.world), albedo, emission);
}

fn object_colour(in: VertexOut) -> vec4f {
    let s = surfaces[in.surface];
    return vec4f(shade(in, surface_albedo(s, in.uv), surface_emission(s, in.uv)), 1.0);
}

// A mirror in a path's world: its front shows the terminal radiance (overwritten by the
// child path's world wherever that path was kept); its back is diffuse.
fn mirror_colour(in: VertexOut) -> vec4f {
    let s = surfaces[in.surface];
    if (dot(in.normal, path.eye - in.world) > 0.0) {
        return vec4f(path.attenuation * frame.terminal, 1.0);
    }
    return vec4f(shade(in, s.back_albedo, vec3f(0.0)), 1.0);
}

// Entry points fs_object, fs_mirror and their *_discard variants:
// shaders/mirror_plane_fragments.wgsl, composed after this file.

// A path's empty pixels see the background through its mirrors.
@fragment
fn fs_background() -> @location(0) vec4f {
    return vec4f(path.attenuation * frame.background, 1.0);
}

// Stencil-only draws write no colour.
@fragment
fn fs_none() -> @location(0) vec4f {
    return vec4f(0.0);
}

// A mirror's stencil mark without clip distances: not behind the path's last mirror.
@fragment
fn fs_mark_discard(in: VertexOut) -> @location(0) vec4f {
    if (in.plane_distance < 0.0) {
        discard;
    }
    return vec4f(0.0);
}

// A screen-covering triangle infinitely far (depth 0, reversed Z), for depth clears and
// stencil edits.
@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4f {
    let uv = vec2f(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4f(uv * 2.0 - 1.0, 0.0, 1.0);
}
