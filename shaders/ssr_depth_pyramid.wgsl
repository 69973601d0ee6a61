// The depth pyramid of screen-space reflections (crates/raster/src/methods/
// screen_space_reflections.rs): level 0 is the scene pass's reversed depth (written by that
// pass, screen_space_reflections.wgsl's fs_base), each texel of a
// coarser level the largest — nearest — of the (up to 3×3, at odd sizes) texels it covers, so
// that a ray in front of a cell's value is in front of everything in it. Depths are kept as
// their f32 bits in R32Uint (renderable everywhere, wgpu's GL backend included, where R32Float
// is not); for depths ≥ 0 the bits order as the floats do. Stands alone.

@group(0) @binding(0) var finer: texture_2d<u32>;

struct FullscreenOut {
    @builtin(position) clip: vec4f,
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> FullscreenOut {
    let uv = vec2f(f32((i << 1u) & 2u), f32(i & 2u));
    var out: FullscreenOut;
    out.clip = vec4f(uv * vec2f(2.0, -2.0) + vec2f(-1.0, 1.0), 0.0, 1.0);
    return out;
}

// A coarser texel: the nearest of the finer level's texels it covers (a cell of an odd-sized
// level also takes the row or column the halving drops).
@fragment
fn fs_reduce(in: FullscreenOut) -> @location(0) vec4u {
    let dims = vec2i(textureDimensions(finer));
    let base = 2 * vec2i(floor(in.clip.xy));
    var nearest = 0u;
    for (var j = 0; j < 3; j++) {
        for (var i = 0; i < 3; i++) {
            let t = base + vec2i(i, j);
            // The third row/column only where it would otherwise be dropped.
            let extra_x = i == 2 && !(t.x == dims.x - 1 && dims.x % 2 == 1);
            let extra_y = j == 2 && !(t.y == dims.y - 1 && dims.y % 2 == 1);
            if (extra_x || extra_y || t.x >= dims.x || t.y >= dims.y) {
                continue;
            }
            nearest = max(nearest, textureLoad(finer, t, 0).r);
        }
    }
    return vec4u(nearest, 0u, 0u, 0u);
}
