//! The colour format every method renders linear radiance into: one per device, RGBA32F
//! where the adapter has it, else RGBA16F (docs/methods.md, "Colour targets").

/// The format of every colour target and mirror texture of a device: linear radiance,
/// unclamped. RGBA32F wherever the adapter can render to it, sample it and copy it out;
/// otherwise RGBA16F (wgpu's GL backend on a core-profile desktop GL such as Mesa's llvmpipe
/// has half-float colour buffers but no float ones). `MIRRORBOX_COLOR_FORMAT` (or
/// [`crate::gpu::GpuOptions::color_format`]) forces one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorFormat {
    Rgba32Float,
    Rgba16Float,
}

/// The environment variable that forces the colour format (`rgba32float` or `rgba16float`).
pub const COLOR_FORMAT_ENV: &str = "MIRRORBOX_COLOR_FORMAT";

impl ColorFormat {
    /// In order of preference: the first the adapter can use is chosen.
    pub const PREFERENCE: [ColorFormat; 2] = [ColorFormat::Rgba32Float, ColorFormat::Rgba16Float];

    /// WebGPU's name of the format (also in `render --json`, EXR headers and sweep records).
    pub fn name(self) -> &'static str {
        match self {
            ColorFormat::Rgba32Float => "rgba32float",
            ColorFormat::Rgba16Float => "rgba16float",
        }
    }

    /// The format from its name (`rgba32float`, `rgba16float`; `rgba32f`, `rgba16f` too),
    /// case-insensitive.
    pub fn parse(text: &str) -> Option<ColorFormat> {
        match text.trim().to_ascii_lowercase().as_str() {
            "rgba32float" | "rgba32f" => Some(ColorFormat::Rgba32Float),
            "rgba16float" | "rgba16f" => Some(ColorFormat::Rgba16Float),
            _ => None,
        }
    }

    pub fn texture_format(self) -> wgpu::TextureFormat {
        match self {
            ColorFormat::Rgba32Float => wgpu::TextureFormat::Rgba32Float,
            ColorFormat::Rgba16Float => wgpu::TextureFormat::Rgba16Float,
        }
    }

    /// Bytes of one RGBA texel.
    pub fn texel_bytes(self) -> u32 {
        match self {
            ColorFormat::Rgba32Float => 16,
            ColorFormat::Rgba16Float => 8,
        }
    }

    /// The relative error of storing one value, ε = 2^(1−p) with p significant bits (24 for
    /// f32, 11 for f16): a normal value x is stored as x(1 + δ), |δ| < ε. That is one unit in
    /// the last place, not half of one, because Vulkan and GL let a device round a float
    /// conversion either to nearest or toward zero — lavapipe truncates (its RGBA16F images
    /// never lie above the RGBA32F ones). For f16, ε = 9.8e-4; below its normal range
    /// (2^−14 ≈ 6.1e-5) the error is absolute, under 2^−24 ≈ 6e-8.
    pub fn relative_store_error(self) -> f32 {
        match self {
            ColorFormat::Rgba32Float => f32::EPSILON,
            ColorFormat::Rgba16Float => 1.0 / 1024.0,
        }
    }

    /// Whether `adapter` can render to this format, sample it and copy it to a buffer — all
    /// that the methods, the resolve and the readback do with a colour target.
    pub fn usable_on(self, adapter: &wgpu::Adapter) -> bool {
        let needed = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        adapter
            .get_texture_format_features(self.texture_format())
            .allowed_usages
            .contains(needed)
    }

    /// The format to use on `adapter`: `forced` if given (and usable), else the first usable
    /// one of [`ColorFormat::PREFERENCE`]. The error says why none fits.
    pub fn choose(adapter: &wgpu::Adapter, forced: Option<ColorFormat>) -> Result<Self, String> {
        match forced {
            Some(f) if f.usable_on(adapter) => Ok(f),
            Some(f) => Err(format!(
                "{f} targets were forced, but it cannot render to, sample and copy them \
                 (without {COLOR_FORMAT_ENV} the best format it has is chosen)"
            )),
            None => Self::PREFERENCE
                .into_iter()
                .find(|f| f.usable_on(adapter))
                .ok_or_else(|| {
                    "it can render to neither RGBA32F nor RGBA16F targets, one of which every \
                     raster method needs; install Mesa's Vulkan driver \
                     (scripts/install-system-deps.sh) or use a Vulkan adapter"
                        .into()
                }),
        }
    }

    /// The format `MIRRORBOX_COLOR_FORMAT` forces, if it is set; `Err(value)` if it names none.
    pub fn from_env() -> Result<Option<ColorFormat>, String> {
        match std::env::var(COLOR_FORMAT_ENV) {
            Ok(value) if !value.is_empty() => ColorFormat::parse(&value).map(Some).ok_or(value),
            _ => Ok(None),
        }
    }
}

impl std::fmt::Display for ColorFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
