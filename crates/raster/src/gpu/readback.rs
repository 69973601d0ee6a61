//! Reading textures and buffers back to the CPU.

use crate::color_format::ColorFormat;
use crate::gpu::{Gpu, RasterError};
use half::f16;
use mirrorbox_image::RgbImage;

pub fn map_read<T: bytemuck::Pod>(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<T>, RasterError> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    gpu.wait()?;
    rx.recv()
        .map_err(|e| RasterError::Gpu(e.to_string()))?
        .map_err(|e| RasterError::Gpu(e.to_string()))?;
    let view = buffer
        .get_mapped_range(..)
        .map_err(|e| RasterError::Gpu(e.to_string()))?;
    let data = bytemuck::cast_slice(&view).to_vec();
    drop(view);
    buffer.unmap();
    Ok(data)
}

/// Copies an RGBA32F or RGBA16F texture into a linear RGB image (halves widened to f32,
/// exactly: every f16 is an f32).
pub fn read_texture(gpu: &Gpu, texture: &wgpu::Texture) -> Result<RgbImage, RasterError> {
    let format = match texture.format() {
        wgpu::TextureFormat::Rgba32Float => ColorFormat::Rgba32Float,
        wgpu::TextureFormat::Rgba16Float => ColorFormat::Rgba16Float,
        other => panic!("read_texture: {other:?} is not a colour format of the methods"),
    };
    let (w, h) = (texture.width(), texture.height());
    let row = w * format.texel_bytes();
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: (padded * h) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("readback"),
        });
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        texture.size(),
    );
    gpu.queue.submit([encoder.finish()]);
    // Channels as f32, row by row (rows padded to the copy alignment).
    let (channels, per_row): (Vec<f32>, usize) = match format {
        ColorFormat::Rgba32Float => (map_read(gpu, &buffer)?, padded as usize / 4),
        ColorFormat::Rgba16Float => {
            let bits: Vec<u16> = map_read(gpu, &buffer)?;
            let floats = bits.iter().map(|&b| f16::from_bits(b).to_f32()).collect();
            (floats, padded as usize / 2)
        }
    };
    Ok(RgbImage::from_fn(w, h, |x, y| {
        let i = y as usize * per_row + x as usize * 4;
        [channels[i], channels[i + 1], channels[i + 2]]
    }))
}
