//! Colour textures: a diffuse surface's albedo and emission may vary over it
//! (`docs/shading.md`, "Textures"). Implemented once here; the tracer calls
//! [`TextureMap::sample`], the WGSL twin (`texture_sample` in `shaders/shading.wgsl`) performs
//! the same f32 operations in the same order, and `crates/raster/src/shading.rs`'s tests hold
//! the two together.
//!
//! The rule, for a texture `W × H` and a point with texture coordinates `uv`:
//! 1. `uv' = M·(uv, 1)`, `M` the map's 2×3 transform (glTF's `KHR_texture_transform`:
//!    `T·R·S`; identity without it);
//! 2. `x = u'·W − ½`, `y = v'·H − ½` (texel `(i, j)` is centred at `((i + ½)/W, (j + ½)/H)`;
//!    row 0 is the image's first row, at `v = 0`: glTF's convention);
//! 3. `i = ⌊x⌋`, `j = ⌊y⌋`, `f = x − i`, `g = y − j`; the four texels `(i, j)`, `(i+1, j)`,
//!    `(i, j+1)`, `(i+1, j+1)`, each index wrapped by its axis's mode (repeat, clamp to edge,
//!    mirrored repeat), are decoded from sRGB to linear and blended bilinearly:
//!    `a + (b − a)·f` along x, then along y. No mip-maps: the same texel weights at any
//!    distance, in both renderers, so minification aliases identically in both and the
//!    image's supersampling averages it.
//!
//! `x` and `y` are clamped to ±2²⁴ before `⌊⌋` so that huge coordinates stay integers in
//! both renderers.

use glam::{Vec2, Vec3};

/// Largest texture side, in texels (a 4096² RGBA texture is 64 MiB).
pub const MAX_TEXTURE_SIDE: u32 = 4096;
/// Largest number of texels of all textures of a scene together (128 MiB as RGBA8).
pub const MAX_TEXTURE_TEXELS: u64 = 1 << 25;
/// Texel coordinates are clamped to ±this before rounding down (see the module docs).
pub const MAX_TEXEL_COORDINATE: f32 = 16_777_216.0;

/// How a texel index outside `0..size` is brought back (glTF's sampler wrap modes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    #[default]
    Repeat,
    ClampToEdge,
    MirroredRepeat,
}

impl Wrap {
    /// The index the texel `i` of an axis of `size` texels reads.
    pub fn index(self, i: i32, size: i32) -> i32 {
        match self {
            Wrap::Repeat => i.rem_euclid(size),
            Wrap::ClampToEdge => i.clamp(0, size - 1),
            Wrap::MirroredRepeat => {
                let m = i.rem_euclid(2 * size);
                if m >= size { 2 * size - 1 - m } else { m }
            }
        }
    }
    /// The number the WGSL twin switches on.
    pub fn code(self) -> u32 {
        match self {
            Wrap::Repeat => 0,
            Wrap::ClampToEdge => 1,
            Wrap::MirroredRepeat => 2,
        }
    }
}

/// An sRGB-encoded RGBA image, row 0 first (at `v = 0`). Alpha is kept but never read:
/// every surface is opaque (`docs/shading.md`).
#[derive(Clone, PartialEq)]
pub struct Texture {
    /// Where it came from (`BoxTextured.gltf: images[0]`), for messages and exports.
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[u8; 4]>,
}

impl std::fmt::Debug for Texture {
    /// The texels enter the scene's content hash through an FNV-1a of their bytes, not as a
    /// list of millions of numbers.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut h = crate::hash::Fnv1a::new();
        for t in &self.texels {
            h.write_bytes(t);
        }
        write!(
            f,
            "Texture({:?} {}x{} {:016x})",
            self.name,
            self.width,
            self.height,
            h.finish()
        )
    }
}

impl Texture {
    /// Texel `(i, j)` (already wrapped) in linear RGB.
    fn linear(&self, i: i32, j: i32) -> Vec3 {
        let t = self.texels[j as usize * self.width as usize + i as usize];
        let table = &*SRGB_TO_LINEAR;
        Vec3::new(
            table[usize::from(t[0])],
            table[usize::from(t[1])],
            table[usize::from(t[2])],
        )
    }
}

/// [`srgb_to_linear`] of every 8-bit value, computed once: the same bits as the function,
/// without a `powf` per channel of each of a bilinear sample's four texels (which were 15 %
/// of `textured_box`'s trace).
static SRGB_TO_LINEAR: std::sync::LazyLock<[f32; 256]> =
    std::sync::LazyLock::new(|| std::array::from_fn(|v| srgb_to_linear(v as u8)));

/// The sRGB transfer function's inverse for an 8-bit value, in f32 (the WGSL twin computes
/// the same expression).
pub fn srgb_to_linear(value: u8) -> f32 {
    let c = f32::from(value) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A texture as one surface reads it: which image, how its coordinates wrap, and the
/// transform of its texture coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureMap {
    /// Index into [`crate::Geometry::textures`].
    pub texture: u32,
    /// Wrap modes along u and v.
    pub wrap: [Wrap; 2],
    /// Row-major 2×3 matrix: `u' = m[0]·u + m[1]·v + m[2]`, `v' = m[3]·u + m[4]·v + m[5]`.
    pub transform: [f32; 6],
}

/// The identity texture transform.
pub const IDENTITY_TRANSFORM: [f32; 6] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

impl TextureMap {
    /// The texture coordinates after the map's transform.
    pub fn transformed(&self, uv: Vec2) -> Vec2 {
        let m = self.transform;
        Vec2::new(
            m[0] * uv.x + m[1] * uv.y + m[2],
            m[3] * uv.x + m[4] * uv.y + m[5],
        )
    }

    /// The linear RGB value of `texture` (this map's image) at texture coordinates `uv`, by
    /// the rule of the module docs.
    pub fn sample(&self, texture: &Texture, uv: Vec2) -> Vec3 {
        let (w, h) = (texture.width as i32, texture.height as i32);
        let t = self.transformed(uv);
        let x =
            (t.x * texture.width as f32 - 0.5).clamp(-MAX_TEXEL_COORDINATE, MAX_TEXEL_COORDINATE);
        let y =
            (t.y * texture.height as f32 - 0.5).clamp(-MAX_TEXEL_COORDINATE, MAX_TEXEL_COORDINATE);
        let (x0, y0) = (x.floor(), y.floor());
        let (f, g) = (x - x0, y - y0);
        let (i, j) = (x0 as i32, y0 as i32);
        let [wu, wv] = self.wrap;
        let (i0, i1) = (wu.index(i, w), wu.index(i.wrapping_add(1), w));
        let (j0, j1) = (wv.index(j, h), wv.index(j.wrapping_add(1), h));
        let top = lerp(texture.linear(i0, j0), texture.linear(i1, j0), f);
        let bottom = lerp(texture.linear(i0, j1), texture.linear(i1, j1), f);
        lerp(top, bottom, g)
    }
}

/// `a + (b − a)·t`, the order the WGSL twin uses.
fn lerp(a: Vec3, b: Vec3, t: f32) -> Vec3 {
    a + (b - a) * t
}

/// A diffuse surface's textures: albedo = factor ⊙ albedo texture, emission = factor ⊙
/// emission texture (`docs/shading.md`, "Textures").
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceMaps {
    pub albedo: Option<TextureMap>,
    pub emission: Option<TextureMap>,
}

impl SurfaceMaps {
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.albedo.is_none() && self.emission.is_none()
    }
}

/// Barycentric weights `(b1, b2)` of point `p` in triangle `t` (`p ≈ t0 + b1(t1−t0) +
/// b2(t2−t0)`), from the point's projection on the triangle's plane; `(0, 0)` for a
/// degenerate triangle.
pub fn barycentric(t: &[Vec3; 3], p: Vec3) -> Vec2 {
    let (e1, e2, ep) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (dp1, dp2) = (ep.dot(e1), ep.dot(e2));
    let det = d11 * d22 - d12 * d12;
    if det.abs() <= f32::MIN_POSITIVE || !det.is_finite() {
        return Vec2::ZERO;
    }
    Vec2::new((d22 * dp1 - d12 * dp2) / det, (d11 * dp2 - d12 * dp1) / det)
}

/// The texture coordinates at barycentric weights `b` of a triangle whose corners have `uv`.
pub fn interpolate_uv(uv: &[Vec2; 3], b: Vec2) -> Vec2 {
    uv[0] + (uv[1] - uv[0]) * b.x + (uv[2] - uv[0]) * b.y
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker() -> Texture {
        // 2×2: black, white / red, blue.
        Texture {
            name: "checker".into(),
            width: 2,
            height: 2,
            texels: vec![
                [0, 0, 0, 255],
                [255, 255, 255, 255],
                [255, 0, 0, 255],
                [0, 0, 255, 255],
            ],
        }
    }

    fn map(wrap: Wrap) -> TextureMap {
        TextureMap {
            texture: 0,
            wrap: [wrap; 2],
            transform: IDENTITY_TRANSFORM,
        }
    }

    #[test]
    fn texel_centres_return_their_texel_and_midpoints_blend_in_linear() {
        let t = checker();
        let m = map(Wrap::Repeat);
        assert_eq!(m.sample(&t, Vec2::new(0.25, 0.25)), Vec3::ZERO);
        assert_eq!(m.sample(&t, Vec2::new(0.75, 0.25)), Vec3::ONE);
        assert_eq!(m.sample(&t, Vec2::new(0.25, 0.75)), Vec3::X);
        // Half-way between black and white: 0.5 in linear (sRGB 188), not sRGB 128.
        let mid = m.sample(&t, Vec2::new(0.5, 0.25));
        assert!((mid - Vec3::splat(0.5)).abs().max_element() < 1e-6, "{mid}");
    }

    #[test]
    fn wrap_modes_bring_indices_back_as_gltf_defines() {
        assert_eq!(
            (-3..7)
                .map(|i| Wrap::Repeat.index(i, 3))
                .collect::<Vec<_>>(),
            [0, 1, 2, 0, 1, 2, 0, 1, 2, 0]
        );
        assert_eq!(
            (-3..7)
                .map(|i| Wrap::ClampToEdge.index(i, 3))
                .collect::<Vec<_>>(),
            [0, 0, 0, 0, 1, 2, 2, 2, 2, 2]
        );
        assert_eq!(
            (-3..7)
                .map(|i| Wrap::MirroredRepeat.index(i, 3))
                .collect::<Vec<_>>(),
            [2, 1, 0, 0, 1, 2, 2, 1, 0, 0]
        );
        let t = checker();
        // Past the right edge: repeat blends the last column with the first, clamp does not.
        let at = Vec2::new(1.0, 0.25);
        assert!(
            (map(Wrap::Repeat).sample(&t, at) - Vec3::splat(0.5))
                .abs()
                .max_element()
                < 1e-6
        );
        assert_eq!(map(Wrap::ClampToEdge).sample(&t, at), Vec3::ONE);
        assert_eq!(map(Wrap::MirroredRepeat).sample(&t, at), Vec3::ONE);
    }

    #[test]
    fn the_transform_applies_before_the_lookup_and_huge_coordinates_stay_finite() {
        let t = checker();
        let mut m = map(Wrap::Repeat);
        m.transform = [1.0, 0.0, 0.5, 0.0, 1.0, 0.0]; // offset u by half the texture
        assert_eq!(m.sample(&t, Vec2::new(0.25, 0.25)), Vec3::ONE);
        for uv in [
            Vec2::splat(1e30),
            Vec2::splat(-1e30),
            Vec2::new(f32::MAX, 0.0),
        ] {
            assert!(m.sample(&t, uv).is_finite());
        }
    }

    #[test]
    fn srgb_table_is_the_function() {
        for v in 0..=255u8 {
            assert_eq!(
                SRGB_TO_LINEAR[usize::from(v)].to_bits(),
                srgb_to_linear(v).to_bits()
            );
        }
    }

    #[test]
    fn srgb_decoding_matches_the_standard_at_its_ends_and_knee() {
        assert_eq!(srgb_to_linear(0), 0.0);
        assert_eq!(srgb_to_linear(255), 1.0);
        assert!((srgb_to_linear(10) - 10.0 / 255.0 / 12.92).abs() < 1e-7);
        assert!((srgb_to_linear(188) - 0.5029).abs() < 1e-3);
    }

    #[test]
    fn barycentric_weights_recover_the_point() {
        let tri = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 1.0),
        ];
        let b = barycentric(
            &tri,
            tri[0] + 0.25 * (tri[1] - tri[0]) + 0.5 * (tri[2] - tri[0]),
        );
        assert!((b - Vec2::new(0.25, 0.5)).abs().max_element() < 1e-6, "{b}");
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
        assert_eq!(interpolate_uv(&uv, b), b);
    }
}
