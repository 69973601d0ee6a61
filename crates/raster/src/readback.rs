//! Reading textures and buffers back to the CPU.

use crate::gpu::{Gpu, RasterError};
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

/// Copies an `Rgba32Float` texture into a linear RGB image.
pub fn read_texture(gpu: &Gpu, texture: &wgpu::Texture) -> Result<RgbImage, RasterError> {
    let (w, h) = (texture.width(), texture.height());
    let row = w * 16;
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
    let floats: Vec<f32> = map_read(gpu, &buffer)?;
    let per_row = (padded / 4) as usize;
    Ok(RgbImage::from_fn(w, h, |x, y| {
        let i = y as usize * per_row + x as usize * 4;
        [floats[i], floats[i + 1], floats[i + 2]]
    }))
}
