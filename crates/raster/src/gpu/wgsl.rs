//! All WGSL composition. WGSL has no includes: a shader is an optional `enable` line, then
//! its parts in order — `shaders/shading.wgsl` (the contract, `docs/shading.md`) first for
//! every scene pipeline, then the method's own file(s) — and, for the clip-distance variant
//! of the methods that clip at a mirror's plane, `shaders/mirror_plane_clip_distances.wgsl`.
//!
//! Each method lists its shader variants in its registry entry ([`MethodEntry::shaders`]),
//! and its `#[repr(C)]` GPU structs ([`MethodEntry::gpu_structs`]); the tests below parse and
//! validate every variant with naga on every machine (whatever the adapter supports) and
//! check every struct's size and field offsets against its WGSL twin.
//!
//! [`MethodEntry::shaders`]: crate::method::MethodEntry::shaders
//! [`MethodEntry::gpu_structs`]: crate::method::MethodEntry::gpu_structs

/// `shaders/shading.wgsl` then `shaders/shadow_map_legs.wgsl`: the shading contract and the
/// scene bindings (group 0), with shadows tested in the shadow maps (every raster method).
pub const SHADING: &str = concat!(
    include_str!("../../../../shaders/shading.wgsl"),
    "\n",
    include_str!("../../../../shaders/shadow_map_legs.wgsl")
);

/// `shaders/shading.wgsl` alone: the contract without a shadow test, for a shader that brings
/// its own `unshadowed` (`ray-query`: a ray query per leg).
pub const SHADING_CONTRACT: &str = include_str!("../../../../shaders/shading.wgsl");

/// `shaders/mirror_plane_vertex.wgsl`: the vertex stage of the methods that draw a mirror's
/// world through its plane (`VertexOut`, `scene_vertex`, `vs_main`), from the view the
/// method's own file gives (`view_clip_from_world`, `view_plane`).
pub const MIRROR_PLANE_VERTEX: &str = include_str!("../../../../shaders/mirror_plane_vertex.wgsl");

/// `shaders/scene_vertex.wgsl`: the plain vertex stage of a scene seen through one camera
/// (`SceneVertexOut`, `scene_vertex_through`), for the methods that clip at no mirror plane.
pub const SCENE_VERTEX: &str = include_str!("../../../../shaders/scene_vertex.wgsl");

/// `shaders/pass_view.wgsl`: the view hooks and diffuse shading of a method whose passes read
/// one `Pass` uniform `pass_` (the paper's methods, `cubemap`); it follows the method's file.
pub const PASS_VIEW: &str = include_str!("../../../../shaders/pass_view.wgsl");

/// `shaders/mirror_plane_clip_distances.wgsl`: the clip-distance vertex stage of the methods
/// that clip a mirror's world at the mirror's plane (`portal`, `naive`, `auxiliary`); it
/// follows [`MIRROR_PLANE_VERTEX`]'s `VertexOut` and `scene_vertex`.
pub const MIRROR_PLANE_CLIP_DISTANCES: &str =
    include_str!("../../../../shaders/mirror_plane_clip_distances.wgsl");
/// The fragment entry points of the methods that clip a mirror's world at its plane (plain,
/// and `*_discard` for adapters without clip distances).
pub const MIRROR_PLANE_FRAGMENTS: &str =
    include_str!("../../../../shaders/mirror_plane_fragments.wgsl");

/// Declares `SHADER` and `CLIP_DISTANCE_SHADER`, the two variants of a method that clips a
/// mirror's world at the mirror's plane (`portal`, the paper's methods, `cubemap`), from its
/// own parts (its entry points, and [`PASS_VIEW`] where it reads a `Pass`): `SHADER` runs on
/// every adapter and tests the plane per fragment (the `*_discard` entry points of
/// [`MIRROR_PLANE_FRAGMENTS`]); `CLIP_DISTANCE_SHADER` adds the hardware clip-distance
/// vertex stage ([`MIRROR_PLANE_CLIP_DISTANCES`]) for adapters with `CLIP_DISTANCES`.
#[macro_export]
macro_rules! mirror_plane_shaders {
    ($label:literal, $($part:expr),+ $(,)?) => {
        static SHADER: $crate::wgsl::WgslSource = $crate::wgsl::WgslSource {
            label: $label,
            enable: &[],
            parts: &[
                $crate::wgsl::SHADING,
                $crate::wgsl::MIRROR_PLANE_VERTEX,
                $($part,)+
                $crate::wgsl::MIRROR_PLANE_FRAGMENTS,
            ],
        };
        static CLIP_DISTANCE_SHADER: $crate::wgsl::WgslSource = $crate::wgsl::WgslSource {
            label: concat!($label, " clip distances"),
            enable: &["clip_distances"],
            parts: &[
                $crate::wgsl::SHADING,
                $crate::wgsl::MIRROR_PLANE_VERTEX,
                $($part,)+
                $crate::wgsl::MIRROR_PLANE_FRAGMENTS,
                $crate::wgsl::MIRROR_PLANE_CLIP_DISTANCES,
            ],
        };
    };
}

/// One shader variant: what a pipeline's module is made of.
#[derive(Debug)]
pub struct WgslSource {
    /// Module label (captures, validation errors).
    pub label: &'static str,
    /// WGSL extensions to `enable` (e.g. `clip_distances`); the device must have the
    /// matching feature to compile it.
    pub enable: &'static [&'static str],
    /// The parts, concatenated in order.
    pub parts: &'static [&'static str],
}

impl WgslSource {
    /// The composed WGSL text, with the constant `TEXTURED` the shading contract reads:
    /// `false` compiles a module whose `surface_albedo` and `surface_emission` return the
    /// factors (the texture lookups become dead code the driver drops), for scenes without
    /// textures — the same images, a faster pipeline compile.
    pub fn source(&self, textured: bool) -> String {
        let mut s = String::new();
        for e in self.enable {
            s.push_str(&format!("enable {e};\n"));
        }
        s.push_str(&format!("const TEXTURED: bool = {textured};\n"));
        for p in self.parts {
            s.push_str(p);
            s.push('\n');
        }
        s
    }
}

/// The SSAA resolve (no scene bindings).
pub static RESOLVE: WgslSource = WgslSource {
    label: "resolve",
    enable: &[],
    parts: &[include_str!("../../../../shaders/resolve.wgsl")],
};

/// Compiles a variant on `device`.
pub fn shader_module(
    device: &wgpu::Device,
    shader: &WgslSource,
    textured: bool,
) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(shader.label),
        source: wgpu::ShaderSource::Wgsl(shader.source(textured).into()),
    })
}

/// A host struct's layout, to compare with the WGSL struct `wgsl_name`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HostLayout {
    pub wgsl_name: &'static str,
    pub size: usize,
    /// Field names and byte offsets, in declaration order.
    pub fields: Vec<(&'static str, usize)>,
}

/// `host_layout!(RustStruct as "WgslStruct" { field, ... })`: the layout of a `#[repr(C)]`
/// struct from `size_of` and `offset_of!`. List every field the WGSL struct has; padding
/// fields of the Rust struct that WGSL leaves implicit are omitted.
#[macro_export]
macro_rules! host_layout {
    ($ty:ty as $name:literal { $($field:ident),* $(,)? }) => {
        $crate::wgsl::HostLayout {
            wgsl_name: $name,
            size: std::mem::size_of::<$ty>(),
            fields: vec![$((stringify!($field), std::mem::offset_of!($ty, $field))),*],
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::METHODS;

    fn every_source() -> Vec<(&'static str, &'static WgslSource)> {
        let mut all = vec![
            ("resolve", &RESOLVE),
            ("shadow maps", &crate::shadow_maps::SHADER),
            ("display tone map", &crate::display_tone_map::SHADER),
        ];
        for e in METHODS {
            assert!(!e.shaders.is_empty(), "{} lists no shader", e.name);
            all.extend(e.shaders.iter().map(|s| (e.name, *s)));
        }
        all
    }

    fn parse(shader: &WgslSource) -> naga::Module {
        parse_variant(shader, true)
    }

    fn parse_variant(shader: &WgslSource, textured: bool) -> naga::Module {
        let source = shader.source(textured);
        naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{}: {}", shader.label, e.emit_to_string(&source)))
    }

    /// Every variant parses and validates, including those only some adapters compile
    /// (clip distances), so a shader error cannot hide behind a missing feature — each with
    /// and without textures.
    #[test]
    fn every_shader_variant_validates() {
        for ((method, shader), textured) in every_source()
            .into_iter()
            .flat_map(|s| [(s, false), (s, true)])
        {
            let module = parse_variant(shader, textured);
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            )
            .validate(&module)
            .unwrap_or_else(|e| {
                panic!(
                    "{method}: shader {}: {}",
                    shader.label,
                    e.emit_to_string(&shader.source(textured))
                )
            });
        }
    }

    /// The WGSL struct `name`'s size and member offsets, from the first of `shaders`
    /// defining it.
    fn wgsl_layout(name: &str, shaders: &[&WgslSource]) -> Option<(usize, Vec<(String, usize)>)> {
        for shader in shaders {
            let module = parse(shader);
            let mut layouter = naga::proc::Layouter::default();
            layouter.update(module.to_ctx()).unwrap();
            for (handle, ty) in module.types.iter() {
                if ty.name.as_deref() != Some(name) {
                    continue;
                }
                if let naga::TypeInner::Struct { members, .. } = &ty.inner {
                    let fields = members
                        .iter()
                        .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
                        .collect();
                    return Some((layouter[handle].size as usize, fields));
                }
            }
        }
        None
    }

    /// Every `#[repr(C)]` struct sent to the GPU has its WGSL twin's size and offsets.
    #[test]
    fn host_structs_match_their_wgsl_structs() {
        // The contract's structs, in every scene shader; each method's, in its own shaders
        // only (two methods may both have a struct `Path`).
        let every: Vec<&WgslSource> = every_source().into_iter().map(|(_, s)| s).collect();
        let mut layouts: Vec<(HostLayout, Vec<&WgslSource>)> = crate::shading::gpu_structs()
            .into_iter()
            .map(|l| (l, every.clone()))
            .collect();
        layouts.extend(
            crate::shadow_maps::gpu_structs()
                .into_iter()
                .map(|l| (l, vec![&crate::shadow_maps::SHADER])),
        );
        layouts.extend(
            crate::display_tone_map::gpu_structs()
                .into_iter()
                .map(|l| (l, vec![&crate::display_tone_map::SHADER])),
        );
        for e in METHODS {
            layouts.extend(
                (e.gpu_structs)()
                    .into_iter()
                    .map(|l| (l, e.shaders.to_vec())),
            );
        }
        assert!(layouts.len() >= 8, "{} structs", layouts.len());
        for (host, shaders) in layouts {
            let (size, fields) = wgsl_layout(host.wgsl_name, &shaders)
                .unwrap_or_else(|| panic!("no WGSL struct {}", host.wgsl_name));
            assert_eq!(host.size, size, "size of {}", host.wgsl_name);
            assert_eq!(
                host.fields.len(),
                fields.len(),
                "{}: host fields {:?}, WGSL members {:?}",
                host.wgsl_name,
                host.fields,
                fields
            );
            for ((hn, ho), (wn, wo)) in host.fields.iter().zip(&fields) {
                assert_eq!(ho, wo, "{}.{hn} (WGSL {wn}) offset", host.wgsl_name);
            }
        }
    }
}
