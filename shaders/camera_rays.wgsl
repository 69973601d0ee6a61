// The camera on the GPU for the methods that follow rays from it (ray_query.wgsl,
// screen_space_reflections.wgsl), driven by crates/raster/src/gpu/camera_rays.rs: its raster
// transform, and its primary ray through any position of the render target — the CPU's
// crates/scene/src/camera.rs, `RayGenerator::dir`, in f32:
// d = normalize(forward + (ndc_x − shift_x)·right + ndc_y·up), right and up scaled by the
// half field of view. Also the full-screen triangle their per-pixel passes draw.

struct CameraRays {
    clip_from_world: mat4x4f,
    eye: vec3f,
    shift_x: f32,
    forward: vec3f,
    // The projection's near distance (reversed depth is near / w).
    near: f32,
    right: vec3f,
    _pad0: f32,
    up: vec3f,
    _pad1: f32,
    // The render target's size in pixels.
    size: vec2f,
    _pad2: vec2f,
}

// The unit direction of the camera's ray through render-target position `pixel` (x right,
// y down, pixel centres at +½).
fn camera_ray(c: CameraRays, pixel: vec2f) -> vec3f {
    let ndc = vec2f(2.0 * pixel.x / c.size.x - 1.0, 1.0 - 2.0 * pixel.y / c.size.y);
    let v = c.forward + c.right * (ndc.x - c.shift_x) + c.up * ndc.y;
    return v * (1.0 / sqrt(dot(v, v)));
}

// A world point in render-target pixels (x right, y down) and its reversed depth near / w.
fn camera_to_screen(c: CameraRays, x: vec3f) -> vec3f {
    let p = c.clip_from_world * vec4f(x, 1.0);
    let ndc = p.xyz / p.w;
    return vec3f((ndc.x + 1.0) * 0.5 * c.size.x, (1.0 - ndc.y) * 0.5 * c.size.y, ndc.z);
}

struct FullscreenOut {
    @builtin(position) clip: vec4f,
}

// One triangle covering the target.
@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> FullscreenOut {
    let uv = vec2f(f32((i << 1u) & 2u), f32(i & 2u));
    var out: FullscreenOut;
    out.clip = vec4f(uv * vec2f(2.0, -2.0) + vec2f(-1.0, 1.0), 0.0, 1.0);
    return out;
}
