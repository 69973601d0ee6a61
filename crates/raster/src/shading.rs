//! The shading contract in WGSL (`shaders/shading.wgsl`) and the scene data it reads.
//!
//! WGSL composition (the contract first in every scene pipeline) lives in [`crate::wgsl`].

use bytemuck::{Pod, Zeroable};
use mirrorbox_scene::{Scene, Surface};
use wgpu::util::DeviceExt;

/// The `#[repr(C)]` structs of `shading.wgsl`, for the layout test of [`crate::wgsl`].
pub fn gpu_structs() -> Vec<crate::wgsl::HostLayout> {
    vec![
        crate::host_layout!(GpuSurface as "Surface" {
            albedo, kind, emission, mirror, reflectance, _pad0, back_albedo, _pad1, bump,
            albedo_map, emission_map
        }),
        crate::host_layout!(GpuTextureMap as "TextureMap" {
            row_u, present, row_v, wrap, origin, size
        }),
        crate::host_layout!(GpuLight as "Light" {
            position, first_plane, intensity, plane_count, shadow_from_world, shadow_layer,
            parent, shadow_texel, mirror
        }),
        crate::host_layout!(GpuFrame as "Frame" {
            ambient, light_count, background, shadow_bias, terminal, shadows
        }),
        crate::host_layout!(GpuMirrorBump as "MirrorBump" {
            center, flags, right, width, up, height, normal, amplitude, ripple_dir,
            wavenumber, phase, map_offset, map_width, map_height, strength, tiling, _pad
        }),
    ]
}

/// A mirror's frame and bump for `shading.wgsl`'s `mirror_shading_normal`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuMirrorBump {
    center: [f32; 3],
    /// Bit 0: a ripple; bit 1: a normal map.
    flags: u32,
    right: [f32; 3],
    width: f32,
    up: [f32; 3],
    height: f32,
    normal: [f32; 3],
    amplitude: f32,
    ripple_dir: [f32; 2],
    wavenumber: f32,
    phase: f32,
    map_offset: u32,
    map_width: u32,
    map_height: u32,
    strength: f32,
    tiling: [f32; 2],
    _pad: [f32; 2],
}

/// The normal maps' atlas width: the widest map's (1 when there is none).
fn atlas_width(scene: &Scene) -> u32 {
    scene
        .bumps
        .iter()
        .flatten()
        .filter_map(|b| b.normal_map.as_ref())
        .map(|m| m.width)
        .max()
        .unwrap_or(1)
}

/// The mirrors' frames and bumps, and the normal maps' atlas: its width and its texels
/// packed one u32 each, every map's rows below the previous map's — each map once, however
/// many mirrors share it (the loader decodes a file once; mirrors sharing it share its
/// texels, which identify it here).
fn mirror_bumps(scene: &Scene) -> (Vec<GpuMirrorBump>, u32, Vec<u32>) {
    let atlas_width = atlas_width(scene);
    let mut texels: Vec<u32> = Vec::new();
    let mut placed: std::collections::HashMap<*const mirrorbox_scene::bump::Texels, u32> =
        Default::default();
    let mut bumps = Vec::with_capacity(scene.mirrors.len());
    for (m, bump) in scene.mirrors.iter().zip(&scene.bumps) {
        let mut g = GpuMirrorBump {
            center: m.center.to_array(),
            right: m.right().to_array(),
            width: m.width,
            up: m.up.to_array(),
            height: m.height,
            normal: m.normal.to_array(),
            ..Zeroable::zeroed()
        };
        if let Some(b) = bump {
            if let Some(r) = b.ripple {
                g.flags |= 1;
                g.amplitude = r.amplitude;
                g.ripple_dir = [r.direction.cos(), r.direction.sin()];
                g.wavenumber = std::f32::consts::TAU / r.wavelength;
                g.phase = r.phase;
            }
            if let Some(map) = &b.normal_map {
                g.flags |= 2;
                g.map_width = map.width;
                g.map_height = map.height;
                g.strength = map.strength;
                g.tiling = map.tiling;
                g.map_offset = *placed
                    .entry(std::sync::Arc::as_ptr(&map.texels))
                    .or_insert_with(|| {
                        let offset = (texels.len() / atlas_width as usize) as u32;
                        for row in map.texels.chunks_exact(map.width as usize) {
                            let start = texels.len();
                            texels.extend(row.iter().map(|t| {
                                u32::from(t[0]) | u32::from(t[1]) << 8 | u32::from(t[2]) << 16
                            }));
                            texels.resize(start + atlas_width as usize, 0);
                        }
                        offset
                    });
            }
        }
        bumps.push(g);
    }
    if texels.is_empty() {
        texels.push(0);
    }
    (bumps, atlas_width, texels)
}

/// Rows of the normal-map atlas: every distinct map's height, stacked (what
/// [`mirror_bumps`] packs: a map shared by many mirrors once).
fn atlas_rows(scene: &Scene) -> u32 {
    let mut seen = std::collections::HashSet::new();
    scene
        .bumps
        .iter()
        .flatten()
        .filter_map(|b| b.normal_map.as_ref())
        .filter(|m| seen.insert(std::sync::Arc::as_ptr(&m.texels)))
        .map(|m| m.height)
        .sum::<u32>()
        .max(1)
}

/// A texture as a surface reads it, for `shading.wgsl`'s `texture_sample`.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuTextureMap {
    row_u: [f32; 3],
    /// 1 where the surface has this texture.
    present: u32,
    row_v: [f32; 3],
    /// Wrap along u in bits 0–3, along v in bits 4–7 ([`mirrorbox_scene::texture::Wrap::code`]).
    wrap: u32,
    /// The texture's top-left texel in the colour atlas, and its size.
    origin: [u32; 2],
    size: [u32; 2],
}

/// Where each texture of a geometry lies in the colour atlas: shelves of textures, tallest
/// first, in an atlas as wide as the widest texture or the square root of all texels (at
/// most [`MAX_ATLAS_WIDTH`]).
struct AtlasLayout {
    width: u32,
    height: u32,
    origins: Vec<[u32; 2]>,
}

/// The colour atlas's widest row: WebGPU's default 2D texture limit.
const MAX_ATLAS_WIDTH: u32 = 8192;

fn atlas_layout(g: &mirrorbox_scene::Geometry) -> AtlasLayout {
    let textures = &g.textures;
    if textures.is_empty() {
        return AtlasLayout {
            width: 1,
            height: 1,
            origins: Vec::new(),
        };
    }
    let widest = textures.iter().map(|t| t.width).max().unwrap_or(1);
    let texels: u64 = textures
        .iter()
        .map(|t| u64::from(t.width) * u64::from(t.height))
        .sum();
    let width = widest.max(((texels as f64).sqrt().ceil() as u32).min(MAX_ATLAS_WIDTH));
    let mut order: Vec<usize> = (0..textures.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(textures[i].height));
    let mut origins = vec![[0u32; 2]; textures.len()];
    let (mut x, mut y, mut shelf) = (0u32, 0u32, 0u32);
    for i in order {
        let t = &textures[i];
        if x + t.width > width {
            y += shelf;
            x = 0;
            shelf = 0;
        }
        origins[i] = [x, y];
        x += t.width;
        shelf = shelf.max(t.height);
    }
    AtlasLayout {
        width,
        height: y + shelf,
        origins,
    }
}

/// The atlas's texels, sRGB RGBA8 packed little-endian in a u32 each.
fn atlas_texels(g: &mirrorbox_scene::Geometry, layout: &AtlasLayout) -> Vec<u32> {
    let mut texels = vec![0u32; layout.width as usize * layout.height as usize];
    for (t, origin) in g.textures.iter().zip(&layout.origins) {
        for (row, line) in t.texels.chunks_exact(t.width as usize).enumerate() {
            let start = (origin[1] as usize + row) * layout.width as usize + origin[0] as usize;
            for (dst, src) in texels[start..start + line.len()].iter_mut().zip(line) {
                *dst = u32::from_le_bytes(*src);
            }
        }
    }
    texels
}

fn texture_map(
    g: &mirrorbox_scene::Geometry,
    layout: &AtlasLayout,
    map: Option<mirrorbox_scene::texture::TextureMap>,
) -> GpuTextureMap {
    let Some(m) = map else {
        return Zeroable::zeroed();
    };
    let t = &g.textures[m.texture as usize];
    let k = m.transform;
    GpuTextureMap {
        row_u: [k[0], k[1], k[2]],
        present: 1,
        row_v: [k[3], k[4], k[5]],
        wrap: m.wrap[0].code() | m.wrap[1].code() << 4,
        origin: layout.origins[m.texture as usize],
        size: [t.width, t.height],
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct GpuSurface {
    albedo: [f32; 3],
    kind: u32,
    emission: [f32; 3],
    mirror: u32,
    reflectance: [f32; 3],
    _pad0: u32,
    back_albedo: [f32; 3],
    _pad1: u32,
    /// A mirror's frame and bump.
    bump: GpuMirrorBump,
    albedo_map: GpuTextureMap,
    emission_map: GpuTextureMap,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuLight {
    position: [f32; 3],
    first_plane: u32,
    intensity: [f32; 3],
    plane_count: u32,
    /// Light images with shadow maps: their layer's clip-from-world.
    shadow_from_world: [[f32; 4]; 4],
    /// First shadow-map layer (a real light's six cube faces start here).
    shadow_layer: u32,
    /// Light images: the light the chain's previous leg leads to (its index in this list).
    parent: u32,
    /// The layer's texel size in tangent units (slope bias).
    shadow_texel: f32,
    /// Light images: the chain's last mirror (a shadow leg from it skips it).
    mirror: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuFrame {
    ambient: [f32; 3],
    light_count: u32,
    background: [f32; 3],
    /// `--shadow-bias` (scene units).
    shadow_bias: f32,
    terminal: [f32; 3],
    /// 1: every leg is tested against the shadow maps; 0: nothing occludes.
    shadows: u32,
}

/// One vertex: position, the triangle's face normal (the same f32 values the tracer uses)
/// and its surface id.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    surface: u32,
    /// Texture coordinates (location 5: 3 and 4 are the methods' own per-instance data).
    uv: [f32; 2],
}

pub const VERTEX_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: std::mem::size_of::<Vertex>() as u64,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Uint32, 5 => Float32x2],
};

/// Triangle `i` of `g` as three vertices sharing its face normal and surface.
fn triangle_vertices(g: &mirrorbox_scene::Geometry, i: usize) -> [Vertex; 3] {
    let normal = g.face_normal(i).to_array();
    let uv = g.uvs[i];
    let mut k = 0;
    g.triangles[i].map(|p| {
        let v = Vertex {
            position: p.to_array(),
            normal,
            surface: g.surface_of[i],
            uv: uv[k].to_array(),
        };
        k += 1;
        v
    })
}

/// Every triangle of `scene` (objects and mirrors) as one vertex buffer, and its vertex
/// count: what a shadow map draws.
pub fn all_vertices(device: &wgpu::Device, scene: &Scene) -> (wgpu::Buffer, u32) {
    let g = &scene.geometry;
    let mut vertices: Vec<Vertex> = Vec::with_capacity(3 * g.triangles.len());
    for i in 0..g.triangles.len() {
        vertices.extend(triangle_vertices(g, i));
    }
    let count = vertices.len() as u32;
    if vertices.is_empty() {
        vertices.push(Zeroable::zeroed()); // a buffer may not be empty
    }
    let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("shadow map vertices"),
        contents: bytemuck::cast_slice(&vertices),
        usage: wgpu::BufferUsages::VERTEX,
    });
    (buffer, count)
}

/// The scene on the GPU: vertices (objects first, then each mirror's two triangles) and the
/// group-0 bind group of `shading.wgsl`.
pub struct SceneBuffers {
    pub vertices: wgpu::Buffer,
    /// Vertex range of all non-mirror triangles.
    pub objects: std::ops::Range<u32>,
    /// Vertex range of each scene mirror.
    pub mirrors: Vec<std::ops::Range<u32>>,
    /// Vertex range and world-space bounds (min, max) of each non-mirror part, inside `objects`.
    pub parts: Vec<(std::ops::Range<u32>, glam::Vec3, glam::Vec3)>,
    pub layout: wgpu::BindGroupLayout,
    pub bind_group: wgpu::BindGroup,
    /// Whether the drawn geometry has textures: the shader variant its pipelines need
    /// (`Gpu::shader_module`).
    pub textured: bool,
}

impl SceneBuffers {
    /// A frame's memory estimate that starts with these buffers for `g` (the scene's
    /// geometry, or a method's own baked copy): every method uploads them.
    pub fn memory_estimate(
        scene: &Scene,
        g: &mirrorbox_scene::Geometry,
    ) -> crate::memory::MemoryEstimate {
        let mut e = crate::memory::MemoryEstimate::new();
        e.gpu(
            "the scene buffers",
            "the scene's triangles",
            SceneBuffers::memory_bytes(scene, g),
        );
        e
    }

    /// GPU bytes of `scene`'s buffers drawing `g` ([`SceneBuffers::for_geometry`]), before
    /// any is created: the vertex buffer (3 × 36 bytes a triangle), the frame uniform, the
    /// surface, light and light-plane storage buffers, the normal-map atlas and the colour
    /// atlas (4 bytes a texel each), each at [`crate::memory`]'s granularity.
    pub fn memory_bytes(scene: &Scene, g: &mirrorbox_scene::Geometry) -> u64 {
        use crate::memory::{buffer_bytes, texture_bytes};
        let size = |n: usize, each: usize| buffer_bytes((n.max(1) * each) as u64);
        let l = &scene.lighting;
        let planes: usize = l.images.images.iter().map(|i| i.beam.len()).sum();
        let atlas_width = atlas_width(scene);
        size(3 * g.triangles.len(), std::mem::size_of::<Vertex>())
            + size(1, std::mem::size_of::<GpuFrame>())
            + size(g.surfaces.len(), std::mem::size_of::<GpuSurface>())
            + size(
                l.lights.len() + l.images.images.len(),
                std::mem::size_of::<GpuLight>(),
            )
            + size(planes, 16)
            + texture_bytes(atlas_width, atlas_rows(scene), 4)
            + {
                let colour = atlas_layout(g);
                texture_bytes(colour.width, colour.height, 4)
            }
    }

    /// The vertex range of every mesh drawn as it is: each non-mirror part, then each mirror
    /// (the methods that draw the scene once: `ray-query`, `ssr`).
    pub fn draw_ranges(&self) -> Vec<std::ops::Range<u32>> {
        let parts = self.parts.iter().map(|(r, _, _)| r.clone());
        let mirrors = self.mirrors.iter().filter(|r| !r.is_empty()).cloned();
        parts.chain(mirrors).collect()
    }

    /// Refuses a scene whose buffers this device cannot hold, before any is created.
    pub fn check_fits(gpu: &crate::Gpu, scene: &Scene) -> Result<(), crate::RasterError> {
        Self::check_fits_geometry(gpu, scene, &scene.geometry)
    }

    /// [`SceneBuffers::check_fits`] for `scene` drawing `g` instead of its geometry.
    pub fn check_fits_geometry(
        gpu: &crate::Gpu,
        scene: &Scene,
        g: &mirrorbox_scene::Geometry,
    ) -> Result<(), crate::RasterError> {
        let vertices = 3 * g.triangles.len() as u64 * std::mem::size_of::<Vertex>() as u64;
        gpu.check_buffer("vertex", vertices, false)?;
        let surfaces = g.surfaces.len() as u64 * std::mem::size_of::<GpuSurface>() as u64;
        gpu.check_buffer("surface", surfaces, true)?;
        let l = &scene.lighting;
        let count = (l.lights.len() + l.images.images.len()) as u64;
        gpu.check_buffer(
            "light",
            count * std::mem::size_of::<GpuLight>() as u64,
            true,
        )?;
        let planes: usize = l.images.images.iter().map(|i| i.beam.len()).sum();
        gpu.check_buffer("light plane", planes as u64 * 16, true)?;
        // The atlas is one texture: every distinct map's rows stacked.
        let rows = atlas_rows(scene);
        let limit = gpu.device.limits().max_texture_dimension_2d;
        if rows > limit {
            return Err(crate::RasterError::ExceedsDevice {
                what: "the normal-map atlas (every normal map's rows stacked)".into(),
                needed: format!("{rows} rows"),
                limit: format!("{limit} rows"),
                adapter: gpu.report.name.clone(),
                advice: "; use fewer or smaller normal maps",
            });
        }
        let colour = atlas_layout(g);
        if colour.height > limit || colour.width > limit {
            return Err(crate::RasterError::ExceedsDevice {
                what: "the colour-texture atlas (every texture packed in shelves)".into(),
                needed: format!("{}×{} texels", colour.width, colour.height),
                limit: format!("{limit} texels a side"),
                adapter: gpu.report.name.clone(),
                advice: "; use fewer or smaller textures",
            });
        }
        Ok(())
    }

    pub fn new(
        gpu: &crate::Gpu,
        scene: &Scene,
        shadows: crate::shadow_plan::ShadowBinding<'_>,
    ) -> Self {
        Self::for_geometry(gpu, scene, &scene.geometry, shadows)
    }

    /// `scene`'s buffers drawing `g` (its mirror surfaces index `scene.mirrors`) instead of
    /// `scene.geometry`: the symmetry methods draw the objects before the planes, or a fresh
    /// bake.
    pub fn for_geometry(
        gpu: &crate::Gpu,
        scene: &Scene,
        g: &mirrorbox_scene::Geometry,
        shadows: crate::shadow_plan::ShadowBinding<'_>,
    ) -> Self {
        let device = &gpu.device;
        let (bumps, atlas_width, texels) = mirror_bumps(scene);
        let colour_layout = atlas_layout(g);
        let vertex = |i: usize| triangle_vertices(g, i);
        let mut vertices: Vec<Vertex> = Vec::with_capacity(g.triangles.len() * 3);
        let mut mirror_tris = vec![Vec::new(); scene.mirrors.len()];
        for i in 0..g.triangles.len() {
            match g.surface(i) {
                Surface::Diffuse { .. } => vertices.extend(vertex(i)),
                Surface::Mirror { mirror, .. } => mirror_tris[*mirror].push(i),
            }
        }
        let objects = 0..vertices.len() as u32;
        // Diffuse parts are contiguous, in geometry order, inside `objects`.
        let mut parts = Vec::new();
        let mut start = 0u32;
        for part in &g.parts {
            if !matches!(g.surfaces[part.surface as usize], Surface::Diffuse { .. })
                || part.triangles.is_empty()
            {
                continue;
            }
            let tris = &g.triangles[part.triangles.clone()];
            let (lo, hi) = tris.iter().flatten().fold(
                (glam::Vec3::INFINITY, glam::Vec3::NEG_INFINITY),
                |(a, b), p| (a.min(*p), b.max(*p)),
            );
            let end = start + 3 * tris.len() as u32;
            parts.push((start..end, lo, hi));
            start = end;
        }
        let mut mirrors = Vec::new();
        for tris in mirror_tris {
            let start = vertices.len() as u32;
            for i in tris {
                vertices.extend(vertex(i));
            }
            mirrors.push(start..vertices.len() as u32);
        }
        if vertices.is_empty() {
            // An empty scene (camera only) renders its background; a zero-sized buffer
            // cannot be bound, so hold one vertex that no draw range covers.
            vertices.push(Zeroable::zeroed());
        }
        let mut surfaces: Vec<GpuSurface> = g
            .surfaces
            .iter()
            .map(|s| match s {
                Surface::Diffuse {
                    albedo,
                    emission,
                    maps,
                } => GpuSurface {
                    albedo: albedo.to_array(),
                    emission: emission.to_array(),
                    albedo_map: texture_map(g, &colour_layout, maps.albedo),
                    emission_map: texture_map(g, &colour_layout, maps.emission),
                    ..Zeroable::zeroed()
                },
                Surface::Mirror {
                    mirror,
                    reflectance,
                    back_albedo,
                } => GpuSurface {
                    kind: 1,
                    mirror: *mirror as u32,
                    reflectance: reflectance.to_array(),
                    back_albedo: back_albedo.to_array(),
                    bump: bumps[*mirror],
                    ..Zeroable::zeroed()
                },
            })
            .collect();
        // The real lights, then their images with their beams' planes.
        let plan = shadows.plan;
        // The shadow facts of entry `i` of the list (real lights, then images).
        let shadow_of = |i: usize, light: &mut GpuLight| {
            if let Some(s) = plan.map(|p| p.lights[i]) {
                light.shadow_from_world = s.clip_from_world.to_cols_array_2d();
                light.shadow_layer = s.layer;
                light.shadow_texel = s.texel;
            }
        };
        let real = scene.lighting.lights.len();
        let mut lights: Vec<GpuLight> = Vec::new();
        for (i, l) in scene.lighting.lights.iter().enumerate() {
            let mut light = GpuLight {
                position: l.position.to_array(),
                intensity: l.intensity.to_array(),
                ..Zeroable::zeroed()
            };
            shadow_of(i, &mut light);
            lights.push(light);
        }
        let mut planes: Vec<[f32; 4]> = Vec::new();
        for (j, image) in scene.lighting.images.images.iter().enumerate() {
            let mut light = GpuLight {
                position: image.position.to_array(),
                first_plane: planes.len() as u32,
                intensity: image.intensity.to_array(),
                plane_count: image.beam.len() as u32,
                parent: image.parent.map_or(image.light, |p| real + p) as u32,
                mirror: image.mirror as u32,
                ..Zeroable::zeroed()
            };
            shadow_of(real + j, &mut light);
            lights.push(light);
            planes.extend(image.beam.iter().map(|p| p.to_array()));
        }
        if planes.is_empty() {
            planes.push([0.0; 4]); // a storage buffer may not be empty
        }
        if surfaces.is_empty() {
            surfaces.push(Zeroable::zeroed()); // a storage buffer may not be empty
        }
        let light_count = lights.len() as u32;
        if lights.is_empty() {
            lights.push(Zeroable::zeroed()); // a storage buffer may not be empty
        }
        let frame = GpuFrame {
            ambient: scene.lighting.ambient.to_array(),
            light_count,
            background: scene.background.to_array(),
            shadow_bias: plan.map_or(0.0, |p| p.settings.bias),
            terminal: scene.terminal.to_array(),
            shadows: u32::from(plan.is_some()),
        };
        let init = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let vertices_buf = init(
            "vertices",
            bytemuck::cast_slice(&vertices),
            wgpu::BufferUsages::VERTEX,
        );
        let frame_buf = init(
            "frame",
            bytemuck::bytes_of(&frame),
            wgpu::BufferUsages::UNIFORM,
        );
        let surfaces_buf = init(
            "surfaces",
            bytemuck::cast_slice(&surfaces),
            wgpu::BufferUsages::STORAGE,
        );
        let lights_buf = init(
            "lights",
            bytemuck::cast_slice(&lights),
            wgpu::BufferUsages::STORAGE,
        );
        let planes_buf = init(
            "light planes",
            bytemuck::cast_slice(&planes),
            wgpu::BufferUsages::STORAGE,
        );
        let atlas = wgpu::util::DeviceExt::create_texture_with_data(
            device,
            &gpu.queue,
            &wgpu::TextureDescriptor {
                label: Some("normal map atlas"),
                size: wgpu::Extent3d {
                    width: atlas_width,
                    height: texels.len() as u32 / atlas_width,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::R32Uint,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(&texels),
        );
        let atlas_view = atlas.create_view(&Default::default());
        let colour_atlas = wgpu::util::DeviceExt::create_texture_with_data(
            device,
            &gpu.queue,
            &wgpu::TextureDescriptor {
                label: Some("colour texture atlas"),
                size: wgpu::Extent3d {
                    width: colour_layout.width,
                    height: colour_layout.height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::R32Uint,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(&atlas_texels(g, &colour_layout)),
        );
        let colour_view = colour_atlas.create_view(&Default::default());
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty,
            count: None,
        };
        let storage = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let layout = gpu.bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene"),
            entries: &[
                entry(
                    0,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                ),
                entry(1, storage),
                entry(2, storage),
                entry(3, storage),
                entry(
                    4,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                ),
                entry(
                    5,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Uint,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                entry(
                    6,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Uint,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
            ],
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: frame_buf.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: surfaces_buf.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: lights_buf.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: planes_buf.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(shadows.layers),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: wgpu::BindingResource::TextureView(&atlas_view),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: wgpu::BindingResource::TextureView(&colour_view),
                },
            ],
        });
        SceneBuffers {
            vertices: vertices_buf,
            objects,
            mirrors,
            parts,
            layout,
            bind_group,
            textured: g.has_textures(),
        }
    }
}

/// A frame drawn in one pass over the scene with its depth cleared to far (the exact methods
/// `portal` and `unrolled`, and `ray-query`): what its pass is, then what it draws in it.
/// Its [`FrameEncoder`](crate::timing::FrameEncoder) is the one below, so no method writes a
/// pass's preamble of its own.
pub trait OnePassFrame {
    /// The pass this frame draws in.
    fn pass(&self) -> OnePass<'_>;
    /// Everything drawn in the pass (the scene bound at group 0 and the frame's group 1).
    fn draw(&self, pass: &mut wgpu::RenderPass<'_>);
}

/// A frame's one pass: colour cleared to `clear`, `depth` (the frame's own depth(-stencil)
/// view) to far and its stencil to `stencil` where given, `scene` bound at group 0 and
/// `group1` (a bind group and its dynamic offsets) at group 1.
pub struct OnePass<'a> {
    pub scene: &'a SceneBuffers,
    pub label: &'static str,
    pub clear: glam::Vec3,
    pub depth: &'a wgpu::TextureView,
    pub stencil: Option<u32>,
    pub group1: (&'a wgpu::BindGroup, &'a [u32]),
}

impl<T: OnePassFrame> crate::timing::FrameEncoder for T {
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &crate::targets::RenderTarget,
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let p = self.pass();
        let mut pass = target.begin_pass_with(
            encoder,
            p.label,
            p.clear,
            crate::targets::DepthClear {
                view: p.depth,
                depth: crate::projection::FAR_DEPTH,
                stencil: p.stencil,
            },
            first_pass,
        );
        pass.set_bind_group(0, &p.scene.bind_group, &[]);
        pass.set_bind_group(1, p.group1.0, p.group1.1);
        self.draw(&mut pass);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// Mirrors sharing a normal map share one copy of it in the atlas (issue 51: 100 facets
    /// sharing a 256² map needed 25 600 rows and were refused on lavapipe's 16 384).
    #[test]
    fn a_shared_normal_map_is_packed_once() {
        let mirror = |x: f32, map: &str| {
            format!(
                r#"{{ "center": [{x}, 1, 0], "normal": [0, 0, 1], "up": [0, 1, 0], "width": 0.5,
                     "height": 0.5, "bump": {{ "normal_map": {{ "path": "{map}" }} }} }}"#
            )
        };
        let mut mirrors: Vec<String> = (0..100)
            .map(|k| mirror(k as f32, "textures/hammered.png"))
            .collect();
        // Another read of the same image (another spelling of its path): a second copy.
        mirrors.push(mirror(200.0, "textures/../textures/hammered.png"));
        let text = format!(
            r#"{{ "camera": {{ "position": [0, 1, 3], "look_at": [0, 1, 0], "fov_y_deg": 60,
                              "width": 32, "height": 18 }},
                 "mirrors": [{}] }}"#,
            mirrors.join(",")
        );
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/shared.json");
        let scene = mirrorbox_scene::load::parse_scene(&text, &file).unwrap();
        let map_height = 256;
        assert_eq!(atlas_rows(&scene), 2 * map_height);
        let (bumps, width, texels) = mirror_bumps(&scene);
        assert_eq!(texels.len(), (2 * map_height * width) as usize);
        assert!(bumps[..100].iter().all(|b| b.map_offset == 0));
        assert_eq!(bumps[100].map_offset, map_height);
    }
}
