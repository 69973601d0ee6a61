//! GPU timing of frames. A frame is every scene pass of the method plus the resolve. With
//! `TIMESTAMP_QUERY` the time is measured on the GPU from the start of the frame's first pass
//! to the end of the resolve; otherwise it is the wall clock from submission to completion.
//! Frames are submitted and waited for one by one, after `warmup` untimed frames.

use crate::gpu::{Gpu, RasterError};
use crate::readback::{map_read, read_texture};
use crate::resolve::Resolve;
use crate::targets::RenderTarget;
use mirrorbox_image::RgbImage;
use std::time::Instant;

/// A method that draws one frame's scene passes, ending with the full view in `target`.
pub trait FrameEncoder {
    /// `first_pass` carries the timestamp write the method must attach to its first pass.
    fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &RenderTarget,
        first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>,
    );

    /// Frames a stateful method draws and commits ([`FrameEncoder::advance`]) from this view
    /// before the frame that is timed and read back (`feedback --history`); 0 for the others.
    fn preroll_frames(&self) -> u32 {
        0
    }

    /// Commits the frame last encoded as the state the next one starts from. Without it a
    /// stateful method redraws the same frame from the same state every time (so timed
    /// frames are all the same frame); stateless methods have nothing to commit.
    fn advance(&self) {}

    /// The reflections the frame last encoded shows, where that changes from frame to frame
    /// (`feedback`); `None` where [`crate::FrameStats::depth`] holds for every frame.
    fn drawn_depth(&self) -> Option<usize> {
        None
    }

    /// The state the next frame of a sequence continues from (after [`FrameEncoder::advance`]).
    fn history(&self) -> Option<FrameHistory> {
        None
    }
}

/// Draws and commits a stateful method's pre-roll frames ([`FrameEncoder::preroll_frames`])
/// into `target`, one submission each, waiting for each (no frame queue builds up).
pub fn preroll(
    gpu: &Gpu,
    method: &dyn FrameEncoder,
    target: &RenderTarget,
) -> Result<(), RasterError> {
    for _ in 0..method.preroll_frames() {
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("pre-roll frame"),
            });
        method.encode(&mut encoder, target, None);
        gpu.queue.submit([encoder.finish()]);
        method.advance();
        gpu.wait()?;
    }
    gpu.check()
}

/// What a stateful method's frame leaves for the next frame of a sequence (`feedback`: its
/// mirror textures and the cameras they were rendered from). Opaque: only the method that
/// made it reads it; another method, or a frame of another size, starts afresh.
#[derive(Clone)]
pub struct FrameHistory(pub(crate) std::sync::Arc<dyn std::any::Any + Send + Sync>);

impl std::fmt::Debug for FrameHistory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("FrameHistory")
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimingSource {
    GpuTimestamps,
    WallClock,
}

impl TimingSource {
    pub fn name(self) -> &'static str {
        match self {
            TimingSource::GpuTimestamps => "gpu-timestamps",
            TimingSource::WallClock => "wall-clock",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct FrameTiming {
    pub source: TimingSource,
    /// Milliseconds of each timed frame, in order.
    pub frames_ms: Vec<f64>,
    /// CPU milliseconds of each timed frame's encoding and submission: from creating its
    /// command encoder until `submit` returns (the driver's share of recording the passes,
    /// which GPU timestamps do not see), in order.
    pub encode_ms: Vec<f64>,
}

impl FrameTiming {
    pub fn median_ms(&self) -> f64 {
        let mut v = self.frames_ms.clone();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        if n == 0 {
            f64::NAN
        } else if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    }
    pub fn min_ms(&self) -> f64 {
        self.frames_ms.iter().copied().fold(f64::INFINITY, f64::min)
    }
}

/// Renders `warmup + frames` frames, times the last `frames`, and reads the final image back.
pub fn run_frames(
    gpu: &Gpu,
    method: &dyn FrameEncoder,
    target: &RenderTarget,
    resolve: &Resolve,
    warmup: u32,
    frames: u32,
) -> Result<(RgbImage, FrameTiming), RasterError> {
    let encode = |encoder: &mut wgpu::CommandEncoder,
                  first_pass: Option<wgpu::RenderPassTimestampWrites<'_>>| {
        method.encode(encoder, target, first_pass)
    };
    let (mut images, timing) = run_frames_of(gpu, &encode, &[resolve], warmup, frames)?;
    Ok((images.remove(0), timing))
}

/// A frame's two timestamps (the start of its first pass, the end of its last resolve) and
/// the buffers they are read through; `None` on a device without timestamps.
pub struct FrameQueries {
    set: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    read: wgpu::Buffer,
}

impl FrameQueries {
    pub fn new(gpu: &Gpu) -> Option<FrameQueries> {
        let device = &gpu.device;
        gpu.timestamps.then(|| FrameQueries {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("frame"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            }),
            resolved: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps"),
                size: 16,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            read: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamps read"),
                size: 16,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
        })
    }

    fn writes(&self, index: u32) -> wgpu::RenderPassTimestampWrites<'_> {
        wgpu::RenderPassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: (index == 0).then_some(0),
            end_of_pass_write_index: (index == 1).then_some(1),
        }
    }
}

/// Encodes one frame — `encode`'s passes, then each of `resolves` — submits it and waits
/// for it. Returns its milliseconds (GPU
/// timestamps from the first pass to the end of the last resolve, or the wall time of
/// submit-to-done without them) and the CPU milliseconds of encoding and submitting it.
pub fn submit_frame(
    gpu: &Gpu,
    queries: Option<&FrameQueries>,
    encode: &EncodeFrame<'_>,
    resolves: &[&Resolve],
) -> Result<(f64, f64), RasterError> {
    let encoding = Instant::now();
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame"),
        });
    encode(&mut encoder, queries.map(|q| q.writes(0)));
    let (last, others) = resolves.split_last().expect("a frame resolves a view");
    for resolve in others {
        resolve.encode(&mut encoder, None);
    }
    last.encode(&mut encoder, queries.map(|q| q.writes(1)));
    if let Some(q) = queries {
        encoder.resolve_query_set(&q.set, 0..2, &q.resolved, 0);
        encoder.copy_buffer_to_buffer(&q.resolved, 0, &q.read, 0, 16);
    }
    let started = Instant::now();
    gpu.queue.submit([encoder.finish()]);
    let encoded_ms = encoding.elapsed().as_secs_f64() * 1e3;
    gpu.wait()?;
    let wall_ms = started.elapsed().as_secs_f64() * 1e3;
    gpu.check()?;
    let ms = match queries {
        Some(q) => {
            let ticks: Vec<u64> = map_read(gpu, &q.read)?;
            let period_ns = f64::from(gpu.queue.get_timestamp_period());
            ticks[1].wrapping_sub(ticks[0]) as f64 * period_ns / 1e6
        }
        None => wall_ms,
    };
    Ok((ms, encoded_ms))
}

/// What a frame draws before its resolves: its scene passes, the first one carrying the
/// timestamp write it is given.
pub type EncodeFrame<'a> =
    dyn Fn(&mut wgpu::CommandEncoder, Option<wgpu::RenderPassTimestampWrites<'_>>) + 'a;

/// [`run_frames`] for a frame of several views (a stereo pair, [`crate::stereo_pair`]):
/// `encode` draws every view, then each of `resolves` resolves one; the time runs from the
/// first pass to the end of the last resolve. Returns each resolve's image, in order.
pub fn run_frames_of(
    gpu: &Gpu,
    encode: &EncodeFrame<'_>,
    resolves: &[&Resolve],
    warmup: u32,
    frames: u32,
) -> Result<(Vec<RgbImage>, FrameTiming), RasterError> {
    let queries = FrameQueries::new(gpu);
    let mut frames_ms = Vec::with_capacity(frames as usize);
    let mut encode_ms = Vec::with_capacity(frames as usize);
    for frame in 0..warmup + frames.max(1) {
        let (ms, encoded_ms) = submit_frame(gpu, queries.as_ref(), encode, resolves)?;
        if frame >= warmup {
            frames_ms.push(ms);
            encode_ms.push(encoded_ms);
        }
    }
    let source = if queries.is_some() {
        TimingSource::GpuTimestamps
    } else {
        TimingSource::WallClock
    };
    let images = resolves
        .iter()
        .map(|r| read_texture(gpu, &r.output))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((
        images,
        FrameTiming {
            source,
            frames_ms,
            encode_ms,
        },
    ))
}
