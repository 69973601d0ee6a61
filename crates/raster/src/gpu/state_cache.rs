//! Pipeline state made once per device: bind-group layouts, pipeline layouts and render
//! pipelines, each kept under a key of everything its descriptor says and handed out again
//! to every frame built after on the same device.
//!
//! Why: a render pipeline is where the driver compiles the shaders for their fixed-function
//! state — on lavapipe 5–9 ms each (LLVM), a third of a millisecond on a desktop driver —
//! and a frame is built again for every camera position `mirrorbox view` draws while
//! walking (the plan depends on the camera), for every point of a sweep and every test.
//! Engines keep such a cache for the same reason (Bevy's `PipelineCache`, Unreal's PSO
//! cache); the states it holds are the same objects wgpu would create, so a cached
//! pipeline draws what a new one would.
//!
//! The keys hold the layouts and shader modules themselves (wgpu compares them by
//! identity): a pipeline layout made of cached bind-group layouts is itself found again, and
//! a render pipeline over a cached layout and a cached module ([`crate::Gpu::shader_module`])
//! too. Descriptors with pipeline-overridable constants are not cached (none of the methods
//! has one). A pipeline that fails validation is kept like any other: its error surfaces
//! when it is made (the build's `gpu.check()`), and a later frame drawing it fails on it. The cache only grows, by one entry per distinct state: a few dozen per method
//! and option combination drawn in the process.

// The one place the device makes these states (clippy.toml refuses them elsewhere).
#![allow(clippy::disallowed_methods)]

use std::collections::HashMap;
use std::hash::Hash;
use std::sync::Mutex;

#[derive(Clone, PartialEq, Eq, Hash)]
struct BindGroupLayoutKey {
    label: Option<String>,
    entries: Vec<wgpu::BindGroupLayoutEntry>,
}

#[derive(Clone, PartialEq, Eq, Hash)]
struct PipelineLayoutKey {
    label: Option<String>,
    groups: Vec<Option<wgpu::BindGroupLayout>>,
    immediate_size: u32,
}

#[derive(Clone, PartialEq, Eq, Hash)]
struct VertexBufferKey {
    array_stride: u64,
    step_mode: wgpu::VertexStepMode,
    attributes: Vec<wgpu::VertexAttribute>,
}

#[derive(Clone, PartialEq, Eq, Hash)]
struct StageKey {
    module: wgpu::ShaderModule,
    entry_point: Option<String>,
    zero_initialize_workgroup_memory: bool,
}

#[derive(Clone, PartialEq, Eq, Hash)]
struct RenderPipelineKey {
    label: Option<String>,
    layout: Option<wgpu::PipelineLayout>,
    vertex: StageKey,
    buffers: Vec<Option<VertexBufferKey>>,
    primitive: wgpu::PrimitiveState,
    depth_stencil: Option<wgpu::DepthStencilState>,
    multisample: wgpu::MultisampleState,
    fragment: Option<(StageKey, Vec<Option<wgpu::ColorTargetState>>)>,
    multiview_mask: Option<std::num::NonZeroU32>,
}

/// How many states were made and how many found again (the tests hold a moved camera to
/// none made).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StateCounts {
    pub made: u64,
    pub reused: u64,
}

/// The cache; one per [`crate::Gpu`].
#[derive(Default)]
pub struct StateCache {
    bind_group_layouts: Mutex<HashMap<BindGroupLayoutKey, wgpu::BindGroupLayout>>,
    pipeline_layouts: Mutex<HashMap<PipelineLayoutKey, wgpu::PipelineLayout>>,
    render_pipelines: Mutex<HashMap<RenderPipelineKey, wgpu::RenderPipeline>>,
    counts: Mutex<StateCounts>,
}

impl StateCache {
    pub fn counts(&self) -> StateCounts {
        *lock(&self.counts)
    }

    fn find_or_make<K: Eq + Hash, V: Clone>(
        &self,
        map: &Mutex<HashMap<K, V>>,
        key: K,
        make: impl FnOnce() -> V,
    ) -> V {
        // Made outside the lock: two threads asking at once may both make it (the second
        // one's kept), never wait on each other's compile.
        if let Some(found) = lock(map).get(&key) {
            lock(&self.counts).reused += 1;
            return found.clone();
        }
        let made = make();
        lock(&self.counts).made += 1;
        lock(map).entry(key).or_insert(made).clone()
    }

    pub fn bind_group_layout(
        &self,
        device: &wgpu::Device,
        desc: &wgpu::BindGroupLayoutDescriptor,
    ) -> wgpu::BindGroupLayout {
        let key = BindGroupLayoutKey {
            label: desc.label.map(str::to_owned),
            entries: desc.entries.to_vec(),
        };
        self.find_or_make(&self.bind_group_layouts, key, || {
            device.create_bind_group_layout(desc)
        })
    }

    pub fn pipeline_layout(
        &self,
        device: &wgpu::Device,
        desc: &wgpu::PipelineLayoutDescriptor,
    ) -> wgpu::PipelineLayout {
        let key = PipelineLayoutKey {
            label: desc.label.map(str::to_owned),
            groups: desc.bind_group_layouts.iter().map(|g| g.cloned()).collect(),
            immediate_size: desc.immediate_size,
        };
        self.find_or_make(&self.pipeline_layouts, key, || {
            device.create_pipeline_layout(desc)
        })
    }

    pub fn render_pipeline(
        &self,
        device: &wgpu::Device,
        desc: &wgpu::RenderPipelineDescriptor,
    ) -> wgpu::RenderPipeline {
        let Some(key) = render_pipeline_key(desc) else {
            lock(&self.counts).made += 1;
            return device.create_render_pipeline(desc);
        };
        self.find_or_make(&self.render_pipelines, key, || {
            device.create_render_pipeline(desc)
        })
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Everything `desc` says, or `None` where it cannot be keyed (overridable constants, an
/// explicit driver pipeline cache).
fn render_pipeline_key(desc: &wgpu::RenderPipelineDescriptor) -> Option<RenderPipelineKey> {
    let stage = |module: &wgpu::ShaderModule,
                 entry: Option<&str>,
                 options: &wgpu::PipelineCompilationOptions| {
        options.constants.is_empty().then(|| StageKey {
            module: module.clone(),
            entry_point: entry.map(str::to_owned),
            zero_initialize_workgroup_memory: options.zero_initialize_workgroup_memory,
        })
    };
    if desc.cache.is_some() {
        return None;
    }
    let vertex = stage(
        desc.vertex.module,
        desc.vertex.entry_point,
        &desc.vertex.compilation_options,
    )?;
    let fragment = match &desc.fragment {
        None => None,
        Some(f) => Some((
            stage(f.module, f.entry_point, &f.compilation_options)?,
            f.targets.to_vec(),
        )),
    };
    Some(RenderPipelineKey {
        label: desc.label.map(str::to_owned),
        layout: desc.layout.cloned(),
        vertex,
        buffers: desc
            .vertex
            .buffers
            .iter()
            .map(|b| {
                b.as_ref().map(|b| VertexBufferKey {
                    array_stride: b.array_stride,
                    step_mode: b.step_mode,
                    attributes: b.attributes.to_vec(),
                })
            })
            .collect(),
        primitive: desc.primitive,
        depth_stencil: desc.depth_stencil.clone(),
        multisample: desc.multisample,
        fragment,
        multiview_mask: desc.multiview_mask,
    })
}
