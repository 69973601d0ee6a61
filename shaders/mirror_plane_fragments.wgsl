// The fragment entry points of the methods that draw a mirror's world through the mirror's
// plane (crates/raster/src/methods/portal_stencil.rs, recursive_texture.rs and cubemap.rs),
// composed after mirror_plane_vertex.wgsl (`VertexOut`, with `plane_distance`) and the
// method's file, which defines `object_colour` and `mirror_colour`.

@fragment
fn fs_object(in: VertexOut) -> @location(0) vec4f {
    return object_colour(in);
}

@fragment
fn fs_mirror(in: VertexOut) -> @location(0) vec4f {
    return mirror_colour(in);
}

// Without clip distances: what lies behind the mirror's plane is discarded here.
@fragment
fn fs_object_discard(in: VertexOut) -> @location(0) vec4f {
    if (in.plane_distance < 0.0) {
        discard;
    }
    return object_colour(in);
}

@fragment
fn fs_mirror_discard(in: VertexOut) -> @location(0) vec4f {
    if (in.plane_distance < 0.0) {
        discard;
    }
    return mirror_colour(in);
}
