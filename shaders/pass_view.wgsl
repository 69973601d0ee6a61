// The view of a method whose passes read one `Pass` uniform, `pass_` (group 1), with the
// fields `clip_from_world`, `eye` and `plane` (crates/raster/src/methods/recursive_texture.rs
// and cubemap.rs): mirror_plane_vertex.wgsl's hooks, and the contract's diffuse shading seen
// from the pass's eye. It follows the method's own file, which declares `Pass` and `pass_`.

fn view_clip_from_world() -> mat4x4f {
    return pass_.clip_from_world;
}

fn view_plane() -> vec4f {
    return pass_.plane;
}

fn shade_diffuse(in: VertexOut, albedo: vec3f, emission: vec3f) -> vec3f {
    return diffuse_radiance(in.world, in.normal, normalize(pass_.eye - in.world), albedo, emission);
}
