// The plain vertex stage of a scene seen through one camera, nothing clipped at a mirror
// (crates/raster/src/methods/ray_query.rs, screen_space_reflections.rs, symmetry.rs for its
// unmoved mirrors): follows shading.wgsl (`VertexIn`); a method names the struct as its own
// (`alias VertexOut = SceneVertexOut;`) and calls `scene_vertex_through` with its camera.

struct SceneVertexOut {
    // Invariant: a pass that meets the depth another pass wrote (a depth pre-pass, the
    // mirrors drawn beside the copies) computes the same positions.
    @builtin(position) @invariant clip: vec4f,
    @location(0) world: vec3f,
    @location(1) @interpolate(flat) normal: vec3f,
    @location(2) @interpolate(flat) surface: u32,
    @location(8) uv: vec2f,
}

fn scene_vertex_through(v: VertexIn, clip_from_world: mat4x4f) -> SceneVertexOut {
    var out: SceneVertexOut;
    out.clip = clip_from_world * vec4f(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.surface = v.surface;
    out.uv = v.uv;
    return out;
}
