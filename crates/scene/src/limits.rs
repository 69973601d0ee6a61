//! Every size a user controls, bounded before anything is allocated, and the one validation
//! of the settings that more than one command takes (`trace`, `render`, `sweep`): a bad value
//! is refused with the same words wherever it is given. The limits are documented in
//! `docs/scene-format.md`; each keeps the main job and the tests within an 8 GB laptop.

/// Largest image side accepted, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// Widest vertical field of view accepted, in degrees: a field of view in (0, this]. Wider,
/// a rasterizer's perspective loses its precision (`naive` on mirror_box against its truth,
/// FLIP mean 1.7e-4 at 175°, 5.5e-2 at 179°, 1.1e-1 at 179.5°, where it drew the background
/// only), and every scene must be one both renderers draw; the viewer's zoom stops here too.
pub const MAX_FOV_Y_DEG: f32 = 170.0;

/// Whether `fov` (degrees) is a vertical field of view a scene may have.
pub fn fov_ok(fov: f32) -> bool {
    fov > 0.0 && fov <= MAX_FOV_Y_DEG
}
/// Most pixels in one image (8192²): an RGB float image of this size is 0.8 GB, and a traced
/// truth holds two (colour and bounce counts).
pub const MAX_PIXELS: u64 = 1 << 26;
/// Largest scene file read (JSON).
pub const MAX_SCENE_FILE_BYTES: u64 = 16 << 20;
/// Largest OBJ file read.
pub const MAX_OBJ_FILE_BYTES: u64 = 256 << 20;
/// Most triangles in a scene, objects and mirrors together (2²², e.g. twelve spheres at
/// subdivision level 7). See [`MEMORY_PER_TRIANGLE`].
pub const MAX_TRIANGLES: usize = 1 << 22;
/// Peak bytes per triangle of a scene, measured: `mirrorbox trace` of twelve spheres at
/// subdivision level 7 (3.93 M triangles) on the development machine. With the 8-wide
/// hierarchy of the single-ray queries (the default since issue 56) and the BVH2 of the
/// packets, it peaked at 2.72 GB resident (`whitted`, `--spp 4`) and 2.73 GB (`path`, 64×36,
/// 2026-11-30): 695 bytes each. (On 2026-11-25, with obvhs's CWBVH for the single rays, 1.75
/// GB; with `--bvh bvh2`, one hierarchy for both, 1.16 GB.) `render --method naive` of it
/// peaked at 1.55 GB. Used to say what a refused scene would have needed.
pub const MEMORY_PER_TRIANGLE: u64 = 700;
/// Every position in a scene (vertices after their transform, mirror corners, camera, lights)
/// lies within `±MAX_COORDINATE` scene units on every axis, so that every triangle, its
/// bounds, the BVH and the products the intersection tests form stay finite in f32 (their
/// squares stay below 10¹³, far from f32's 3.4·10³⁸).
pub const MAX_COORDINATE: f32 = 1e6;
/// Inside the scene extent: finite, and within [`MAX_COORDINATE`] on every axis.
pub fn within_extent(p: glam::Vec3) -> bool {
    // `max_element` skips NaN, hence the explicit finiteness test.
    p.is_finite() && p.abs().max_element() <= MAX_COORDINATE
}

/// Most samples per pixel of the tracer (a 256 × 256 sub-pixel grid).
pub const MAX_SPP: u32 = 1 << 16;

/// A setting outside what is allowed, named by its command-line flag (`--width`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{flag} must be {allowed}, got {got}")]
pub struct SettingError {
    pub flag: String,
    pub allowed: String,
    pub got: String,
}

impl SettingError {
    pub fn new(flag: &str, allowed: impl Into<String>, got: impl ToString) -> Self {
        SettingError {
            flag: flag.to_string(),
            allowed: allowed.into(),
            got: got.to_string(),
        }
    }
}

/// An image side given as `flag` (`--width`, `--height`): in `[1, MAX_IMAGE_SIDE]`.
pub fn image_side(flag: &str, side: u32) -> Result<u32, SettingError> {
    if side == 0 || side > MAX_IMAGE_SIDE {
        return Err(SettingError::new(
            flag,
            format!("in [1, {MAX_IMAGE_SIDE}] pixels"),
            side,
        ));
    }
    Ok(side)
}

/// An image of `width × height` pixels, each side checked by [`image_side`], the area by
/// [`MAX_PIXELS`].
pub fn image_size(width: u32, height: u32) -> Result<(u32, u32), SettingError> {
    image_side("--width", width)?;
    image_side("--height", height)?;
    let pixels = u64::from(width) * u64::from(height);
    if pixels > MAX_PIXELS {
        return Err(SettingError::new(
            "--width × --height",
            format!(
                "at most {MAX_PIXELS} pixels (8192²; each float image of that size takes {})",
                mirrorbox_files::human_bytes(MAX_PIXELS * 12)
            ),
            format!(
                "{width}×{height} = {pixels} (would need {} per image)",
                mirrorbox_files::human_bytes(pixels * 12)
            ),
        ));
    }
    Ok((width, height))
}

/// The side s of `--spp s²`: a positive perfect square, at most [`MAX_SPP`].
pub fn spp_grid_side(spp: u32) -> Result<u32, SettingError> {
    let s = f64::from(spp).sqrt().round() as u32;
    if spp == 0 || spp > MAX_SPP || s * s != spp {
        return Err(SettingError::new(
            "--spp",
            format!(
                "a positive perfect square (the s×s sub-pixel grid) of at most {MAX_SPP}: 1, 4, 9, 16, …"
            ),
            spp,
        ));
    }
    Ok(s)
}

/// A reflectance or α: a number in `[0, 1]`.
pub fn unit_interval(flag: &str, value: f32) -> Result<f32, SettingError> {
    if !(0.0..=1.0).contains(&value) {
        return Err(SettingError::new(flag, "in [0, 1]", value));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_bounded_with_the_flag_and_the_range_in_the_message() {
        assert_eq!(image_size(640, 360), Ok((640, 360)));
        let e = image_side("--width", 0).unwrap_err().to_string();
        assert_eq!(e, "--width must be in [1, 16384] pixels, got 0");
        assert!(image_side("--height", 2_147_483_648u64 as u32).is_err());
        let e = image_size(16384, 16384).unwrap_err().to_string();
        assert!(e.contains("3.0 GiB per image"), "{e}");
    }

    #[test]
    fn spp_is_a_positive_bounded_square() {
        assert_eq!(spp_grid_side(16), Ok(4));
        assert_eq!(spp_grid_side(1), Ok(1));
        assert_eq!(spp_grid_side(MAX_SPP), Ok(256));
        for bad in [0, 2, 15, 4_294_836_225u64 as u32, 258 * 258] {
            let e = spp_grid_side(bad).unwrap_err().to_string();
            assert!(e.contains("a positive perfect square"), "{e}");
        }
    }

    #[test]
    fn unit_interval_refuses_nan_and_outside() {
        assert!(unit_interval("--alpha", 0.7).is_ok());
        for bad in [f32::NAN, -0.1, 1.5, f32::INFINITY] {
            assert!(unit_interval("--alpha", bad).is_err());
        }
    }
}
