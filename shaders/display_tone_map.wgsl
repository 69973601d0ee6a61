// Entry point of crates/raster/src/display_tone_map.rs: the linear image tone-mapped to the
// 8-bit sRGB bytes `RgbImage::to_srgb8` writes, on the GPU (what `mirrorbox view` paints).
//
// The CPU encodes byte = srgb::encode8(c * exposure). That function is monotone in its
// argument, so the byte of v is the number of thresholds t_1 <= … <= t_255 with v >= t_k,
// where t_k is the smallest f32 encode8 maps to k or above (computed on the CPU with
// encode8 itself). Here: the same single f32 multiply, a guess of the byte, then the table
// walked from the guess to the byte whose thresholds enclose the value — the same byte for
// every input, NaN (0), negatives (0) and values above 1 (255) included, however the GPU's
// pow rounds.

struct ToneMap {
    exposure: f32,
    width: u32,
    height: u32,
    // Words (pixels) per row of the output buffer: rows are padded to 256 bytes for the
    // copy into the pane's texture.
    row_words: u32,
}

@group(0) @binding(0) var<uniform> tone_map: ToneMap;
@group(0) @binding(1) var source: texture_2d<f32>;
// thresholds[k] = t_k for k in 1…255; thresholds[0] is unused.
@group(0) @binding(2) var<storage, read> thresholds: array<f32, 256>;
// One RGBA8 pixel per word: red in the low byte.
@group(0) @binding(3) var<storage, read_write> pixels: array<u32>;

fn byte_of(v: f32) -> u32 {
    // Below the first threshold, or NaN (no comparison holds): 0; from the last: 255.
    if !(v >= thresholds[1]) {
        return 0u;
    }
    if v >= thresholds[255] {
        return 255u;
    }
    // A first guess from the transfer function (any guess would do: the walks below end at
    // the exact byte, whatever the precision of this pow), then the table: a step or none
    // each way, two lookups where a binary search needs eight.
    let x = clamp(v, 0.0, 1.0);
    let e = select(1.055 * pow(x, 1.0 / 2.4) - 0.055, 12.92 * x, x <= 0.0031308);
    var k = clamp(u32(e * 255.0 + 0.5), 1u, 254u);
    while v < thresholds[k] {
        k -= 1u;
    }
    while v >= thresholds[k + 1u] {
        k += 1u;
    }
    return k;
}

@compute @workgroup_size(8, 8)
fn cs_main(@builtin(global_invocation_id) id: vec3u) {
    if id.x >= tone_map.width || id.y >= tone_map.height {
        return;
    }
    let c = textureLoad(source, id.xy, 0).rgb * tone_map.exposure;
    pixels[id.y * tone_map.row_words + id.x] =
        byte_of(c.r) | (byte_of(c.g) << 8u) | (byte_of(c.b) << 16u) | (255u << 24u);
}
