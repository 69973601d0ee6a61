//! Memory as a planned quantity (issue 37): what a planned frame will hold, estimated from
//! the plan before any GPU resource exists, and the budget a plan is refused above (exit 2).
//!
//! **The estimate** ([`crate::Planned::memory_estimate`]) is `gpu_bytes + host_bytes`:
//!
//! - GPU: every texture and buffer the frame creates, each at lavapipe's layout
//!   ([`texture_bytes`]: rows padded to 64 bytes, height to 4 texels, the whole to 256
//!   bytes; [`buffer_bytes`]: 256-byte granules) — the render target at the SSAA size
//!   (colour + 32-bit depth), the SSAA resolve's output and the readback buffer at the image
//!   size, the shadow maps (`layers × size² × 4` plus one depth layer, their view uniforms
//!   and a vertex buffer of every triangle), and what the method's plan says it creates
//!   ([`crate::method::PlannedFrame::memory`]: its scene buffers, mirror textures, cube
//!   faces, per-path uniforms and instance buffers, baked meshes …), plus wgpu's own
//!   [`WGPU_DEVICE_BYTES`].
//! - Host: the driver's fixed [`DRIVER_HOST_BYTES`] (measured), the image's copies on the
//!   CPU ([`HOST_BYTES_PER_PIXEL`] per output pixel), and what a method's plan keeps on the
//!   CPU (reflection paths, baked meshes).
//!
//! On lavapipe, the CPU Vulkan driver mirrorbox runs on, the "GPU" memory is host memory
//! too, so the sum is the process's expected peak.
//!
//! The colour format is not known before the device is opened: the estimate takes the
//! larger one, RGBA32F (16 bytes a texel).
//!
//! What is not modelled: lavapipe records every draw of a render pass until the pass ends,
//! which for frames of millions of triangles (`portal`, `unrolled` at large depths) adds
//! host memory that is bounded by those methods' triangle limits, not by this estimate.

use std::fmt;

/// The default `--memory-budget`: 2 GiB.
pub const DEFAULT_MEMORY_BUDGET: u64 = 2 << 30;

/// The driver's and the process's own memory before any frame: the peak resident memory of
/// a 1×1 `render` of `single_mirror` on lavapipe (Mesa 25.0.7, 2 cores) was 100–104 MB,
/// a 64×36 one of every bundled scene 103–113 MB; 128 MiB (134 MB) covers them.
pub const DRIVER_HOST_BYTES: u64 = 128 << 20;

/// wgpu's own device buffers: its 512 KiB zero buffer (texture clears), and 64 KiB for
/// timestamp queries, staging belts and pipeline-layout bookkeeping.
pub const WGPU_DEVICE_BYTES: u64 = (512 + 64) << 10;

/// Host bytes per output pixel: the readback's f32 RGBA channels (16), the linear RGB image
/// (12), and the PNG and EXR encoders' copies (at most 20).
pub const HOST_BYTES_PER_PIXEL: u64 = 48;

/// The largest uniform-offset alignment a device may ask for (WebGPU's limit): every record
/// of a uniform arena ([`crate::pipeline::UniformArena`]) is counted at this size.
pub const MAX_UNIFORM_ALIGNMENT: u64 = 256;

/// Bytes a 32-bit depth texel takes; a depth-stencil one is counted at 8 (lavapipe's
/// `Depth32FloatStencil8` is 64 bits a texel).
pub const DEPTH_BYTES: u64 = 4;
pub const DEPTH_STENCIL_BYTES: u64 = 8;

fn align(n: u64, to: u64) -> u64 {
    n.div_ceil(to) * to
}

/// A 2D texture of `width × height` texels of `texel_bytes` at lavapipe's layout: rows
/// padded to 64 bytes, the height to 4 rows, the whole to 256 bytes (measured: a 65×37
/// RGBA32F target takes 68×40 texels, a 1×1 one 256 bytes).
pub fn texture_bytes(width: u32, height: u32, texel_bytes: u64) -> u64 {
    let row = align(u64::from(width.max(1)) * texel_bytes, 64);
    align(row * align(u64::from(height.max(1)), 4), 256)
}

/// A buffer of `bytes`, in 256-byte granules (at least one).
pub fn buffer_bytes(bytes: u64) -> u64 {
    align(bytes.max(1), 256)
}

/// A colour + 32-bit depth target ([`crate::targets::RenderTarget`]).
pub fn target_bytes(width: u32, height: u32, color_bytes_per_texel: u64) -> u64 {
    texture_bytes(width, height, color_bytes_per_texel) + texture_bytes(width, height, DEPTH_BYTES)
}

/// A uniform arena of `records` records (never empty).
pub fn uniform_arena_bytes(records: u64) -> u64 {
    buffer_bytes(records.max(1) * MAX_UNIFORM_ALIGNMENT)
}

/// One named part of an estimate and the flags that lower it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MemoryPart {
    /// What it is: "render target", "mirror textures", "shadow maps", …
    pub what: &'static str,
    pub gpu_bytes: u64,
    pub host_bytes: u64,
    /// What lowers it, for the refusal's hint ("" for a fixed part).
    pub lower: &'static str,
}

/// The memory a planned frame will hold: GPU and host bytes, and the parts they come from.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MemoryEstimate {
    pub gpu_bytes: u64,
    pub host_bytes: u64,
    pub parts: Vec<MemoryPart>,
}

impl MemoryEstimate {
    pub fn new() -> Self {
        Self::default()
    }

    fn part(&mut self, what: &'static str, lower: &'static str) -> &mut MemoryPart {
        let i = match self.parts.iter().position(|p| p.what == what) {
            Some(i) => i,
            None => {
                self.parts.push(MemoryPart {
                    what,
                    gpu_bytes: 0,
                    host_bytes: 0,
                    lower,
                });
                self.parts.len() - 1
            }
        };
        &mut self.parts[i]
    }

    /// Adds `bytes` of GPU memory to part `what` (lowered by `lower`).
    pub fn gpu(&mut self, what: &'static str, lower: &'static str, bytes: u64) -> &mut Self {
        self.part(what, lower).gpu_bytes += bytes;
        self.gpu_bytes += bytes;
        self
    }

    /// Adds `bytes` of host memory to part `what`.
    pub fn host(&mut self, what: &'static str, lower: &'static str, bytes: u64) -> &mut Self {
        self.part(what, lower).host_bytes += bytes;
        self.host_bytes += bytes;
        self
    }

    /// Adds every part of `other`.
    pub fn merge(&mut self, other: MemoryEstimate) -> &mut Self {
        for p in other.parts {
            self.gpu(p.what, p.lower, p.gpu_bytes);
            self.host(p.what, p.lower, p.host_bytes);
        }
        self
    }

    /// GPU + host bytes.
    pub fn total(&self) -> u64 {
        self.gpu_bytes + self.host_bytes
    }

    /// The largest part that a flag lowers (not the driver's fixed allowance).
    pub fn dominant(&self) -> Option<&MemoryPart> {
        self.parts
            .iter()
            .filter(|p| !p.lower.is_empty())
            .max_by_key(|p| p.gpu_bytes + p.host_bytes)
    }

    /// Refuses an estimate above `budget` bytes (exit 2), naming what to lower.
    pub fn check(&self, budget: u64) -> Result<(), OverMemoryBudget> {
        if self.total() > budget {
            return Err(OverMemoryBudget {
                estimate: self.clone(),
                budget,
            });
        }
        Ok(())
    }
}

impl fmt::Display for MemoryEstimate {
    /// `1.20 GiB (GPU 1.08 GiB + host 128 MiB)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} (GPU {} + host {})",
            format_bytes(self.total()),
            format_bytes(self.gpu_bytes),
            format_bytes(self.host_bytes)
        )
    }
}

/// A plan whose estimate exceeds `--memory-budget`, refused before any GPU work.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OverMemoryBudget {
    pub estimate: MemoryEstimate,
    pub budget: u64,
}

impl OverMemoryBudget {
    /// What to lower: the flags of the largest part.
    pub fn hint(&self) -> String {
        match self.estimate.dominant() {
            Some(p) => format!(
                "the largest part is {} ({}): lower {}",
                p.what,
                format_bytes(p.gpu_bytes + p.host_bytes),
                p.lower
            ),
            None => "lower the image size (--width/--height)".into(),
        }
    }
}

impl fmt::Display for OverMemoryBudget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "this frame would need about {}, above --memory-budget {}; {} (or raise --memory-budget)",
            self.estimate,
            format_bytes(self.budget),
            self.hint()
        )
    }
}

impl std::error::Error for OverMemoryBudget {}

/// Bytes in binary units: `512 B`, `1.50 KiB`, `118 MiB`, `2.00 GiB`.
pub fn format_bytes(n: u64) -> String {
    match mirrorbox_files::binary_unit(n) {
        Some((v, unit)) if v >= 100.0 => format!("{v:.0} {unit}"),
        Some((v, unit)) => format!("{v:.2} {unit}"),
        None => format!("{n} B"),
    }
}

/// Most bytes `--memory-budget` accepts (1 TiB): beyond it the check means nothing.
pub const MAX_MEMORY_BUDGET: u64 = 1 << 40;
/// Fewest bytes `--memory-budget` accepts (1 MiB).
pub const MIN_MEMORY_BUDGET: u64 = 1 << 20;

/// Parses a `--memory-budget` value: plain bytes (`2147483648`) or a number with a binary
/// unit `K`, `M`, `G` or `T` (1024-based), optionally followed by `B` or `iB`: `2G`,
/// `512M`, `1.5GB`, `768MiB`. The result must lie in [1 MiB, 1 TiB]. The error names
/// `flag` and what is allowed.
pub fn parse_memory_size(flag: &str, text: &str) -> Result<u64, String> {
    let bad = || {
        format!(
            "{flag} {text:?}: expected a size such as 2G, 512M, 1.5GB or a plain number of \
             bytes (K, M, G, T are powers of 1024), between 1M and 1T"
        )
    };
    let t = text.trim();
    let upper = t.to_ascii_uppercase();
    let body = upper
        .strip_suffix("IB")
        .or_else(|| upper.strip_suffix('B'))
        .unwrap_or(&upper);
    let (number, scale) = match body.chars().last() {
        Some('K') => (&body[..body.len() - 1], 1u64 << 10),
        Some('M') => (&body[..body.len() - 1], 1 << 20),
        Some('G') => (&body[..body.len() - 1], 1 << 30),
        Some('T') => (&body[..body.len() - 1], 1 << 40),
        _ if body.len() < upper.len() => (body, 1), // "512B"
        _ => (body, 1),
    };
    let number = number.trim();
    if number.is_empty()
        || !number.chars().all(|c| c.is_ascii_digit() || c == '.')
        || number.matches('.').count() > 1
    {
        return Err(bad());
    }
    let value: f64 = number.parse().map_err(|_| bad())?;
    let bytes = value * scale as f64;
    if !bytes.is_finite() || bytes < MIN_MEMORY_BUDGET as f64 || bytes > MAX_MEMORY_BUDGET as f64 {
        return Err(bad());
    }
    Ok(bytes.round() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_in_binary_units() {
        let p = |t: &str| parse_memory_size("--memory-budget", t);
        assert_eq!(p("2G"), Ok(DEFAULT_MEMORY_BUDGET));
        assert_eq!(p("2GiB"), Ok(2 << 30));
        assert_eq!(p("512M"), Ok(512 << 20));
        assert_eq!(p("512mb"), Ok(512 << 20));
        assert_eq!(p("1.5GB"), Ok(3 << 29));
        assert_eq!(p("2147483648"), Ok(2 << 30));
        assert_eq!(p("1048576B"), Ok(1 << 20));
        assert_eq!(p("1T"), Ok(1 << 40));
        for bad in [
            "", "G", "-1G", "1.2.3G", "2X", "lots", "0", "100K", "2T", "nanG", "1e9",
        ] {
            let e = p(bad).unwrap_err();
            assert!(e.starts_with("--memory-budget"), "{bad}: {e}");
            assert!(e.contains("2G, 512M, 1.5GB"), "{e}");
        }
    }

    #[test]
    fn textures_follow_lavapipes_layout() {
        // Measured (wgpu's texture counter): a 64×36 and a 63×35 RGBA32F target + depth +
        // resolve output take 82 944 bytes; 65×37 99 840; 1×1 768; 100×7 29 184.
        let frame = |w, h| target_bytes(w, h, 16) + texture_bytes(w, h, 16);
        assert_eq!(frame(64, 36), 82_944);
        assert_eq!(frame(63, 35), 82_944);
        assert_eq!(frame(65, 37), 99_840);
        assert_eq!(frame(1, 1), 768);
        assert_eq!(frame(100, 7), 29_184);
    }

    #[test]
    fn refusal_names_the_estimate_budget_and_largest_part() {
        let mut e = MemoryEstimate::new();
        e.host("driver", "", DRIVER_HOST_BYTES);
        e.gpu("mirror textures", "--texture-scale or --n", 3 << 30);
        e.gpu("render target", "--width/--height or --ssaa", 1 << 20);
        assert!(e.check(4 << 30).is_ok());
        let message = e.check(DEFAULT_MEMORY_BUDGET).unwrap_err().to_string();
        assert_eq!(
            message,
            "this frame would need about 3.13 GiB (GPU 3.00 GiB + host 128 MiB), above \
             --memory-budget 2.00 GiB; the largest part is mirror textures (3.00 GiB): lower \
             --texture-scale or --n (or raise --memory-budget)"
        );
    }
}
