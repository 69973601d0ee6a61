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
}

// A point light, or a light's image through a chain of mirrors (docs/shading.md, "Shadows
// and mirrored lights"): an image lights a point only inside its beam, the planes
// light_planes[first_plane ..][.. plane_count] (the first strict, the others ≥ 0). Real
// lights have no planes.
struct Light {
    position: vec3f,
    first_plane: u32,
    intensity: vec3f,
    plane_count: u32,
}

struct Frame {
    ambient: vec3f,
    light_count: u32,
    background: vec3f,
    _pad0: u32,
    terminal: vec3f,
    _pad1: u32,
}

// One scene vertex (VERTEX_LAYOUT in crates/raster/src/shading.rs): position, the
// triangle's face normal and its surface id.
struct VertexIn {
    @location(0) position: vec3f,
    @location(1) normal: vec3f,
    @location(2) surface: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> surfaces: array<Surface>;
@group(0) @binding(2) var<storage, read> lights: array<Light>;
@group(0) @binding(3) var<storage, read> light_planes: array<vec4f>;

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
        if (cos_theta > 0.0) {
            irradiance += lights[i].intensity * (cos_theta / r2);
        }
    }
    let emitted = select(vec3f(0.0), emission, front);
    return emitted + albedo * (irradiance * FRAC_1_PI + frame.ambient);
}
