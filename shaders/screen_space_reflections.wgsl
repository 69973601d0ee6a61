// Entry points of crates/raster/src/methods/screen_space_reflections.rs: screen-space
// reflections as engines ship them (Unreal, Unity, Godot; the march of McGuire & Mara, JCGT
// 2014, over a hierarchical depth buffer). Follows shading.wgsl and shadow_map_legs.wgsl.
//
// 1. vs_scene / fs_base: the scene drawn once; a diffuse surface (or a mirror's back) shaded
//    by the contract, a mirror's front marked: alpha holds its surface + 1 (0 elsewhere).
// 2. ssr_depth_pyramid.wgsl: the depth pyramid above that pass's depth, each texel the
//    nearest depth below.
// 3. vs_fullscreen / fs_reflect: every mirror pixel marches its reflected ray through the
//    pyramid; a hit on a non-mirror pixel shows that pixel's colour × the reflectance; a miss
//    (off screen, behind a surface thicker than --ssr-thickness, out of steps, or a mirror hit:
//    one bounce only) shows the fallback's pixel.

struct SsrParams {
    camera: CameraRays,
    // Most pyramid steps a ray takes (--ssr-steps).
    steps: u32,
    // How far behind the depth buffer's surface a ray may pass and still hit it (scene units).
    thickness: f32,
    // 1: misses show the fallback target's pixel; 0: the terminal radiance.
    fallback: u32,
    // Mip levels of the depth pyramid.
    levels: u32,
}

@group(1) @binding(0) var<uniform> ssr: SsrParams;

alias SceneOut = SceneVertexOut;

@vertex
fn vs_scene(v: VertexIn) -> SceneOut {
    return scene_vertex_through(v, ssr.camera.clip_from_world);
}

// The scene pass's two targets: the contract's radiance with the mirror mark in alpha, and the
// reversed depth's f32 bits — the depth pyramid's level 0 (ssr_depth_pyramid.wgsl says why
// bits: R32Uint renders on every backend, and depth textures cannot be read on GL).
struct BaseOut {
    @location(0) colour: vec4f,
    @location(1) depth: vec4u,
}

// The scene pass: the contract's radiance, and which mirror (if any) shows its front here.
@fragment
fn fs_base(in: SceneOut) -> BaseOut {
    let s = surfaces[in.surface];
    let to_eye = normalize(ssr.camera.eye - in.world);
    let front = dot(in.normal, to_eye) > 0.0;
    var out: BaseOut;
    out.depth = vec4u(bitcast<u32>(max(in.clip.z, 0.0)), 0u, 0u, 0u);
    if (s.kind == 1u && front) {
        out.colour = vec4f(s.reflectance * frame.terminal, f32(in.surface + 1u));
    } else if (s.kind == 1u) {
        out.colour = vec4f(diffuse_radiance(in.world, in.normal, to_eye, s.back_albedo, vec3f(0.0)), 0.0);
    } else {
        out.colour = vec4f(diffuse_radiance(in.world, in.normal, to_eye, surface_albedo(s, in.uv), surface_emission(s, in.uv)), 0.0);
    }
    return out;
}

@group(1) @binding(1) var base_colour: texture_2d<f32>;
@group(1) @binding(2) var fallback_colour: texture_2d<f32>;
// The pyramid's depths as f32 bits (ssr_depth_pyramid.wgsl).
@group(1) @binding(3) var depth_pyramid: texture_2d<u32>;

// The nearest depth (largest reversed depth) of pyramid cell `cell` at `level`. The level's
// size is level 0's halved `level` times: `textureDimensions(t, level)` with a level known
// only at run time returns wrong sizes on Mesa 25.0.7's lavapipe (the march then skipped
// cells it must not; docs/methods.md, `ssr`).
fn pyramid(cell: vec2i, level: u32) -> f32 {
    let dims = max(vec2i(textureDimensions(depth_pyramid, 0u)) >> vec2u(level), vec2i(1));
    let c = clamp(cell, vec2i(0), dims - 1);
    return bitcast<f32>(textureLoad(depth_pyramid, c, i32(level)).r);
}

// The pixel a reflected ray from x along r hits in the depth buffer, or (-1, -1) on a miss.
// Screen-space: P(s) = P0 + s·(P1 − P0) with the reversed depth near/w linear in s
// (perspective-correct), so the march tests it against the pyramid directly: a cell the
// ray's depth stays nearer than over its whole span is stepped over and the next one tried a
// level up; otherwise the level goes down, and at level 0 the ray hits the pixel if it is
// behind its surface by at most the thickness.
fn march(x: vec3f, r: vec3f) -> vec2i {
    // Keep the segment in front of the camera: at most `reach` long, ending before the near plane.
    let c = ssr.camera;
    let w0 = dot(x - c.eye, c.forward);
    let towards = dot(r, c.forward);
    var reach = 1.0e4;
    if (towards < 0.0) {
        reach = min(reach, (w0 - 2.0 * c.near) / -towards);
    }
    let p0 = camera_to_screen(c, x);
    let p1 = camera_to_screen(c, x + r * reach);
    let delta = p1 - p0;
    let length_px = length(delta.xy);
    if (length_px < 1e-3) {
        return vec2i(-1);
    }
    // Where the segment leaves the screen.
    var s_end = 1.0;
    for (var k = 0; k < 2; k++) {
        if (delta[k] > 0.0) {
            s_end = min(s_end, (c.size[k] - p0[k]) / delta[k]);
        } else if (delta[k] < 0.0) {
            s_end = min(s_end, -p0[k] / delta[k]);
        }
    }
    let step_s = 1.0 / length_px;
    // Start one pixel away from the mirror pixel itself.
    var s = step_s;
    var level = 0u;
    for (var i = 0u; i < ssr.steps; i++) {
        if (s >= s_end) {
            return vec2i(-1);
        }
        let p = p0 + delta * s;
        let cell_size = f32(1u << level);
        let cell = vec2i(floor(p.xy / cell_size));
        // s where the ray leaves this cell.
        var s_exit = s_end;
        for (var k = 0; k < 2; k++) {
            if (delta[k] > 0.0) {
                s_exit = min(s_exit, ((f32(cell[k]) + 1.0) * cell_size - p0[k]) / delta[k]);
            } else if (delta[k] < 0.0) {
                s_exit = min(s_exit, (f32(cell[k]) * cell_size - p0[k]) / delta[k]);
            }
        }
        let z_entry = p.z;
        let z_exit = p0.z + delta.z * s_exit;
        let nearest = pyramid(cell, level);
        if (min(z_entry, z_exit) > nearest) {
            // In front of everything in this cell: step over it, and try a coarser level.
            s = s_exit + 0.01 * step_s;
            level = min(level + 1u, ssr.levels - 1u);
            continue;
        }
        if (level > 0u) {
            level -= 1u;
            continue;
        }
        // Level 0: the ray reaches this pixel's surface depth. It hits if it crosses the
        // surface inside the pixel (in front of it on entry), or enters behind it by at most
        // the thickness (view depth w = near / z).
        let w_surface = c.near / nearest;
        let w_entry = c.near / z_entry;
        if (z_entry >= nearest || w_entry - w_surface <= ssr.thickness) {
            return cell;
        }
        s = s_exit + 0.01 * step_s;
    }
    return vec2i(-1);
}

// The final image: non-mirror pixels as drawn; a mirror's front shows what its reflected ray
// hits on screen, or the fallback.
@fragment
fn fs_reflect(in: FullscreenOut) -> @location(0) vec4f {
    let pixel = vec2i(floor(in.clip.xy));
    let base = textureLoad(base_colour, pixel, 0);
    if (base.a < 0.5) {
        return vec4f(base.rgb, 1.0);
    }
    let surface = u32(base.a + 0.5) - 1u;
    let s = surfaces[surface];
    var missed = base.rgb;
    if (ssr.fallback == 1u) {
        missed = textureLoad(fallback_colour, pixel, 0).rgb;
    }
    // The camera's ray through this pixel's centre, met at the mirror's plane.
    let d = camera_ray(ssr.camera, in.clip.xy);
    let eye = ssr.camera.eye;
    let n = s.bump.normal;
    let x = eye + d * (dot(n, s.bump.center - eye) / dot(n, d));
    // The contract's reflection, the uneven-mirror rule included (absorbed: nothing).
    let r = mirror_reflection(s.bump, d, x);
    if (r.w == 0.0) {
        return vec4f(0.0, 0.0, 0.0, 1.0);
    }
    let hit = march(x, r.xyz);
    if (hit.x < 0) {
        return vec4f(missed, 1.0);
    }
    let seen = textureLoad(base_colour, hit, 0);
    if (seen.a > 0.5) {
        // A mirror seen in the mirror: one bounce only.
        return vec4f(missed, 1.0);
    }
    return vec4f(s.reflectance * seen.rgb, 1.0);
}
