//! Adapter selection: one rule for every command, so `mirrorbox info` reports exactly the
//! adapter that `render` and `sweep` will time.
//!
//! Order: the backends named by `WGPU_BACKEND` (e.g. `vulkan`, `gl`) when it is set;
//! otherwise Vulkan, then GL. Within a backend wgpu's high-performance preference decides
//! (a real GPU before a CPU rasterizer).

use std::fmt;

/// The chosen adapter with the instance that owns it.
pub struct SelectedAdapter {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub report: AdapterReport,
}

/// What an adapter is and which of the features mirrorbox relies on it has.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AdapterReport {
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    pub driver_info: String,
    /// GPU timestamps at pass boundaries (`Features::TIMESTAMP_QUERY`).
    pub timestamp_query: bool,
    /// Timestamps inside encoders and passes (finer-grained timing).
    pub timestamp_query_inside_passes: bool,
    /// `clip_distances` in WGSL (the unrolled method clips with them; otherwise it discards).
    pub clip_distances: bool,
    /// Multiview render passes (`Features::MULTIVIEW`: one pass draws both eyes of a stereo
    /// pair into a two-layer target). Reported, not used: `--stereo` renders each eye's
    /// passes one after the other (docs/methods.md, "Stereo mirrors").
    pub multiview: bool,
    /// Ray queries in shaders (`Features::EXPERIMENTAL_RAY_QUERY`; Mesa ≥ 25's lavapipe has
    /// them). Reported for the methods that will trace on the GPU.
    pub ray_query: bool,
}

/// The oldest Mesa whose lavapipe mirrorbox supports: Mesa 22.3's keeps the memory of every
/// executed render pass until the process exits (a 32×18 `auxiliary --n 2` render of
/// `mirror_room` peaked at 18.3 GB there, 235 MB on 25.0.7, the same image bit for bit).
pub const MIN_MESA: (u32, u32) = (25, 0);

/// The Mesa version `(major, minor, patch)` named in a driver description such as
/// `Mesa 25.0.7-2~bpo12+1 (LLVM 19.1.7)`; `None` when it names no Mesa.
pub fn mesa_version(driver_info: &str) -> Option<(u32, u32, u32)> {
    let rest = &driver_info[driver_info.find("Mesa ")? + 5..];
    let token: String = rest
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect();
    let mut parts = token.split('.').map(|p| p.parse::<u32>().ok());
    let major = parts.next()??;
    let minor = parts.next().flatten().unwrap_or(0);
    let patch = parts.next().flatten().unwrap_or(0);
    Some((major, minor, patch))
}

/// Whether Mesa's on-disk shader cache is off in this process (`MESA_SHADER_CACHE_DISABLE`).
pub fn mesa_shader_cache_disabled() -> bool {
    shader_cache_disabled_by(std::env::var("MESA_SHADER_CACHE_DISABLE").ok().as_deref())
}

/// Whether a value of `MESA_SHADER_CACHE_DISABLE` turns Mesa's disk cache off, read as Mesa
/// reads a boolean option: `1`, `true`, `yes`, `y`, `t` in any case; anything else or unset
/// leaves it on.
pub fn shader_cache_disabled_by(value: Option<&str>) -> bool {
    value.is_some_and(|v| {
        matches!(
            v.trim().to_ascii_lowercase().as_str(),
            "1" | "true" | "yes" | "y" | "t"
        )
    })
}

impl AdapterReport {
    /// For a Mesa driver, whether its on-disk shader cache is on: shaders lavapipe loads from
    /// there run slower than those it compiles (Mesa 25.0.7: `portal` depth 64 1.7×, issue
    /// 54, docs/budgets.md), so a timing must say which it had. `None` for other drivers.
    pub fn shader_cache(&self) -> Option<&'static str> {
        mesa_version(&format!("{} {}", self.driver, self.driver_info))?;
        Some(if mesa_shader_cache_disabled() {
            "Mesa's disk shader cache off"
        } else {
            "Mesa's disk shader cache on"
        })
    }

    /// Whether this is Mesa's CPU rasterizer (lavapipe on Vulkan, llvmpipe on GL).
    pub fn is_llvmpipe(&self) -> bool {
        self.name.contains("llvmpipe")
    }

    /// A warning when the adapter is a Mesa CPU driver older than [`MIN_MESA`], naming the
    /// fix; `None` otherwise.
    pub fn platform_warning(&self) -> Option<String> {
        if !self.is_llvmpipe() {
            return None;
        }
        let found = mesa_version(&format!("{} {}", self.driver, self.driver_info));
        let old = found.is_none_or(|(major, minor, _)| (major, minor) < MIN_MESA);
        old.then(|| {
            let version = found.map_or_else(
                || "an unknown Mesa".to_string(),
                |(a, b, c)| format!("Mesa {a}.{b}.{c}"),
            );
            format!(
                "{} runs on {version}; mirrorbox needs Mesa >= {}.{} (older lavapipe keeps \
                 the memory of every render pass: gigabytes for a small render). Install it \
                 with scripts/install-system-deps.sh (Debian 12: bookworm-backports).",
                self.name, MIN_MESA.0, MIN_MESA.1
            )
        })
    }

    fn of(adapter: &wgpu::Adapter) -> Self {
        let info = adapter.get_info();
        let features = adapter.features();
        AdapterReport {
            name: info.name,
            backend: info.backend.to_string(),
            device_type: format!("{:?}", info.device_type),
            driver: info.driver,
            driver_info: info.driver_info,
            timestamp_query: features.contains(wgpu::Features::TIMESTAMP_QUERY),
            timestamp_query_inside_passes: features.contains(
                wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
                    | wgpu::Features::TIMESTAMP_QUERY_INSIDE_PASSES,
            ),
            clip_distances: features.contains(wgpu::Features::CLIP_DISTANCES),
            multiview: features.contains(wgpu::Features::MULTIVIEW),
            ray_query: features.contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY),
        }
    }
}

impl fmt::Display for AdapterReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let yes_no = |b: bool| if b { "yes" } else { "no" };
        writeln!(f, "adapter:          {}", self.name)?;
        writeln!(f, "backend:          {}", self.backend)?;
        writeln!(f, "device type:      {}", self.device_type)?;
        writeln!(f, "driver:           {} {}", self.driver, self.driver_info)?;
        if let Some(cache) = self.shader_cache() {
            writeln!(f, "shader cache:     {cache}")?;
        }
        writeln!(f, "timestamp query:  {}", yes_no(self.timestamp_query))?;
        writeln!(
            f,
            "  inside passes:  {}",
            yes_no(self.timestamp_query_inside_passes)
        )?;
        writeln!(f, "clip distances:   {}", yes_no(self.clip_distances))?;
        writeln!(f, "multiview:        {}", yes_no(self.multiview))?;
        write!(f, "ray query:        {}", yes_no(self.ray_query))
    }
}

#[derive(Debug, thiserror::Error)]
pub enum AdapterError {
    #[error(
        "no wgpu adapter found (tried: {tried}).\n\
         hint: on Debian/Ubuntu install Mesa's software Vulkan driver with\n  \
         sudo apt-get install mesa-vulkan-drivers libvulkan1\n\
         (scripts/install-system-deps.sh does this), or Mesa's EGL/GL drivers\n  \
         (libegl1 libegl-mesa0 libgl1-mesa-dri); WGPU_BACKEND=vulkan|gl picks a backend."
    )]
    NoneFound { tried: String },
    #[error("WGPU_BACKEND={value:?} names no backend wgpu knows (use vulkan, gl, metal or dx12)")]
    BadOverride { value: String },
}

fn try_backends(backends: wgpu::Backends) -> Option<SelectedAdapter> {
    try_backends_presenting(backends, None).map(|(selected, _)| selected)
}

/// What a window adds to adapter selection (`mirrorbox view`): the display connection the
/// instance is made with (GL needs it to present; Vulkan ignores it) and the surface the
/// adapter must be able to present to.
pub struct PresentTarget<'a> {
    pub display: &'a dyn Fn() -> Box<dyn wgpu::wgt::WgpuHasDisplayHandle>,
    pub surface:
        &'a dyn Fn(&wgpu::Instance) -> Result<wgpu::Surface<'static>, wgpu::CreateSurfaceError>,
}

fn try_backends_presenting(
    backends: wgpu::Backends,
    present: Option<&PresentTarget<'_>>,
) -> Option<(SelectedAdapter, Option<wgpu::Surface<'static>>)> {
    let mut desc = match present {
        Some(p) => wgpu::InstanceDescriptor::new_with_display_handle((p.display)()),
        None => wgpu::InstanceDescriptor::new_without_display_handle(),
    };
    desc.backends = backends;
    // Keep validation/debug flags controllable from the environment (WGPU_VALIDATION=1, ...).
    desc.flags = wgpu::InstanceFlags::default().with_env();
    let instance = wgpu::Instance::new(desc);
    let surface = match present {
        Some(p) => Some((p.surface)(&instance).ok()?),
        None => None,
    };
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        force_fallback_adapter: false,
        compatible_surface: surface.as_ref(),
        ..Default::default()
    }))
    .ok()?;
    let report = AdapterReport::of(&adapter);
    Some((
        SelectedAdapter {
            instance,
            adapter,
            report,
        },
        surface,
    ))
}

/// The backends to try, in order, each with what chose it.
fn backend_order(
    backends: Option<wgpu::Backends>,
) -> Result<Vec<(&'static str, wgpu::Backends)>, AdapterError> {
    Ok(match (backends, std::env::var("WGPU_BACKEND")) {
        (Some(backends), _) => vec![("the caller's choice", backends)],
        (None, Ok(value)) => {
            let backends = wgpu::Backends::from_comma_list(&value);
            if backends.is_empty() {
                return Err(AdapterError::BadOverride { value });
            }
            vec![("WGPU_BACKEND", backends)]
        }
        (None, Err(_)) => vec![
            ("Vulkan", wgpu::Backends::VULKAN),
            ("GL", wgpu::Backends::GL),
        ],
    })
}

fn none_found(order: &[(&str, wgpu::Backends)], what: &str) -> AdapterError {
    let tried = order
        .iter()
        .map(|(name, b)| format!("{name} ({b:?})"))
        .collect::<Vec<_>>()
        .join(", then ");
    AdapterError::NoneFound {
        tried: format!("{tried}{what}"),
    }
}

/// Chooses the adapter by the same rule as [`select_adapter`], among those that can present
/// to `present`'s surface; returns it with the surface.
pub fn select_adapter_presenting(
    present: &PresentTarget<'_>,
) -> Result<(SelectedAdapter, wgpu::Surface<'static>), AdapterError> {
    let order = backend_order(None)?;
    for (_, backends) in &order {
        if let Some((selected, Some(surface))) = try_backends_presenting(*backends, Some(present)) {
            return Ok((selected, surface));
        }
    }
    Err(none_found(&order, " that can present to the window"))
}

/// Chooses the adapter (see the module docs for the order).
pub fn select_adapter() -> Result<SelectedAdapter, AdapterError> {
    select_adapter_from(None)
}

/// Chooses the adapter among `backends` when given, else as [`select_adapter`] does.
pub fn select_adapter_from(
    backends: Option<wgpu::Backends>,
) -> Result<SelectedAdapter, AdapterError> {
    let order = backend_order(backends)?;
    for (_, backends) in &order {
        if let Some(selected) = try_backends(*backends) {
            return Ok(selected);
        }
    }
    Err(none_found(&order, ""))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lavapipe(driver_info: &str) -> AdapterReport {
        AdapterReport {
            name: "llvmpipe (LLVM 19.1.7, 256 bits)".into(),
            backend: "vulkan".into(),
            device_type: "Cpu".into(),
            driver: "llvmpipe".into(),
            driver_info: driver_info.into(),
            timestamp_query: true,
            timestamp_query_inside_passes: true,
            clip_distances: true,
            multiview: true,
            ray_query: false,
        }
    }

    #[test]
    fn mesa_versions_are_read_from_driver_descriptions() {
        assert_eq!(
            mesa_version("Mesa 25.0.7-2~bpo12+1 (LLVM 19.1.7)"),
            Some((25, 0, 7))
        );
        assert_eq!(mesa_version("Mesa 22.3.6 (LLVM 15.0.6)"), Some((22, 3, 6)));
        assert_eq!(
            mesa_version("4.5 (Core Profile) Mesa 25.2"),
            Some((25, 2, 0))
        );
        assert_eq!(mesa_version("NVIDIA 550.54"), None);
        assert_eq!(mesa_version("Mesa x"), None);
    }

    #[test]
    fn the_shader_cache_is_off_for_the_values_mesa_reads_as_true() {
        for off in ["1", "true", "TRUE", "yes", "y", "t", " true "] {
            assert!(shader_cache_disabled_by(Some(off)), "{off:?}");
        }
        for on in [
            None,
            Some(""),
            Some("0"),
            Some("false"),
            Some("no"),
            Some("off"),
        ] {
            assert!(!shader_cache_disabled_by(on), "{on:?}");
        }
        // Only a Mesa driver has Mesa's cache to report.
        let nvidia = AdapterReport {
            driver: "NVIDIA".into(),
            driver_info: "580.159.04".into(),
            ..lavapipe("")
        };
        assert_eq!(nvidia.shader_cache(), None);
        assert!(lavapipe("Mesa 25.0.7").shader_cache().is_some());
    }

    #[test]
    fn old_lavapipe_is_warned_about_and_a_current_one_is_not() {
        let old = lavapipe("Mesa 22.3.6 (LLVM 15.0.6)").platform_warning();
        assert!(old.is_some_and(|w| w.contains("Mesa 22.3.6") && w.contains(">= 25.0")));
        assert_eq!(
            lavapipe("Mesa 25.0.7 (LLVM 19.1.7)").platform_warning(),
            None
        );
        assert!(lavapipe("unknown").platform_warning().is_some());
        let gpu = AdapterReport {
            name: "NVIDIA H100".into(),
            driver_info: "550.54".into(),
            ..lavapipe("")
        };
        assert_eq!(gpu.platform_warning(), None);
    }
}
