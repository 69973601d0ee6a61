// The shadow test of every raster method: each straight leg of a light's path against the
// shadow maps of crates/raster/src/shadow_maps.rs (docs/shading.md, "Shadow maps"). Follows
// shading.wgsl, whose diffuse_radiance calls `unshadowed`.

// The longest chain a shadow test follows: mirrored_lights is at most 64.
const MAX_SHADOW_LEGS: u32 = 65u;

// Whether nothing nearer than x (plus the bias) lies on the ray from `light` towards x in its
// shadow-map layer. `cos_incidence`: |cos| between the leg and the surface x lies on.
fn leg_clear(light: Light, x: vec3f, cos_incidence: f32) -> bool {
    let d = x - light.position;
    var clip: vec4f;
    var layer = light.shadow_layer;
    if (light.plane_count == 0u) {
        // A cube face: the axis of d's largest component (ties to the lowest axis).
        let m = abs(d);
        var a = 2u;
        if (m.x >= m.y && m.x >= m.z) {
            a = 0u;
        } else if (m.y >= m.z) {
            a = 1u;
        }
        let b = (a + 1u) % 3u;
        let c = (a + 2u) % 3u;
        layer += 2u * a + select(1u, 0u, d[a] >= 0.0);
        clip = vec4f(d[b], d[c], 0.0, abs(d[a]));
    } else {
        clip = light.shadow_from_world * vec4f(x, 1.0);
    }
    if (clip.w <= 0.0) {
        return true;
    }
    let ndc = clip.xy / clip.w;
    let size = vec2f(textureDimensions(shadow_maps));
    let texel = vec2i(floor(vec2f(0.5 * ndc.x + 0.5, 0.5 - 0.5 * ndc.y) * size));
    let clamped = clamp(texel, vec2i(0), vec2i(size) - 1);
    let stored = textureLoad(shadow_maps, clamped, i32(layer), 0).r;
    let r = length(d);
    let cos_i = max(cos_incidence, 0.05);
    let tan_i = sqrt(max(1.0 - cos_i * cos_i, 0.0)) / cos_i;
    let bias = frame.shadow_bias + r * light.shadow_texel * min(tan_i, 8.0);
    return r <= stored + bias;
}

// Shadows (docs/shading.md): light i reaches p only if every straight leg is clear — p to the
// light (or image), then for an image each mirror point c back to the real light. `cos_p`:
// the first leg's incidence on p's surface (diffuse_radiance has it already).
fn unshadowed(i: u32, p: vec3f, cos_p: f32) -> bool {
    if (frame.shadows == 0u) {
        return true;
    }
    var light = lights[i];
    var x = p;
    var cos_i = cos_p;
    for (var leg = 0u; leg < MAX_SHADOW_LEGS; leg++) {
        if (!leg_clear(light, x, cos_i)) {
            return false;
        }
        if (light.plane_count == 0u) {
            return true;
        }
        // Where the segment x → image meets the image's last mirror (the beam's first plane).
        let plane = light_planes[light.first_plane];
        let a = dot(plane, vec4f(x, 1.0));
        let b = dot(plane, vec4f(light.position, 1.0));
        x = mix(x, light.position, a / (a - b));
        light = lights[light.parent];
        cos_i = abs(dot(plane.xyz, normalize(light.position - x)));
    }
    return true;
}
