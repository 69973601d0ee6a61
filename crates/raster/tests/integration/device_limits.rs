//! Resources beyond the device's limits are refused with the numbers before they are created
//! (issue #12: 6.5 M triangles once failed inside wgpu with "Buffer with 'vertices' label is
//! invalid", exit 101).

use mirrorbox_raster::{Gpu, RasterError};

#[test]
fn buffers_and_targets_beyond_the_device_are_refused_with_the_numbers() {
    let gpu = Gpu::new().expect("a wgpu adapter (scripts/install-system-deps.sh)");
    let limits = gpu.device.limits();
    assert!(
        limits.max_buffer_size < u64::MAX && limits.max_texture_dimension_2d < u32::MAX,
        "an adapter without limits: nothing to refuse"
    );
    let e = gpu
        .check_buffer("vertex", limits.max_buffer_size + 1, false)
        .unwrap_err();
    assert!(e.is_refusal(), "{e}");
    assert!(matches!(e, RasterError::ExceedsDevice { .. }));
    let text = e.to_string();
    assert!(
        text.contains("a vertex buffer") && text.contains("use fewer triangles"),
        "{text}"
    );
    gpu.check_buffer("vertex", limits.max_buffer_size, false)
        .expect("at the limit is fine");
    let storage = limits.max_storage_buffer_binding_size;
    assert!(
        gpu.check_buffer("surface", storage.saturating_add(1), true)
            .is_err()
    );
    let side = limits.max_texture_dimension_2d;
    let e = gpu
        .check_target(side + 1, 16, "; lower --ssaa or the image size")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("{} pixels per side", side)) && e.contains("--ssaa"),
        "{e}"
    );
    gpu.check_target(side, 16, "")
        .expect("at the limit is fine");
}
