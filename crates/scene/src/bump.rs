//! Uneven mirrors: seed 002 names "uneven mirrors (e.g. with a normal map)" a limit of the
//! planar mirror camera. A mirror may carry a `bump` (`docs/scene-format.md`): a procedural
//! ripple and/or a tangent-space normal map. The geometry stays planar; only the shading
//! normal at a hit point changes (`docs/shading.md`, "Uneven mirrors"). Both renderers
//! evaluate [`MirrorBump::tangent_normal`] (the tracer here in f64, the WGSL twin in
//! `shaders/shading.wgsl` in f32, held to it by `crates/raster/src/shading.rs`'s tests).
//!
//! Mirror-local coordinates of a point `p`: `u = (p − c)·right`, `v = (p − c)·up` (scene
//! units, `c` the mirror's centre).
//! - **Ripple** (amplitude `A`, wavelength `λ`, direction `β`, phase `φ`): the normal tilts by
//!   `θ = A·sin(2π(u cos β + v sin β)/λ + φ)` towards `(cos β, sin β)`:
//!   `n = (sin θ cos β, sin θ sin β, cos θ)` in the frame (right, up, normal).
//! - **Normal map** (`W × H` texels, tiling `(a, b)`, strength `s`): texture coordinates
//!   `x = (u/width + ½)·a`, `y = (½ − v/height)·b` (row 0 at the mirror's top edge), texel
//!   `(i, j)` centred at `((i + ½)/W, (j + ½)/H)`, repeated; the decoded texels `2·rgb/255 − 1`
//!   (green = +up, the OpenGL convention) are interpolated bilinearly into `m`, and
//!   `n = normalize(s·m.x, s·m.y, m.z)`.
//! - **Both**: their slopes add, `n = normalize(r.x/r.z + m.x/m.z, r.y/r.z + m.y/m.z, 1)`.

use glam::{DVec3, Vec3};
use std::path::PathBuf;
use std::sync::Arc;

/// Largest normal map side, in texels (a 4096² RGB map is 48 MiB decoded).
pub const MAX_NORMAL_MAP_SIDE: u32 = 4096;
/// Largest normal map file, in bytes, read before decoding.
pub const MAX_NORMAL_MAP_FILE_BYTES: u64 = 64 << 20;
/// Tilts must stay below this (degrees): at 90° the normal lies in the mirror's plane.
pub const MAX_AMPLITUDE_DEG: f32 = 90.0;
/// Largest normal-map strength and tiling.
pub const MAX_STRENGTH: f32 = 100.0;
pub const MAX_TILING: f32 = 10_000.0;

/// A sinusoidal tilt field (angles in radians, lengths in scene units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ripple {
    pub amplitude: f32,
    pub wavelength: f32,
    pub direction: f32,
    pub phase: f32,
}

/// A tangent-space normal map, decoded: 8-bit RGB texels, row 0 at the mirror's top.
#[derive(Clone, PartialEq)]
pub struct NormalMap {
    /// The path as the scene file wrote it (resolved against the scene's folder).
    pub path: String,
    /// Where it was read from.
    pub resolved: PathBuf,
    pub width: u32,
    pub height: u32,
    /// Shared by every mirror that names the same file (decoded once, issue 51).
    pub texels: Arc<Texels>,
    pub tiling: [f32; 2],
    pub strength: f32,
}

/// A normal map's texels with their FNV-1a hash, computed once when decoded: the scene's
/// content hash reads it for every mirror, which for 20 000 facets sharing a 256² map was
/// 3.9·10⁹ bytes hashed per call (issue 51).
#[derive(PartialEq)]
pub struct Texels {
    texels: Vec<[u8; 3]>,
    hash: u64,
}

impl Texels {
    pub fn new(texels: Vec<[u8; 3]>) -> Self {
        let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
        for b in texels.iter().flatten() {
            hash ^= u64::from(*b);
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
        Texels { texels, hash }
    }
}

impl std::fmt::Debug for Texels {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Texels {{ {} texels, hash {:016x} }}",
            self.texels.len(),
            self.hash
        )
    }
}

impl std::ops::Deref for Texels {
    type Target = [[u8; 3]];
    fn deref(&self) -> &[[u8; 3]] {
        &self.texels
    }
}

impl std::fmt::Debug for NormalMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "NormalMap {{ {}×{}, texels {:016x}, tiling: {:?}, strength: {:?} }}",
            self.width,
            self.height,
            self.texel_hash(),
            self.tiling,
            self.strength
        )
    }
}

impl NormalMap {
    /// FNV-1a of the texels (the scene's content hash: the image, not its path, matters),
    /// computed when they were decoded.
    pub fn texel_hash(&self) -> u64 {
        self.texels.hash
    }

    /// Texel `(i, j)` decoded to `[−1, 1]³`, repeated beyond the edges.
    fn decoded(&self, i: i64, j: i64) -> DVec3 {
        let (w, h) = (i64::from(self.width), i64::from(self.height));
        let t = self.texels[(j.rem_euclid(h) * w + i.rem_euclid(w)) as usize];
        DVec3::new(t[0].into(), t[1].into(), t[2].into()) * (2.0 / 255.0) - DVec3::ONE
    }

    /// The bilinear interpolation `m` of the decoded texels at texture coordinates `(x, y)`.
    pub fn sample(&self, x: f64, y: f64) -> DVec3 {
        let px = x * f64::from(self.width) - 0.5;
        let py = y * f64::from(self.height) - 0.5;
        let (i, j) = (px.floor(), py.floor());
        let (fx, fy) = (px - i, py - j);
        let (i, j) = (i as i64, j as i64);
        let top = self.decoded(i, j) * (1.0 - fx) + self.decoded(i + 1, j) * fx;
        let bottom = self.decoded(i, j + 1) * (1.0 - fx) + self.decoded(i + 1, j + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The steepest slope `|xy|/z` among the decoded texels at strength 1 (the sweep's
    /// amplitude axis sets the strength that tilts the steepest texel by a given angle).
    pub fn max_slope(&self) -> f64 {
        let mut most: f64 = 0.0;
        for j in 0..i64::from(self.height) {
            for i in 0..i64::from(self.width) {
                let m = self.decoded(i, j);
                most = most.max((m.x * m.x + m.y * m.y).sqrt() / m.z);
            }
        }
        most
    }
}

/// A mirror's uneven shading: a ripple, a normal map, or both.
#[derive(Clone, Debug, PartialEq)]
pub struct MirrorBump {
    pub ripple: Option<Ripple>,
    pub normal_map: Option<NormalMap>,
}

impl MirrorBump {
    /// The perturbed normal in the mirror's tangent frame (right, up, normal) at mirror-local
    /// `(u, v)` of a `width × height` mirror: the module's formulas. Unit length.
    #[inline(always)]
    pub fn tangent_normal(&self, u: f64, v: f64, width: f64, height: f64) -> DVec3 {
        let ripple = self.ripple.map(|r| {
            let (sb, cb) = f64::from(r.direction).sin_cos();
            let k = std::f64::consts::TAU / f64::from(r.wavelength);
            let theta = f64::from(r.amplitude) * (k * (u * cb + v * sb) + f64::from(r.phase)).sin();
            let (st, ct) = theta.sin_cos();
            DVec3::new(st * cb, st * sb, ct)
        });
        let map = self.normal_map.as_ref().map(|m| {
            let x = (u / width + 0.5) * f64::from(m.tiling[0]);
            let y = (0.5 - v / height) * f64::from(m.tiling[1]);
            let s = m.sample(x, y);
            let k = f64::from(m.strength);
            DVec3::new(k * s.x, k * s.y, s.z)
        });
        match (ripple, map) {
            (Some(r), None) => r,
            (None, Some(m)) => m.normalize(),
            (Some(r), Some(m)) => {
                DVec3::new(r.x / r.z + m.x / m.z, r.y / r.z + m.y / m.z, 1.0).normalize()
            }
            (None, None) => DVec3::Z,
        }
    }

    /// Sets the steepest tilt to `degrees`: the ripple's amplitude, and the normal map's
    /// strength that tilts its steepest texel by that angle (the sweep's amplitude axis).
    pub fn set_amplitude(&mut self, degrees: f32) {
        let radians = degrees.to_radians();
        if let Some(r) = &mut self.ripple {
            r.amplitude = radians;
        }
        if let Some(m) = &mut self.normal_map {
            let slope = m.max_slope();
            m.strength = if slope > 0.0 {
                (f64::from(radians).tan() / slope) as f32
            } else {
                0.0
            };
        }
    }
}

/// The mirror's frame in f64: unit right, up and normal (the normal exactly as
/// [`crate::Mirror::plane_f64`] has it, so that a flat bump reflects bit for bit as a plain
/// mirror does).
pub fn frame_f64(mirror: &crate::Mirror) -> [DVec3; 3] {
    let n = mirror.normal.as_dvec3().normalize();
    let up = mirror.up.as_dvec3();
    let right = up.cross(mirror.normal.as_dvec3());
    [right, up, n]
}

/// The perturbed world normal of `mirror` at point `p` on it.
#[inline(always)]
pub fn world_normal(mirror: &crate::Mirror, bump: &MirrorBump, p: DVec3) -> DVec3 {
    let [right, up, n] = frame_f64(mirror);
    let d = p - mirror.center.as_dvec3();
    let t = bump.tangent_normal(
        d.dot(right),
        d.dot(up),
        f64::from(mirror.width),
        f64::from(mirror.height),
    );
    // Untilted: the plane's normal itself, not a renormalised copy (bit-exact reflections).
    if t == DVec3::Z {
        return n;
    }
    (right * t.x + up * t.y + n * t.z).normalize()
}

/// The contract's reflection at an uneven mirror (`docs/shading.md`): `d` (unit) reflected about the
/// shading normal `n_s`, or `None` — the mirror reflects nothing, radiance 0 — where the
/// incoming ray sees the back of the perturbed facet (`d·n_s ≥ 0`) or the reflected ray
/// points behind the mirror's plane (`r·n_g ≤ 0`). Mitsuba's `normalmap` BSDF has the same
/// rule.
#[inline(always)]
pub fn reflect(d: DVec3, n_geometric: DVec3, n_shading: DVec3) -> Option<DVec3> {
    if d.dot(n_shading) >= 0.0 {
        return None;
    }
    let r = (d - 2.0 * d.dot(n_shading) * n_shading).normalize();
    (r.dot(n_geometric) > 0.0).then_some(r)
}

/// The f32 form of [`world_normal`], for tests of the WGSL twin.
pub fn world_normal_f32(mirror: &crate::Mirror, bump: &MirrorBump, p: Vec3) -> Vec3 {
    world_normal(mirror, bump, p.as_dvec3()).as_vec3()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ripple(deg: f32) -> MirrorBump {
        MirrorBump {
            ripple: Some(Ripple {
                amplitude: deg.to_radians(),
                wavelength: 0.5,
                direction: 0.3,
                phase: 0.1,
            }),
            normal_map: None,
        }
    }

    fn flat_map(rgb: [u8; 3], strength: f32) -> NormalMap {
        NormalMap {
            path: "m.png".into(),
            resolved: "m.png".into(),
            width: 2,
            height: 2,
            texels: Arc::new(Texels::new(vec![rgb; 4])),
            tiling: [1.0, 1.0],
            strength,
        }
    }

    #[test]
    fn a_zero_ripple_is_the_plane_normal_exactly() {
        let n = ripple(0.0).tangent_normal(0.37, -1.2, 2.0, 3.0);
        assert_eq!(n, DVec3::Z);
    }

    #[test]
    fn the_ripple_tilts_by_its_formula() {
        let b = ripple(10.0);
        let r = b.ripple.unwrap();
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (-1.0, 0.25)] {
            let n = b.tangent_normal(u, v, 4.0, 4.0);
            let (sb, cb) = f64::from(r.direction).sin_cos();
            let arg = std::f64::consts::TAU / f64::from(r.wavelength) * (u * cb + v * sb)
                + f64::from(r.phase);
            let theta = f64::from(r.amplitude) * arg.sin();
            assert!((n.z.acos() - theta.abs()).abs() < 1e-12);
            // Tilted towards ±(cos β, sin β).
            assert!((n.x * sb - n.y * cb).abs() < 1e-12);
        }
    }

    #[test]
    fn a_uniform_map_gives_its_normal_scaled_by_the_strength() {
        // Texel (160, 128, 230): decoded (0.2549, 0.0039, 0.8039).
        let b = MirrorBump {
            ripple: None,
            normal_map: Some(flat_map([160, 128, 230], 2.0)),
        };
        let n = b.tangent_normal(0.1, 0.2, 1.0, 1.0);
        let m = DVec3::new(160.0, 128.0, 230.0) * (2.0 / 255.0) - DVec3::ONE;
        let want = DVec3::new(2.0 * m.x, 2.0 * m.y, m.z).normalize();
        assert!((n - want).length() < 1e-12, "{n} vs {want}");
    }

    #[test]
    fn map_lookups_are_bilinear_between_texel_centres_and_repeat() {
        let mut m = flat_map([128, 128, 255], 1.0);
        m.texels = Arc::new(Texels::new(vec![
            [0, 128, 255],
            [255, 128, 255],
            [0, 128, 255],
            [255, 128, 255],
        ]));
        // Texel centres: x = 0.25 (left, −1) and 0.75 (right, +1); halfway between them 0.
        assert!((m.sample(0.25, 0.5).x + 1.0).abs() < 1e-12);
        assert!((m.sample(0.75, 0.5).x - 1.0).abs() < 1e-12);
        assert!(m.sample(0.5, 0.5).x.abs() < 1e-12);
        // Repeat: x = 1.0 lies between texel 1 (0.75) and texel 0 of the next tile (1.25).
        assert!(m.sample(1.0, 0.5).x.abs() < 1e-12);
        assert!((m.sample(1.25, 0.5).x + 1.0).abs() < 1e-12);
    }

    #[test]
    fn slopes_add_when_both_are_present() {
        let mut b = ripple(0.0);
        b.normal_map = Some(flat_map([160, 128, 230], 1.0));
        let alone = MirrorBump {
            ripple: None,
            normal_map: b.normal_map.clone(),
        };
        let n = b.tangent_normal(0.0, 0.0, 1.0, 1.0);
        assert!((n - alone.tangent_normal(0.0, 0.0, 1.0, 1.0)).length() < 1e-12);
    }

    #[test]
    fn set_amplitude_tilts_the_steepest_texel_by_that_angle() {
        let mut b = MirrorBump {
            ripple: None,
            normal_map: Some(flat_map([200, 100, 220], 1.0)),
        };
        b.set_amplitude(7.0);
        let n = b.tangent_normal(0.0, 0.0, 1.0, 1.0);
        assert!((n.z.acos().to_degrees() - 7.0).abs() < 1e-4);
    }

    #[test]
    fn the_reflection_rule_absorbs_rays_sent_behind_the_plane() {
        let n = DVec3::Z;
        let d = DVec3::new(1.0, 0.0, -0.1).normalize();
        let facet = |deg: f64| {
            let (s, c) = deg.to_radians().sin_cos();
            DVec3::new(s, 0.0, c)
        };
        assert!(reflect(d, n, n).is_some());
        assert!(reflect(d, n, facet(-5.0)).is_some());
        // Tilted 5° towards d: the reflection leaves below the mirror's plane.
        let r = d - 2.0 * d.dot(facet(5.0)) * facet(5.0);
        assert!(d.dot(facet(5.0)) < 0.0 && r.z < 0.0);
        assert!(reflect(d, n, facet(5.0)).is_none());
        // Tilted 10°: the ray sees the facet's back.
        let steep = facet(10.0);
        assert!(d.dot(steep) > 0.0);
        assert!(reflect(d, n, steep).is_none());
    }
}
