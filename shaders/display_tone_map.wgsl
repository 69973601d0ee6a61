// Entry points of crates/raster/src/gpu/display_tone_map.rs: the linear image tone-mapped to the
// 8-bit sRGB bytes `RgbImage::to_srgb8` writes, drawn into a rectangle of an RGBA8 or BGRA8
// unorm target (what `mirrorbox view` paints as the method's pane, inside the window's own
// paint).
//
// The CPU encodes byte = srgb::encode8(c * exposure). That function is monotone in its
// argument, so the byte of v is the number of thresholds t_1 <= … <= t_255 with v >= t_k,
// where t_k is the smallest f32 encode8 maps to k or above (computed on the CPU with
// encode8 itself; `srgb::encode8_by_thresholds` is this file's search on the CPU, tested
// against encode8 for every f32 in [0, 1]). Here: the same single f32 multiply, then the
// byte found from its bits: a value with the sign bit set (negatives, -0) or a NaN pattern
// is 0, as encode8 has it, decided on the bit pattern because WGSL lets a compiler assume
// there are no NaNs; the rest are non-negative, where floats order as their bit patterns,
// so the thresholds are compared as integers — exact whatever the compiler does to float
// comparisons. A guess of the byte from the transfer function, then a walk through the
// table to the byte whose thresholds enclose the value, exact whatever the guess.
//
// The byte k leaves as (k + 1/4) / 255, which the target's unorm conversion stores as k
// whether it rounds to nearest (as Vulkan recommends) or truncates (as it allows).

struct ToneMap {
    // The rectangle's top-left corner in the target's pixels.
    origin: vec2f,
    // Image pixels per target pixel, per axis: (1, 1) shows the image 1:1 (the exact
    // bytes); above 1 the image is shrunk to fit, each target pixel the bilinear blend of
    // the linear image at its centre, then tone-mapped.
    step: vec2f,
    exposure: f32,
    pad: f32,
}

@group(0) @binding(0) var<uniform> tone_map: ToneMap;
@group(0) @binding(1) var source: texture_2d<f32>;
// The bit patterns of t_k for k in 1…255 (all positive and finite); entry 0 is unused.
@group(0) @binding(2) var<storage, read> thresholds: array<u32, 256>;

fn byte_of(v: f32) -> u32 {
    let b = bitcast<u32>(v);
    // Sign bit set (negatives, -0, negative NaNs) or a NaN: 0.
    if b >= 0x80000000u || b > 0x7f800000u {
        return 0u;
    }
    if b < thresholds[1] {
        return 0u;
    }
    if b >= thresholds[255] {
        return 255u;
    }
    // A first guess from the transfer function (any guess would do), then the table: a step
    // or none each way.
    let x = clamp(v, 0.0, 1.0);
    let e = select(1.055 * pow(x, 1.0 / 2.4) - 0.055, 12.92 * x, x <= 0.0031308);
    var k = clamp(u32(e * 255.0 + 0.5), 1u, 254u);
    while b < thresholds[k] {
        k -= 1u;
    }
    while b >= thresholds[k + 1u] {
        k += 1u;
    }
    return k;
}

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4f {
    // One triangle covering the viewport (the rectangle).
    let uv = vec2f(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4f(uv * 2.0 - 1.0, 0.0, 1.0);
}

fn texel(p: vec2i) -> vec3f {
    let last = vec2i(textureDimensions(source)) - 1;
    return textureLoad(source, clamp(p, vec2i(0), last), 0).rgb;
}

@fragment
fn fs_main(@builtin(position) frag: vec4f) -> @location(0) vec4f {
    let local = frag.xy - tone_map.origin;
    var c: vec3f;
    if all(tone_map.step == vec2f(1.0)) {
        c = texel(vec2i(floor(local)));
    } else {
        let p = local * tone_map.step - 0.5;
        let base = floor(p);
        let f = p - base;
        let i = vec2i(base);
        c = mix(
            mix(texel(i), texel(i + vec2i(1, 0)), f.x),
            mix(texel(i + vec2i(0, 1)), texel(i + vec2i(1, 1)), f.x),
            f.y,
        );
    }
    let v = c * tone_map.exposure;
    let bytes = vec3f(f32(byte_of(v.r)), f32(byte_of(v.g)), f32(byte_of(v.b)));
    return vec4f((bytes + 0.25) / 255.0, 1.0);
}
