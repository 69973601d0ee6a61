// Entry points of crates/raster/src/methods/recursive_texture.rs: one scene pass of the seed paper's
// Algorithm 1, drawn from a (possibly reflected) camera into a screen-space texture, keeping
// what lies in front of the pass's mirror. Prepended with shading.wgsl and
// mirror_plane_vertex.wgsl; followed by pass_view.wgsl, mirror_plane_fragments.wgsl and
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
    // The pass's camera without the crop (world to the whole screen's clip space) and the
    // screen's size: where the uneven-mirror tricks project their points.
    screen_from_world: mat4x4f,
    screen_size: vec2f,
    // crates/raster/src/uneven.rs: 0 flat, 1 distort, 2 distort-distance, 3 proxy, 4 march,
    // 5 normals; the march's samples; the distortion strength; the proxy plane's distance;
    // the march's reach.
    bump_mode: u32,
    march_steps: u32,
    bump_strength: f32,
    proxy_distance: f32,
    march_distance: f32,
    // 1 in the main pass of an eye sharing the head's textures (--stereo-mirrors shared):
    // lookups project the fragment's world position with lookup_from_world (the head's
    // camera); the march compares distances from lookup_eye. Elsewhere lookup_from_world is
    // screen_from_world and lookup_eye is eye.
    projected_lookup: u32,
    lookup_from_world: mat4x4f,
    lookup_eye: vec3f,
    _pad1: f32,
}

struct MirrorDraw {
    // The applied texture covers screen region origin .. origin + size.
    origin: vec2f,
    size: vec2f,
    texels_per_pixel: vec2f,
    // 1 when texel (x, y) is exactly screen pixel origin + (x, y): no resampling.
    exact: u32,
    has_texture: u32,
    // With projected = 1 (feedback): the camera the texture was rendered from; a fragment
    // is looked up where that camera saw its world position.
    lookup_from_world: mat4x4f,
    projected: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(1) @binding(0) var<uniform> pass_: Pass;
@group(2) @binding(0) var<uniform> mirror: MirrorDraw;
@group(2) @binding(1) var mirror_texture: texture_2d<f32>;

// The pass's view and diffuse shading: pass_view.wgsl.

// Alpha: the distance from the pass's eye (a texture's distances, which --bump march reads).
fn eye_distance(in: VertexOut) -> f32 {
    return length(in.world - pass_.eye);
}

fn object_colour(in: VertexOut) -> vec4f {
    let s = surfaces[in.surface];
    return vec4f(shade_diffuse(in, surface_albedo(s, in.uv), surface_emission(s, in.uv)), eye_distance(in));
}

fn load_clamped(t: vec2i) -> vec3f {
    let size = vec2i(textureDimensions(mirror_texture));
    return textureLoad(mirror_texture, clamp(t, vec2i(0), size - 1), 0).rgb;
}

// The applied texture's texel coordinates of a screen position.
fn texture_position(screen: vec2f) -> vec2f {
    return (screen - mirror.origin) * mirror.texels_per_pixel;
}

// Bilinear radiance of the applied texture at screen position `screen`, clamped to its edge
// (a resampled texture, and the uneven-mirror tricks' lookups, fall between texels).
fn mirror_sample(screen: vec2f) -> vec3f {
    let t = texture_position(screen) - 0.5;
    let i = vec2i(floor(t));
    let f = t - floor(t);
    let a = mix(load_clamped(i), load_clamped(i + vec2i(1, 0)), f.x);
    let b = mix(load_clamped(i + vec2i(0, 1)), load_clamped(i + vec2i(1, 1)), f.x);
    return mix(a, b, f.y);
}

// The projective lookup: the radiance the applied texture holds for this screen position
// (texel for pixel where no resampling is needed).
fn mirror_lookup(frag: vec2f, world: vec3f) -> vec3f {
    if (mirror.projected == 1u) {
        let c = mirror.lookup_from_world * vec4f(world, 1.0);
        let ndc = c.xy / c.w;
        return mirror_sample(vec2f(ndc.x + 1.0, 1.0 - ndc.y) * 0.5 * pass_.screen_size);
    }
    if (pass_.projected_lookup == 1u) {
        return mirror_sample(to_screen(world));
    }
    let screen = pass_.origin + frag * pass_.pixels_per_texel;
    if (mirror.exact == 1u) {
        return load_clamped(vec2i(floor(texture_position(screen))));
    }
    return mirror_sample(screen);
}

// The screen position of world point p in the applied textures' screen space (the pass's
// camera, or the head's for an eye sharing its textures).
fn to_screen(p: vec3f) -> vec2f {
    let c = pass_.lookup_from_world * vec4f(p, 1.0);
    let ndc = c.xy / c.w;
    return vec2f(ndc.x + 1.0, 1.0 - ndc.y) * 0.5 * pass_.screen_size;
}

// Whether a screen position lies on the applied texture.
fn on_texture(screen: vec2f) -> bool {
    let local = screen - mirror.origin;
    return all(local >= vec2f(0.0)) && all(local < mirror.size);
}

// The distance the applied texture stores at a screen position (nearest texel).
fn stored_distance(screen: vec2f) -> f32 {
    let size = vec2i(textureDimensions(mirror_texture));
    let t = clamp(vec2i(floor(texture_position(screen))), vec2i(0), size - 1);
    return textureLoad(mirror_texture, t, 0).a;
}

// --bump march: the reflected ray r from x, mirrored into the texture's world (x + t·r',
// r' = r reflected in the mirror's plane, seen by this pass's camera exactly where the
// mirror camera sees x + t·r), sampled at t = T·(i/N)² until its distance from the eye
// passes the distance stored under it, then bisected 6 times. It stops at the texture's
// edge: what the mirror camera never rendered cannot be found.
fn march(x: vec3f, r: vec3f, n: vec3f, fallback: vec2f) -> vec2f {
    let rv = r - 2.0 * dot(r, n) * n;
    var miss = 0.0;
    var last = fallback;
    let steps = pass_.march_steps;
    for (var i = 1u; i <= steps; i++) {
        let f = f32(i) / f32(steps);
        let t = pass_.march_distance * f * f;
        let p = x + t * rv;
        let screen = to_screen(p);
        if (!on_texture(screen)) {
            return last;
        }
        if (length(p - pass_.lookup_eye) >= stored_distance(screen)) {
            var lo = miss;
            var hi = t;
            for (var k = 0; k < 6; k++) {
                let mid = 0.5 * (lo + hi);
                let q = x + mid * rv;
                if (length(q - pass_.lookup_eye) >= stored_distance(to_screen(q))) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            return to_screen(x + hi * rv);
        }
        miss = t;
        last = screen;
    }
    return last;
}

// A front hit on an uneven mirror (docs/shading.md, "Uneven mirrors"), read with the pass's
// trick (crates/raster/src/uneven.rs): black where the contract absorbs the reflection.
fn uneven_mirror_colour(in: VertexOut, s: Surface, b: MirrorBump) -> vec4f {
    let n_s = mirror_shading_normal(b, in.world);
    let d = normalize(in.world - pass_.eye);
    let alpha = eye_distance(in);
    if (pass_.bump_mode == 5u) {
        return vec4f(n_s * 0.5 + 0.5, alpha);
    }
    let r = d - 2.0 * dot(d, n_s) * n_s;
    if (dot(d, n_s) >= 0.0 || dot(r, b.normal) <= 0.0) {
        return vec4f(vec3f(0.0), alpha);
    }
    if (mirror.has_texture == 0u) {
        return vec4f(frame.terminal, alpha);
    }
    let frag = in.clip.xy;
    var screen = pass_.origin + frag * pass_.pixels_per_texel;
    if (pass_.projected_lookup == 1u) {
        screen = to_screen(in.world);
    }
    let tangent = vec2f(dot(n_s, b.right), -dot(n_s, b.up));
    switch pass_.bump_mode {
        case 1u: {
            screen += pass_.bump_strength * tangent * pass_.screen_size.y;
        }
        case 2u: {
            screen += pass_.bump_strength * tangent * pass_.screen_size.y / alpha;
        }
        case 3u: {
            let p = in.world + r * (pass_.proxy_distance / max(dot(r, b.normal), 1e-3));
            screen = to_screen(p - 2.0 * dot(p - b.center, b.normal) * b.normal);
        }
        case 4u: {
            screen = march(in.world, r, b.normal, screen);
        }
        default: {}
    }
    return vec4f(s.reflectance * mirror_sample(screen), alpha);
}

fn mirror_colour(in: VertexOut) -> vec4f {
    let s = surfaces[in.surface];
    let front = dot(in.normal, pass_.eye - in.world) > 0.0;
    if (!front) {
        return vec4f(shade_diffuse(in, s.back_albedo, vec3f(0.0)), eye_distance(in));
    }
    let b = s.bump;
    if (b.flags != 0u && pass_.bump_mode != 0u) {
        return uneven_mirror_colour(in, s, b);
    }
    if (mirror.has_texture == 0u) {
        return vec4f(frame.terminal, eye_distance(in));
    }
    return vec4f(s.reflectance * mirror_lookup(in.clip.xy, in.world), eye_distance(in));
}

// Entry points fs_object, fs_mirror and their *_discard variants:
// shaders/mirror_plane_fragments.wgsl, composed after this file.
