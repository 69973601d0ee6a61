// Entry points of crates/raster/src/gpu/resolve.rs: box-filters the s×s supersampled image down
// to the output, summing the samples row by row like the tracer (docs/shading.md).

struct Resolve {
    factor: u32,
}

@group(0) @binding(0) var<uniform> resolve: Resolve;
@group(0) @binding(1) var source: texture_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4f {
    // One triangle covering the screen.
    let uv = vec2f(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4f(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) frag: vec4f) -> @location(0) vec4f {
    let s = resolve.factor;
    let base = vec2u(floor(frag.xy)) * s;
    var sum = vec3f(0.0);
    for (var j = 0u; j < s; j++) {
        for (var i = 0u; i < s; i++) {
            sum += textureLoad(source, base + vec2u(i, j), 0).rgb;
        }
    }
    return vec4f(sum / f32(s * s), 1.0);
}
