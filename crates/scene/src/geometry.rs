//! The one triangle list both renderers consume.
//!
//! Every triangle is stored by value in world space, wound counter-clockwise as seen from
//! its front side, and carries the id of its [`Surface`]. Shading uses the *face* normal
//! (`(v1 − v0) × (v2 − v0)`, normalized), never interpolated normals, so that the rasterizer,
//! the tracer and Mitsuba (`face_normals`) all see exactly the same surface.

use crate::texture::{SurfaceMaps, Texture, barycentric, interpolate_uv};
use glam::{Vec2, Vec3};
use std::ops::Range;

/// Index into [`Geometry::surfaces`].
pub type SurfaceId = u32;

/// What a triangle is made of. See `docs/shading.md` for how each is shaded.
#[derive(Clone, PartialEq)]
pub enum Surface {
    /// Lambertian reflector (two-sided) with optional emission (front side only); `maps`
    /// multiply them by textures (`docs/shading.md`, "Textures").
    Diffuse {
        albedo: Vec3,
        emission: Vec3,
        maps: SurfaceMaps,
    },
    /// Front side of mirror `mirror` (index into `Scene::mirrors`) reflects `reflectance`;
    /// the back side is diffuse with `back_albedo`.
    Mirror {
        mirror: usize,
        reflectance: Vec3,
        back_albedo: Vec3,
    },
}

impl std::fmt::Debug for Surface {
    /// As derived, except that an untextured diffuse surface prints without its (empty)
    /// maps: the scene's content hash, which is the key of cached truths, stays what it was
    /// before textures existed.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Surface::Diffuse {
                albedo,
                emission,
                maps,
            } => {
                let mut d = f.debug_struct("Diffuse");
                d.field("albedo", albedo).field("emission", emission);
                if !maps.is_empty() {
                    d.field("maps", maps);
                }
                d.finish()
            }
            Surface::Mirror {
                mirror,
                reflectance,
                back_albedo,
            } => f
                .debug_struct("Mirror")
                .field("mirror", mirror)
                .field("reflectance", reflectance)
                .field("back_albedo", back_albedo)
                .finish(),
        }
    }
}

impl Surface {
    /// A diffuse surface without textures.
    pub fn diffuse(albedo: Vec3, emission: Vec3) -> Surface {
        Surface::Diffuse {
            albedo,
            emission,
            maps: SurfaceMaps::default(),
        }
    }
}

/// A named group of consecutive triangles (one scene object or one mirror).
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    pub name: String,
    pub surface: SurfaceId,
    pub triangles: Range<usize>,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Geometry {
    pub triangles: Vec<[Vec3; 3]>,
    /// `surface_of[i]` is the surface of `triangles[i]`.
    pub surface_of: Vec<SurfaceId>,
    /// `uvs[i]` are the texture coordinates of `triangles[i]`'s corners (zero where the
    /// triangle's surface has no texture). Always as long as `triangles`.
    pub uvs: Vec<[Vec2; 3]>,
    /// The images that surfaces' [`SurfaceMaps`] index.
    pub textures: Vec<Texture>,
    pub surfaces: Vec<Surface>,
    pub parts: Vec<Part>,
    /// Triangles dropped at load because they had (near) zero area.
    pub degenerate_dropped: usize,
    /// What loading the OBJ files passed over, one line each (`objects[2].path: line 233:
    /// an empty material name, ignored`): material statements are never read (the scene gives
    /// each object its albedo), so a broken one does not refuse the file.
    pub obj_notes: Vec<String>,
}

/// Twice the area below which a triangle is considered degenerate and dropped, relative to
/// the square of its longest edge (a sliver this thin has no reliable normal).
const DEGENERATE_RELATIVE_AREA: f32 = 1e-7;

/// True for a triangle of (near) zero area: twice its area at most
/// [`DEGENERATE_RELATIVE_AREA`] times its longest edge squared, or not a number.
pub(crate) fn is_degenerate(t: &[Vec3; 3]) -> bool {
    let doubled_area = (t[1] - t[0]).cross(t[2] - t[0]).length();
    let longest = (t[1] - t[0])
        .length_squared()
        .max((t[2] - t[1]).length_squared())
        .max((t[0] - t[2]).length_squared());
    doubled_area.is_nan() || doubled_area <= DEGENERATE_RELATIVE_AREA * longest
}

impl Geometry {
    /// Appends a part; degenerate triangles are dropped (and counted) so that every stored
    /// triangle has a well-defined face normal.
    pub fn push_part(&mut self, name: String, surface: Surface, triangles: Vec<[Vec3; 3]>) {
        let uvs = vec![[Vec2::ZERO; 3]; triangles.len()];
        self.push_textured_part(name, surface, triangles, uvs);
    }

    /// [`Geometry::push_part`] with each triangle's texture coordinates (`uvs[i]` for
    /// `triangles[i]`).
    pub fn push_textured_part(
        &mut self,
        name: String,
        surface: Surface,
        triangles: Vec<[Vec3; 3]>,
        uvs: Vec<[Vec2; 3]>,
    ) {
        debug_assert_eq!(triangles.len(), uvs.len());
        let id = self.surfaces.len() as SurfaceId;
        self.surfaces.push(surface);
        let start = self.triangles.len();
        for (t, uv) in triangles.into_iter().zip(uvs) {
            if is_degenerate(&t) {
                self.degenerate_dropped += 1;
                continue;
            }
            self.triangles.push(t);
            self.surface_of.push(id);
            self.uvs.push(uv);
        }
        let end = self.triangles.len();
        self.parts.push(Part {
            name,
            surface: id,
            triangles: start..end,
        });
    }

    /// A geometry without triangles that keeps this one's textures: parts copied into it
    /// (with [`Geometry::push_textured_part`]) read the same images.
    pub fn empty_like(&self) -> Geometry {
        Geometry {
            textures: self.textures.clone(),
            ..Geometry::default()
        }
    }

    /// Unit face normal of triangle `i` (front side).
    pub fn face_normal(&self, i: usize) -> Vec3 {
        let [a, b, c] = self.triangles[i];
        (b - a).cross(c - a).normalize()
    }

    #[inline]
    pub fn surface(&self, triangle: usize) -> &Surface {
        &self.surfaces[self.surface_of[triangle] as usize]
    }

    /// The texture coordinates of point `p` (on triangle `triangle`'s plane).
    pub fn uv_at(&self, triangle: usize, p: Vec3) -> Vec2 {
        let b = barycentric(&self.triangles[triangle], p);
        interpolate_uv(&self.uvs[triangle], b)
    }

    /// Whether any surface reads a texture.
    pub fn has_textures(&self) -> bool {
        self.surfaces
            .iter()
            .any(|s| matches!(s, Surface::Diffuse { maps, .. } if !maps.is_empty()))
    }

    /// The albedo and emission of the diffuse surface of `triangle` at point `p`: its
    /// factors times its textures there (`docs/shading.md`, "Textures"). `None` for a mirror.
    #[inline(always)]
    pub fn diffuse_at(&self, triangle: usize, p: Vec3) -> Option<(Vec3, Vec3)> {
        let Surface::Diffuse {
            albedo,
            emission,
            maps,
        } = self.surface(triangle)
        else {
            return None;
        };
        if maps.is_empty() {
            return Some((*albedo, *emission));
        }
        Some(self.textured_at(triangle, p, *albedo, *emission, maps))
    }

    /// [`Geometry::diffuse_at`]'s textured case, out of line: the untextured case, inlined
    /// into the tracers' walks, was 8–14 % of `whitted`'s time as a call (issue 41).
    #[inline(never)]
    fn textured_at(
        &self,
        triangle: usize,
        p: Vec3,
        albedo: Vec3,
        emission: Vec3,
        maps: &crate::texture::SurfaceMaps,
    ) -> (Vec3, Vec3) {
        let uv = self.uv_at(triangle, p);
        let texel = |m: &Option<crate::texture::TextureMap>| {
            m.map_or(Vec3::ONE, |m| {
                m.sample(&self.textures[m.texture as usize], uv)
            })
        };
        (
            albedo * texel(&maps.albedo),
            emission * texel(&maps.emission),
        )
    }

    pub fn mirror_triangle_count(&self) -> usize {
        self.surface_of
            .iter()
            .filter(|&&s| matches!(self.surfaces[s as usize], Surface::Mirror { .. }))
            .count()
    }

    pub(crate) fn set_mirror_reflectance(&mut self, value: Vec3) {
        for s in &mut self.surfaces {
            if let Surface::Mirror { reflectance, .. } = s {
                *reflectance = value;
            }
        }
    }

    /// Axis-aligned bounds (min, max) of all triangles; `None` for an empty scene.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.triangles.iter().flatten();
        let first = *it.next()?;
        Some(it.fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_triangles_are_dropped_and_counted() {
        let mut g = Geometry::default();
        let good = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let collinear = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
        let repeated = [Vec3::ONE, Vec3::ONE, Vec3::Y];
        let diffuse = Surface::Diffuse {
            albedo: Vec3::splat(0.5),
            emission: Vec3::ZERO,
            maps: Default::default(),
        };
        g.push_part("p".into(), diffuse, vec![good, collinear, repeated]);
        assert_eq!(g.triangles, vec![good]);
        assert_eq!(g.degenerate_dropped, 2);
        assert_eq!(g.parts[0].triangles, 0..1);
        assert_eq!(g.face_normal(0), Vec3::Z);
    }
}
