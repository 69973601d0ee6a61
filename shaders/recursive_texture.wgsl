// Entry points of crates/raster/src/recursive_texture.rs: one scene pass of the seed paper's
// Algorithm 1, drawn from a (possibly reflected) camera into a screen-space texture, keeping
// what lies in front of the pass's mirror. Prepended with shading.wgsl; followed by
// mirror_plane_clip_distances.wgsl where the adapter has clip distances (vs_clip_distances with
// fs_object / fs_mirror), else the plane is tested per fragment (vs_main with
// fs_object_discard / fs_mirror_discard).

struct Pass {
    clip_from_world: mat4x4f,
    // Virtual eye in world space (where the mirror camera sits).
    eye: vec3f,
    _pad0: f32,
    // This pass's target covers the screen region starting at `origin` (render-resolution
    // pixels), `pixels_per_texel` screen pixels per target texel.
    origin: vec2f,
    pixels_per_texel: vec2f,
    // The pass's mirror plane in scene space, front positive ((0, 0, 0, 1) for the camera's
    // pass): the mirror's world is what lies in front of it.
    plane: vec4f,
}

struct MirrorDraw {
    // The applied texture covers screen region origin .. origin + size.
    origin: vec2f,
    size: vec2f,
    texels_per_pixel: vec2f,
    // 1 when texel (x, y) is exactly screen pixel origin + (x, y): no resampling.
    exact: u32,
    has_texture: u32,
}

@group(1) @binding(0) var<uniform> pass_: Pass;
@group(2) @binding(0) var<uniform> mirror: MirrorDraw;
@group(2) @binding(1) var mirror_texture: texture_2d<f32>;

struct VertexOut {
    @builtin(position) @invariant clip: vec4f,
    @location(0) world: vec3f,
    @location(1) @interpolate(flat) normal: vec3f,
    @location(2) @interpolate(flat) surface: u32,
    // Signed distance to the pass's mirror plane (scene units).
    @location(3) plane_distance: f32,
}

fn scene_vertex(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = pass_.clip_from_world * vec4f(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.surface = v.surface;
    out.plane_distance = dot(pass_.plane, vec4f(v.position, 1.0));
    return out;
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    return scene_vertex(v);
}

fn shade_diffuse(in: VertexOut, albedo: vec3f, emission: vec3f) -> vec3f {
    return diffuse_radiance(in.world, in.normal, normalize(pass_.eye - in.world), albedo, emission);
}

fn object_colour(in: VertexOut) -> vec4f {
    let s = surfaces[in.surface];
    return vec4f(shade_diffuse(in, s.albedo, s.emission), 1.0);
}

fn load_clamped(t: vec2i) -> vec3f {
    let size = vec2i(textureDimensions(mirror_texture));
    return textureLoad(mirror_texture, clamp(t, vec2i(0), size - 1), 0).rgb;
}

// The projective lookup: the radiance the applied texture holds for this screen position.
fn mirror_lookup(frag: vec2f) -> vec3f {
    let screen = pass_.origin + frag * pass_.pixels_per_texel;
    let local = (screen - mirror.origin) * mirror.texels_per_pixel;
    if (mirror.exact == 1u) {
        return load_clamped(vec2i(floor(local)));
    }
    let t = local - 0.5;
    let i = vec2i(floor(t));
    let f = t - floor(t);
    let a = mix(load_clamped(i), load_clamped(i + vec2i(1, 0)), f.x);
    let b = mix(load_clamped(i + vec2i(0, 1)), load_clamped(i + vec2i(1, 1)), f.x);
    return mix(a, b, f.y);
}

fn mirror_colour(in: VertexOut) -> vec4f {
    let s = surfaces[in.surface];
    let front = dot(in.normal, pass_.eye - in.world) > 0.0;
    if (!front) {
        return vec4f(shade_diffuse(in, s.back_albedo, vec3f(0.0)), 1.0);
    }
    if (mirror.has_texture == 0u) {
        return vec4f(frame.terminal, 1.0);
    }
    return vec4f(s.reflectance * mirror_lookup(in.clip.xy), 1.0);
}

// Entry points fs_object, fs_mirror and their *_discard variants:
// shaders/mirror_plane_fragments.wgsl, composed after this file.
