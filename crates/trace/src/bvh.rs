//! One obvhs hierarchy over all of a scene's triangles (objects and mirrors).
//!
//! obvhs reports hits by *BVH primitive slot*: the id passed to the intersection closure and
//! stored in `RayHit::primitive_id` indexes `bvh.primitive_indices`, not the input list. We
//! therefore copy the triangles once into slot order (`slots`) and keep, per slot, the index of
//! the original triangle (`original`), so traversal reads memory in BVH order and every hit
//! maps back to [`mirrorbox_scene::Geometry`]'s numbering.
//!
//! Triangles are tested with [`crate::watertight`], not obvhs' own test (see there why).

mod flat_surfaces;
pub mod packet;
mod wide;

use crate::cpu_features::{Vectorised, widest};
use crate::watertight::WatertightRay;
use glam::{Vec3, Vec3A};
use mirrorbox_scene::limits::{MAX_COORDINATE, within_extent};
use mirrorbox_scene::{Geometry, Ray};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::RayHit;
use obvhs::triangle::Triangle;
use packet::{LANES, LaneHits, LaneMask, PacketBvh, RayPacket};
use std::sync::OnceLock;
use std::time::Duration;

/// A closest hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the (unit-direction) ray.
    pub t: f32,
    /// Index of the triangle in the scene's [`Geometry`].
    pub triangle: usize,
}

/// A query of [`SceneBvh::queries`]: a ray with the limits and skips of
/// [`SceneBvh::closest_hit_skipping`] and [`SceneBvh::occluded`].
#[derive(Clone, Copy, Debug)]
pub struct Query {
    pub ray: Ray,
    pub t_min: f32,
    pub t_max: f32,
    pub skip_flat: Option<usize>,
    pub skip_triangle: Option<usize>,
}

/// A placeholder entry of a fixed array of queries (never traced).
pub(crate) const NO_QUERY: Query = Query {
    ray: Ray {
        origin: glam::Vec3::ZERO,
        dir: glam::Vec3::Z,
    },
    t_min: 0.0,
    t_max: 0.0,
    skip_flat: None,
    skip_triangle: None,
};

/// Which hierarchy the single-ray queries traverse (shadow legs, `path`, `whitted` below 4
/// samples per pixel or with `--kernel single`). `Wide`, the default, is our own 8-wide one
/// ([`wide`], issue 56): obvhs's binary hierarchy collapsed, its boxes uncompressed, eight
/// boxes and a leaf's triangles tested at once; the BVH2's answers bit for bit, a tenth faster
/// than obvhs's CWBVH on `path`. obvhs's CWBVH (8-wide, compressed) misses some hits a few
/// 10⁻⁵ from a mirror corner, which the BVH2 finds; its BVH2 is slower on incoherent rays
/// (`path` in `mirror_room`: 1.45 s against the CWBVH's 1.11 s; docs/tracer-performance.md).
/// The packet kernel always traverses a BVH2 (this one when `Bvh2` is chosen, else its own).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BvhKind {
    Cwbvh,
    Bvh2,
    #[default]
    Wide,
}

enum Hierarchy {
    Empty,
    Cw(CwBvh),
    Binary(Bvh2),
    Wide(wide::WideBvh),
}

/// A query of the 8-wide hierarchy, compiled for the CPU's widest vectors
/// ([`crate::cpu_features::widest`]), the watertight test specialised for the ray's axis
/// permutation.
struct WideQuery<'a, const ANY_HIT: bool> {
    bvh: &'a wide::WideBvh,
    ray: &'a Ray,
    query: (f32, f32, Option<usize>, Option<usize>),
}

/// `ray` through the wide hierarchy with `(t_min, t_max, skip_flat, skip_triangle)`: the
/// closest hit, or with `ANY_HIT` the first, as `(t, triangle)`.
fn wide_query<const ANY_HIT: bool>(
    bvh: &wide::WideBvh,
    ray: &Ray,
    query: (f32, f32, Option<usize>, Option<usize>),
) -> Option<(f32, u32)> {
    widest(WideQuery::<ANY_HIT> { bvh, ray, query })
}

impl<const ANY_HIT: bool> Vectorised for WideQuery<'_, ANY_HIT> {
    type Output = Option<(f32, u32)>;

    #[inline(always)]
    fn run(self) -> Self::Output {
        let (t_min, t_max, skip_flat, skip_triangle) = self.query;
        let r = &wide::WideRay::new(
            self.ray.origin,
            self.ray.dir,
            t_min,
            t_max,
            skip_flat,
            skip_triangle,
        );
        let b = self.bvh;
        match r.wt.axes() {
            (1, 2, 0) => b.trace::<wide::ConstAxes<1, 2, 0>, ANY_HIT>(r),
            (2, 1, 0) => b.trace::<wide::ConstAxes<2, 1, 0>, ANY_HIT>(r),
            (2, 0, 1) => b.trace::<wide::ConstAxes<2, 0, 1>, ANY_HIT>(r),
            (0, 2, 1) => b.trace::<wide::ConstAxes<0, 2, 1>, ANY_HIT>(r),
            (0, 1, 2) => b.trace::<wide::ConstAxes<0, 1, 2>, ANY_HIT>(r),
            (1, 0, 2) => b.trace::<wide::ConstAxes<1, 0, 2>, ANY_HIT>(r),
            other => unreachable!("not an axis permutation: {other:?}"),
        }
    }
}

/// Runs `$body` with `$test`, the closure obvhs calls per primitive slot: the skips, then
/// the watertight test specialised for the ray's axis permutation (six monomorphised
/// traversals instead of indexing vectors by a run-time axis for every triangle).
macro_rules! with_triangle_test {
    ($bvh:expr, $wt:expr, $skip_flat:expr, $skip_triangle:expr, |$test:ident| $body:expr) => {{
        let skip = $skip_flat.map_or(NO_ONE_FLAT, |m| m as u32);
        let skip_tri = $skip_triangle.map_or(u32::MAX, |t| t as u32);
        let slots = &$bvh.slots;
        let original = &$bvh.original;
        let wt = &$wt;
        macro_rules! run {
            ($kx:literal, $ky:literal, $kz:literal) => {{
                let $test = |r: &obvhs::ray::Ray, slot: usize| {
                    let s = &slots[slot];
                    // No slot is on NO_ONE_FLAT, what a query skipping none compares with.
                    if (s.flat == skip) | (original[slot] == skip_tri) {
                        return f32::INFINITY;
                    }
                    wt.intersect_axes::<$kx, $ky, $kz>(s.v[0], s.v[1], s.v[2], r.tmin, r.tmax)
                };
                $body
            }};
        }
        match wt.axes() {
            (1, 2, 0) => run!(1, 2, 0),
            (2, 1, 0) => run!(2, 1, 0),
            (2, 0, 1) => run!(2, 0, 1),
            (0, 2, 1) => run!(0, 2, 1),
            (0, 1, 2) => run!(0, 1, 2),
            (1, 0, 2) => run!(1, 0, 2),
            other => unreachable!("not an axis permutation: {other:?}"),
        }
    }};
}

/// Marks a node whose triangles are not all on one flat surface, and a query that skips
/// none ([`flat_surfaces`]: every triangle is on one).
const NO_ONE_FLAT: u32 = u32::MAX;

#[derive(Clone, Copy)]
struct Slot {
    v: [Vec3; 3],
    /// The triangle's flat surface ([`flat_surfaces`]).
    flat: u32,
}

pub struct SceneBvh {
    hierarchy: Hierarchy,
    slots: Vec<Slot>,
    original: Vec<u32>,
    /// Per triangle (the scene's numbering), its flat surface ([`flat_surfaces`]).
    flat: Vec<u32>,
    /// Time spent building the hierarchy (obvhs, the collapse to 8 wide, the flat surfaces).
    pub build_time: Duration,
    pub kind: BvhKind,
    /// Whether [`SceneBvh::closest_hits`] traces packets (else one ray at a time).
    packets: bool,
    /// The binary hierarchy of the packet kernel, built at its first use or by
    /// [`SceneBvh::prepare_packets`], and the time its build took.
    packet_bvh: OnceLock<(PacketBvh, Duration)>,
}

/// Deepest 8-wide hierarchy obvhs's traversal holds (`cwbvh::TRAVERSAL_STACK_SIZE`, private:
/// its `validate` asserts depth < 32).
const CWBVH_MAX_DEPTH: u32 = 31;

/// obvhs's `build_cwbvh_from_tris` without pre-splits (our parameters have none), keeping the
/// binary hierarchy: the 8-wide one collapsed from it, or the binary one where the collapsed
/// hierarchy is deeper than [`CWBVH_MAX_DEPTH`] (its traversal would overrun its stack, and
/// obvhs's debug validation asserts). Same steps, same result as the helper otherwise.
fn build_cwbvh(
    boxes: &[Aabb],
    params: BvhBuildParams,
    max_depth: u32,
    build_time: &mut Duration,
) -> Result<CwBvh, Box<obvhs::bvh2::Bvh2>> {
    let start = std::time::Instant::now();
    let mut bvh2 = ploc(boxes, &params);
    obvhs::bvh2::reinsertion::ReinsertionOptimizer::default().run(
        &mut bvh2,
        params.reinsertion_batch_ratio,
        None,
    );
    let cwbvh = obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(
        &bvh2,
        params.max_prims_per_leaf.clamp(1, 3),
        true,
        false,
    );
    *build_time += start.elapsed();
    if cwbvh_depth(&cwbvh) > max_depth {
        Err(Box::new(bvh2))
    } else {
        Ok(cwbvh)
    }
}

/// The build of the hierarchies mirrorbox traverses itself (the 8-wide one, and the binary
/// ones of `--bvh bvh2` and the packet kernel) up to [`HIGH_QUALITY_BUILD_TRIANGLES`]
/// ([`build_binary`]): obvhs's `medium_build` with the PLOC search, reinsertion and sort
/// precision of its slowest presets (no pre-splits). Against `medium_build`, timed inside one process
/// (`scripts/ab-inprocess.sh`, 64 pairs, 320×180, 16 spp; issue 56, sixth session): `path`
/// ×0.977 [0.967–0.996] / ×0.993 [0.971–1.008], `whitted` ×0.995 [0.990–0.998] / ×0.978
/// [0.971–0.991] (`mirror_room` / `mirror_box`), the same bits; each build 3–4× slower
/// (docs/tracer-performance.md). obvhs's own CWBVH keeps `medium_build`.
const HIGH_QUALITY_BUILD: BvhBuildParams = BvhBuildParams {
    ploc_search_distance: obvhs::ploc::PlocSearchDistance::High,
    search_depth_threshold: 1,
    reinsertion_batch_ratio: 1.0,
    post_collapse_reinsertion_batch_ratio_multiplier: 1.0,
    sort_precision: obvhs::ploc::SortPrecision::U128,
    ..BvhBuildParams::medium_build()
};

/// A binary hierarchy over `primitives` by obvhs's `build_bvh2` steps (PLOC, reinsertion,
/// leaf collapse, reinsertion) with [`HIGH_QUALITY_BUILD`] as `tune` adjusts it, or with
/// `medium_build` above [`HIGH_QUALITY_BUILD_TRIANGLES`]. Full reinsertion
/// can deepen a pathological tree (the assimp corpus's long line of boxes: 232 levels) beyond
/// the depth obvhs sized its traversal stacks for (`max_depth`, set by the PLOC step; deeper,
/// its fixed stacks would overwrite their top entry): such a tree is built again with
/// `medium_build`, as before. `build_time` gains the build's time.
pub(crate) fn build_binary<T: obvhs::Boundable>(
    primitives: &[T],
    tune: impl Fn(BvhBuildParams) -> BvhBuildParams,
    build_time: &mut Duration,
) -> obvhs::bvh2::Bvh2 {
    let medium = tune(BvhBuildParams::medium_build());
    if primitives.len() > HIGH_QUALITY_BUILD_TRIANGLES {
        return obvhs::bvh2::builder::build_bvh2(primitives, medium, build_time);
    }
    let params = tune(HIGH_QUALITY_BUILD);
    let start = std::time::Instant::now();
    let mut bvh = ploc(primitives, &params);
    let mut reinsertion = obvhs::bvh2::reinsertion::ReinsertionOptimizer::default();
    reinsertion.run(&mut bvh, params.reinsertion_batch_ratio, None);
    obvhs::bvh2::leaf_collapser::collapse(
        &mut bvh,
        params.max_prims_per_leaf.clamp(1, 255),
        params.collapse_traversal_cost,
    );
    reinsertion.run(
        &mut bvh,
        params.reinsertion_batch_ratio * params.post_collapse_reinsertion_batch_ratio_multiplier,
        None,
    );
    *build_time += start.elapsed();
    if binary_depth(&bvh) < bvh.max_depth {
        #[cfg(debug_assertions)]
        bvh.validate(primitives, false, false);
        bvh
    } else {
        obvhs::bvh2::builder::build_bvh2(primitives, medium, build_time)
    }
}

/// obvhs's PLOC build of a binary hierarchy over `primitives` with `params`' search, sort
/// and depth threshold: the first step of every build here.
fn ploc<T: obvhs::Boundable>(primitives: &[T], params: &BvhBuildParams) -> obvhs::bvh2::Bvh2 {
    obvhs::ploc::PlocBuilder::with_capacity(primitives.len()).build(
        params.ploc_search_distance,
        primitives,
        (0..primitives.len() as u32).collect::<Vec<_>>(),
        params.sort_precision,
        params.search_depth_threshold,
    )
}

/// Levels of a binary hierarchy (a lone leaf: 1), without recursion.
fn binary_depth(bvh: &obvhs::bvh2::Bvh2) -> usize {
    let mut deepest = 0;
    let mut todo = vec![(0usize, 1usize)];
    while let Some((i, depth)) = todo.pop() {
        let Some(node) = bvh.nodes.get(i) else {
            continue;
        };
        deepest = deepest.max(depth);
        if !node.is_leaf() {
            let first = node.first_index as usize;
            todo.extend([(first, depth + 1), (first + 1, depth + 1)]);
        }
    }
    deepest
}

/// Most triangles for [`HIGH_QUALITY_BUILD`], the slower, better build: 110 342 triangles (an imported
/// glTF engine) took 0.56 s and 0.59 s for the 8-wide and packet hierarchies against 0.17 s
/// and 0.15 s on the Zen 3 development machine, where its 640×360, 16-spp `whitted` render
/// takes 0.14 s on two threads: a few per cent of that is not worth 0.8 s. The bench scenes
/// have about 2 000.
const HIGH_QUALITY_BUILD_TRIANGLES: usize = 50_000;

/// Fewest triangles sharing one box exactly whose boxes [`primitive_boxes`] spreads.
const TIED_BOXES: usize = 32;

/// Each triangle's box, as the builder sees it. Where many triangles share one box exactly
/// (coincident mirrors: a degenerate scene, but one the format accepts), every merge cost of
/// obvhs's PLOC ties, and a sweep merges only the one pair whose neighbours agree: one pair
/// per sweep, quadratic (20 000 coincident mirrors: 19.6 s, issue 51). Those boxes are
/// spread: each grown on every side by a pseudo-random share (at most 10⁻³) of its size,
/// which breaks the ties; it still bounds its triangle (traversal tests the triangles
/// themselves, [`Slot`]). Boxes shared by fewer than [`TIED_BOXES`] triangles — every box of
/// the bundled scenes — are the triangles' own, so those hierarchies are unchanged.
fn primitive_boxes(tris: &[Triangle]) -> Vec<Aabb> {
    use obvhs::Boundable;
    let mut boxes: Vec<Aabb> = tris.iter().map(Boundable::aabb).collect();
    let key = |b: &Aabb| {
        let (lo, hi) = (b.min.to_array(), b.max.to_array());
        [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]].map(f32::to_bits)
    };
    let mut sharing: std::collections::HashMap<[u32; 6], usize> = Default::default();
    for b in &boxes {
        *sharing.entry(key(b)).or_default() += 1;
    }
    if sharing.values().all(|&n| n < TIED_BOXES) {
        return boxes;
    }
    for (i, b) in boxes.iter_mut().enumerate() {
        if sharing[&key(b)] < TIED_BOXES {
            continue;
        }
        // A share in (0, 1] from the index.
        let share = crate::sampler::SplitMix64::for_pixel(0, i as u64).next_unit() + 1e-3;
        let size = (b.max - b.min).max_element() + 1e-6 * (1.0 + b.max.abs().max_element());
        let pad = Vec3A::splat(1e-3 * share * size);
        *b = Aabb::new(b.min - pad, b.max + pad);
    }
    boxes
}

/// Levels below the root of the deepest inner node (obvhs's `calculate_max_depth`).
fn cwbvh_depth(bvh: &CwBvh) -> u32 {
    let mut deepest = 0;
    let mut stack = vec![(0usize, 0u32)];
    while let Some((i, d)) = stack.pop() {
        deepest = deepest.max(d);
        let node = &bvh.nodes[i];
        for ch in 0..8 {
            if !node.is_child_empty(ch) && !node.is_leaf(ch) {
                stack.push((node.child_node_index(ch) as usize, d + 1));
            }
        }
    }
    deepest
}

impl SceneBvh {
    pub fn build(geometry: &Geometry) -> Self {
        Self::build_with(geometry, BvhKind::default())
    }

    /// Builds `kind` over `geometry`. Every vertex must lie within the scene extent
    /// ([`MAX_COORDINATE`], what loading a scene checks): obvhs indexes out of bounds on
    /// non-finite or overflowing bounds, so they are never handed to it.
    ///
    /// A [`BvhKind::Cwbvh`] deeper than obvhs's 32-entry traversal stack (degenerate input:
    /// assimp's `box_longline.obj`, one long thin box) is replaced by the binary hierarchy
    /// it was built from, and `kind` says so.
    pub fn build_with(geometry: &Geometry, kind: BvhKind) -> Self {
        Self::build_within(geometry, kind, CWBVH_MAX_DEPTH)
    }

    /// [`SceneBvh::build_with`], an 8-wide hierarchy kept only up to `max_depth` levels (the
    /// tests lower it to reach the fallback, which real input reaches only when degenerate).
    fn build_within(geometry: &Geometry, kind: BvhKind, max_depth: u32) -> Self {
        let mut kind = kind;
        if let Some(p) = geometry
            .triangles
            .iter()
            .flatten()
            .find(|p| !within_extent(**p))
        {
            panic!(
                "a vertex at {p} lies outside the scene extent ±{MAX_COORDINATE:e}: \
                 scenes from mirrorbox_scene::load_scene never have one"
            );
        }
        // First, so that its working memory is gone before the hierarchy's build.
        let start = std::time::Instant::now();
        let flat = flat_surfaces::flat_surfaces(geometry);
        let flat_time = start.elapsed();
        let tris: Vec<Triangle> = geometry
            .triangles
            .iter()
            .map(|t| Triangle {
                v0: Vec3A::from(t[0]),
                v1: Vec3A::from(t[1]),
                v2: Vec3A::from(t[2]),
            })
            .collect();
        let boxes = primitive_boxes(&tris);
        let mut build_time = flat_time;
        let params = BvhBuildParams::medium_build();
        let (hierarchy, original) = if tris.is_empty() {
            (Hierarchy::Empty, Vec::new())
        } else {
            match kind {
                BvhKind::Cwbvh => match build_cwbvh(&boxes, params, max_depth, &mut build_time) {
                    Ok(bvh) => {
                        let order = bvh.primitive_indices.clone();
                        (Hierarchy::Cw(bvh), order)
                    }
                    // Too deep for obvhs's fixed traversal stack: the binary hierarchy it
                    // was collapsed from, whose traversal stack grows as needed.
                    Err(bvh2) => {
                        kind = BvhKind::Bvh2;
                        let order = bvh2.primitive_indices.clone();
                        (Hierarchy::Binary(*bvh2), order)
                    }
                },
                BvhKind::Bvh2 | BvhKind::Wide => {
                    // [`build_binary`] over the boxes (no pre-splits, the one step that needs
                    // the triangles); collapsed to 8 wide below, once the slots are known.
                    let bvh = if kind == BvhKind::Wide {
                        build_binary(&boxes, wide::leaf_params, &mut build_time)
                    } else {
                        build_binary(&boxes, |params| params, &mut build_time)
                    };
                    let order = bvh.primitive_indices.clone();
                    (Hierarchy::Binary(bvh), order)
                }
            }
        };
        let slots: Vec<Slot> = original
            .iter()
            .map(|&i| Slot {
                v: geometry.triangles[i as usize],
                flat: flat[i as usize],
            })
            .collect();
        let hierarchy = match hierarchy {
            Hierarchy::Binary(bvh) if kind == BvhKind::Wide => {
                let start = std::time::Instant::now();
                let wide = wide::WideBvh::from_bvh2(&bvh, &slots, &original);
                build_time += start.elapsed();
                match wide {
                    Some(w) => Hierarchy::Wide(w),
                    // Too deep for the 8-wide traversal's stack: the binary hierarchy.
                    None => {
                        kind = BvhKind::Bvh2;
                        Hierarchy::Binary(bvh)
                    }
                }
            }
            other => other,
        };
        SceneBvh {
            hierarchy,
            slots,
            original,
            flat,
            build_time,
            kind,
            packets: true,
            packet_bvh: OnceLock::new(),
        }
    }

    /// The flat surface of `triangle` ([`flat_surfaces`]): what a ray leaving it may skip
    /// (`skip_flat`). A mirror's flat surface is its index.
    pub fn flat_surface(&self, triangle: usize) -> usize {
        self.flat[triangle] as usize
    }

    /// This hierarchy with the packet kernel on (the default) or off: off,
    /// [`SceneBvh::closest_hits`] asks [`SceneBvh::closest_hit`] lane by lane (the
    /// benchmark's baseline; the answers are the same).
    pub fn with_packets(self, packets: bool) -> Self {
        SceneBvh { packets, ..self }
    }

    /// Whether packets are traced.
    pub fn packets(&self) -> bool {
        self.packets
    }

    /// The closest triangle hit by `ray` with `t` in `[t_min, t_max]` (of equally close
    /// ones, the lowest index in the scene's numbering), ignoring the triangles
    /// of flat surface `skip_flat` ([`SceneBvh::flat_surface`]: a mirror's index, or a
    /// plane's diffuse triangles; the plane a ray is leaving cannot be hit again by it, so
    /// skipping it replaces any self-intersection epsilon).
    pub fn closest_hit(
        &self,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
        skip_flat: Option<usize>,
    ) -> Option<Hit> {
        self.closest_hit_skipping(ray, t_min, t_max, skip_flat, None)
    }

    /// [`SceneBvh::closest_hit`] that also ignores triangle `skip_triangle` (the planar
    /// triangle a secondary ray starts on cannot be hit again by it).
    pub fn closest_hit_skipping(
        &self,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
        skip_flat: Option<usize>,
        skip_triangle: Option<usize>,
    ) -> Option<Hit> {
        if let Hierarchy::Wide(w) = &self.hierarchy {
            let q = (t_min, t_max, skip_flat, skip_triangle);
            return wide_query::<false>(w, ray, q).map(|(t, triangle)| Hit {
                t,
                triangle: triangle as usize,
            });
        }
        let wt = WatertightRay::new(ray.origin, ray.dir);
        let r = obvhs::ray::Ray::new(Vec3A::from(ray.origin), Vec3A::from(ray.dir), t_min, t_max);
        let mut hit = RayHit::none();
        // obvhs keeps the first of equally distant hits; `best` keeps the lowest triangle
        // index among them instead, so the answer does not depend on the visiting order
        // (the packet kernel's rule too).
        let mut best = u32::MAX;
        let found = with_triangle_test!(self, wt, skip_flat, skip_triangle, |test| {
            let original = &self.original;
            let keep_lowest = |r: &obvhs::ray::Ray, slot: usize| {
                let t = test(r, slot);
                let tie =
                    t == r.tmax && best != u32::MAX && original[slot] < original[best as usize];
                if t < r.tmax || tie {
                    best = slot as u32;
                }
                t
            };
            match &self.hierarchy {
                Hierarchy::Empty => false,
                Hierarchy::Cw(bvh) => bvh.ray_traverse(r, &mut hit, keep_lowest),
                Hierarchy::Binary(bvh) => bvh.ray_traverse(r, &mut hit, keep_lowest),
                Hierarchy::Wide(_) => unreachable!("answered above"),
            }
        });
        found.then(|| Hit {
            t: hit.t,
            triangle: self.original[best as usize] as usize,
        })
    }
}

impl SceneBvh {
    /// The closest hit of every lane of `active` in `packet` (what
    /// [`SceneBvh::closest_hit`] answers for each lane's ray and skipped flat surface) into `out`;
    /// lanes outside `active` are left as they are. Traced together through the packet
    /// kernel ([`packet`]) unless it is off or cannot hold this hierarchy.
    pub fn closest_hits(
        &self,
        packet: &RayPacket,
        active: LaneMask,
        out: &mut [Option<Hit>; LANES],
    ) {
        struct Kernel<'a> {
            bvh: &'a SceneBvh,
            packet: &'a RayPacket,
            active: LaneMask,
            out: &'a mut [Option<Hit>; LANES],
        }
        impl Vectorised for Kernel<'_> {
            type Output = ();
            #[inline(always)]
            fn run(self) {
                self.run_wide::<8>()
            }
            #[inline(always)]
            fn run_wide<const F32_LANES: usize>(self) {
                self.bvh
                    .closest_hits_inline::<F32_LANES>(self.packet, self.active, self.out)
            }
        }
        widest(Kernel {
            bvh: self,
            packet,
            active,
            out,
        })
    }

    /// [`SceneBvh::closest_hits`] for callers already compiled for this CPU
    /// ([`crate::cpu_features::widest`]): the kernel is inlined into them.
    #[inline(always)]
    pub(crate) fn closest_hits_inline<const F32_LANES: usize>(
        &self,
        packet: &RayPacket,
        active: LaneMask,
        out: &mut [Option<Hit>; LANES],
    ) {
        let mut hits = LaneHits::default();
        self.closest_hit_lanes_inline::<F32_LANES>(packet, active, &mut hits);
        for lane in packet::lanes(active) {
            out[lane] = hits.get(lane);
        }
    }

    /// [`SceneBvh::closest_hits_inline`] as structure of arrays ([`LaneHits`], what the
    /// kernel keeps): every lane is written, those outside `active` with no hit.
    #[inline(always)]
    pub(crate) fn closest_hit_lanes_inline<const F32_LANES: usize>(
        &self,
        packet: &RayPacket,
        active: LaneMask,
        out: &mut LaneHits,
    ) {
        if self.packets {
            let bvh = self.packet_bvh();
            if bvh.usable() {
                return bvh.closest_hit_lanes_inline::<F32_LANES>(packet, active, out);
            }
        }
        *out = LaneHits::default();
        for lane in packet::lanes(active) {
            let (ray, skip) = packet.lane(lane);
            out.set(lane, self.closest_hit(&ray, 0.0, f32::INFINITY, skip));
        }
    }

    /// The lanes of `active` in `packet` whose segment is blocked: lane `i`'s ray hits
    /// something in `[0, t_max[i])` other than its skipped flat surface and triangle
    /// `skip_triangle[i]` ([`packet::NO_TRIANGLE`]: none) — what [`SceneBvh::occluded`]
    /// answers for each lane. Traced together through the packet kernel's any-hit mode
    /// unless it is off or cannot hold this hierarchy.
    pub fn occluded_lanes(
        &self,
        packet: &RayPacket,
        active: LaneMask,
        t_max: &[f32; LANES],
        skip_triangle: &[u32; LANES],
    ) -> LaneMask {
        struct Kernel<'a> {
            bvh: &'a SceneBvh,
            packet: &'a RayPacket,
            active: LaneMask,
            t_max: &'a [f32; LANES],
            skip_triangle: &'a [u32; LANES],
        }
        impl Vectorised for Kernel<'_> {
            type Output = LaneMask;
            #[inline(always)]
            fn run(self) -> LaneMask {
                self.run_wide::<8>()
            }
            #[inline(always)]
            fn run_wide<const F32_LANES: usize>(self) -> LaneMask {
                self.bvh.occluded_lanes_inline::<F32_LANES>(
                    self.packet,
                    self.active,
                    self.t_max,
                    self.skip_triangle,
                )
            }
        }
        widest(Kernel {
            bvh: self,
            packet,
            active,
            t_max,
            skip_triangle,
        })
    }

    /// [`SceneBvh::occluded_lanes`] for callers already compiled for this CPU
    /// ([`crate::cpu_features::widest`]): the kernel is inlined into them.
    #[inline(always)]
    pub(crate) fn occluded_lanes_inline<const F32_LANES: usize>(
        &self,
        packet: &RayPacket,
        active: LaneMask,
        t_max: &[f32; LANES],
        skip_triangle: &[u32; LANES],
    ) -> LaneMask {
        if self.packets {
            let bvh = self.packet_bvh();
            if bvh.usable() {
                return bvh.occluded_lanes_inline::<F32_LANES>(
                    packet,
                    active,
                    t_max,
                    skip_triangle,
                );
            }
        }
        packet::lanes(active)
            .filter(|&lane| {
                let (ray, skip) = packet.lane(lane);
                let skip_triangle = (skip_triangle[lane] != packet::NO_TRIANGLE)
                    .then_some(skip_triangle[lane] as usize);
                self.occluded(&ray, 0.0, t_max[lane], skip, skip_triangle)
            })
            .fold(0, |blocked, lane| blocked | 1 << lane)
    }

    /// The answers to `queries` in order, into `out` (as long): with `ANY_HIT` false each
    /// query's [`SceneBvh::closest_hit_skipping`], with it true its
    /// [`SceneBvh::occluded`] (`Some` for blocked). For callers already compiled for this CPU
    /// ([`crate::cpu_features::widest`]). The 8-wide hierarchy traces them two at a time
    /// ([`wide::WideBvh::trace_pair`]: the same answers, the two traversals' waits
    /// overlapped); the others one at a time.
    #[inline(always)]
    pub(crate) fn queries_inline<const ANY_HIT: bool>(
        &self,
        queries: &[Query],
        out: &mut [Option<Hit>],
    ) {
        debug_assert_eq!(queries.len(), out.len());
        let Hierarchy::Wide(w) = &self.hierarchy else {
            for (q, o) in queries.iter().zip(out.iter_mut()) {
                *o = if ANY_HIT {
                    self.occluded(&q.ray, q.t_min, q.t_max, q.skip_flat, q.skip_triangle)
                        .then_some(Hit {
                            t: 0.0,
                            triangle: usize::MAX,
                        })
                } else {
                    self.closest_hit_skipping(
                        &q.ray,
                        q.t_min,
                        q.t_max,
                        q.skip_flat,
                        q.skip_triangle,
                    )
                };
            }
            return;
        };
        let wide_ray = |q: &Query| {
            wide::WideRay::new(
                q.ray.origin,
                q.ray.dir,
                q.t_min,
                q.t_max,
                q.skip_flat,
                q.skip_triangle,
            )
        };
        let hit = |found: Option<(f32, u32)>| {
            found.map(|(t, triangle)| Hit {
                t,
                triangle: triangle as usize,
            })
        };
        let mut pairs = queries.chunks_exact(2);
        let mut outs = out.chunks_exact_mut(2);
        for (q, o) in (&mut pairs).zip(&mut outs) {
            let (a, b) = (wide_ray(&q[0]), wide_ray(&q[1]));
            let [ha, hb] = w.trace_pair::<ANY_HIT>([&a, &b]);
            o[0] = hit(ha);
            o[1] = hit(hb);
        }
        if let ([q], [o]) = (pairs.remainder(), outs.into_remainder()) {
            *o = hit(WideQuery::<ANY_HIT> {
                bvh: w,
                ray: &q.ray,
                query: (q.t_min, q.t_max, q.skip_flat, q.skip_triangle),
            }
            .run());
        }
    }

    /// [`SceneBvh::queries_inline`] compiled for the widest vectors, as a call of its own:
    /// for callers not compiled for this CPU (benchmarks) and for `whitted`'s few shadow
    /// legs, kept out of its walk (measured: docs/tracer-performance.md, 2026-11-28). With
    /// `ANY_HIT` only whether an answer is `Some` means anything (blocked); its hit is any.
    #[inline(never)]
    pub fn queries<const ANY_HIT: bool>(&self, queries: &[Query], out: &mut [Option<Hit>]) {
        struct Batch<'b, const ANY_HIT: bool> {
            bvh: &'b SceneBvh,
            queries: &'b [Query],
            out: &'b mut [Option<Hit>],
        }
        impl<const ANY_HIT: bool> Vectorised for Batch<'_, ANY_HIT> {
            type Output = ();
            #[inline(always)]
            fn run(self) {
                self.bvh.queries_inline::<ANY_HIT>(self.queries, self.out)
            }
        }
        widest(Batch::<ANY_HIT> {
            bvh: self,
            queries,
            out,
        })
    }

    /// Builds the packet kernel's hierarchy now if packets are on (an integrator that
    /// traces packets calls it when it is created, so that the build is not part of the
    /// image loop's time, as the single-ray hierarchy's is not).
    pub fn prepare_packets(&self) {
        if self.packets {
            self.packet_bvh();
        }
    }

    /// Time spent building the packet kernel's hierarchy, if it was built (beside
    /// [`SceneBvh::build_time`]; zero when the kernel reuses the BVH2 of `--bvh bvh2`).
    pub fn packet_build_time(&self) -> Option<Duration> {
        self.packet_bvh.get().map(|(_, time)| *time)
    }

    fn packet_bvh(&self) -> &PacketBvh {
        &self
            .packet_bvh
            .get_or_init(|| {
                let start = std::time::Instant::now();
                let bvh = self.build_packet_bvh();
                (bvh, start.elapsed())
            })
            .0
    }

    fn build_packet_bvh(&self) -> PacketBvh {
        if let Hierarchy::Binary(bvh) = &self.hierarchy {
            // The packet kernel traverses this very hierarchy, slots in the same order.
            return PacketBvh::from_bvh2(bvh, self.slots.clone(), self.original.clone());
        }
        // The slot of each triangle, by the scene's numbering: the input order of the build.
        let mut slot_of = vec![0u32; self.slots.len()];
        for (slot, &i) in self.original.iter().enumerate() {
            slot_of[i as usize] = slot as u32;
        }
        let slot = |i: u32| self.slots[slot_of[i as usize] as usize];
        let tris: Vec<Triangle> = (0..self.slots.len() as u32)
            .map(|i| {
                let [v0, v1, v2] = slot(i).v.map(Vec3A::from);
                Triangle { v0, v1, v2 }
            })
            .collect();
        PacketBvh::build(&tris, slot)
    }
}

impl SceneBvh {
    /// Whether anything [`SceneBvh::closest_hit_skipping`] would find is there, without
    /// finding the closest: traversal stops at the first hit (a shadow leg needs only yes or
    /// no, and gets the same answer).
    pub fn occluded(
        &self,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
        skip_flat: Option<usize>,
        skip_triangle: Option<usize>,
    ) -> bool {
        if let Hierarchy::Wide(w) = &self.hierarchy {
            let q = (t_min, t_max, skip_flat, skip_triangle);
            return wide_query::<true>(w, ray, q).is_some();
        }
        let wt = WatertightRay::new(ray.origin, ray.dir);
        let r = obvhs::ray::Ray::new(Vec3A::from(ray.origin), Vec3A::from(ray.dir), t_min, t_max);
        with_triangle_test!(self, wt, skip_flat, skip_triangle, |test| {
            match &self.hierarchy {
                Hierarchy::Empty => false,
                Hierarchy::Cw(bvh) => !bvh.ray_traverse_miss(r, test),
                Hierarchy::Binary(bvh) => !bvh.ray_traverse_miss(r, test),
                Hierarchy::Wide(_) => unreachable!("answered above"),
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_scene::Surface;
    use mirrorbox_scene::load::parse_scene;
    use std::path::Path;

    const SCENE: &str = r#"{
        "camera": { "position": [0.5, 1.5, 3], "look_at": [0, 0.5, 0], "fov_y_deg": 50,
                    "width": 48, "height": 32 },
        "mirrors": [ { "center": [0, 1, -1.5], "normal": [0, 0, 1], "up": [0, 1, 0],
                       "width": 2, "height": 2 } ],
        "objects": [
            { "type": "quad", "size": [6, 6], "transform": { "rotate_deg": [-90, 0, 0] } },
            { "type": "box", "transform": { "translate": [-0.5, 0.5, 0], "rotate_deg": [0, 25, 0] } },
            { "type": "sphere", "radius": 0.4, "transform": { "translate": [0.8, 0.4, 0.3] } }
        ]
    }"#;

    /// Brute force over every triangle, for comparison.
    fn brute_force(g: &Geometry, ray: &Ray) -> Option<Hit> {
        let wt = WatertightRay::new(ray.origin, ray.dir);
        g.triangles
            .iter()
            .enumerate()
            .map(|(i, t)| Hit {
                t: wt.intersect(t[0], t[1], t[2], 0.0, f32::INFINITY),
                triangle: i,
            })
            .filter(|h| h.t.is_finite())
            .min_by(|a, b| a.t.total_cmp(&b.t))
    }

    #[test]
    fn both_hierarchies_match_brute_force_in_the_scene_numbering() {
        let scene = parse_scene(SCENE, Path::new("inline.json")).unwrap();
        for kind in [BvhKind::Cwbvh, BvhKind::Bvh2, BvhKind::Wide] {
            let bvh = SceneBvh::build_with(&scene.geometry, kind);
            let cam = &scene.camera;
            let mut hits = 0;
            for y in 0..cam.height {
                for x in 0..cam.width {
                    let ray = cam.primary_ray(x as f32 + 0.5, y as f32 + 0.5);
                    let got = bvh.closest_hit(&ray, 0.0, f32::INFINITY, None);
                    let want = brute_force(&scene.geometry, &ray);
                    assert_eq!(
                        got.map(|h| h.triangle),
                        want.map(|h| h.triangle),
                        "{kind:?} ({x},{y})"
                    );
                    hits += got.is_some() as usize;
                }
            }
            assert!(hits > cam.width as usize * cam.height as usize / 2);
        }
    }

    /// Coincident mirrors (issue 51): the builder sees their boxes spread, and both
    /// hierarchies still find the closest hit at every pixel — the same distance as brute
    /// force, on one of the coincident triangles where the brute force finds one of them.
    #[test]
    fn coincident_mirrors_are_found_as_brute_force_finds_them() {
        let mirror = r#"{ "center": [0, 1, -1], "normal": [0, 0, 1], "up": [0, 1, 0],
                          "width": 2, "height": 2 }"#;
        let text = format!(
            r#"{{ "camera": {{ "position": [0.3, 1.2, 2], "look_at": [0, 1, -1],
                              "fov_y_deg": 60, "width": 24, "height": 16 }},
                 "mirrors": [{}],
                 "objects": [ {{ "type": "quad", "size": [6, 6],
                                 "transform": {{ "rotate_deg": [-90, 0, 0] }} }} ] }}"#,
            vec![mirror; 2 * TIED_BOXES].join(",")
        );
        let scene = parse_scene(&text, Path::new("coincident.json")).unwrap();
        let g = &scene.geometry;
        let tris: Vec<Triangle> = g
            .triangles
            .iter()
            .map(|t| Triangle {
                v0: t[0].into(),
                v1: t[1].into(),
                v2: t[2].into(),
            })
            .collect();
        let boxes = primitive_boxes(&tris);
        for (t, b) in tris.iter().zip(&boxes) {
            let own = obvhs::Boundable::aabb(t);
            assert!(b.contains_point(own.min) && b.contains_point(own.max));
        }
        // The floor's two triangles keep their own boxes; the mirrors' are spread apart.
        let is_mirror = |i: usize| matches!(g.surface(i), Surface::Mirror { .. });
        let floor = (0..tris.len()).find(|&i| !is_mirror(i)).unwrap();
        assert_eq!(boxes[floor], obvhs::Boundable::aabb(&tris[floor]));
        let mirrors: Vec<usize> = (0..tris.len()).filter(|&i| is_mirror(i)).collect();
        assert!(
            boxes[mirrors[0]] != boxes[mirrors[1]],
            "tied boxes are spread"
        );
        for kind in [BvhKind::Cwbvh, BvhKind::Bvh2, BvhKind::Wide] {
            assert_finds_as_brute_force(&scene, &SceneBvh::build_with(g, kind));
        }
    }

    /// At every pixel centre of `scene`'s camera, `bvh` finds the closest hit brute force
    /// finds: the same distance, on a triangle of the same corners (one of coincident ones).
    fn assert_finds_as_brute_force(scene: &mirrorbox_scene::Scene, bvh: &SceneBvh) {
        let (g, cam) = (&scene.geometry, &scene.camera);
        for y in 0..cam.height {
            for x in 0..cam.width {
                let ray = cam.primary_ray(x as f32 + 0.5, y as f32 + 0.5);
                let got = bvh.closest_hit(&ray, 0.0, f32::INFINITY, None);
                let want = brute_force(g, &ray);
                let kind = bvh.kind;
                assert_eq!(got.map(|h| h.t), want.map(|h| h.t), "{kind:?} ({x},{y})");
                assert_eq!(
                    got.map(|h| g.triangles[h.triangle]),
                    want.map(|h| g.triangles[h.triangle]),
                    "{kind:?} ({x},{y})"
                );
            }
        }
    }

    /// An 8-wide hierarchy deeper than obvhs's 32-entry traversal stack holds (degenerate
    /// input; here the limit lowered to 0 levels) is replaced by the binary one, said by
    /// `kind`, which finds what brute force finds.
    #[test]
    fn a_hierarchy_too_deep_for_eight_wide_traversal_falls_back_to_the_binary_one() {
        let scene = parse_scene(SCENE, Path::new("inline.json")).unwrap();
        let g = &scene.geometry;
        assert_eq!(
            SceneBvh::build_within(g, BvhKind::Cwbvh, 31).kind,
            BvhKind::Cwbvh
        );
        let bvh = SceneBvh::build_within(g, BvhKind::Cwbvh, 0);
        assert_eq!(bvh.kind, BvhKind::Bvh2);
        assert_finds_as_brute_force(&scene, &bvh);
    }

    /// The 8-wide hierarchy gives the binary one's answers bit for bit (distance bits and
    /// triangle; occluded or not) on the inline scene and the bundled mirror scenes: camera
    /// rays, rays leaving a mirror from a point on it (skipping it), segments starting on a
    /// triangle (skipping it, as shadow legs do), and scattered rays from anywhere, with
    /// bounded and unbounded far limits; one at a time and as a batch
    /// ([`SceneBvh::queries_inline`], two rays traversed at once). Its nodes hold more than
    /// three children on average (a binary node two).
    #[test]
    fn the_wide_hierarchy_answers_as_the_binary_one() {
        let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes"));
        let scenes = [
            parse_scene(SCENE, Path::new("inline.json")).unwrap(),
            mirrorbox_scene::load_scene(&root.join("mirror_box.json")).unwrap(),
            mirrorbox_scene::load_scene(&root.join("mirror_room.json")).unwrap(),
        ];
        for scene in &scenes {
            let g = &scene.geometry;
            let binary = SceneBvh::build_with(g, BvhKind::Bvh2);
            let wide = SceneBvh::build_with(g, BvhKind::Wide);
            assert_eq!(wide.kind, BvhKind::Wide);
            let Hierarchy::Wide(w) = &wide.hierarchy else {
                panic!("not wide")
            };
            assert!(
                w.mean_children() > 3.0,
                "{} children per node",
                w.mean_children()
            );
            let mirror_of = |i: usize| match g.surface(i) {
                Surface::Mirror { mirror, .. } => Some(*mirror),
                Surface::Diffuse { .. } => None,
            };
            let mut rng = crate::sampler::SplitMix64::for_pixel(56, 0);
            let mut r = || rng.next_unit();
            let cam = &scene.camera;
            let (mut hits, mut blocked) = (0, 0);
            let mut queries = Vec::new();
            for i in 0..4000usize {
                let (ray, skip_flat, skip_triangle) = match i % 4 {
                    0 => (
                        cam.primary_ray(r() * cam.width as f32, r() * cam.height as f32),
                        None,
                        None,
                    ),
                    1 | 2 => {
                        // From a point on triangle t (barycentric), into a random direction,
                        // skipping its mirror or the triangle (as Whitted's shadow legs) or
                        // its flat surface (as `path`'s rays).
                        let t = (r() * g.triangles.len() as f32) as usize % g.triangles.len();
                        let [v0, v1, v2] = g.triangles[t];
                        let (a, b) = (r(), r());
                        let (a, b) = if a + b > 1.0 {
                            (1.0 - a, 1.0 - b)
                        } else {
                            (a, b)
                        };
                        let origin = v0 + a * (v1 - v0) + b * (v2 - v0);
                        let dir = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize_or(Vec3::Y);
                        let m = mirror_of(t);
                        if i % 4 == 2 {
                            (Ray { origin, dir }, Some(wide.flat_surface(t)), None)
                        } else {
                            (Ray { origin, dir }, m, m.is_none().then_some(t))
                        }
                    }
                    _ => {
                        let (lo, hi) = g.bounds().unwrap();
                        let size = hi - lo;
                        let origin = lo + Vec3::new(r(), r(), r()) * size;
                        let dir = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize_or(Vec3::Y);
                        (Ray { origin, dir }, None, None)
                    }
                };
                let t_max = [f32::INFINITY, 0.7, 3.0][i % 3];
                let want = binary.closest_hit_skipping(&ray, 0.0, t_max, skip_flat, skip_triangle);
                let got = wide.closest_hit_skipping(&ray, 0.0, t_max, skip_flat, skip_triangle);
                assert_eq!(
                    got.map(|h| (h.t.to_bits(), h.triangle)),
                    want.map(|h| (h.t.to_bits(), h.triangle)),
                    "ray {i}: {ray:?} to {t_max}"
                );
                hits += got.is_some() as usize;
                let want = binary.occluded(&ray, 0.0, t_max, skip_flat, skip_triangle);
                let got = wide.occluded(&ray, 0.0, t_max, skip_flat, skip_triangle);
                assert_eq!(got, want, "ray {i}: {ray:?} to {t_max}");
                blocked += got as usize;
                queries.push(Query {
                    ray,
                    t_min: 0.0,
                    t_max,
                    skip_flat,
                    skip_triangle,
                });
            }
            assert!(
                hits > 1000 && blocked > 1000,
                "{hits} hits, {blocked} blocked"
            );
            // The same rays as a batch, two at a time (an odd count: one alone at the end).
            let queries = &queries[..queries.len() - 1];
            let mut closest = vec![None; queries.len()];
            let mut any = vec![None; queries.len()];
            wide.queries::<false>(queries, &mut closest);
            wide.queries::<true>(queries, &mut any);
            for (i, q) in queries.iter().enumerate() {
                let (ray, t_max) = (q.ray, q.t_max);
                let want =
                    binary.closest_hit_skipping(&ray, 0.0, t_max, q.skip_flat, q.skip_triangle);
                assert_eq!(
                    closest[i].map(|h: Hit| (h.t.to_bits(), h.triangle)),
                    want.map(|h| (h.t.to_bits(), h.triangle)),
                    "batch ray {i}: {ray:?} to {t_max}"
                );
                let want = binary.occluded(&ray, 0.0, t_max, q.skip_flat, q.skip_triangle);
                assert_eq!(any[i].is_some(), want, "batch ray {i}: {ray:?} to {t_max}");
            }
        }
    }

    /// A ray leaving one of the floor quad's two triangles and skipping its flat surface
    /// skips the other too: from just below the floor (10⁻⁴, a self-intersection made large),
    /// straight up, under the other triangle. Skipping only the triangle it leaves, it hits
    /// the other one there; skipping the flat surface, nothing — in every hierarchy, closest
    /// and any hit. The floor's flat surface is exactly the triangles in the plane y = 0: its
    /// two, and the bottom face of the box standing on it.
    #[test]
    fn skipping_a_flat_surface_skips_every_triangle_on_its_plane() {
        let scene = parse_scene(SCENE, Path::new("inline.json")).unwrap();
        let g = &scene.geometry;
        let floor = g
            .parts
            .iter()
            .find(|p| {
                p.triangles.len() == 2
                    && !matches!(g.surface(p.triangles.start), Surface::Mirror { .. })
            })
            .expect("the floor quad")
            .triangles
            .clone();
        let ray = Ray {
            origin: Vec3::new(2.5, -1e-4, 2.5),
            dir: Vec3::Y,
        };
        let wt = WatertightRay::new(ray.origin, ray.dir);
        let under = floor
            .clone()
            .find(|&i| {
                let t = g.triangles[i];
                wt.intersect(t[0], t[1], t[2], 0.0, f32::INFINITY)
                    .is_finite()
            })
            .expect("a floor triangle above the origin");
        let left = floor.clone().find(|&i| i != under).unwrap();
        for kind in [BvhKind::Cwbvh, BvhKind::Bvh2, BvhKind::Wide] {
            let bvh = SceneBvh::build_with(g, kind);
            let flat = bvh.flat_surface(left);
            assert_eq!(flat, bvh.flat_surface(under), "{kind:?}");
            let hit = bvh.closest_hit_skipping(&ray, 0.0, f32::INFINITY, None, Some(left));
            assert_eq!(hit.map(|h| h.triangle), Some(under), "{kind:?}");
            assert!(hit.unwrap().t < 2e-4);
            assert!(bvh.occluded(&ray, 0.0, 1.0, None, Some(left)), "{kind:?}");
            let skipped = bvh.closest_hit_skipping(&ray, 0.0, f32::INFINITY, Some(flat), None);
            assert_eq!(skipped, None, "{kind:?}");
            assert!(!bvh.occluded(&ray, 0.0, 1.0, Some(flat), None), "{kind:?}");
            let on_floor = |i: usize| g.triangles[i].iter().all(|p| p.y.abs() < 1e-6);
            let sharing: Vec<usize> = (0..g.triangles.len())
                .filter(|&i| bvh.flat_surface(i) == flat)
                .collect();
            let in_plane: Vec<usize> = (0..g.triangles.len()).filter(|&i| on_floor(i)).collect();
            assert_eq!(sharing, in_plane, "{kind:?}");
            assert_eq!(sharing.len(), 4, "the floor's two, the box's bottom two");
        }
    }

    #[test]
    fn skipping_a_mirror_sees_what_is_behind_it() {
        let scene = parse_scene(SCENE, Path::new("inline.json")).unwrap();
        let bvh = SceneBvh::build(&scene.geometry);
        let ray = Ray {
            origin: Vec3::new(0.0, 1.0, 1.0),
            dir: Vec3::NEG_Z,
        };
        let first = bvh.closest_hit(&ray, 0.0, f32::INFINITY, None).unwrap();
        assert!(matches!(
            scene.geometry.surface(first.triangle),
            Surface::Mirror { mirror: 0, .. }
        ));
        assert!((first.t - 2.5).abs() < 1e-5);
        // Behind the mirror there is nothing but the floor's far edge: no hit straight on.
        assert_eq!(bvh.closest_hit(&ray, 0.0, f32::INFINITY, Some(0)), None);
    }

    /// The primary ray through a sub-pixel position hits the scene point that the camera's
    /// projection maps back to that same position.
    #[test]
    fn primary_ray_hit_projects_to_its_subpixel_position() {
        let scene = parse_scene(SCENE, Path::new("inline.json")).unwrap();
        let bvh = SceneBvh::build(&scene.geometry);
        let cam = &scene.camera;
        let grid = mirrorbox_scene::SubpixelGrid::new(4);
        for (x, y) in [(3u32, 28u32), (24, 16), (40, 27), (10, 20)] {
            for offset in grid.offsets() {
                let (px, py) = (x as f32 + offset.x, y as f32 + offset.y);
                let ray = cam.primary_ray(px, py);
                let hit = bvh
                    .closest_hit(&ray, 0.0, f32::INFINITY, None)
                    .expect("scene covers these pixels");
                let back = cam.project_to_pixel(ray.at(hit.t)).unwrap();
                assert!(
                    (back - glam::Vec2::new(px, py)).length() < 1e-3,
                    "({px},{py}) → {back}"
                );
            }
        }
    }

    /// The any-hit query answers exactly as the closest-hit one, for both hierarchies,
    /// segments of every length and both kinds of skip.
    #[test]
    fn occluded_agrees_with_closest_hit() {
        let scene = parse_scene(SCENE, Path::new("inline.json")).unwrap();
        let mut rng = crate::sampler::SplitMix64::for_pixel(7, 0);
        let mut r = || rng.next_unit();
        for kind in [BvhKind::Cwbvh, BvhKind::Bvh2] {
            let bvh = SceneBvh::build_with(&scene.geometry, kind);
            let (mut hits, mut misses) = (0, 0);
            for i in 0..4000 {
                let origin = Vec3::new(r() * 4.0 - 2.0, r() * 2.5, r() * 4.0 - 2.0);
                let dir = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize_or(Vec3::Y);
                let ray = Ray { origin, dir };
                let t_max = [0.5, 2.0, f32::INFINITY][i % 3];
                let n = scene.geometry.triangles.len();
                // A mirror's flat surface, a diffuse plane's, or none.
                let skip_flat = match i % 5 {
                    0 => Some(0),
                    1 => Some(bvh.flat_surface(i % n)),
                    _ => None,
                };
                let skip_triangle = (i % 7 == 0).then_some(i % n);
                let closest = bvh.closest_hit_skipping(&ray, 0.0, t_max, skip_flat, skip_triangle);
                let any = bvh.occluded(&ray, 0.0, t_max, skip_flat, skip_triangle);
                assert_eq!(
                    any,
                    closest.is_some(),
                    "{kind:?} ray {i}: {ray:?} to {t_max}"
                );
                if any { hits += 1 } else { misses += 1 }
            }
            assert!(hits > 500 && misses > 500, "{hits} hits, {misses} misses");
        }
    }

    /// Every lane of `rays` (in packets of [`LANES`], with every lane active or only some)
    /// gets from the packet kernel exactly the single-ray answer: the same distance bits and
    /// the same triangle. Returns how many lanes hit something.
    fn assert_packets_answer_as_single_rays(
        bvh: &SceneBvh,
        rays: &[(Ray, Option<usize>)],
    ) -> usize {
        let mut hits = 0;
        for (c, chunk) in rays.chunks(LANES).enumerate() {
            let mut packet = RayPacket::default();
            for (lane, (ray, skip)) in chunk.iter().enumerate() {
                packet.set(lane, ray, *skip);
            }
            let all = packet::first_lanes(chunk.len());
            for active in [all, all & 0x5555_5555, all & 0xf0f0_f0f0, all & 0xffff_0000] {
                let mut out = [None; LANES];
                bvh.closest_hits(&packet, active, &mut out);
                for lane in 0..chunk.len() {
                    let (ray, skip) = &chunk[lane];
                    if active >> lane & 1 == 0 {
                        assert_eq!(out[lane], None, "lane {lane} not asked about");
                        continue;
                    }
                    let want = bvh.closest_hit(ray, 0.0, f32::INFINITY, *skip);
                    assert_eq!(
                        out[lane].map(|h| h.t.to_bits()),
                        want.map(|h| h.t.to_bits()),
                        "packet {c} lane {lane}: {ray:?} skipping {skip:?}"
                    );
                    assert_eq!(
                        out[lane].map(|h| h.triangle),
                        want.map(|h| h.triangle),
                        "packet {c} lane {lane}: {ray:?} skipping {skip:?}"
                    );
                    hits += (active == all && want.is_some()) as usize;
                }
            }
        }
        hits
    }

    /// Coherent packets (each pixel's 4×4 sub-pixel grid, and the same rays after their
    /// first reflection) and incoherent ones (random origins and directions, random skips).
    #[test]
    fn packets_answer_as_single_rays() {
        let scene = parse_scene(SCENE, Path::new("inline.json")).unwrap();
        // Packets off too: the same queries answered lane by lane (the fallback).
        for (kind, packets) in [
            (BvhKind::Cwbvh, true),
            (BvhKind::Bvh2, true),
            (BvhKind::Cwbvh, false),
        ] {
            let bvh = SceneBvh::build_with(&scene.geometry, kind).with_packets(packets);
            let cam = &scene.camera;
            let grid = mirrorbox_scene::SubpixelGrid::new(4);
            let planes = crate::mirror_bounce::MirrorPlanes::new(&scene);
            let mut coherent = Vec::new();
            let mut reflected = Vec::new();
            for y in 0..cam.height {
                for x in 0..cam.width {
                    for o in grid.offsets() {
                        let ray = cam.primary_ray(x as f32 + o.x, y as f32 + o.y);
                        coherent.push((ray, None));
                        let Some(hit) = bvh.closest_hit(&ray, 0.0, f32::INFINITY, None) else {
                            continue;
                        };
                        if let Surface::Mirror { mirror, .. } =
                            *scene.geometry.surface(hit.triangle)
                        {
                            let (o, d) = planes
                                .reflect(mirror, ray.origin.as_dvec3(), ray.dir.as_dvec3())
                                .expect("a flat mirror reflects");
                            let ray = Ray {
                                origin: o.as_vec3(),
                                dir: d.as_vec3(),
                            };
                            reflected.push((ray, Some(mirror)));
                        }
                    }
                }
            }
            let mut rng = crate::sampler::SplitMix64::for_pixel(11, 0);
            let mut r = || rng.next_unit();
            let scattered: Vec<_> = (0..4000)
                .map(|i| {
                    let origin = Vec3::new(r() * 4.0 - 2.0, r() * 2.5, r() * 4.0 - 2.0);
                    let dir = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize_or(Vec3::Y);
                    let skip_flat = match i % 3 {
                        0 => Some(0),
                        1 => Some(bvh.flat_surface(i % scene.geometry.triangles.len())),
                        _ => None,
                    };
                    (Ray { origin, dir }, skip_flat)
                })
                .collect();
            let n = coherent.len();
            assert!(
                assert_packets_answer_as_single_rays(&bvh, &coherent) > n / 2,
                "{kind:?}"
            );
            let reflected_hits = assert_packets_answer_as_single_rays(&bvh, &reflected);
            assert!(
                reflected.len() > 1000 && reflected_hits > reflected.len() / 4,
                "{reflected_hits} of {} reflected rays hit",
                reflected.len()
            );
            assert!(assert_packets_answer_as_single_rays(&bvh, &scattered) > 1000);
        }
    }

    /// The any-hit packets answer each lane as [`SceneBvh::occluded`] does: random
    /// segments (short, long, unbounded), skipped flat surfaces and triangles (among them the
    /// triangle a segment starts on, as a shadow ray's), some lanes inactive.
    #[test]
    fn occlusion_packets_answer_as_single_rays() {
        let scene = parse_scene(SCENE, Path::new("inline.json")).unwrap();
        let g = &scene.geometry;
        let mut rng = crate::sampler::SplitMix64::for_pixel(13, 0);
        let mut r = || rng.next_unit();
        // The kernel traverses a BVH2: against the single-ray BVH2 query the answers are
        // the same bit for bit. (The CWBVH's single-ray traversal misses some hits at
        // t = 0 of segments starting where two surfaces touch: the box's bottom on the
        // floor here; see `BvhKind`.)
        let bvh = SceneBvh::build_with(g, BvhKind::Bvh2);
        let (mut blocked, mut clear) = (0, 0);
        for c in 0..200 {
            let mut packet = RayPacket::default();
            let mut t_max = [0.0; LANES];
            let mut skip_triangle = [packet::NO_TRIANGLE; LANES];
            let mut asked = Vec::new();
            for lane in 0..LANES {
                let i = c * LANES + lane;
                // Every fourth segment starts on a triangle (its centroid), skipping it.
                let start = i.is_multiple_of(4).then_some(i % g.triangles.len());
                let origin = match start {
                    Some(t) => g.triangles[t].iter().sum::<Vec3>() / 3.0,
                    None => Vec3::new(r() * 4.0 - 2.0, r() * 2.5, r() * 4.0 - 2.0),
                };
                let dir = Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5).normalize_or(Vec3::Y);
                let ray = Ray { origin, dir };
                // The mirror, the flat surface of the triangle it starts on, or none.
                let skip_flat = match (i % 5, start) {
                    (0, _) => Some(0),
                    (1 | 2, Some(t)) => Some(bvh.flat_surface(t)),
                    _ => None,
                };
                packet.set(lane, &ray, skip_flat);
                t_max[lane] = [0.5, 2.0, f32::INFINITY][i % 3];
                skip_triangle[lane] = start.map_or(packet::NO_TRIANGLE, |t| t as u32);
                asked.push((ray, skip_flat, start));
            }
            for active in [u32::MAX, 0x5555_5555, 0xffff_0000] {
                let got = bvh.occluded_lanes(&packet, active, &t_max, &skip_triangle);
                assert_eq!(got & !active, 0, "only active lanes answer");
                for lane in packet::lanes(active) {
                    let (ray, skip_flat, start) = &asked[lane];
                    let want = bvh.occluded(ray, 0.0, t_max[lane], *skip_flat, *start);
                    assert_eq!(
                        got >> lane & 1 == 1,
                        want,
                        "packet {c} lane {lane}: {ray:?} to {}",
                        t_max[lane]
                    );
                    if active == u32::MAX {
                        if want { blocked += 1 } else { clear += 1 }
                    }
                }
            }
        }
        assert!(
            blocked > 1000 && clear > 1000,
            "{blocked} blocked, {clear} clear"
        );
    }

    /// Rays aimed at the mirror's diagonal seam (and at its corner) from many origins, as
    /// packets: none leaks through, and each gets the single-ray answer.
    #[test]
    fn packets_do_not_leak_through_a_seam() {
        let scene = parse_scene(SCENE, Path::new("inline.json")).unwrap();
        let bvh = SceneBvh::build(&scene.geometry);
        let mirror: Vec<usize> = (0..scene.geometry.triangles.len())
            .filter(|&i| matches!(scene.geometry.surface(i), Surface::Mirror { .. }))
            .collect();
        assert_eq!(mirror.len(), 2, "the mirror is one quad");
        // The vertex the two triangles do not share with the other lies off the diagonal.
        let [a, b] = [mirror[0], mirror[1]].map(|i| scene.geometry.triangles[i]);
        let shared: Vec<Vec3> = a.iter().copied().filter(|p| b.contains(p)).collect();
        assert_eq!(shared.len(), 2, "two triangles share the diagonal");
        let mut rng = crate::sampler::SplitMix64::for_pixel(3, 0);
        let mut r = || rng.next_unit();
        let rays: Vec<_> = (0..1600)
            .map(|i| {
                let f = (i % 100) as f32 / 100.0;
                let target = shared[0] + (shared[1] - shared[0]) * f;
                let origin = Vec3::new(r() * 3.0 - 1.5, r() * 2.0 + 0.2, r() * 2.0 + 0.5);
                (
                    Ray {
                        origin,
                        dir: (target - origin).normalize(),
                    },
                    None,
                )
            })
            .collect();
        let hits = assert_packets_answer_as_single_rays(&bvh, &rays);
        assert_eq!(hits, rays.len(), "a ray through the seam leaked");
        // The 8-wide hierarchy, whose leaf tests both triangles at once: none leaks either,
        // and where both are hit at the same distance the lower triangle wins, as in the BVH2.
        let binary = SceneBvh::build_with(&scene.geometry, BvhKind::Bvh2);
        let wide = SceneBvh::build_with(&scene.geometry, BvhKind::Wide);
        let mut ties = 0;
        for (ray, _) in &rays {
            let want = binary.closest_hit(ray, 0.0, f32::INFINITY, None).unwrap();
            let got = wide.closest_hit(ray, 0.0, f32::INFINITY, None);
            assert_eq!(got, Some(want), "{ray:?}");
            let wt = WatertightRay::new(ray.origin, ray.dir);
            let [ta, tb] = [a, b].map(|t| wt.intersect(t[0], t[1], t[2], 0.0, f32::INFINITY));
            ties += (ta == tb && ta.is_finite()) as usize;
        }
        assert!(ties > 10, "{ties} rays hit both triangles at one distance");
    }

    #[test]
    fn empty_scene_hits_nothing() {
        let bvh = SceneBvh::build(&Geometry::default());
        let ray = Ray {
            origin: Vec3::ZERO,
            dir: Vec3::Z,
        };
        assert_eq!(bvh.closest_hit(&ray, 0.0, f32::INFINITY, None), None);
    }
}
