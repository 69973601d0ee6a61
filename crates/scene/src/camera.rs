//! The pinhole camera shared by both renderers.
//!
//! **Pixel convention** (one for the whole project): pixel `(x, y)` covers
//! `[x, x+1) × [y, y+1)` in continuous image coordinates, `y` pointing down, `(0, 0)` the
//! top-left corner. A sample at sub-pixel offset `(u, v) ∈ [0,1)²` sits at `(x+u, y+v)`.
//! NDC: `ndc_x = 2·px/W − 1`, `ndc_y = 1 − 2·py/H` — the mapping wgpu's viewport applies,
//! so a rasterized pixel centre and [`Camera::primary_ray`] at `(x+½, y+½)` see one point.
//!
//! View space is right-handed, y up, looking down −z (glam's `rh` camera module); the
//! projection maps depth to `[0, 1]` (WebGPU), see [`Camera::projection`].

use glam::{Mat4, Vec2, Vec3, Vec4};

/// A ray with origin and unit direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl Ray {
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// A validated pinhole camera (see `docs/scene-format.md`, `camera`).
#[derive(Clone, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    pub look_at: Vec3,
    /// World up hint (unit); the true up is orthogonalized against the view direction.
    pub up: Vec3,
    /// Vertical field of view in degrees, in (0, 170] ([`crate::limits::MAX_FOV_Y_DEG`]).
    pub fov_y_deg: f32,
    pub width: u32,
    pub height: u32,
    /// Linear multiplier applied to radiance before the sRGB transfer (`docs/shading.md`).
    pub exposure: f32,
    /// Horizontal lens shift in NDC units: the image's centre looks `shift_x` to the side
    /// (`ndc_x = projected + shift_x`), the asymmetric frustum of an off-axis stereo eye
    /// ([`crate::stereo`]); 0 for a centred camera.
    pub shift_x: f32,
}

/// As derived, with `shift_x` only where it is not 0: a centred camera prints (and so
/// hashes, [`crate::Scene::content_hash`]) as it did before lens shifts existed.
impl std::fmt::Debug for Camera {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut d = f.debug_struct("Camera");
        d.field("position", &self.position)
            .field("look_at", &self.look_at)
            .field("up", &self.up)
            .field("fov_y_deg", &self.fov_y_deg)
            .field("width", &self.width)
            .field("height", &self.height)
            .field("exposure", &self.exposure);
        if self.shift_x != 0.0 {
            d.field("shift_x", &self.shift_x);
        }
        d.finish()
    }
}

impl Camera {
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// The same camera at another image size (the CLI's `--width/--height`). The vertical
    /// field of view is kept, so the horizontal one follows the new aspect ratio.
    pub fn with_size(&self, width: u32, height: u32) -> Camera {
        Camera {
            width,
            height,
            ..self.clone()
        }
    }

    /// World → view transform (right-handed, looking down −z).
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.position, self.look_at, self.up)
    }

    /// View → clip transform with depth in `[0, 1]` (WebGPU/DirectX convention), shifted by
    /// `shift_x` (`clip_x += −shift_x·z_view`, so `ndc_x` moves by `shift_x`).
    pub fn projection(&self, near: f32, far: f32) -> Mat4 {
        let mut m = glam::camera::rh::proj::directx::perspective(
            self.fov_y_deg.to_radians(),
            self.aspect(),
            near,
            far,
        );
        if self.shift_x != 0.0 {
            m.z_axis.x = -self.shift_x;
        }
        m
    }

    /// The ray through continuous image position `(px, py)` (pixel convention above).
    pub fn primary_ray(&self, px: f32, py: f32) -> Ray {
        self.ray_generator().ray(px, py)
    }

    /// Precomputes the camera frame for generating many rays.
    pub fn ray_generator(&self) -> RayGenerator {
        let forward = (self.look_at - self.position).normalize();
        let right = forward.cross(self.up).normalize();
        let up = right.cross(forward);
        let tan_half = (0.5 * self.fov_y_deg.to_radians()).tan();
        RayGenerator {
            origin: self.position,
            right: right * (tan_half * self.aspect()),
            up: up * tan_half,
            forward,
            width: self.width as f32,
            height: self.height as f32,
            shift_x: self.shift_x,
        }
    }

    /// Continuous image position of a world point, through `projection · view`; `None` if
    /// the point is not in front of the camera.
    pub fn project_to_pixel(&self, p: Vec3) -> Option<Vec2> {
        let clip = self.projection(0.01, 1000.0) * self.view() * p.extend(1.0);
        (clip.w > 0.0).then(|| ndc_to_pixel(clip.truncate().truncate() / clip.w, self.size()))
    }

    pub fn size(&self) -> Vec2 {
        Vec2::new(self.width as f32, self.height as f32)
    }
}

/// Generates primary rays for one camera (its frame precomputed).
#[derive(Clone, Copy, Debug)]
pub struct RayGenerator {
    origin: Vec3,
    /// Camera right scaled by tan(fov/2)·aspect.
    right: Vec3,
    /// Camera up scaled by tan(fov/2).
    up: Vec3,
    forward: Vec3,
    width: f32,
    height: f32,
    shift_x: f32,
}

impl RayGenerator {
    /// The frame a GPU twin needs to make the same rays: (forward, right·tan(fov/2)·aspect,
    /// up·tan(fov/2), shift_x) — `ray-query --primary rays`.
    pub fn frame(&self) -> (Vec3, Vec3, Vec3, f32) {
        (self.forward, self.right, self.up, self.shift_x)
    }

    /// `d = normalize(forward + (ndc_x − shift_x)·tan(fov/2)·aspect·right + ndc_y·tan(fov/2)·up)`,
    /// the inverse of [`Camera::projection`] on the plane z_view = −1.
    pub fn ray(&self, px: f32, py: f32) -> Ray {
        Ray {
            origin: self.origin,
            dir: Vec3::from(self.dir(px, py)),
        }
    }

    /// The rays through the image positions `positions`, in order, appended to `out`:
    /// [`RayGenerator::ray`]'s, bit for bit, computed sixteen at a time in lane loops
    /// ([`RayGenerator::dirs_at`]).
    #[inline(always)]
    pub fn rays_at_positions(&self, positions: &[Vec2], out: &mut Vec<Ray>) {
        const LANES: usize = 16;
        for chunk in positions.chunks(LANES) {
            let dir = self.dirs_through::<LANES>(chunk);
            out.extend((0..chunk.len()).map(|i| Ray {
                origin: self.origin,
                dir: Vec3::new(dir[0][i], dir[1][i], dir[2][i]),
            }));
        }
    }

    /// The directions of [`RayGenerator::ray`] through `positions` (1 to `N` of them), one
    /// per lane, bit for bit (`RayGenerator::dirs_at`); lanes past the end repeat the last
    /// position (a lane loop with a clamped index stayed scalar).
    #[inline(always)]
    pub fn dirs_through<const N: usize>(&self, positions: &[Vec2]) -> [[f32; N]; 3] {
        let last = positions[positions.len() - 1];
        let (mut px, mut py) = ([last.x; N], [last.y; N]);
        for (i, p) in positions.iter().enumerate() {
            (px[i], py[i]) = (p.x, p.y);
        }
        self.dirs_at(&px, &py)
    }

    /// The directions of [`RayGenerator::ray`] through `(px[i], py[i])` for every lane `i`,
    /// bit for bit, in a lane loop that the compiler vectorises (inline: compiled for the
    /// caller's CPU features).
    #[inline(always)]
    fn dirs_at<const N: usize>(&self, px: &[f32; N], py: &[f32; N]) -> [[f32; N]; 3] {
        let mut dir = [[0.0f32; N]; 3];
        for i in 0..N {
            let d = self.dir(px[i], py[i]);
            for k in 0..3 {
                dir[k][i] = d[k];
            }
        }
        dir
    }

    /// Where every ray starts: the camera's position.
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// The unit direction through pixel position `(px, py)`: glam's arithmetic
    /// (`forward + right·a + up·b`, then `v · (1/√(v·v))`) written on components, branch
    /// free, so that lane loops vectorise it with the same bits.
    #[inline(always)]
    fn dir(&self, px: f32, py: f32) -> [f32; 3] {
        let ndc = pixel_to_ndc(Vec2::new(px, py), Vec2::new(self.width, self.height));
        let (a, b) = (ndc.x - self.shift_x, ndc.y);
        let (f, r, u) = (self.forward, self.right, self.up);
        let v = [
            f.x + r.x * a + u.x * b,
            f.y + r.y * a + u.y * b,
            f.z + r.z * a + u.z * b,
        ];
        let inv_length = 1.0 / (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        [v[0] * inv_length, v[1] * inv_length, v[2] * inv_length]
    }
}

/// Continuous image position → NDC (x right, y up, both in [−1, 1] over the image).
#[inline(always)]
pub fn pixel_to_ndc(p: Vec2, size: Vec2) -> Vec2 {
    Vec2::new(2.0 * p.x / size.x - 1.0, 1.0 - 2.0 * p.y / size.y)
}

/// NDC → continuous image position (inverse of [`pixel_to_ndc`]).
pub fn ndc_to_pixel(ndc: Vec2, size: Vec2) -> Vec2 {
    Vec2::new((ndc.x + 1.0) * 0.5 * size.x, (1.0 - ndc.y) * 0.5 * size.y)
}

/// The fixed `s × s` grid of sub-pixel sample positions shared by the tracer (`--spp s²`)
/// and the rasterizer (`--ssaa s`): offsets `((i+½)/s, (j+½)/s)` for `j` (rows) then `i`.
///
/// Rendering at `s×` resolution puts high-resolution pixel `(s·x+i, s·y+j)`'s centre at
/// `x + (i+½)/s` in low-resolution coordinates, so box-filtering the supersampled raster
/// image averages exactly these positions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SubpixelGrid {
    pub per_axis: u32,
}

impl SubpixelGrid {
    pub fn new(per_axis: u32) -> Self {
        assert!(
            per_axis > 0,
            "a sub-pixel grid needs at least one sample per axis"
        );
        SubpixelGrid { per_axis }
    }
    pub fn samples_per_pixel(&self) -> u32 {
        self.per_axis * self.per_axis
    }
    /// The sample offsets within a pixel, row by row.
    pub fn offsets(&self) -> impl Iterator<Item = Vec2> + '_ {
        let s = self.per_axis;
        (0..s).flat_map(move |j| {
            (0..s).map(move |i| Vec2::new((i as f32 + 0.5) / s as f32, (j as f32 + 0.5) / s as f32))
        })
    }
}

/// Homogeneous point helper used in tests and by the renderers.
pub fn point4(p: Vec3) -> Vec4 {
    p.extend(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn test_camera() -> Camera {
        Camera {
            position: Vec3::new(0.7, 1.6, 1.5),
            look_at: Vec3::new(-0.4, 1.1, -2.0),
            up: Vec3::Y,
            fov_y_deg: 55.0,
            width: 64,
            height: 36,
            exposure: 1.0,
            shift_x: 0.0,
        }
    }

    /// The lane loops give [`RayGenerator::ray`]'s bits, for a full packet of positions and
    /// a short tail, with a shifted (stereo) frustum too.
    #[test]
    fn rays_at_positions_are_ray_bit_for_bit() {
        let mut camera = test_camera();
        for shift_x in [0.0, 0.031] {
            camera.shift_x = shift_x;
            let generator = camera.ray_generator();
            let offsets: Vec<Vec2> = (0..23)
                .map(|i| Vec2::new((i as f32 * 0.618_034).fract(), (i as f32 * 0.414_2).fract()))
                .collect();
            for (x, y) in [(0.0, 0.0), (17.0, 5.0), (63.0, 35.0)] {
                let positions: Vec<Vec2> = offsets
                    .iter()
                    .map(|o| Vec2::new(x + o.x, y + o.y))
                    .collect();
                let mut rays = Vec::new();
                generator.rays_at_positions(&positions, &mut rays);
                assert_eq!(rays.len(), offsets.len());
                for (ray, o) in rays.iter().zip(&offsets) {
                    let one = generator.ray(x + o.x, y + o.y);
                    assert_eq!(ray.origin, one.origin);
                    assert_eq!(
                        ray.dir.to_array().map(f32::to_bits),
                        one.dir.to_array().map(f32::to_bits)
                    );
                }
            }
        }
    }

    #[test]
    fn primary_ray_hits_the_point_projected_to_its_subpixel_position() {
        let cam = test_camera();
        for (px, py) in [
            (0.0, 0.0),
            (12.25, 7.75),
            (31.5, 17.5),
            (63.9, 35.9),
            (5.1, 30.3),
        ] {
            let ray = cam.primary_ray(px, py);
            for t in [0.5, 3.0, 40.0] {
                let p = ray.at(t);
                let back = cam.project_to_pixel(p).unwrap();
                assert!(
                    (back - Vec2::new(px, py)).length() < 2e-3,
                    "({px},{py}) at t={t} projects to {back}"
                );
            }
        }
    }

    #[test]
    fn centre_ray_looks_at_the_target_and_frame_is_right_handed() {
        let cam = test_camera();
        let r = cam.primary_ray(32.0, 18.0);
        let expected = (cam.look_at - cam.position).normalize();
        assert!(r.dir.abs_diff_eq(expected, 1e-6));
        // Moving right in the image turns the ray to the camera's right (forward × up).
        let right = expected.cross(Vec3::Y);
        assert!(cam.primary_ray(60.0, 18.0).dir.dot(right) > 0.0);
        // Moving down in the image lowers the ray.
        assert!(cam.primary_ray(32.0, 35.0).dir.y < r.dir.y);
    }

    #[test]
    fn vertical_fov_spans_the_image_height() {
        let cam = test_camera();
        let top = cam.primary_ray(32.0, 0.0).dir;
        let bottom = cam.primary_ray(32.0, 36.0).dir;
        let angle = top.angle_between(bottom).to_degrees();
        assert!((angle - cam.fov_y_deg).abs() < 1e-3, "{angle}");
    }

    #[test]
    fn subpixel_grid_matches_supersampled_pixel_centres() {
        let grid = SubpixelGrid::new(3);
        let offsets: Vec<Vec2> = grid.offsets().collect();
        assert_eq!(offsets.len(), 9);
        let (x, y) = (5u32, 2u32);
        for j in 0..3 {
            for i in 0..3 {
                let hi_res_centre = Vec2::new((3 * x + i) as f32 + 0.5, (3 * y + j) as f32 + 0.5);
                let expected = hi_res_centre / 3.0;
                let got = Vec2::new(x as f32, y as f32) + offsets[(j * 3 + i) as usize];
                assert!(got.abs_diff_eq(expected, 1e-6));
            }
        }
    }

    #[test]
    fn ndc_round_trip() {
        let size = Vec2::new(640.0, 360.0);
        for p in [Vec2::ZERO, Vec2::new(320.0, 180.0), Vec2::new(640.0, 360.0)] {
            assert!(ndc_to_pixel(pixel_to_ndc(p, size), size).abs_diff_eq(p, 1e-4));
        }
        assert_eq!(pixel_to_ndc(Vec2::ZERO, size), Vec2::new(-1.0, 1.0));
    }
}
