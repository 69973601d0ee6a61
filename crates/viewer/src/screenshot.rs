//! Screenshots and the frame log.
//!
//! A screenshot `OUT.png` is the window as presented (the same egui paint jobs drawn into a
//! texture that is read back), with beside it:
//! - `OUT.method.exr`: the method's linear image (the values `render` writes);
//! - `OUT.truth.exr`: the truth's linear image, when the truth of the view is complete;
//! - `OUT.error.png`: the heat map, when there is one;
//! - `OUT.json`: the method, camera, timings, metrics, where the truth is traced (and why
//!   not on the GPU, where that failed) and each pane's rectangle in the window's pixels (so
//!   a test can cut the panes out of `OUT.png`).

use crate::ViewOptions;
use crate::session::Session;
use mirrorbox_raster::Gpu;
use serde_json::json;
use std::path::{Path, PathBuf};

/// An offscreen copy of the window's frame.
pub struct Capture {
    texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    buffer: wgpu::Buffer,
    size: (u32, u32),
    padded_row: u32,
    bgra: bool,
}

impl Capture {
    pub fn new(gpu: &Gpu, format: wgpu::TextureFormat, size: (u32, u32)) -> Capture {
        let texture = mirrorbox_raster::targets::texture_2d(
            &gpu.device,
            "screenshot",
            size.0,
            size.1,
            format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let view = texture.create_view(&Default::default());
        let padded_row = (4 * size.0).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("screenshot read"),
            size: u64::from(padded_row) * u64::from(size.1),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Capture {
            texture,
            view,
            buffer,
            size,
            padded_row,
            bgra: matches!(
                format,
                wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
            ),
        }
    }

    pub fn copy(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_texture_to_buffer(
            self.texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row),
                    rows_per_image: Some(self.size.1),
                },
            },
            wgpu::Extent3d {
                width: self.size.0,
                height: self.size.1,
                depth_or_array_layers: 1,
            },
        );
    }

    /// The frame as RGB bytes, row-major (after the copy was submitted).
    pub fn read(&self, gpu: &Gpu) -> Result<(u32, u32, Vec<u8>), String> {
        let slice = self.buffer.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        gpu.wait().map_err(|e| e.to_string())?;
        let data = slice.get_mapped_range().map_err(|e| e.to_string())?;
        let (w, h) = self.size;
        let mut rgb = Vec::with_capacity((w * h * 3) as usize);
        for row in data.chunks_exact(self.padded_row as usize).take(h as usize) {
            for p in row[..(4 * w) as usize].chunks_exact(4) {
                if self.bgra {
                    rgb.extend([p[2], p[1], p[0]]);
                } else {
                    rgb.extend([p[0], p[1], p[2]]);
                }
            }
        }
        drop(data);
        self.buffer.unmap();
        Ok((w, h, rgb))
    }
}

/// Every file a screenshot to `path` may write (see the module docs): the PNG, the method's
/// and the truth's EXR, the error map, the record — what [`save`] writes and what the checks
/// made before the window opens ([`crate::script::check_writes`]) look at.
pub fn files(path: &Path) -> [PathBuf; 5] {
    [
        path.to_path_buf(),
        with_ending(path, ".method.exr"),
        with_ending(path, ".truth.exr"),
        with_ending(path, ".error.png"),
        path.with_extension("json"),
    ]
}

/// The first number from `from` on whose files `of(n)` are all absent, for the files a key
/// writes under numbered names (`mirrorbox-view-N.png` and its companions, `scene.view-N.json`):
/// a key never replaces an earlier session's file, nor an input that happens to bear such a
/// name. Up to 10 000 numbers are tried; `None` past that.
pub fn unused_number<I>(from: u32, of: impl Fn(u32) -> I) -> Option<u32>
where
    I: IntoIterator<Item = PathBuf>,
{
    (from..from.saturating_add(10_000)).find(|&n| {
        of(n)
            .into_iter()
            .all(|f| std::fs::symlink_metadata(f).is_err())
    })
}

/// `shot.png` → `shot.method.exr`: the path without its extension, then `ending`.
fn with_ending(path: &Path, ending: &str) -> PathBuf {
    let stem = path.with_extension("");
    PathBuf::from(format!("{}{ending}", stem.display()))
}

fn panes_json(panes: &[(&'static str, [u32; 4])]) -> serde_json::Value {
    panes
        .iter()
        .map(|(name, r)| ((*name).to_string(), json!(r)))
        .collect::<serde_json::Map<_, _>>()
        .into()
}

/// Where a frame's CPU time went, in milliseconds.
pub struct Phases {
    /// The session's update: building the method's frame (a changed view), drawing it (the
    /// GPU frame; its image is read back only when a screenshot or the error view asks), and
    /// the truth's and error's panes.
    pub update: crate::session::UpdatePhases,
    /// egui: the panel's layout and tessellation.
    pub ui: f64,
    /// Waiting for the window's next image.
    pub acquire: f64,
    /// Painting the window and presenting it.
    pub paint_present: f64,
    /// The whole frame from the update to the present.
    pub total: f64,
}

/// One frame of the `--log`: what was shown and what it cost.
pub fn frame_record(
    frame: u64,
    phases: &Phases,
    session: &Session,
    panes: &[(&'static str, [u32; 4])],
    window: (u32, u32),
) -> serde_json::Value {
    let method = session.frame.as_ref();
    let history = session.history.back();
    json!({
        "frame": frame,
        "method": session.method.key(),
        "ssaa": session.ssaa,
        "method_error": session.method_error,
        "passes": method.map(|f| f.stats.passes),
        "draws": method.map(|f| f.stats.draws),
        "reflections": method.map(|f| f.stats.depth),
        "paths": method.and_then(|f| f.stats.paths.map(|p| p.kept)),
        "gpu_ms": method.map(|f| f.gpu_ms),
        "timing": method.map(|f| f.timing_source.clone()),
        "wall_ms": history.map(|t| t.wall_ms),
        "build_ms": history.map(|t| t.build_ms),
        "plan_ms": history.map(|t| t.plan_ms),
        "truth_level": session.truth_shown.as_ref().map(|l| l.level),
        "truth_complete": session.complete_truth().is_some(),
        "truth_device": session.truth_device(),
        "flip_mean": session.error.as_ref().map(|e| e.metrics.flip_mean),
        "window": [window.0, window.1],
        "panes": panes_json(panes),
        "phases_ms": {
            "build": phases.update.build,
            "plan": phases.update.plan,
            "draw": phases.update.draw,
            "panes": phases.update.panes,
            "ui": phases.ui,
            "acquire": phases.acquire,
            "paint_present": phases.paint_present,
            "total": phases.total,
        },
    })
}

/// Writes a screenshot and its companions (see the module docs); every file atomically.
pub fn save(
    path: &Path,
    (w, h, rgb): &(u32, u32, Vec<u8>),
    session: &Session,
    method_image: Option<&mirrorbox_image::RgbImage>,
    panes: &[(&'static str, [u32; 4])],
    options: &ViewOptions,
) -> Result<(), String> {
    let err = |e: mirrorbox_image::ImageError| format!("{}: {e}", path.display());
    let [png, method_exr, truth_exr, error_png, record_json] = files(path);
    mirrorbox_image::write_png_bytes(&png, *w, *h, rgb).map_err(err)?;
    let camera = session.view_camera();
    if let Some(image) = method_image {
        mirrorbox_image::write_exr(
            &method_exr,
            image,
            &[("mirrorbox.method", session.method.key())],
        )
        .map_err(err)?;
    }
    let truth = session.complete_truth();
    if let Some(level) = truth {
        let side = level.request.grid_side;
        mirrorbox_image::write_exr(
            &truth_exr,
            &level.image,
            &[("mirrorbox.spp", (side * side).to_string())],
        )
        .map_err(err)?;
    }
    if let Some(e) = &session.error {
        mirrorbox_image::write_png_bytes(&error_png, e.width, e.height, &e.heat_rgb8)
            .map_err(err)?;
    }
    // A companion not written this time would be an earlier shot's at the same path, beside
    // a record that says it is not there.
    for (file, written) in [
        (&method_exr, method_image.is_some()),
        (&truth_exr, truth.is_some()),
        (&error_png, session.error.is_some()),
    ] {
        if !written {
            mirrorbox_files::remove_stale(file).map_err(|e| e.to_string())?;
        }
    }
    let frame = session.frame.as_ref();
    let record = json!({
        "scene": options.scene_path.display().to_string(),
        "method": session.method.key(),
        "ssaa": session.ssaa,
        "size": [session.size.0, session.size.1],
        "camera": {
            "position": camera.position.to_array(),
            "look_at": camera.look_at.to_array(),
            "up": camera.up.to_array(),
            "fov_y_deg": camera.fov_y_deg,
        },
        "passes": frame.map(|f| f.stats.passes),
        "draws": frame.map(|f| f.stats.draws),
        "reflections": frame.map(|f| f.stats.depth),
        "gpu_ms": frame.map(|f| f.gpu_ms),
        "truth_complete": truth.is_some(),
        "truth_device": session.truth_device(),
        "error_map": session.error_mode.name(),
        "metrics": session.error.as_ref().map(|e| json!({
            "flip_mean": e.metrics.flip_mean,
            "relmse": e.metrics.relmse,
            "psnr": if e.metrics.psnr.is_finite() { json!(e.metrics.psnr) } else { json!(null) },
            "ssim": e.metrics.ssim,
        })),
        "window": [w, h],
        "panes": panes_json(panes),
    });
    let mut text = serde_json::to_string_pretty(&record).map_err(|e| e.to_string())?;
    text.push('\n');
    mirrorbox_files::write_atomically(&record_json, text.as_bytes()).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A numbered file is never one that exists: any of a screenshot's five files (an
    /// earlier session's, or an input such as a scene named like its JSON) moves it on.
    #[test]
    fn a_numbered_screenshot_skips_every_number_with_a_file() {
        let dir = tempfile::tempdir().unwrap();
        let shot = |n: u32| files(&dir.path().join(format!("mirrorbox-view-{n}.png")));
        assert_eq!(unused_number(1, shot), Some(1));
        std::fs::write(dir.path().join("mirrorbox-view-1.png"), b"").unwrap();
        std::fs::write(dir.path().join("mirrorbox-view-2.json"), b"{}").unwrap();
        std::fs::write(dir.path().join("mirrorbox-view-3.truth.exr"), b"").unwrap();
        assert_eq!(unused_number(1, shot), Some(4));
        assert_eq!(unused_number(5, shot), Some(5));
        assert_eq!(unused_number(u32::MAX, shot), None, "no number left");
    }
}
