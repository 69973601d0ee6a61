// The shading contract (docs/shading.md) in WGSL, the GPU twin of
// crates/scene/src/shading.rs; crates/raster/src/shading.rs prepends it to every pipeline
// and its tests hold the two to the same numbers.
//
// L = E·[front] + ρ/π · Σ I·max(0, n·l)/r² + ρ·A, n = face normal turned to the viewer.

struct Surface {
    albedo: vec3f,
    kind: u32,           // 0 = diffuse, 1 = mirror
    emission: vec3f,
    mirror: u32,
    reflectance: vec3f,
    _pad0: u32,
    back_albedo: vec3f,
    _pad1: u32,
    // A mirror's frame and bump (zero for a diffuse surface).
    bump: MirrorBump,
    // A diffuse surface's textures (docs/shading.md, "Textures"); `present` 0: none.
    albedo_map: TextureMap,
    emission_map: TextureMap,
}

// A texture as a surface reads it (the CPU twin is crates/scene/src/texture.rs): the 2×3
// transform of its coordinates as two rows, its wrap modes (u in bits 0–3, v in 4–7: 0
// repeat, 1 clamp to edge, 2 mirrored repeat) and its rectangle in the colour atlas.
struct TextureMap {
    row_u: vec3f,
    present: u32,
    row_v: vec3f,
    wrap: u32,
    origin: vec2u,
    size: vec2u,
}

// A point light, or a light's image through a chain of mirrors (docs/shading.md, "Shadows
// and mirrored lights"): an image lights a point only inside its beam, the planes
// light_planes[first_plane ..][.. plane_count] (the first strict, the others ≥ 0). Real
// lights have no planes.
//
// With shadow maps (crates/raster/src/shadow_maps.rs) a light also names its first layer
// (six cube faces for a real light, one layer through its last mirror for an image), the
// image's layer transform, its texel size, and the light the chain's previous leg leads to.
struct Light {
    position: vec3f,
    first_plane: u32,
    intensity: vec3f,
    plane_count: u32,
    shadow_from_world: mat4x4f,
    shadow_layer: u32,
    parent: u32,
    shadow_texel: f32,
    // Light images: the chain's last mirror (a leg from it skips it); unused for real lights.
    mirror: u32,
}

struct Frame {
    ambient: vec3f,
    light_count: u32,
    background: vec3f,
    shadow_bias: f32,
    terminal: vec3f,
    shadows: u32,
}

// A mirror's frame and its bump (docs/shading.md, "Uneven mirrors"; the CPU twin is
// crates/scene/src/bump.rs): flags bit 0 a ripple, bit 1 a normal map; map_offset is the
// map's first row in the atlas.
struct MirrorBump {
    center: vec3f,
    flags: u32,
    right: vec3f,
    width: f32,
    up: vec3f,
    height: f32,
    normal: vec3f,
    // The ripple: largest tilt (radians), (cos β, sin β), 2π/λ, phase (radians).
    amplitude: f32,
    ripple_dir: vec2f,
    wavenumber: f32,
    phase: f32,
    map_offset: u32,
    map_width: u32,
    map_height: u32,
    strength: f32,
    tiling: vec2f,
    _pad: vec2f,
}

// One scene vertex (VERTEX_LAYOUT in crates/raster/src/shading.rs): position, the
// triangle's face normal, its surface id and its texture coordinates (location 5; every
// method passes them on to its fragments at location 8, interpolated perspective-correct,
// which is the tracer's barycentric interpolation at the sample's point).
struct VertexIn {
    @location(0) position: vec3f,
    @location(1) normal: vec3f,
    @location(2) surface: u32,
    @location(5) uv: vec2f,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> surfaces: array<Surface>;
@group(0) @binding(2) var<storage, read> lights: array<Light>;
@group(0) @binding(3) var<storage, read> light_planes: array<vec4f>;
// Distance from each layer's light to the nearest surface, per texel.
@group(0) @binding(4) var shadow_maps: texture_2d_array<f32>;
// The normal maps' texels, 8-bit RGB packed in a u32 each: one atlas, every map's rows from
// its map_offset down, row 0 at the mirror's top (a texture: storage buffers are scarcer).
@group(0) @binding(5) var normal_texels: texture_2d<u32>;
// The colour textures' texels, sRGB RGBA8 packed in a u32 each, every texture at its
// TextureMap's origin in one atlas (read texel by texel: the contract's bilinear rule is
// evaluated here, not by a sampler, so both renderers weigh the same texels alike).
@group(0) @binding(6) var colour_texels: texture_2d<u32>;

const FRAC_1_PI: f32 = 0.31830988618379067;
const MIN_LIGHT_DISTANCE_SQUARED: f32 = 1e-8;

// Whether a light (always) or a light image (inside its beam) reaches point p.
fn in_beam(light: Light, p: vec3f) -> bool {
    if (light.plane_count == 0u) {
        return true;
    }
    let x = vec4f(p, 1.0);
    if (dot(light_planes[light.first_plane], x) <= 0.0) {
        return false;
    }
    for (var k = 1u; k < light.plane_count; k++) {
        if (dot(light_planes[light.first_plane + k], x) < 0.0) {
            return false;
        }
    }
    return true;
}

// Shadows (docs/shading.md): `unshadowed(i, p, cos_p)` — whether light i's every straight
// leg from p is clear — is defined by the part that follows this one: shadow_map_legs.wgsl
// (every raster method: a shadow-map lookup per leg) or ray_query.wgsl (a ray query per leg).

fn diffuse_radiance(p: vec3f, face_normal: vec3f, to_viewer: vec3f, albedo: vec3f, emission: vec3f) -> vec3f {
    let front = dot(face_normal, to_viewer) >= 0.0;
    let n = select(-face_normal, face_normal, front);
    var irradiance = vec3f(0.0);
    for (var i = 0u; i < frame.light_count; i++) {
        if (!in_beam(lights[i], p)) {
            continue;
        }
        let to_light = lights[i].position - p;
        let r2 = dot(to_light, to_light);
        if (r2 < MIN_LIGHT_DISTANCE_SQUARED) {
            continue;
        }
        let cos_theta = dot(n, to_light) / sqrt(r2);
        if (cos_theta > 0.0 && unshadowed(i, p, cos_theta)) {
            irradiance += lights[i].intensity * (cos_theta / r2);
        }
    }
    let emitted = select(vec3f(0.0), emission, front);
    return emitted + albedo * (irradiance * FRAC_1_PI + frame.ambient);
}

// The sRGB transfer function's inverse for an 8-bit value (texture.rs's srgb_to_linear).
fn srgb_to_linear(value: u32) -> f32 {
    let c = f32(value) / 255.0;
    if (c <= 0.04045) {
        return c / 12.92;
    }
    return pow((c + 0.055) / 1.055, 2.4);
}

// Texel index i of an axis of n texels brought back by wrap mode `mode` (texture.rs's
// Wrap::index).
fn wrap_index(mode: u32, i: i32, n: i32) -> i32 {
    if (mode == 1u) {
        return clamp(i, 0, n - 1);
    }
    if (mode == 2u) {
        let m = ((i % (2 * n)) + 2 * n) % (2 * n);
        return select(m, 2 * n - 1 - m, m >= n);
    }
    return ((i % n) + n) % n;
}

fn colour_texel(m: TextureMap, i: i32, j: i32) -> vec3f {
    let t = textureLoad(colour_texels, vec2i(m.origin) + vec2i(i, j), 0).r;
    return vec3f(srgb_to_linear(t & 255u), srgb_to_linear((t >> 8u) & 255u), srgb_to_linear((t >> 16u) & 255u));
}

// The contract's texture lookup (texture.rs's TextureMap::sample, the same f32 steps).
fn texture_sample(m: TextureMap, uv: vec2f) -> vec3f {
    let t = vec2f(
        m.row_u.x * uv.x + m.row_u.y * uv.y + m.row_u.z,
        m.row_v.x * uv.x + m.row_v.y * uv.y + m.row_v.z,
    );
    let size = vec2i(m.size);
    let xy = clamp(t * vec2f(m.size) - 0.5, vec2f(-16777216.0), vec2f(16777216.0));
    let base = floor(xy);
    let f = xy - base;
    let ij = vec2i(base);
    let wu = m.wrap & 15u;
    let wv = (m.wrap >> 4u) & 15u;
    let i0 = wrap_index(wu, ij.x, size.x);
    let i1 = wrap_index(wu, ij.x + 1, size.x);
    let j0 = wrap_index(wv, ij.y, size.y);
    let j1 = wrap_index(wv, ij.y + 1, size.y);
    let a = colour_texel(m, i0, j0);
    let b = colour_texel(m, i1, j0);
    let c = colour_texel(m, i0, j1);
    let d = colour_texel(m, i1, j1);
    let top = a + (b - a) * f.x;
    let bottom = c + (d - c) * f.x;
    return top + (bottom - top) * f.y;
}

// A diffuse surface's albedo and emission at texture coordinates uv: factor × texture.
// TEXTURED is set by the composer (crates/raster/src/gpu/wgsl.rs): false for a scene without
// textures, where the lookups are dead code.
fn surface_albedo(s: Surface, uv: vec2f) -> vec3f {
    if (!TEXTURED || s.albedo_map.present == 0u) {
        return s.albedo;
    }
    return s.albedo * texture_sample(s.albedo_map, uv);
}

fn surface_emission(s: Surface, uv: vec2f) -> vec3f {
    if (!TEXTURED || s.emission_map.present == 0u) {
        return s.emission;
    }
    return s.emission * texture_sample(s.emission_map, uv);
}

// Normal map texel (i, j) of mirror bump b, repeated, decoded to [−1, 1]³.
fn normal_texel(b: MirrorBump, i: i32, j: i32) -> vec3f {
    let w = i32(b.map_width);
    let h = i32(b.map_height);
    let ii = ((i % w) + w) % w;
    let jj = ((j % h) + h) % h;
    let t = textureLoad(normal_texels, vec2i(ii, i32(b.map_offset) + jj), 0).x;
    let rgb = vec3f(f32(t & 255u), f32((t >> 8u) & 255u), f32((t >> 16u) & 255u));
    return rgb * (2.0 / 255.0) - 1.0;
}

// The perturbed normal in the mirror's tangent frame (right, up, normal) at mirror-local
// (u, v): a ripple tilts by θ = A·sin(k(u cos β + v sin β) + φ) towards (cos β, sin β); a
// normal map is read bilinearly between texel centres, its tangential part scaled by the
// strength; with both, their slopes add.
fn mirror_tangent_normal(b: MirrorBump, u: f32, v: f32) -> vec3f {
    var r = vec3f(0.0, 0.0, 1.0);
    let has_ripple = (b.flags & 1u) != 0u;
    if (has_ripple) {
        let theta = b.amplitude * sin(b.wavenumber * (u * b.ripple_dir.x + v * b.ripple_dir.y) + b.phase);
        r = vec3f(sin(theta) * b.ripple_dir, cos(theta));
    }
    if ((b.flags & 2u) == 0u) {
        return r;
    }
    let x = (u / b.width + 0.5) * b.tiling.x;
    let y = (0.5 - v / b.height) * b.tiling.y;
    let p = vec2f(x * f32(b.map_width) - 0.5, y * f32(b.map_height) - 0.5);
    let i = floor(p);
    let f = p - i;
    let ii = i32(i.x);
    let jj = i32(i.y);
    let top = mix(normal_texel(b, ii, jj), normal_texel(b, ii + 1, jj), f.x);
    let bottom = mix(normal_texel(b, ii, jj + 1), normal_texel(b, ii + 1, jj + 1), f.x);
    let s = mix(top, bottom, f.y);
    let m = vec3f(b.strength * s.xy, s.z);
    if (!has_ripple) {
        return normalize(m);
    }
    return normalize(vec3f(r.xy / r.z + m.xy / m.z, 1.0));
}

// A mirror's shading normal at point p on it (its plane's normal where it is flat).
fn mirror_shading_normal(b: MirrorBump, p: vec3f) -> vec3f {
    if (b.flags == 0u) {
        return b.normal;
    }
    let d = p - b.center;
    let t = mirror_tangent_normal(b, dot(d, b.right), dot(d, b.up));
    return normalize(t.x * b.right + t.y * b.up + t.z * b.normal);
}

// The reflection of direction d at point x on a mirror's front (docs/shading.md): about its
// plane's normal, or about its bumped normal — and then nothing where the contract's rule
// absorbs it (d · n_s ≥ 0, or r · n_f ≤ 0). (r, 1), or (0, 0, 0, 0) where absorbed.
fn mirror_reflection(b: MirrorBump, d: vec3f, x: vec3f) -> vec4f {
    let n = b.normal;
    if (b.flags == 0u) {
        return vec4f(normalize(d - 2.0 * dot(d, n) * n), 1.0);
    }
    let ns = mirror_shading_normal(b, x);
    if (dot(d, ns) >= 0.0) {
        return vec4f(0.0);
    }
    let r = normalize(d - 2.0 * dot(d, ns) * ns);
    if (dot(r, n) <= 0.0) {
        return vec4f(0.0);
    }
    return vec4f(r, 1.0);
}
