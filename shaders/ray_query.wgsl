// Entry points of crates/raster/src/methods/ray_query.rs: every reflection chain followed by
// ray queries against the scene's acceleration structure (a BLAS per mesh, a TLAS of their
// instances), shaded by the contract (shading.wgsl, which this follows, without the shadow
// maps: shadow legs are ray queries too, below).
//
// Two ways to find the first surface, one path after it:
// - vs_main / fs_depth / fs_main: the scene rasterized for primary visibility (a depth
//   pre-pass, then one shaded fragment per pixel: the `ray-query` method);
// - vs_fullscreen / fs_primary_rays: a primary ray per pixel of the render target, the
//   camera's ray of that position (crates/scene/src/camera.rs) — the truth on the GPU
//   (`trace --device gpu`, `ray-query primary=rays`).
// From there the path is the tracer's `whitted` (crates/trace/src/integrator/whitted.rs): a
// front mirror hit re-solved on the mirror's plane and reflected about its (bumped) normal,
// the next ray skipping the mirror it leaves; a diffuse hit shaded; a miss the background;
// the depth cap or the attenuation cut the terminal radiance.

struct RayQueryParams {
    camera: CameraRays,
    max_depth: u32,
    min_attenuation: f32,
    // 1: shadow legs are traced (the scene's lighting.shadows).
    shadows: u32,
    _pad: u32,
}

// Triangle i of the scene's geometry: its face normal, its plane's offset n·v0, surface and
// its corners' texture coordinates.
struct TriangleRecord {
    normal: vec3f,
    surface: u32,
    offset: f32,
    _pad0: u32,
    uv0: vec2f,
    uv1: vec2f,
    uv2: vec2f,
}

@group(1) @binding(0) var acc: acceleration_structure;
@group(1) @binding(1) var<storage, read> triangles: array<TriangleRecord>;
@group(1) @binding(2) var<uniform> params: RayQueryParams;

const NO_MIRROR: u32 = 0xffffffffu;
const FAR: f32 = 3.0e38;

// The scene triangle a ray query's intersection is (instance custom data: the mesh's first
// triangle).
fn triangle_of(instance_custom_data: u32, primitive_index: u32) -> u32 {
    return instance_custom_data + primitive_index;
}

// A ray's closest hit: its distance and the hit triangle's face normal, plane offset and
// surface.
struct Hit {
    found: bool,
    t: f32,
    normal: vec3f,
    offset: f32,
    surface: u32,
    // Texture coordinates at the hit (the query's barycentrics).
    uv: vec2f,
}

// The first committed hit of o + t·d at t ≥ tmin (every mesh is opaque).
fn first_hit(o: vec3f, d: vec3f, tmin: f32, tmax: f32) -> Hit {
    var rq: ray_query;
    rayQueryInitialize(&rq, acc, RayDesc(RAY_FLAG_FORCE_OPAQUE, 0xffu, tmin, tmax, o, d));
    rayQueryProceed(&rq);
    let h = rayQueryGetCommittedIntersection(&rq);
    var hit: Hit;
    hit.found = h.kind != RAY_QUERY_INTERSECTION_NONE;
    hit.t = h.t;
    if (hit.found) {
        let r = triangles[triangle_of(h.instance_custom_data, h.primitive_index)];
        hit.normal = r.normal;
        hit.offset = r.offset;
        hit.surface = r.surface;
        let b = h.barycentrics;
        hit.uv = r.uv0 + (r.uv1 - r.uv0) * b.x + (r.uv2 - r.uv0) * b.y;
    }
    return hit;
}

// The next float after t ≥ 0: a query restarted there skips the hit at t and nothing else.
fn just_after(t: f32) -> f32 {
    return bitcast<f32>(bitcast<u32>(max(t, 0.0)) + 1u);
}

// Most hits one query steps past (a mirror's own triangles, the shaded plane's).
const MAX_SKIPS: u32 = 16u;

// The mirror `hit` lies on, or NO_MIRROR.
fn hit_mirror(hit: Hit) -> u32 {
    let s = surfaces[hit.surface];
    return select(NO_MIRROR, s.mirror, s.kind == 1u);
}

// The closest hit along o + t·d, skipping the triangles of mirror `leaving` (the tracer's rule:
// a planar mirror cannot be hit again by its own reflection): a hit on it — only where the ray
// starts, at t ≈ 0 — restarts the query just after it. (Candidate intersections, the other
// way to skip, crash Mesa 25.0.7's lavapipe: docs/ray-query.md.)
fn closest_hit(o: vec3f, d: vec3f, leaving: u32) -> Hit {
    var tmin = 0.0;
    for (var k = 0u; k < MAX_SKIPS; k++) {
        let hit = first_hit(o, d, tmin, FAR);
        if (!hit.found || leaving == NO_MIRROR || hit_mirror(hit) != leaving) {
            return hit;
        }
        tmin = just_after(hit.t);
    }
    var none: Hit;
    return none;
}

// The plane of the diffuse triangle being shaded: its shadow legs skip it (the tracer skips the
// shaded triangle). A leg towards a light that lights the point leaves that plane, so it can
// meet a triangle in the same plane only where it starts: any such triangle is skipped.
var<private> shaded_plane: vec4f;

// Whether the straight leg from a to b is unoccluded (docs/shading.md, "Shadows"): it starts
// on mirror `from_mirror` (skipped) or, with NO_MIRROR, on the shaded triangle's plane; hits
// within 10⁻⁴ of its length from b are not counted.
fn leg_clear(a: vec3f, from_mirror: u32, b: vec3f) -> bool {
    let v = b - a;
    let length = sqrt(dot(v, v));
    if (length == 0.0) {
        return true;
    }
    let d = v / length;
    let tmax = length * (1.0 - 1e-4);
    var tmin = 0.0;
    for (var k = 0u; k < MAX_SKIPS; k++) {
        let hit = first_hit(a, d, tmin, tmax);
        if (!hit.found) {
            return true;
        }
        var skip: bool;
        if (from_mirror != NO_MIRROR) {
            skip = hit_mirror(hit) == from_mirror;
        } else {
            skip = abs(dot(hit.normal, shaded_plane.xyz) - 1.0) < 1e-6
                && abs(hit.offset - shaded_plane.w) <= 1e-5 * (1.0 + abs(hit.offset));
        }
        if (!skip) {
            return false;
        }
        tmin = just_after(hit.t);
    }
    return true;
}

// shading.wgsl's shadow test, by ray queries: light i reaches p only if every straight leg is
// clear — p to the light, or for an image p → c_j → … → c₁ → L, each c where the segment to
// the image meets its last mirror (crates/scene/src/light_images.rs, for_each_leg).
fn unshadowed(i: u32, p: vec3f, cos_p: f32) -> bool {
    if (params.shadows == 0u) {
        return true;
    }
    var light = lights[i];
    var start = p;
    var from_mirror = NO_MIRROR;
    for (var leg = 0u; leg < MAX_LEGS; leg++) {
        if (light.plane_count == 0u) {
            return leg_clear(start, from_mirror, light.position);
        }
        let plane = light_planes[light.first_plane];
        let a = dot(plane, vec4f(start, 1.0));
        let b = dot(plane, vec4f(light.position, 1.0));
        let c = start + (light.position - start) * (a / (a - b));
        if (!leg_clear(start, from_mirror, c)) {
            return false;
        }
        start = c;
        from_mirror = light.mirror;
        light = lights[light.parent];
    }
    return true;
}

// The longest chain of legs: mirrored_lights is at most 64.
const MAX_LEGS: u32 = 65u;

fn max3(v: vec3f) -> f32 {
    return max(v.x, max(v.y, v.z));
}

// Radiance along o + t·d whose first hit is `first` (the tracer's whitted path).
fn follow(origin: vec3f, direction: vec3f, first: Hit) -> vec3f {
    var o = origin;
    var d = direction;
    var hit = first;
    var throughput = vec3f(1.0);
    var bounces = 0u;
    loop {
        if (!hit.found) {
            return throughput * frame.background;
        }
        let s = surfaces[hit.surface];
        let front = dot(hit.normal, d) < 0.0;
        if (s.kind != 1u || !front) {
            let p = o + d * hit.t;
            shaded_plane = vec4f(hit.normal, hit.offset);
            if (s.kind == 1u) {
                return throughput * diffuse_radiance(p, hit.normal, -d, s.back_albedo, vec3f(0.0));
            }
            return throughput * diffuse_radiance(p, hit.normal, -d, surface_albedo(s, hit.uv), surface_emission(s, hit.uv));
        }
        let next = throughput * s.reflectance;
        if (bounces >= params.max_depth || max3(next) < params.min_attenuation) {
            return throughput * frame.terminal;
        }
        throughput = next;
        bounces += 1u;
        // Plane-exact: the hit re-solved on the mirror's plane, reflected about its normal (or
        // its bumped normal, absorbed by the contract's rule).
        let n = s.bump.normal;
        let t = dot(n, s.bump.center - o) / dot(n, d);
        let x = o + d * t;
        let r = mirror_reflection(s.bump, d, x);
        if (r.w == 0.0) {
            return vec3f(0.0);
        }
        o = x;
        d = r.xyz;
        hit = closest_hit(o, d, s.mirror);
    }
    return vec3f(0.0);
}

// --- Rasterized primary visibility (`ray-query`)

// Invariant (scene_vertex.wgsl): the shading pass meets the depth the pre-pass wrote.
alias VertexOut = SceneVertexOut;

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    return scene_vertex_through(v, params.camera.clip_from_world);
}

@fragment
fn fs_depth(in: VertexOut) {
}

// The pixel's nearest surface, from the rasterizer; everything after it by ray queries.
@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4f {
    let d = normalize(in.world - params.camera.eye);
    let s = surfaces[in.surface];
    let front = dot(in.normal, d) < 0.0;
    if (s.kind != 1u || !front) {
        shaded_plane = vec4f(in.normal, dot(in.normal, in.world));
        if (s.kind == 1u) {
            return vec4f(diffuse_radiance(in.world, in.normal, -d, s.back_albedo, vec3f(0.0)), 1.0);
        }
        return vec4f(diffuse_radiance(in.world, in.normal, -d, surface_albedo(s, in.uv), surface_emission(s, in.uv)), 1.0);
    }
    // A front mirror: the path from the eye, its first hit at the mirror's plane.
    var first: Hit;
    first.found = true;
    first.t = dot(s.bump.normal, s.bump.center - params.camera.eye) / dot(s.bump.normal, d);
    first.normal = in.normal;
    first.surface = in.surface;
    return vec4f(follow(params.camera.eye, d, first), 1.0);
}

// --- Primary rays (the GPU truth)

// The camera's ray through this render-target pixel's centre: pixel (X, Y) of an s× target
// is the sub-pixel position (x + (i+½)/s, y + (j+½)/s) of the output, the tracer's grid.
@fragment
fn fs_primary_rays(in: FullscreenOut) -> @location(0) vec4f {
    let d = camera_ray(params.camera, in.clip.xy);
    let eye = params.camera.eye;
    return vec4f(follow(eye, d, closest_hit(eye, d, NO_MIRROR)), 1.0);
}
