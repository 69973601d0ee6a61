//! The pieces of wgpu set-up every method shares: the scene-pipeline builder, a uniform
//! arena for dynamic offsets, and bind-group layout entries.
//!
//! Every scene pipeline draws linear radiance into a target of the device's colour format
//! ([`crate::targets::ColorFormat`]), with culling
//! off (reflections flip the winding and shading is two-sided, `docs/shading.md`) — except
//! where a method knows back faces cannot be seen first
//! ([`ScenePipeline::build_culling_back_faces`]) — and no
//! multisampling (supersampling is the SSAA grid); what differs between methods is the shader
//! entry points, the vertex buffers, the depth/stencil state and which colours are written.

use crate::gpu::Gpu;
use bytemuck::Pod;
use wgpu::util::DeviceExt;

/// One scene pipeline. Build with [`ScenePipeline::build`]; labels show in captures and in
/// validation errors.
pub struct ScenePipeline<'a> {
    pub label: &'a str,
    pub layout: &'a wgpu::PipelineLayout,
    pub module: &'a wgpu::ShaderModule,
    pub vertex: &'a str,
    pub fragment: &'a str,
    pub buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    pub depth_stencil: wgpu::DepthStencilState,
    /// Colour channels written (none for stencil-only passes).
    pub color_writes: wgpu::ColorWrites,
}

impl ScenePipeline<'_> {
    /// The pipeline on `gpu`, drawing into its colour format, culling nothing.
    pub fn build(&self, gpu: &Gpu) -> wgpu::RenderPipeline {
        self.build_with(gpu, None, wgpu::FrontFace::Ccw)
    }

    /// The pipeline culling back faces, a triangle's front being where it winds as
    /// `front_face` says on screen. Only for closed meshes with the eye outside, where the
    /// first surface along every ray is a front face (the symmetry methods; a reflected copy
    /// winds the other way, `Cw`).
    pub fn build_culling_back_faces(
        &self,
        gpu: &Gpu,
        front_face: wgpu::FrontFace,
    ) -> wgpu::RenderPipeline {
        self.build_with(gpu, Some(wgpu::Face::Back), front_face)
    }

    fn build_with(
        &self,
        gpu: &Gpu,
        cull_mode: Option<wgpu::Face>,
        front_face: wgpu::FrontFace,
    ) -> wgpu::RenderPipeline {
        gpu.render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(self.label),
            layout: Some(self.layout),
            vertex: wgpu::VertexState {
                module: self.module,
                entry_point: Some(self.vertex),
                compilation_options: Default::default(),
                buffers: self.buffers,
            },
            primitive: wgpu::PrimitiveState {
                cull_mode,
                front_face,
                ..Default::default()
            },
            depth_stencil: Some(self.depth_stencil.clone()),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: self.module,
                entry_point: Some(self.fragment),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: gpu.color_format.texture_format(),
                    blend: None,
                    write_mask: self.color_writes,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}

/// A pipeline drawing one full-screen (or full-viewport) triangle with `module`'s `vs_main`,
/// shaded by its `fs_main` into a `format` target, without depth: the SSAA resolve and the
/// viewer's display tone map.
pub fn full_screen_pipeline(
    gpu: &Gpu,
    label: &str,
    groups: &[&wgpu::BindGroupLayout],
    module: &wgpu::ShaderModule,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    let layout = pipeline_layout(gpu, label, groups);
    gpu.render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A depth (or depth-stencil) state without bias.
pub fn depth_state(
    format: wgpu::TextureFormat,
    write: bool,
    compare: wgpu::CompareFunction,
    stencil: wgpu::StencilState,
) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil,
        bias: Default::default(),
    }
}

/// A labelled pipeline layout over `groups` (bind groups 0, 1, …), made once per device.
pub fn pipeline_layout(
    gpu: &Gpu,
    label: &str,
    groups: &[&wgpu::BindGroupLayout],
) -> wgpu::PipelineLayout {
    let groups: Vec<Option<&wgpu::BindGroupLayout>> = groups.iter().map(|g| Some(*g)).collect();
    gpu.pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &groups,
        immediate_size: 0,
    })
}

/// A buffer binding read by the fragment stage at a fixed offset: a uniform, or a read-only
/// storage buffer (full-screen passes: the resolve, the display tone map).
pub fn fragment_buffer_entry(
    binding: u32,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A uniform-buffer binding of one record, read at a dynamic offset.
pub fn dynamic_uniform_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: true,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A bind group and its layout from one list of bindings, each binding's type and resource
/// written once, side by side, numbered from 0 in the order given (in the spirit of kajiya's
/// pass builder: a method says what it binds, the builder writes the layout entries and the
/// group entries that must agree). The layout is made through the device's cache.
///
/// ```ignore
/// let (layout, group) = BindGroupBuilder::new("portal path")
///     .record::<PathUniform>(wgpu::ShaderStages::VERTEX_FRAGMENT, &uniforms)
///     .build(gpu);
/// ```
pub struct BindGroupBuilder<'a> {
    label: &'static str,
    entries: Vec<wgpu::BindGroupLayoutEntry>,
    resources: Vec<wgpu::BindingResource<'a>>,
}

impl<'a> BindGroupBuilder<'a> {
    pub fn new(label: &'static str) -> Self {
        BindGroupBuilder {
            label,
            entries: Vec::new(),
            resources: Vec::new(),
        }
    }

    /// The next binding: `ty`, seen by `visibility`, bound to `resource`.
    pub fn binding(
        mut self,
        visibility: wgpu::ShaderStages,
        ty: wgpu::BindingType,
        resource: wgpu::BindingResource<'a>,
    ) -> Self {
        self.entries.push(wgpu::BindGroupLayoutEntry {
            binding: self.entries.len() as u32,
            visibility,
            ty,
            count: None,
        });
        self.resources.push(resource);
        self
    }

    /// One `T` record of a [`UniformArena`]'s buffer, read at a dynamic offset.
    pub fn record<T>(self, visibility: wgpu::ShaderStages, arena: &'a wgpu::Buffer) -> Self {
        let ty = dynamic_uniform_entry(0, visibility).ty;
        self.binding(visibility, ty, record_binding::<T>(arena))
    }

    /// A whole buffer: a uniform, or a storage buffer (read-only unless `read_only` is false).
    pub fn buffer(
        self,
        visibility: wgpu::ShaderStages,
        ty: wgpu::BufferBindingType,
        buffer: &'a wgpu::Buffer,
    ) -> Self {
        self.binding(
            visibility,
            wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            buffer.as_entire_binding(),
        )
    }

    /// A read-only storage buffer.
    pub fn storage(self, visibility: wgpu::ShaderStages, buffer: &'a wgpu::Buffer) -> Self {
        self.buffer(
            visibility,
            wgpu::BufferBindingType::Storage { read_only: true },
            buffer,
        )
    }

    /// A 2D texture of floats read with `textureLoad` or a non-filtering sampler.
    pub fn texture(self, visibility: wgpu::ShaderStages, view: &'a wgpu::TextureView) -> Self {
        self.binding(
            visibility,
            wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            wgpu::BindingResource::TextureView(view),
        )
    }

    /// The layout alone, as [`BindGroupBuilder::build`] makes it.
    pub fn layout(&self, gpu: &Gpu) -> wgpu::BindGroupLayout {
        gpu.bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(self.label),
            entries: &self.entries,
        })
    }

    /// The layout (from the device's cache) and the bind group.
    pub fn build(self, gpu: &Gpu) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
        let layout = self.layout(gpu);
        let entries: Vec<wgpu::BindGroupEntry> = self
            .resources
            .into_iter()
            .enumerate()
            .map(|(i, resource)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource,
            })
            .collect();
        let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.label),
            layout: &layout,
            entries: &entries,
        });
        (layout, group)
    }
}

/// Uniform records packed into one buffer at the device's offset alignment, each bound by
/// its dynamic offset (one buffer and bind group for all passes or paths of a frame).
pub struct UniformArena {
    alignment: usize,
    bytes: Vec<u8>,
    /// The records' extent; `bytes` holds them only when `keeps_records`.
    len: usize,
    /// False for a memory estimate's arena, which counts without storing (issue 51: the
    /// estimate of 4 000 mirrors' `naive` frame stored 3.8 GB of uniforms to refuse it).
    keeps_records: bool,
}

impl UniformArena {
    pub fn new(device: &wgpu::Device) -> Self {
        UniformArena {
            keeps_records: true,
            ..Self::with_alignment(device.limits().min_uniform_buffer_offset_alignment as usize)
        }
    }

    /// An arena with records `alignment` bytes apart, without a device, that only counts: a
    /// memory estimate ([`crate::memory`]) lays the records out at the largest alignment a
    /// device may ask, and needs their extent, not their bytes.
    pub fn with_alignment(alignment: usize) -> Self {
        UniformArena {
            alignment,
            bytes: Vec::new(),
            len: 0,
            keeps_records: false,
        }
    }

    /// Whether the records' bytes are kept (a device's arena), or only counted.
    pub fn keeps_records(&self) -> bool {
        self.keeps_records
    }

    /// The size of the buffer [`UniformArena::buffer`] would create.
    pub fn buffer_size(&self) -> u64 {
        self.len.max(self.alignment.max(16)) as u64
    }

    /// Appends `value`; returns its dynamic offset.
    pub fn push<T: Pod>(&mut self, value: &T) -> u32 {
        let offset = self.len.next_multiple_of(self.alignment);
        self.len = offset + std::mem::size_of::<T>();
        if self.keeps_records {
            self.bytes.resize(offset, 0);
            self.bytes.extend_from_slice(bytemuck::bytes_of(value));
        }
        offset as u32
    }

    /// The buffer holding every record pushed (at least one aligned block).
    pub fn buffer(&self, device: &wgpu::Device, label: &str) -> wgpu::Buffer {
        // A buffer may not be empty.
        let empty = vec![0; self.alignment.max(16)];
        let bytes = if self.bytes.is_empty() {
            &empty
        } else {
            &self.bytes
        };
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytes,
            usage: wgpu::BufferUsages::UNIFORM,
        })
    }
}

/// The binding of one `T` record of an arena's buffer, at a dynamic offset.
pub fn record_binding<T>(buffer: &wgpu::Buffer) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer,
        offset: 0,
        size: std::num::NonZeroU64::new(std::mem::size_of::<T>() as u64),
    })
}
