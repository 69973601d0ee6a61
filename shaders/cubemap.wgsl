// Entry points of crates/raster/src/methods/cubemap.rs: one scene pass — a cube face seen
// from a cube map's centre, or the camera's view — in which a mirror shows a cube map looked
// up by the reflected view direction, as if everything it reflects were infinitely far away
// (the method's parallax error). Prepended with shading.wgsl and mirror_plane_vertex.wgsl;
// followed by pass_view.wgsl and mirror_plane_fragments.wgsl (and
// mirror_plane_clip_distances.wgsl where the adapter has clip distances): a per-mirror cube
// keeps what lies in front of its mirror.

struct Pass {
    clip_from_world: mat4x4f,
    // The pass's eye: the camera, or the cube's centre.
    eye: vec3f,
    _pad0: f32,
    // Front positive; (0, 0, 0, 1) keeps everything.
    plane: vec4f,
}

struct CubeDraw {
    // The six faces' cameras (+X, -X, +Y, -Y, +Z, -Z), world to clip space, all at the cube's
    // centre: a direction r is looked up where face k sees the point centre + r.
    faces: array<mat4x4f, 6>,
    centre: vec3f,
    // 0: no cube yet (the first frame's cube passes): the depth cap, `terminal`.
    has_cube: u32,
    face_size: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

@group(1) @binding(0) var<uniform> pass_: Pass;
@group(2) @binding(0) var<uniform> cube: CubeDraw;
@group(2) @binding(1) var face0: texture_2d<f32>;
@group(2) @binding(2) var face1: texture_2d<f32>;
@group(2) @binding(3) var face2: texture_2d<f32>;
@group(2) @binding(4) var face3: texture_2d<f32>;
@group(2) @binding(5) var face4: texture_2d<f32>;
@group(2) @binding(6) var face5: texture_2d<f32>;

// The pass's view and diffuse shading: pass_view.wgsl.

fn object_colour(in: VertexOut) -> vec4f {
    let s = surfaces[in.surface];
    return vec4f(shade_diffuse(in, surface_albedo(s, in.uv), surface_emission(s, in.uv)), 1.0);
}

fn face_texel(k: u32, t: vec2i) -> vec3f {
    let n = i32(cube.face_size);
    let c = clamp(t, vec2i(0), vec2i(n - 1));
    switch k {
        case 0u: { return textureLoad(face0, c, 0).rgb; }
        case 1u: { return textureLoad(face1, c, 0).rgb; }
        case 2u: { return textureLoad(face2, c, 0).rgb; }
        case 3u: { return textureLoad(face3, c, 0).rgb; }
        case 4u: { return textureLoad(face4, c, 0).rgb; }
        default: { return textureLoad(face5, c, 0).rgb; }
    }
}

// The cube's radiance in direction r: the face r leaves through, bilinear within the face
// (clamped at its edge).
fn cube_lookup(r: vec3f) -> vec3f {
    let a = abs(r);
    var k = 0u;
    if (a.x >= a.y && a.x >= a.z) {
        k = select(1u, 0u, r.x > 0.0);
    } else if (a.y >= a.z) {
        k = select(3u, 2u, r.y > 0.0);
    } else {
        k = select(5u, 4u, r.z > 0.0);
    }
    let c = cube.faces[k] * vec4f(cube.centre + r, 1.0);
    let ndc = c.xy / c.w;
    let t = vec2f(ndc.x + 1.0, 1.0 - ndc.y) * 0.5 * cube.face_size - 0.5;
    let i = vec2i(floor(t));
    let f = t - floor(t);
    let top = mix(face_texel(k, i), face_texel(k, i + vec2i(1, 0)), f.x);
    let bottom = mix(face_texel(k, i + vec2i(0, 1)), face_texel(k, i + vec2i(1, 1)), f.x);
    return mix(top, bottom, f.y);
}

fn mirror_colour(in: VertexOut) -> vec4f {
    let s = surfaces[in.surface];
    let front = dot(in.normal, pass_.eye - in.world) > 0.0;
    if (!front) {
        return vec4f(shade_diffuse(in, s.back_albedo, vec3f(0.0)), 1.0);
    }
    if (cube.has_cube == 0u) {
        return vec4f(frame.terminal, 1.0);
    }
    let d = normalize(in.world - pass_.eye);
    let r = d - 2.0 * dot(d, in.normal) * in.normal;
    return vec4f(s.reflectance * cube_lookup(r), 1.0);
}

// Entry points fs_object, fs_mirror and their *_discard variants:
// shaders/mirror_plane_fragments.wgsl, composed after this file.
