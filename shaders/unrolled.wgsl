// Entry points of crates/raster/src/methods/unrolled.rs: every kept reflection path drawn as
// instances of the scene, one per convex piece of its visible region. Prepended with
// shading.wgsl; unrolled_clip_distances.wgsl adds the hardware-clipped vertex stage where the
// adapter has clip distances.
//
// An instance draws the real scene through its path's composed reflection `R₁·…·Rₖ` (inside
// `clip_from_world`), keeps only what lies beyond its last mirror's plane and inside its
// piece (planes through the eye and the piece's edges, as clip-space half-planes
// a·x + b·y + c·w ≥ 0) and is attenuated by the product of the reflectances along the path.
// A path's visible region is its portal less what nearer sibling mirrors hide, so the cells
// follow each other along every unfolded ray and one depth buffer (infinite reversed Z,
// shared by every instance: the projection is the camera's) resolves visibility between them.

// One convex piece of a path's cell: the path's transform, plane, eye and attenuation, and
// the piece's edges.
struct CellPiece {
    clip_from_world: mat4x4f,
    // The last mirror's plane in scene space, front positive; (0, 0, 0, 1) for the camera.
    plane: vec4f,
    // The path's virtual eye in scene space (shading's viewer).
    eye: vec3f,
    edge_first: u32,
    attenuation: vec3f,
    edge_count: u32,
}

// A scene mirror for the "behind a mirror" guard: a rectangle on `plane`.
struct MirrorRect {
    plane: vec4f,
    center: vec3f,
    half_width: f32,
    right: vec3f,
    half_height: f32,
    up: vec3f,
    _pad: f32,
}

@group(1) @binding(0) var<storage, read> pieces: array<CellPiece>;
@group(1) @binding(1) var<storage, read> edges: array<vec4f>;
// Draw `d` covers instances `first_instance..` of this list: instance i draws piece ids[i].
@group(1) @binding(2) var<storage, read> ids: array<u32>;
@group(1) @binding(3) var<storage, read> mirror_rects: array<MirrorRect>;

struct GuardedOut {
    @builtin(position) clip: vec4f,
    @location(0) world: vec3f,
    @location(1) @interpolate(flat) normal: vec3f,
    @location(2) @interpolate(flat) surface: u32,
    @location(3) @interpolate(flat) piece: u32,
    // Clip-space x, y, w: affine in the world position, so interpolated exactly.
    @location(4) clip_xyw: vec3f,
    @location(8) uv: vec2f,
}

// Without clip distances every test happens per fragment.
@vertex
fn vs_guarded(v: VertexIn, @builtin(instance_index) instance: u32) -> GuardedOut {
    let id = ids[instance];
    var out: GuardedOut;
    out.clip = pieces[id].clip_from_world * vec4f(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.surface = v.surface;
    out.piece = id;
    out.uv = v.uv;
    out.clip_xyw = out.clip.xyw;
    return out;
}

// Whether scene point `x`, drawn by piece `id`, is really seen through its path: beyond its
// last mirror, inside the piece, and not behind the front of another mirror. The last
// test is the one clipping cannot do: the segment from where the path's ray enters its cell
// (on the last mirror; the eye for the camera) to `x` must not cross a mirror's front, or
// the ray would have been reflected there (an object placed behind a mirror).
fn in_cell(id: u32, x: vec3f, clip_xyw: vec3f) -> bool {
    let p = pieces[id];
    let d_plane = dot(p.plane, vec4f(x, 1.0));
    if (d_plane < 0.0) {
        return false;
    }
    for (var i = 0u; i < p.edge_count; i++) {
        if (dot(edges[p.edge_first + i].xyz, clip_xyw) < 0.0) {
            return false;
        }
    }
    let e = p.eye;
    var t_enter = 0.0;
    if (any(p.plane.xyz != vec3f(0.0))) {
        let d_eye = dot(p.plane, vec4f(e, 1.0));
        t_enter = d_eye / (d_eye - d_plane);
    }
    for (var m = 0u; m < arrayLength(&mirror_rects); m++) {
        let r = mirror_rects[m];
        let de = dot(r.plane, vec4f(e, 1.0));
        let dx = dot(r.plane, vec4f(x, 1.0));
        // Front to back only (a back face is drawn and depth-tested like any surface);
        // points on the plane (a floor meeting a mirror) are in front.
        if (de <= 0.0 || dx >= -GUARD_EPSILON) {
            continue;
        }
        let t = de / (de - dx);
        if (t <= t_enter) {
            continue;
        }
        let q = e + t * (x - e) - r.center;
        if (abs(dot(q, r.right)) <= r.half_width && abs(dot(q, r.up)) <= r.half_height) {
            return false;
        }
    }
    return true;
}

// Scene-space tolerance of the guard (the scene loader's coordinates are metres).
const GUARD_EPSILON: f32 = 1e-5;

fn object_colour(id: u32, world: vec3f, normal: vec3f, surface: u32, uv: vec2f) -> vec4f {
    let p = pieces[id];
    let s = surfaces[surface];
    return vec4f(p.attenuation * diffuse_radiance(world, normal, normalize(p.eye - world), surface_albedo(s, uv), surface_emission(s, uv)), 1.0);
}

// A mirror in a path's world whose own path was not kept (pruned or past the depth cap):
// its front shows the terminal radiance, its back is diffuse. Mirrors whose path was kept
// are not drawn in this world at all; the child instance fills them.
fn mirror_colour(id: u32, world: vec3f, normal: vec3f, surface: u32) -> vec4f {
    let p = pieces[id];
    let s = surfaces[surface];
    if (dot(normal, p.eye - world) > 0.0) {
        return vec4f(p.attenuation * frame.terminal, 1.0);
    }
    return vec4f(p.attenuation * diffuse_radiance(world, normal, normalize(p.eye - world), s.back_albedo, vec3f(0.0)), 1.0);
}

@fragment
fn fs_object_guarded(in: GuardedOut) -> @location(0) vec4f {
    if (!in_cell(in.piece, in.world, in.clip_xyw)) {
        discard;
    }
    return object_colour(in.piece, in.world, in.normal, in.surface, in.uv);
}

@fragment
fn fs_mirror_guarded(in: GuardedOut) -> @location(0) vec4f {
    if (!in_cell(in.piece, in.world, in.clip_xyw)) {
        discard;
    }
    return mirror_colour(in.piece, in.world, in.normal, in.surface);
}

// Each path's visible region, filled with its attenuated background before any geometry
// (paths in order, so a child's background covers its parent's); depth stays at the far
// value 0.
struct BackgroundOut {
    @builtin(position) clip: vec4f,
    @location(0) @interpolate(flat) colour: vec3f,
}

@vertex
fn vs_background(@location(0) ndc: vec2f, @location(1) attenuation: vec3f) -> BackgroundOut {
    var out: BackgroundOut;
    out.clip = vec4f(ndc, 0.0, 1.0);
    out.colour = attenuation * frame.background;
    return out;
}

@fragment
fn fs_background(in: BackgroundOut) -> @location(0) vec4f {
    return vec4f(in.colour, 1.0);
}
