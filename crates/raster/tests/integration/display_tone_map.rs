//! The viewer's tone map on the GPU (`display_tone_map.wgsl`) writes the bytes
//! `srgb::encode8(c × exposure)` gives on the CPU — the bytes of `render`'s PNG — for every
//! threshold of the table and the floats beside it, and for what lies outside [0, 1]: NaNs,
//! infinities, negatives, -0, denormals, values above 1.

use mirrorbox_image::srgb::{encode8, encode8_thresholds};
use mirrorbox_raster::Gpu;
use mirrorbox_raster::display_tone_map::{DisplayToneMap, ToneMapUniform};
use mirrorbox_raster::readback::map_read;

const WIDTH: u32 = 256;

#[test]
fn the_gpu_tone_map_writes_encode8s_bytes() {
    let gpu = Gpu::new().unwrap();
    let mut values = vec![
        f32::NAN,
        -f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        -0.0,
        0.0,
        -1.0,
        1e-40,
        f32::MIN_POSITIVE,
        1.0,
        1.000_001,
        7.5,
        f32::MAX,
    ];
    for t in &encode8_thresholds()[1..] {
        for d in -2i64..=2 {
            values.push(f32::from_bits((i64::from(t.to_bits()) + d) as u32));
        }
    }
    // Three values a texel (R, G, B), alpha 1.
    let texels = values.len().div_ceil(3) as u32;
    let height = texels.div_ceil(WIDTH);
    let mut rgba = vec![0.0f32; (4 * WIDTH * height) as usize];
    for (i, v) in values.iter().enumerate() {
        rgba[4 * (i / 3) + i % 3] = *v;
    }
    for p in rgba.chunks_exact_mut(4) {
        p[3] = 1.0;
    }
    let size = wgpu::Extent3d {
        width: WIDTH,
        height,
        depth_or_array_layers: 1,
    };
    let source = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("values"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    gpu.queue.write_texture(
        source.as_image_copy(),
        bytemuck::cast_slice(&rgba),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(16 * WIDTH),
            rows_per_image: Some(height),
        },
        size,
    );
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let target = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("bytes"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let view = target.create_view(&Default::default());
    let tone_map = DisplayToneMap::new(&gpu, format);
    let bound = tone_map.bind(&gpu, &source);
    let read = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("bytes read"),
        size: u64::from(4 * WIDTH * height),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    for exposure in [1.0f32, 0.7, 3.0] {
        bound.set(
            &gpu.queue,
            ToneMapUniform {
                origin: [0.0, 0.0],
                step: [1.0, 1.0],
                exposure,
                pad: 0.0,
            },
        );
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("tone map"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            tone_map.draw(&mut pass, &bound);
        }
        encoder.copy_texture_to_buffer(
            target.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &read,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(4 * WIDTH),
                    rows_per_image: Some(height),
                },
            },
            size,
        );
        gpu.queue.submit([encoder.finish()]);
        let bytes: Vec<u8> = map_read(&gpu, &read).unwrap();
        let wrong: Vec<String> = values
            .iter()
            .enumerate()
            .filter_map(|(i, &v)| {
                let (got, want) = (bytes[4 * (i / 3) + i % 3], encode8(v * exposure));
                (got != want).then(|| format!("{v:e} × {exposure}: {got}, not {want}"))
            })
            .collect();
        assert!(
            wrong.is_empty(),
            "{} of {} values: {:?}",
            wrong.len(),
            values.len(),
            &wrong[..wrong.len().min(10)]
        );
        assert_eq!(bytes[3], 255, "opaque");
    }
}
