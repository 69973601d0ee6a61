//! The device every raster method renders with, and the errors a raster command can meet.

use crate::adapter::{AdapterError, AdapterReport, select_adapter_from};
use crate::color_format::{COLOR_FORMAT_ENV, ColorFormat};
use std::sync::{Arc, Mutex};

#[derive(Debug, thiserror::Error)]
pub enum RasterError {
    #[error(transparent)]
    Adapter(#[from] AdapterError),
    #[error(transparent)]
    Plan(#[from] crate::plan::PlanError),
    #[error("cannot create the wgpu device on {adapter}: {message}")]
    Device { adapter: String, message: String },
    #[error("{COLOR_FORMAT_ENV}={value:?} names no colour format (use rgba32float or rgba16float)")]
    BadColorFormat { value: String },
    #[error("wgpu reported an error: {0}")]
    Gpu(String),
    /// A resource this frame needs is larger than the device allows (checked before it is
    /// created).
    #[error("this frame needs {what} of {needed}, more than {adapter} allows ({limit}){advice}")]
    ExceedsDevice {
        what: String,
        needed: String,
        limit: String,
        adapter: String,
        advice: &'static str,
    },
    #[error("{} needs {feature}, which {adapter} lacks", needed_by(method))]
    MissingFeature {
        method: &'static str,
        feature: String,
        adapter: String,
    },
}

/// Who needs a method's feature, in the words of the command the user typed: `ray-query` is
/// also `trace --device gpu`'s tracer (whose users never wrote `--method`).
fn needed_by(method: &str) -> String {
    if method == "ray-query" {
        "`--method ray-query` (and `trace --device gpu`, which traces with it)".into()
    } else {
        format!("`--method {method}`")
    }
}

/// Adapter features in words, for messages: the ones the methods need named, any other by
/// wgpu's name (its `Debug` had printed the struct: `Features { features_wgpu: … }`).
pub fn feature_names(features: wgpu::Features) -> String {
    let known = [
        (
            wgpu::Features::EXPERIMENTAL_RAY_QUERY,
            "ray queries (EXPERIMENTAL_RAY_QUERY)",
        ),
        (
            wgpu::Features::CLIP_DISTANCES,
            "clip distances (CLIP_DISTANCES)",
        ),
        (
            wgpu::Features::TIMESTAMP_QUERY,
            "timestamp queries (TIMESTAMP_QUERY)",
        ),
    ];
    let mut names: Vec<String> = known
        .iter()
        .filter(|(f, _)| features.contains(*f))
        .map(|(_, name)| name.to_string())
        .collect();
    let rest = known.iter().fold(features, |left, (f, _)| left - *f);
    if !rest.is_empty() {
        names.push(format!("{rest:?}"));
    }
    names.join(", ")
}

impl RasterError {
    /// Whether the user's input was refused (exit 2) rather than the device failing (exit 1).
    pub fn is_refusal(&self) -> bool {
        matches!(
            self,
            RasterError::Plan(_)
                | RasterError::ExceedsDevice { .. }
                | RasterError::Adapter(AdapterError::BadOverride { .. })
                | RasterError::BadColorFormat { .. }
        )
    }
}

/// What to open, where the environment should not decide: the backends to try and the
/// colour format. `None` leaves each to the environment (`WGPU_BACKEND`,
/// `MIRRORBOX_COLOR_FORMAT`) and then to the defaults (Vulkan, then GL; the best colour
/// format the adapter has).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuOptions {
    pub backends: Option<wgpu::Backends>,
    pub color_format: Option<ColorFormat>,
}

pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub report: AdapterReport,
    /// The format of every colour target and mirror texture on this device.
    pub color_format: ColorFormat,
    /// GPU timestamps are available (and enabled) on this device.
    pub timestamps: bool,
    /// The features enabled on this device: timestamps where available, and every feature
    /// a registered method needs or can use that the adapter has.
    pub features: wgpu::Features,
    errors: Arc<Mutex<Vec<String>>>,
    /// Shader modules compiled on this device, by source ([`Gpu::shader_module`]).
    modules: Mutex<std::collections::HashMap<(usize, bool), wgpu::ShaderModule>>,
    /// Layouts and render pipelines made on this device ([`crate::state_cache`]).
    pub states: crate::state_cache::StateCache,
}

/// wgpu's defaults, raised to what the adapter offers for image sizes and buffer sizes (the
/// default 256 MiB buffer holds only 3 M triangles; the scene limit is 4 M).
/// With ray queries (`ray-query`), the adapter's acceleration-structure limits too (wgpu's
/// defaults are 0).
fn device_limits(adapter: &wgpu::Limits, features: wgpu::Features) -> wgpu::Limits {
    let mut limits = wgpu::Limits {
        max_buffer_size: adapter.max_buffer_size,
        max_storage_buffer_binding_size: adapter.max_storage_buffer_binding_size,
        max_texture_array_layers: adapter.max_texture_array_layers,
        ..wgpu::Limits::default().using_resolution(adapter.clone())
    };
    if features.contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY) {
        limits.max_blas_primitive_count = adapter.max_blas_primitive_count;
        limits.max_blas_geometry_count = adapter.max_blas_geometry_count;
        limits.max_tlas_instance_count = adapter.max_tlas_instance_count;
        limits.max_acceleration_structures_per_shader_stage =
            adapter.max_acceleration_structures_per_shader_stage;
    }
    limits
}

impl Gpu {
    /// Refuses a buffer of `bytes` for `what` that this device cannot hold.
    pub fn check_buffer(&self, what: &str, bytes: u64, storage: bool) -> Result<(), RasterError> {
        let limits = self.device.limits();
        let limit = if storage {
            limits
                .max_storage_buffer_binding_size
                .min(limits.max_buffer_size)
        } else {
            limits.max_buffer_size
        };
        if bytes > limit {
            return Err(RasterError::ExceedsDevice {
                what: format!("a {what} buffer"),
                needed: mirrorbox_files::human_bytes(bytes),
                limit: mirrorbox_files::human_bytes(limit),
                adapter: self.report.name.clone(),
                advice: "; use fewer triangles",
            });
        }
        Ok(())
    }

    /// Refuses a render target of `width × height` beyond the device's largest texture,
    /// saying `advice` (the flags that set its size: a mirror texture's are not `--ssaa`'s).
    pub fn check_target(
        &self,
        width: u32,
        height: u32,
        advice: &'static str,
    ) -> Result<(), RasterError> {
        let limit = self.device.limits().max_texture_dimension_2d;
        if width.max(height) > limit {
            return Err(RasterError::ExceedsDevice {
                what: "a render target".into(),
                needed: format!("{width}×{height} pixels"),
                limit: format!("{limit} pixels per side"),
                adapter: self.report.name.clone(),
                advice,
            });
        }
        Ok(())
    }

    /// Opens the adapter `options` (or the environment) selects, with those of `wanted` (and
    /// timestamp queries) that it has, and chooses its colour format (see [`ColorFormat`]).
    pub fn open(wanted: wgpu::Features, options: GpuOptions) -> Result<Gpu, RasterError> {
        let forced = match options.color_format {
            Some(f) => Some(f),
            None => {
                ColorFormat::from_env().map_err(|value| RasterError::BadColorFormat { value })?
            }
        };
        let selected = select_adapter_from(options.backends)?;
        Gpu::open_adapter(selected, wanted, forced)
    }

    /// Opens `selected` (chosen by [`crate::adapter`]'s rule) as [`Gpu::open`] does, with the
    /// colour format `forced` or the best the adapter has.
    pub fn open_adapter(
        selected: crate::adapter::SelectedAdapter,
        wanted: wgpu::Features,
        forced: Option<ColorFormat>,
    ) -> Result<Gpu, RasterError> {
        // Once per process: an old lavapipe still renders, but may need gigabytes.
        static WARNED: std::sync::Once = std::sync::Once::new();
        if let Some(warning) = selected.report.platform_warning() {
            WARNED.call_once(|| eprintln!("warning: {warning}"));
        }
        let color_format = ColorFormat::choose(&selected.adapter, forced).map_err(|message| {
            RasterError::Device {
                adapter: format!("{} ({})", selected.report.name, selected.report.backend),
                message,
            }
        })?;
        let timestamps = selected.report.timestamp_query;
        let features = (wanted | wgpu::Features::TIMESTAMP_QUERY)
            & selected.adapter.features()
            & !unsafe_on(selected.adapter.get_info().backend);
        let (device, queue) =
            pollster::block_on(selected.adapter.request_device(&wgpu::DeviceDescriptor {
                label: Some("mirrorbox"),
                required_features: features,
                required_limits: device_limits(&selected.adapter.limits(), features),
                // wgpu's ray queries are experimental: they must be opted into
                // (`ray-query`, `trace --device gpu`; issue 39 records what was checked).
                experimental_features: if features.contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY)
                {
                    // SAFETY: only the ray-query method and the GPU truth use the feature,
                    // and their images are tested against the CPU truth.
                    unsafe { wgpu::ExperimentalFeatures::enabled() }
                } else {
                    wgpu::ExperimentalFeatures::disabled()
                },
                ..Default::default()
            }))
            .map_err(|e| RasterError::Device {
                adapter: selected.report.name.clone(),
                message: e.to_string(),
            })?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        // Validation errors become a returned error instead of wgpu's default panic.
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            sink.lock().expect("error list").push(e.to_string());
        }));
        Ok(Gpu {
            device,
            queue,
            report: selected.report,
            color_format,
            timestamps,
            features,
            errors,
            modules: Mutex::default(),
            states: Default::default(),
        })
    }

    /// `shader` compiled on this device, once: every build of a frame asks for its modules,
    /// and a sweep, the viewer and the tests build many frames on one device; naga's parse,
    /// validation and SPIR-V output run once per source (keyed by the static's address,
    /// every [`crate::wgsl::WgslSource`] being a `static`).
    ///
    /// `textured`: whether the scene drawn has textures (`WgslSource::source`): a module
    /// without the texture lookups compiles about 30 % faster on lavapipe (measured), so each
    /// variant is built only where it is drawn.
    pub fn shader_module(
        &self,
        shader: &'static crate::wgsl::WgslSource,
        textured: bool,
    ) -> wgpu::ShaderModule {
        let key = (std::ptr::from_ref(shader) as usize, textured);
        let mut modules = self.modules.lock().unwrap_or_else(|e| e.into_inner());
        modules
            .entry(key)
            .or_insert_with(|| crate::wgsl::shader_module(&self.device, shader, textured))
            .clone()
    }

    /// A bind-group layout as `desc` describes it, made once per device
    /// ([`crate::state_cache`]).
    pub fn bind_group_layout(
        &self,
        desc: &wgpu::BindGroupLayoutDescriptor,
    ) -> wgpu::BindGroupLayout {
        self.states.bind_group_layout(&self.device, desc)
    }

    /// A pipeline layout as `desc` describes it, made once per device.
    pub fn pipeline_layout(&self, desc: &wgpu::PipelineLayoutDescriptor) -> wgpu::PipelineLayout {
        self.states.pipeline_layout(&self.device, desc)
    }

    /// A render pipeline as `desc` describes it, compiled once per device: a frame built
    /// again (a moved camera in `view`, the next point of a sweep) finds it.
    pub fn render_pipeline(&self, desc: &wgpu::RenderPipelineDescriptor) -> wgpu::RenderPipeline {
        self.states.render_pipeline(&self.device, desc)
    }

    /// Fails with the first error wgpu reported since the last check.
    pub fn check(&self) -> Result<(), RasterError> {
        let mut errors = self.errors.lock().expect("error list");
        match errors.first().cloned() {
            Some(e) => {
                errors.clear();
                Err(RasterError::Gpu(e))
            }
            None => Ok(()),
        }
    }

    /// Blocks until all submitted work is done.
    pub fn wait(&self) -> Result<(), RasterError> {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| RasterError::Gpu(e.to_string()))
    }
}

/// Features a backend has but draws wrongly, left off so that the methods take their other
/// path. GL: wgpu-hal 30 tracks the enabled clip distances per command buffer, which GL keeps
/// across them; after a method whose last pipeline clipped (`unrolled`), every later draw
/// without clip distances ran with them enabled and drew an almost empty frame (a `sweep` of
/// `naive,unrolled` on GL: the floor's FLIP 1.6e-1 instead of 7.7e-4). Without the feature the
/// methods clip in the fragment shader (the same images, tested on Vulkan).
pub fn unsafe_on(backend: wgpu::Backend) -> wgpu::Features {
    match backend {
        wgpu::Backend::Gl => wgpu::Features::CLIP_DISTANCES,
        _ => wgpu::Features::empty(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::PlanError;

    /// Every refusal of an input is exit 2, every device failure exit 1 (the CLI maps
    /// `is_refusal`); a new variant must be placed on one side here.
    #[test]
    fn refusals_and_device_failures_are_told_apart() {
        let refusals = [
            PlanError::NoMirrorToAlternateWith(1),
            PlanError::TooManyPaths { limit: 1 },
            PlanError::TooManyTriangles {
                triangles: 2,
                limit: 1,
            },
            PlanError::TooManyPasses {
                predicted: 2,
                limit: 1,
                exceeded_count: false,
            },
            PlanError::StencilTooDeep(255),
        ];
        for p in refusals {
            assert!(RasterError::Plan(p).is_refusal());
        }
        assert!(RasterError::Adapter(AdapterError::BadOverride { value: "x".into() }).is_refusal());
        assert!(RasterError::BadColorFormat { value: "x".into() }.is_refusal());
        let failures = [
            RasterError::Device {
                adapter: "a".into(),
                message: "m".into(),
            },
            RasterError::Gpu("lost".into()),
            RasterError::MissingFeature {
                method: "m",
                feature: "f".into(),
                adapter: "a".into(),
            },
        ];
        for f in failures {
            assert!(!f.is_refusal(), "{f}");
        }
    }
}
