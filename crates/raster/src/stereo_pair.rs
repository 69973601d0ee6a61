//! A stereo pair as one frame (issue 17, seed 002): both eyes' passes recorded in one
//! command buffer and timed together, from the first pass to the second eye's resolve —
//! what a headset pays per displayed frame, to compare against two mono frames.
//!
//! - By default a method plans each eye as its own frame ([`PlannedPair::Separate`]): seed
//!   002's per-eye mirror cameras, per-eye reflection paths for the exact methods. The two
//!   frames are recorded one after the other.
//! - A method may plan the pair jointly ([`PlannedPair::Joint`]): the texture methods with
//!   `--stereo-mirrors shared` render their mirror textures once, from the head, and draw
//!   each eye's main pass with them (`crates/raster/src/stereo_mirrors.rs`). That saving is
//!   the shortcut's whole point, so it is in the pair's time.
//! - Shadow maps depend on the lights, not the eye: drawn once per pair.
//! - Multiview (`Features::MULTIVIEW`, one pass drawing both eyes into a two-layer target) is
//!   not used: the adapter report says whether a device has it (`mirrorbox info`), and
//!   docs/methods.md ("Stereo mirrors") why it did not land.

pub use crate::method::{BuiltPair, PairEncoder, PlannedJointPair, PlannedPair, plan_each_eye};

use crate::gpu::{Gpu, RasterError};
use crate::method::FrameStats;
use crate::plan::PlanError;
use crate::targets::RenderTarget;
use crate::{RenderOutput, RenderSettings};
use mirrorbox_scene::Scene;

/// A stereo pair planned on the CPU (see [`crate::Planned`]).
pub struct Planned {
    pair: PlannedPair,
    shadows: Option<crate::shadow_plan::ShadowPlan>,
    key: String,
    size: (u32, u32),
}

/// Plans `settings.method` for both eyes (each eye's scene: [`Scene::eye`]) at render
/// resolution, without a GPU. The eyes differ only in their cameras.
pub fn plan_pair(eyes: [&Scene; 2], settings: &RenderSettings) -> Result<Planned, PlanError> {
    let params = settings.method.params();
    let lit = eyes.map(|s| crate::lighting::lit_scene(s, params));
    let [left, right] = [&*lit[0], &*lit[1]];
    settings.check(left)?;
    let (w, h) = settings.render_size(left);
    assert_eq!(
        (w, h),
        settings.render_size(right),
        "the eyes of a pair have one size"
    );
    let shadows = crate::lighting::shadow_settings(left, params)
        .map(|s| crate::shadow_plan::ShadowPlan::new(left, s))
        .transpose()?;
    let pair = settings.method.configure().plan_pair([left, right], w, h)?;
    Ok(Planned {
        pair,
        shadows,
        key: settings.method.key(),
        size: (w, h),
    })
}

impl Planned {
    /// The pair's memory ([`crate::Planned::memory_estimate`]): two render targets,
    /// resolves and images, one set of shadow maps, and each eye's frame (or the joint
    /// frame's resources once).
    pub fn memory_estimate(
        &self,
        eyes: [&Scene; 2],
        settings: &RenderSettings,
    ) -> crate::memory::MemoryEstimate {
        let params = settings.method.params();
        let lit = eyes.map(|s| crate::lighting::lit_scene(s, params));
        let [left, right] = [&*lit[0], &*lit[1]];
        let color = u64::from(crate::ColorFormat::Rgba32Float.texel_bytes());
        let mut estimate = crate::frame_memory(left, settings, self.shadows.as_ref(), 2);
        match &self.pair {
            PlannedPair::Separate([l, r]) => {
                estimate.merge(l.memory(left, color));
                estimate.merge(r.memory(right, color));
            }
            PlannedPair::Joint(pair) => {
                estimate.merge(pair.memory([left, right], color));
            }
        }
        estimate
    }

    /// [`Planned::memory_estimate`] refused above `budget` bytes (exit 2).
    pub fn check_memory(
        &self,
        eyes: [&Scene; 2],
        settings: &RenderSettings,
        budget: u64,
    ) -> Result<crate::memory::MemoryEstimate, PlanError> {
        let estimate = self.memory_estimate(eyes, settings);
        estimate.check(budget)?;
        Ok(estimate)
    }
}

/// The counts of two frames drawn one after the other: passes, draws, triangles and paths
/// add; the depth is the deeper one's.
pub fn both(a: &FrameStats, b: &FrameStats) -> FrameStats {
    let paths = match (a.paths, b.paths) {
        (Some(p), Some(q)) => Some(crate::method::PathCounts {
            kept: p.kept + q.kept,
            pruned_empty: p.pruned_empty + q.pruned_empty,
            pruned_no_sample: p.pruned_no_sample + q.pruned_no_sample,
            pruned_small: p.pruned_small + q.pruned_small,
            pruned_attenuation: p.pruned_attenuation + q.pruned_attenuation,
            capped: p.capped + q.capped,
            pruned_hidden: p.pruned_hidden + q.pruned_hidden,
            partly_hidden: p.partly_hidden + q.partly_hidden,
        }),
        (p, q) => p.or(q),
    };
    let copies = match (a.copies, b.copies) {
        (Some(c), Some(d)) => Some(crate::method::CopyCounts {
            total: c.total + d.total,
            drawn: c.drawn + d.drawn,
            pruned_empty: c.pruned_empty + d.pruned_empty,
            pruned_outside_view: c.pruned_outside_view + d.pruned_outside_view,
            culled_parts: c.culled_parts + d.culled_parts,
            parts: c.parts + d.parts,
            ..c
        }),
        (c, d) => c.or(d),
    };
    FrameStats {
        passes: a.passes + b.passes,
        texture_renders: a.texture_renders + b.texture_renders,
        draws: a.draws + b.draws,
        depth: a.depth.max(b.depth),
        triangles: a.triangles + b.triangles,
        paths,
        copies,
        ..*a
    }
}

/// Two frames recorded one after the other.
struct EachEye([Box<dyn crate::timing::FrameEncoder>; 2]);

impl PairEncoder for EachEye {
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: [&RenderTarget; 2],
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        self.0[0].encode(encoder, targets[0], first_pass);
        self.0[1].encode(encoder, targets[1], None);
    }
}

/// Renders a planned pair at the eyes' size: [`RenderOutput::image`] is the left eye,
/// [`RenderOutput::right_eye`] the right; the timing and counts are the pair's.
pub fn render_pair(
    gpu: &Gpu,
    eyes: [&Scene; 2],
    planned: Planned,
    settings: &RenderSettings,
) -> Result<RenderOutput, RasterError> {
    let params = settings.method.params();
    let lit = eyes.map(|s| crate::lighting::lit_scene(s, params));
    let [left, right] = [&*lit[0], &*lit[1]];
    let (w, h) = crate::check_planned_frame(gpu, left, settings, &planned.key, planned.size)?;
    let targets = ["left view", "right view"]
        .map(|l| RenderTarget::new(gpu, l, w, h, wgpu::TextureUsages::TEXTURE_BINDING));
    let resolves = targets
        .each_ref()
        .map(|t| crate::resolve::Resolve::new(gpu, t, settings.ssaa));
    let shadows = crate::shadow_maps::ShadowMaps::new(gpu, left, planned.shadows)?;
    let (encoder, mut stats, mut warnings, bake_ms): (Box<dyn PairEncoder>, _, _, _) =
        match planned.pair {
            PlannedPair::Separate([l, r]) => {
                let (a, b) = (
                    l.build(gpu, left, &shadows)?,
                    r.build(gpu, right, &shadows)?,
                );
                let mut warnings = a.warnings;
                for w in b.warnings {
                    if !warnings.contains(&w) {
                        warnings.push(w);
                    }
                }
                // A stateful method's pre-roll (`feedback --history`), each eye its own, after
                // the shadow maps it reads.
                if a.encoder.preroll_frames() + b.encoder.preroll_frames() > 0 {
                    let mut e = gpu.device.create_command_encoder(&Default::default());
                    shadows.encode(&mut e, None);
                    gpu.queue.submit([e.finish()]);
                    crate::timing::preroll(gpu, a.encoder.as_ref(), &targets[0])?;
                    crate::timing::preroll(gpu, b.encoder.as_ref(), &targets[1])?;
                }
                let bake = match (a.bake_ms, b.bake_ms) {
                    (Some(x), Some(y)) => Some(x + y),
                    (x, y) => x.or(y),
                };
                (
                    Box::new(EachEye([a.encoder, b.encoder])),
                    both(&a.stats, &b.stats),
                    warnings,
                    bake,
                )
            }
            PlannedPair::Joint(pair) => {
                let built = pair.build(gpu, [left, right], &shadows)?;
                (built.encoder, built.stats, Vec::new(), None)
            }
        };
    crate::add_shadow_maps(&mut stats, &mut warnings, &shadows, left, settings);
    gpu.check()?;
    let encode = |e: &mut wgpu::CommandEncoder,
                  first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>| {
        let targets = [&targets[0], &targets[1]];
        if shadows.layers() > 0 {
            shadows.encode(e, first_pass);
            encoder.encode(e, targets, None);
        } else {
            encoder.encode(e, targets, first_pass);
        }
    };
    let (mut images, timing) = crate::timing::run_frames_of(
        gpu,
        &encode,
        &[&resolves[0], &resolves[1]],
        settings.warmup,
        settings.frames,
    )?;
    let right_eye = images.pop();
    let image = images.pop().expect("a pair reads two images back");
    Ok(RenderOutput {
        image,
        right_eye,
        timing,
        stats,
        color_format: gpu.color_format,
        warnings,
        gpu_memory: crate::GpuMemory::read(gpu),
        bake_ms,
        history: None,
    })
}
