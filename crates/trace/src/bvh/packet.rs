//! Coherent ray packets (issue 19): up to [`LANES`] closest-hit queries — or any-hit
//! shadow queries ([`PacketBvh::occluded_lanes_inline`]) — traced together through one
//! binary BVH, each box and triangle test evaluated for all lanes side by side (an inner
//! node's box [`BOX_CHUNK`] lanes at a time, until one lane meets it).
//!
//! Why packets: planar mirrors keep neighbouring rays neighbours, so the sub-pixel samples
//! of neighbouring pixels visit nearly the same nodes and triangles at every bounce. One node
//! fetch and one loop over structure-of-arrays lanes (which the compiler turns into SIMD:
//! eight SSE or four AVX or two AVX-512 operations per line) replace 32 traversals.
//!
//! **The same answer as the single-ray query.** Each lane runs exactly the arithmetic of
//! [`WatertightRay::intersect`]: the same shear constants (computed for all lanes at once,
//! bit-identical, tested), no fused multiply-add, and lanes with an exact zero edge function
//! finished by the scalar test's f64 re-evaluation. A hit is kept if `0 ≤ t < best`; of hits
//! at exactly the same distance the lowest triangle index is kept, the single-ray query's
//! rule, so the answer (distance bits and triangle) does not depend on the visiting order,
//! which differs. Box tests only prune, conservatively: the far distance is widened by
//! `1 + 2γ₃` (Ize, "Robust BVH Ray Traversal", JCGT 2013), so rounding never skips a box.

use super::{Hit, NO_ONE_FLAT, Slot};
use crate::cpu_features::lane_bits;
use crate::watertight::{WatertightRay, axes_of, shear_of};
use glam::Vec3;
use mirrorbox_scene::Ray;
use mirrorbox_scene::lanes::{set_lanes, store_unmasked};
use obvhs::ray::safe_inverse;

/// Rays per packet: two pixels' 4×4 sub-pixel grids. 32 lanes measured 6 % faster than
/// 16 (one pixel) on `mirror_box` and `mirror_room`, and 64 slower than 32: the traversal's
/// control work is shared by more rays, until the lanes diverge.
pub const LANES: usize = 32;

/// Bit `i` set: lane `i` takes part.
pub type LaneMask = u32;

/// The mask of lanes `0..n` (`n ≤ LANES`).
pub fn first_lanes(n: usize) -> LaneMask {
    debug_assert!(n <= LANES);
    if n >= LaneMask::BITS as usize {
        LaneMask::MAX
    } else {
        (1 << n) - 1
    }
}

const _: () = assert!(LANES <= LaneMask::BITS as usize);

type Lanes = [f32; LANES];

/// Deepest hierarchy the fixed traversal stack holds; deeper ones (never built from scenes
/// within the limits, but possible in principle) are traced one ray at a time.
const STACK: usize = 128;

/// A lane that skips no flat surface (never equal to a slot's or to [`NO_ONE_FLAT`]).
const SKIP_NOTHING: u32 = u32::MAX - 1;

/// No triangle: what a lane that skips none holds in an any-hit query's skipped triangles.
pub const NO_TRIANGLE: u32 = u32::MAX;

/// No lane skips a triangle: the closest-hit queries' skipped triangles, and `path`'s shadow
/// rays' (they skip the flat surface they leave instead).
pub(crate) const NO_TRIANGLES: [u32; LANES] = [NO_TRIANGLE; LANES];

/// An any-hit lane's `best_t` once it has hit something: below every box's near distance
/// (never negative), so its box tests fail from then on.
const STOPPED: f32 = -1.0;

/// `1 + 2γ₃` with `γₙ = nε/(1 − nε)`, ε = 2⁻²⁴: the robust far-distance factor.
const FAR_WIDENING: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// The cost of a node's box test relative to a triangle test, by which obvhs decides how
/// far to collapse subtrees into leaves. Its presets use 3 (a node dearer than a triangle,
/// so leaves of up to 8 triangles); here a 32-lane triangle test costs about three box tests,
/// and the leaves of small triangles (the torus in `mirror_room`) were mostly tested for
/// nothing: half of `mirror_room`'s triangle tests missed the triangle's own box for every
/// lane. 0.3 against 3 (one thread, AVX2, paired runs): `mirror_room` Whitted ×0.857
/// [0.838–0.898], `path` ×0.903 [0.890–0.916]; 0.1 measured slower than 0.3, 0.5 and 1
/// the same within noise.
const LEAF_COLLAPSE_COST: f32 = 0.3;

/// A node of the binary hierarchy: a leaf when `count > 0` (slots `first..first + count`),
/// else children `first` and `first + 1`.
#[derive(Clone, Copy, Debug)]
struct Node {
    min: [f32; 3],
    count: u32,
    max: [f32; 3],
    first: u32,
}

/// The binary hierarchy the packets traverse, with the triangles in its own slot order.
pub(super) struct PacketBvh {
    nodes: Vec<Node>,
    slots: Vec<Slot>,
    /// Per slot, the scene's triangle index.
    original: Vec<u32>,
    /// Whether every root-to-leaf path fits the traversal stack.
    fits_stack: bool,
    /// Per node, the flat surface every triangle below it is on ([`NO_ONE_FLAT`] where
    /// they are not all on one): a ray leaving that surface skips the whole subtree.
    node_flat: Vec<u32>,
    /// Per inner node, twice the step from its first child's box centre to its second's
    /// ([`children_gap`]): which child is nearer along a direction, without reading the
    /// children's boxes.
    child_gap: Vec<[f32; 3]>,
}

/// The closest hits of a packet's lanes, structure of arrays: lane `i` hit triangle
/// `triangle[i]` (the scene's numbering) at distance `t[i]`, or nothing where `triangle[i]`
/// is [`NO_TRIANGLE`].
#[derive(Clone)]
pub struct LaneHits {
    pub t: [f32; LANES],
    pub triangle: [u32; LANES],
}

impl Default for LaneHits {
    fn default() -> Self {
        LaneHits {
            t: [f32::INFINITY; LANES],
            triangle: [NO_TRIANGLE; LANES],
        }
    }
}

impl LaneHits {
    /// Lane `lane`'s hit, as [`super::SceneBvh::closest_hit`] answers it.
    #[inline(always)]
    pub fn get(&self, lane: usize) -> Option<Hit> {
        (self.triangle[lane] != NO_TRIANGLE).then(|| Hit {
            t: self.t[lane],
            triangle: self.triangle[lane] as usize,
        })
    }

    /// The lanes with no hit (where [`LaneHits::get`] answers `None`), over all lanes: the
    /// caller masks the lanes it traced.
    #[inline(always)]
    pub fn misses(&self) -> LaneMask {
        lane_bits::<LANES>(|i| self.triangle[i] == NO_TRIANGLE)
    }

    /// Lane `lane` hit `hit`.
    pub fn set(&mut self, lane: usize, hit: Option<Hit>) {
        (self.t[lane], self.triangle[lane]) = match hit {
            Some(h) => (h.t, h.triangle as u32),
            None => (f32::INFINITY, NO_TRIANGLE),
        };
    }
}

/// Up to [`LANES`] rays, structure of arrays, each with the flat surface it skips.
#[derive(Clone)]
pub struct RayPacket {
    origin: [Lanes; 3],
    dir: [Lanes; 3],
    skip: [u32; LANES],
}

impl Default for RayPacket {
    fn default() -> Self {
        RayPacket {
            origin: [[0.0; LANES]; 3],
            dir: [[0.0; LANES], [0.0; LANES], [1.0; LANES]],
            skip: [SKIP_NOTHING; LANES],
        }
    }
}

impl RayPacket {
    /// Lane `lane` asks for the closest hit of `ray` in `[0, ∞)`, skipping flat surface
    /// `skip_flat` (what [`super::SceneBvh::closest_hit`] asks).
    pub fn set(&mut self, lane: usize, ray: &Ray, skip_flat: Option<usize>) {
        for k in 0..3 {
            self.origin[k][lane] = ray.origin[k];
            self.dir[k][lane] = ray.dir[k];
        }
        self.set_skip(lane, skip_flat);
    }

    /// Every lane's ray, from f64 lanes rounded to f32 (as `DVec3::as_vec3` rounds); the
    /// skipped flat surfaces stay as they are. One loop over the lanes per component: vectorised.
    #[inline(always)]
    pub fn set_rays_f64(&mut self, origin: &[[f64; LANES]; 3], dir: &[[f64; LANES]; 3]) {
        for k in 0..3 {
            for i in 0..LANES {
                self.origin[k][i] = origin[k][i] as f32;
                self.dir[k][i] = dir[k][i] as f32;
            }
        }
    }

    /// `rays` (at most [`LANES`]) written as f64 lanes into `origin` and `dir`, the walks'
    /// form; lanes past the end repeat the last ray (they are never active). In place: the
    /// arrays returned by value were copied (`memcpy`, 1.7 % of `whitted` on `mirror_box`).
    /// Plain loops: building these with `std::array::from_fn` stayed out-of-line calls, a
    /// few per cent.
    #[inline(always)]
    pub fn write_f64_lanes(
        rays: &[Ray],
        origin: &mut [[f64; LANES]; 3],
        dir: &mut [[f64; LANES]; 3],
    ) {
        for lane in 0..LANES {
            let ray = &rays[lane.min(rays.len() - 1)];
            for k in 0..3 {
                origin[k][lane] = ray.origin[k] as f64;
                dir[k][lane] = ray.dir[k] as f64;
            }
        }
    }

    /// Every lane's direction (f32, as the queries use it).
    pub fn dirs(&self) -> &[[f32; LANES]; 3] {
        &self.dir
    }

    /// The lanes of `mask` skip flat surface `flat` from now on (a lane loop).
    #[inline(always)]
    pub fn set_skip_lanes(&mut self, mask: LaneMask, flat: usize) {
        set_lanes(&mut self.skip, mask, flat as u32);
    }

    /// Lane `lane` skips flat surface `skip_flat` from now on.
    pub fn set_skip(&mut self, lane: usize, skip_flat: Option<usize>) {
        self.skip[lane] = skip_flat.map_or(SKIP_NOTHING, |m| m as u32);
    }

    /// The ray and skipped flat surface of lane `lane`, as [`RayPacket::set`] was given them.
    pub fn lane(&self, lane: usize) -> (Ray, Option<usize>) {
        let skip = (self.skip[lane] != SKIP_NOTHING).then_some(self.skip[lane] as usize);
        (
            Ray {
                origin: lane_vec(&self.origin, lane),
                dir: lane_vec(&self.dir, lane),
            },
            skip,
        )
    }
}

fn lane_vec(a: &[Lanes; 3], lane: usize) -> Vec3 {
    Vec3::new(a[0][lane], a[1][lane], a[2][lane])
}

/// What the tests need per lane, computed for all lanes at once: the reciprocal direction
/// of the box test (obvhs' `safe_inverse`: no infinities, so no `0 × ∞` in a box test) and
/// the watertight shear ([`shear_of`], as [`WatertightRay::new`]).
struct Prepared {
    inv: [Lanes; 3],
    /// `sx, sy, sz`.
    shear: [Lanes; 3],
    /// The axis permutation, coded as [`shear_of`] codes it.
    axes: [u32; LANES],
}

impl Prepared {
    #[inline(always)]
    fn new(p: &RayPacket) -> Self {
        let mut inv = [[0.0; LANES]; 3];
        let mut shear = [[0.0; LANES]; 3];
        let mut axes = [0; LANES];
        for i in 0..LANES {
            let d = [p.dir[0][i], p.dir[1][i], p.dir[2][i]];
            for k in 0..3 {
                inv[k][i] = safe_inverse(d[k]);
            }
            // Keep the reciprocals' loop apart from the shear's stores: writing both in one
            // loop over k measured 12 % slower on `mirror_box` (the lane loop stayed scalar).
            let (code, s) = shear_of(d);
            shear[0][i] = s[0];
            shear[1][i] = s[1];
            shear[2][i] = s[2];
            axes[i] = code;
        }
        Prepared { inv, shear, axes }
    }
}

#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

impl PacketBvh {
    /// A binary hierarchy built over `tris` (the scene's triangles in its numbering), with
    /// `slot_of(i)` the slot of triangle `i`.
    ///
    /// [`super::build_binary`], with the leaves collapsed for this kernel's costs
    /// ([`LEAF_COLLAPSE_COST`]).
    pub(super) fn build(tris: &[obvhs::triangle::Triangle], slot_of: impl Fn(u32) -> Slot) -> Self {
        if tris.is_empty() {
            return PacketBvh::from_parts(Vec::new(), Vec::new(), Vec::new());
        }
        let mut build_time = std::time::Duration::ZERO;
        let tune = |params| obvhs::BvhBuildParams {
            collapse_traversal_cost: LEAF_COLLAPSE_COST,
            ..params
        };
        let bvh = super::build_binary(tris, tune, &mut build_time);
        let original = bvh.primitive_indices.clone();
        let slots = original.iter().map(|&i| slot_of(i)).collect();
        PacketBvh::from_bvh2(&bvh, slots, original)
    }

    /// The kernel's view of obvhs' `bvh`, whose leaves index `slots` (and `original`, the
    /// scene's triangle of each slot) in its primitive order.
    pub(super) fn from_bvh2(bvh: &obvhs::bvh2::Bvh2, slots: Vec<Slot>, original: Vec<u32>) -> Self {
        let nodes = bvh
            .nodes
            .iter()
            .map(|n| Node {
                min: n.aabb.min.to_array(),
                count: n.prim_count,
                max: n.aabb.max.to_array(),
                first: n.first_index,
            })
            .collect();
        PacketBvh::from_parts(nodes, slots, original)
    }

    fn from_parts(nodes: Vec<Node>, slots: Vec<Slot>, original: Vec<u32>) -> Self {
        let fits_stack = nodes.is_empty() || depth(&nodes, 0) < STACK;
        let node_flat = subtree_flats(&nodes, &slots);
        let child_gap = nodes.iter().map(|n| children_gap(&nodes, n)).collect();
        PacketBvh {
            nodes,
            slots,
            original,
            fits_stack,
            node_flat,
            child_gap,
        }
    }

    /// Whether [`PacketBvh::closest_hit_lanes_inline`] can trace this hierarchy.
    pub(super) fn usable(&self) -> bool {
        self.fits_stack && !self.nodes.is_empty()
    }

    /// The closest hit of every lane in `active`, into `out` as structure of arrays (what
    /// the traversal keeps anyway): every lane is written, those outside `active` with no
    /// hit. All lanes are traversed together; a leaf's triangles are tested once for each
    /// axis permutation of the watertight test among its lanes (a pixel's samples nearly
    /// always share one).
    ///
    /// Inlined into its caller so that it is compiled for the caller's CPU
    /// features ([`crate::cpu_features::widest`]; the same arithmetic, hence the same bits,
    /// in every build).
    #[inline(always)]
    pub(super) fn closest_hit_lanes_inline<const F32_LANES: usize>(
        &self,
        packet: &RayPacket,
        active: LaneMask,
        out: &mut LaneHits,
    ) {
        *out = LaneHits::default();
        self.trace_lanes::<false, F32_LANES>(
            packet,
            active,
            &mut out.t,
            &mut out.triangle,
            &NO_TRIANGLES,
        );
    }

    /// The lanes of `active` whose segment is blocked: whose ray hits a triangle at
    /// `0 ≤ t < t_max[lane]` other than its skipped flat surface's and `skip_triangle[lane]` (the
    /// scene's numbering; [`NO_TRIANGLE`] for none) — what
    /// [`super::SceneBvh::occluded`] answers. A lane stops at its first such hit (any hit
    /// will do), and so does the traversal once every lane has stopped.
    #[inline(always)]
    pub(super) fn occluded_lanes_inline<const F32_LANES: usize>(
        &self,
        packet: &RayPacket,
        active: LaneMask,
        t_max: &[f32; LANES],
        skip_triangle: &[u32; LANES],
    ) -> LaneMask {
        let mut best_t = *t_max;
        let mut best_triangle = [NO_TRIANGLE; LANES];
        self.trace_lanes::<true, F32_LANES>(
            packet,
            active,
            &mut best_t,
            &mut best_triangle,
            skip_triangle,
        );
        lanes(active)
            .filter(|&lane| best_triangle[lane] != NO_TRIANGLE)
            .fold(0, |blocked, lane| blocked | 1 << lane)
    }

    /// The traversal of every lane in `active`, its leaves' triangle tests grouped by the
    /// watertight test's axis permutation: closest hits (`ANY_HIT` false) or blocked
    /// segments (`ANY_HIT` true, see [`PacketBvh::occluded_lanes_inline`]; a lane's `best_t`
    /// becomes [`STOPPED`] at its first hit). Two monomorphised kernels, so that the any-hit
    /// mode costs the closest-hit one nothing.
    #[inline(always)]
    fn trace_lanes<const ANY_HIT: bool, const F32_LANES: usize>(
        &self,
        packet: &RayPacket,
        active: LaneMask,
        best_t: &mut Lanes,
        best_triangle: &mut [u32; LANES],
        skip_triangle: &[u32; LANES],
    ) {
        if active == 0 {
            return;
        }
        let prepared = Prepared::new(packet);
        // The lanes by the watertight test's axis permutation: one traversal for all of
        // them, each leaf's triangles tested per permutation present among its lanes.
        let mut groups = [(0, 0); 6];
        let mut n = 0;
        let mut left = active;
        while left != 0 {
            let code = prepared.axes[left.trailing_zeros() as usize];
            // Over all lanes, then masked: a loop without branches (vectorised).
            let same = lane_bits::<LANES>(|i| prepared.axes[i] == code);
            groups[n] = (code, same & left);
            left &= !same;
            n += 1;
        }
        self.traverse::<ANY_HIT, F32_LANES>(
            packet,
            &prepared,
            active,
            &groups[..n],
            best_t,
            best_triangle,
            skip_triangle,
        );
    }

    /// Depth-first traversal for the lanes of `active` (not empty): a node is entered when
    /// any of them hits its box before its closest hit so far; the nearer child (along the
    /// first active lane's direction) first. A leaf's triangles are tested for each of
    /// `groups` (the lanes by axis permutation, [`PacketBvh::triangle`]) with lanes that met
    /// its box: one walk of the hierarchy where the lanes have several permutations (one
    /// traversal per permutation before: `whitted` `mirror_room`, 13 % of whose queries have
    /// more than one, ×0.971 in one process, `mirror_box` ×0.971 as two builds; issue 56's
    /// tenth session).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn traverse<const ANY_HIT: bool, const F32_LANES: usize>(
        &self,
        p: &RayPacket,
        q: &Prepared,
        active: LaneMask,
        groups: &[(u32, LaneMask)],
        best_t: &mut Lanes,
        best_triangle: &mut [u32; LANES],
        skip_triangle: &[u32; LANES],
    ) {
        let lead = active.trailing_zeros() as usize;
        let lead_dir = [p.dir[0][lead], p.dir[1][lead], p.dir[2][lead]];
        let mut stack = [0u32; STACK];
        let mut sp = 0;
        let mut index = 0usize;
        let mut warm = Warm {
            lane: lead,
            chunk: lead / BOX_CHUNK,
        };
        loop {
            let node = &self.nodes[index];
            let flat = self.node_flat[index];
            if node.count == 0 {
                if box_any(node, flat, p, q, best_t, active, &mut warm) {
                    let (a, b) = (node.first as usize, node.first as usize + 1);
                    let gap = &self.child_gap[index];
                    let along = (0..3).map(|k| gap[k] * lead_dir[k]).sum::<f32>();
                    let (near, far) = if along < 0.0 { (b, a) } else { (a, b) };
                    stack[sp] = far as u32;
                    sp += 1;
                    index = near;
                    continue;
                }
            } else {
                let hit = box_hits(node, flat, p, q, best_t, active);
                if hit != 0 {
                    for &(code, members) in groups {
                        let h = hit & members;
                        if h == 0 {
                            continue;
                        }
                        for slot in node.first..node.first + node.count {
                            let (t, s, k) = (&mut *best_t, &mut *best_triangle, skip_triangle);
                            // (The same arm for every slot of the leaf: one branch, predicted.)
                            macro_rules! test_with_axes {
                                ($(($x:literal, $y:literal, $z:literal)),*) => {
                                    match axes_of(code) {
                                        $(($x, $y, $z) => self
                                            .triangle::<$x, $y, $z, ANY_HIT, F32_LANES>(
                                                slot, p, q, h, t, s, k,
                                            ),)*
                                        other => unreachable!("not an axis permutation: {other:?}"),
                                    }
                                };
                            }
                            test_with_axes!(
                                (1, 2, 0),
                                (2, 1, 0),
                                (2, 0, 1),
                                (0, 2, 1),
                                (0, 1, 2),
                                (1, 0, 2)
                            );
                        }
                    }
                    // Any hit: done once every lane has stopped (a stopped lane's box tests
                    // fail, but the stack would still be walked).
                    if ANY_HIT
                        && (0..LANES).fold(0, |m: LaneMask, i| {
                            m | ((best_t[i] >= 0.0) as LaneMask) << i
                        }) & active
                            == 0
                    {
                        break;
                    }
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            index = stack[sp] as usize;
        }
    }

    /// The watertight test of slot `slot` for the lanes of `hit`, keeping `0 ≤ t < best`
    /// and recording the scene's index of the triangle hit. Two loops branch free over the
    /// lanes (the compiler vectorises them): the edge functions ([`triangle_chunk`] lanes at
    /// a time, chunks with no lane of `hit` skipped: their lanes' flags stay unset), then,
    /// only if some lane is inside the edges, the distance; the rare lanes with an exact
    /// zero edge function or an exact tie are finished one by one. `ANY_HIT`: lanes also
    /// skip `skip_triangle`, and a hit stops the lane (`best` becomes [`STOPPED`]).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn triangle<
        const KX: usize,
        const KY: usize,
        const KZ: usize,
        const ANY_HIT: bool,
        const F32_LANES: usize,
    >(
        &self,
        slot: u32,
        p: &RayPacket,
        q: &Prepared,
        hit: LaneMask,
        best_t: &mut Lanes,
        best_triangle: &mut [u32; LANES],
        skip_triangle: &[u32; LANES],
    ) {
        let s = &self.slots[slot as usize];
        let triangle = self.original[slot as usize];
        let [v0, v1, v2] = s.v;
        let (v0, v1, v2) = (v0.to_array(), v1.to_array(), v2.to_array());
        let mut zero = [false; LANES];
        let mut tie = [false; LANES];
        // First the edge functions: in most tests no lane is inside the triangle, and the
        // distance (a division per lane) is not needed.
        let mut edges = [[0.0f32; LANES]; 3];
        let mut inside = [false; LANES];
        let mut edge_lane = |i: usize| {
            let o = [p.origin[0][i], p.origin[1][i], p.origin[2][i]];
            let (sx, sy) = (q.shear[0][i], q.shear[1][i]);
            let (a_x, a_y, a_z) = (v0[KX] - o[KX], v0[KY] - o[KY], v0[KZ] - o[KZ]);
            let (b_x, b_y, b_z) = (v1[KX] - o[KX], v1[KY] - o[KY], v1[KZ] - o[KZ]);
            let (c_x, c_y, c_z) = (v2[KX] - o[KX], v2[KY] - o[KY], v2[KZ] - o[KZ]);
            let ax = a_x - sx * a_z;
            let ay = a_y - sy * a_z;
            let bx = b_x - sx * b_z;
            let by = b_y - sy * b_z;
            let cx = c_x - sx * c_z;
            let cy = c_y - sy * c_z;
            let u = cx * by - cy * bx;
            let v = ax * cy - ay * cx;
            let w = bx * ay - by * ax;
            let exact_zero = (u == 0.0) | (v == 0.0) | (w == 0.0);
            // Inside: all three edge functions of one sign, none zero. (The scalar test's
            // "no zero, not of both signs, determinant not zero": the same lanes, since
            // three non-zero values of one sign never sum to zero. A lane with a NaN edge
            // function may be flagged otherwise here, but its distance is NaN then and
            // `t >= 0` drops it, as the scalar test does.)
            let all_positive = min(min(u, v), w) > 0.0;
            let all_negative = max(max(u, v), w) < 0.0;
            let asked = (hit >> i & 1 == 1)
                & (s.flat != p.skip[i])
                & (!ANY_HIT || triangle != skip_triangle[i]);
            zero[i] = asked & exact_zero;
            inside[i] = asked & (all_positive | all_negative);
            edges[0][i] = u;
            edges[1][i] = v;
            edges[2][i] = w;
        };
        // Chunk by chunk, skipping the chunks where no lane asks: in `mirror_room` a fifth of
        // the chunk tests of leaves met by some lane (a leaf met by a few lanes of a packet
        // whose rays have spread).
        let chunk = triangle_chunk(F32_LANES);
        let chunk_lanes: LaneMask = (1 << chunk) - 1;
        for c in 0..LANES / chunk {
            if (hit >> (c * chunk)) & chunk_lanes != 0 {
                for j in 0..chunk {
                    edge_lane(c * chunk + j);
                }
            }
        }
        if any(&inside) {
            // The kept distances and triangles into new arrays, stored whole by
            // `store_unmasked` (not as masked stores, slow on AMD's AVX2 CPUs).
            let (mut new_t, mut new_triangle) = ([0.0; LANES], [0; LANES]);
            for i in 0..LANES {
                let o_z = p.origin[KZ][i];
                let sz = q.shear[2][i];
                let [u, v, w] = [edges[0][i], edges[1][i], edges[2][i]];
                let det = u + v + w;
                let az = sz * (v0[KZ] - o_z);
                let bz = sz * (v1[KZ] - o_z);
                let cz = sz * (v2[KZ] - o_z);
                let t = (u * az + v * bz + w * cz) / det;
                let valid = inside[i] & (t >= 0.0);
                let take = valid & (t < best_t[i]);
                tie[i] = !ANY_HIT & valid & (t == best_t[i]);
                let kept = if ANY_HIT { STOPPED } else { t };
                new_t[i] = if take { kept } else { best_t[i] };
                new_triangle[i] = if take { triangle } else { best_triangle[i] };
            }
            store_unmasked(best_t, new_t);
            store_unmasked(best_triangle, new_triangle);
        }
        if any(&zero) {
            // The scalar test's f64 re-evaluation of exact zeros.
            let (v0, v1, v2) = (Vec3::from(v0), Vec3::from(v1), Vec3::from(v2));
            for i in (0..LANES).filter(|&i| zero[i]) {
                let ray = WatertightRay::new(lane_vec(&p.origin, i), lane_vec(&p.dir, i));
                let t = ray.intersect_axes::<KX, KY, KZ>(v0, v1, v2, 0.0, best_t[i]);
                if t < best_t[i] {
                    best_t[i] = if ANY_HIT { STOPPED } else { t };
                    best_triangle[i] = triangle;
                } else if t == best_t[i] && !ANY_HIT {
                    tie[i] = true;
                }
            }
        }
        if any(&tie) {
            // Equally distant hits: the lowest triangle index wins, whatever the visiting
            // order (the single-ray query's rule).
            for i in (0..LANES).filter(|&i| tie[i]) {
                // (A miss of the f64 re-evaluation is an infinite distance, equal to that of
                // a lane with no hit yet: no hit to compare with.)
                let best = best_triangle[i];
                if best != NO_TRIANGLE && triangle < best {
                    best_triangle[i] = triangle;
                }
            }
        }
    }
}

/// Lanes per step of the triangle test's edge functions, skipped where none asks: one vector
/// of f32 in the AVX2 and AVX-512 builds (`f32_lanes` 8 and 16), 8 in the baseline's. Against
/// the whole packet at once, in-process (issue 56, tenth session, AMD EPYC with AVX2): 8 lanes
/// `whitted` `mirror_room` ×0.986 [0.984–0.987], `mirror_box` ×1.002, `path` ×1.000; 16 lanes
/// ×1.031 slower than 8 in AVX2 (×1.023 / ×1.025 on an Intel Xeon, thirteenth session), and
/// the distance loop chunked too ×1.18. In AVX-512 on the Intel Xeon, 16 against 8: `whitted`
/// ×0.904 [0.901–0.918] / ×0.914 [0.897–0.927] (`mirror_room` / `mirror_box`).
const fn triangle_chunk(f32_lanes: usize) -> usize {
    if f32_lanes >= 16 { 16 } else { 8 }
}

// Every lane is in some chunk, whatever the build (chunks of 16 or 8 lanes).
const _: () = assert!(LANES.is_multiple_of(triangle_chunk(16)));

/// One flag per lane.
type Mask = [bool; LANES];

/// Whether any lane is set (an OR over the lanes, which vectorises; no early exit).
#[inline(always)]
fn any(mask: &Mask) -> bool {
    mask.iter().fold(false, |a, &b| a | b)
}

/// The lanes of `group` whose ray meets the node's box no farther than their best hit,
/// and does not skip `flat`, the one flat surface all of the node's triangles are on (if
/// any): a ray leaving a mirror starts inside its boxes and would otherwise enter them all,
/// to skip every triangle there (`mirror_room`: a quarter of the triangle tests).
#[inline(always)]
fn box_hits(
    node: &Node,
    flat: u32,
    p: &RayPacket,
    q: &Prepared,
    best_t: &Lanes,
    group: LaneMask,
) -> LaneMask {
    // As bits, one `movmsk` per chunk: cheaper than a flag per lane, and the group is
    // applied to the bits.
    let mut meets: LaneMask = 0;
    for i in 0..LANES {
        meets |= (box_meets_lane(node, flat, p, q, best_t, i) as LaneMask) << i;
    }
    meets & group
}

/// Lanes per step of [`box_any`]: one AVX-512 vector of f32, two AVX2 ones. Against 8 (plain
/// builds, one thread, `whitted` at 16 spp, 2026-11-27): AVX-512 `mirror_room` ×0.958 twice,
/// `mirror_box` ×0.959 / ×0.997 / ×0.975; the AVX2 build on the same CPU (`trace --simd
/// avx2`) ×0.994 / ×0.969; `path` the same (×0.997–1.007).
const BOX_CHUNK: usize = 16;

// Every lane is in some chunk: a lane left out would never enter an inner node.
const _: () = assert!(LANES.is_multiple_of(BOX_CHUNK));

/// Where [`box_any`] looks first: the lane of the group that met the last box it tested,
/// and that lane's chunk.
struct Warm {
    lane: usize,
    chunk: usize,
}

/// Whether any lane of `group` meets the node's box as [`box_hits`] decides, with the
/// same arithmetic: an inner node needs only this answer. First the warm lane alone (in a
/// coherent packet the lane that met the parent's box usually meets the child's: one lane's
/// test instead of a chunk's, `whitted` ×0.978 on `mirror_room`, issue 56's ninth session),
/// then [`BOX_CHUNK`] lanes at a time from the warm chunk on; `warm` becomes the first lane
/// of the group that met the box in the chunk that did.
#[inline(always)]
fn box_any(
    node: &Node,
    flat: u32,
    p: &RayPacket,
    q: &Prepared,
    best_t: &Lanes,
    group: LaneMask,
    warm: &mut Warm,
) -> bool {
    // The warm lane is always one of the group's (set from the group's bits below).
    if box_meets_lane(node, flat, p, q, best_t, warm.lane) {
        return true;
    }
    const CHUNKS: usize = LANES / BOX_CHUNK;
    for step in 0..CHUNKS {
        let c = (warm.chunk + step) % CHUNKS;
        let base = c * BOX_CHUNK;
        if (group >> base) & ((1 << BOX_CHUNK) - 1) == 0 {
            continue;
        }
        // The chunk's answers as bits (one `movmsk`), the group applied to the bits.
        let mut meets: LaneMask = 0;
        for j in 0..BOX_CHUNK {
            meets |= (box_meets_lane(node, flat, p, q, best_t, base + j) as LaneMask) << j;
        }
        let met = meets & (group >> base);
        if met != 0 {
            *warm = Warm {
                lane: base + met.trailing_zeros() as usize,
                chunk: c,
            };
            return true;
        }
    }
    false
}

/// Whether lane `i` meets the node's box no farther than its best hit and does not skip
/// `flat` (whether it is in the traversed group or not is the caller's business):
/// [`box_hits`]'s and [`box_any`]'s test of one lane.
#[inline(always)]
fn box_meets_lane(
    node: &Node,
    flat: u32,
    p: &RayPacket,
    q: &Prepared,
    best_t: &Lanes,
    i: usize,
) -> bool {
    let slab = |k: usize| {
        let t0 = (node.min[k] - p.origin[k][i]) * q.inv[k][i];
        let t1 = (node.max[k] - p.origin[k][i]) * q.inv[k][i];
        (min(t0, t1), max(t0, t1))
    };
    let (n0, f0) = slab(0);
    let (n1, f1) = slab(1);
    let (n2, f2) = slab(2);
    let near = max(max(0.0, n0), max(n1, n2));
    let far = min(min(f0, f1), f2) * FAR_WIDENING;
    // `near ≤ far` and `near ≤ best`, in one comparison (the same answer for all values
    // but a NaN `far`, which finite boxes and `safe_inverse` never give; with one, `min`
    // returns `best` and the box is entered: pruning less, never more).
    (near <= min(far, best_t[i])) & (flat != p.skip[i])
}

/// The lanes set in `mask`, lowest first.
pub fn lanes(mut mask: LaneMask) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let lane = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            lane
        })
    })
}

/// For an inner node, `b.min + b.max − a.min − a.max` per axis (children `a`, `b`): the
/// second child lies farther along a direction `d` than the first when the gap's dot
/// product with `d` is positive. Zero for a leaf.
fn children_gap(nodes: &[Node], node: &Node) -> [f32; 3] {
    if node.count > 0 {
        return [0.0; 3];
    }
    let (a, b) = (&nodes[node.first as usize], &nodes[node.first as usize + 1]);
    let gap = |k: usize| b.min[k] + b.max[k] - a.min[k] - a.max[k];
    [gap(0), gap(1), gap(2)]
}

/// Per node, the flat surface all the triangles below it are on, or [`NO_ONE_FLAT`] (children
/// before parents: an explicit post-order walk from the root).
fn subtree_flats(nodes: &[Node], slots: &[Slot]) -> Vec<u32> {
    let mut flat = vec![NO_ONE_FLAT; nodes.len()];
    if nodes.is_empty() {
        return flat;
    }
    let mut stack = vec![(0usize, false)];
    while let Some((i, children_done)) = stack.pop() {
        let n = &nodes[i];
        if n.count > 0 {
            let leaf = &slots[n.first as usize..(n.first + n.count) as usize];
            let first = leaf[0].flat;
            flat[i] = if leaf.iter().all(|s| s.flat == first) {
                first
            } else {
                NO_ONE_FLAT
            };
        } else if children_done {
            let (a, b) = (flat[n.first as usize], flat[n.first as usize + 1]);
            flat[i] = if a == b { a } else { NO_ONE_FLAT };
        } else {
            stack.push((i, true));
            stack.push((n.first as usize, false));
            stack.push((n.first as usize + 1, false));
        }
    }
    flat
}

/// Nodes on the longest root-to-leaf path below `index`.
fn depth(nodes: &[Node], index: usize) -> usize {
    let mut deepest = 0;
    let mut stack = vec![(index, 1usize)];
    while let Some((i, d)) = stack.pop() {
        deepest = deepest.max(d);
        let n = &nodes[i];
        if n.count == 0 {
            stack.push((n.first as usize, d + 1));
            stack.push((n.first as usize + 1, d + 1));
        }
    }
    deepest
}

const _: () = assert!(NO_ONE_FLAT != SKIP_NOTHING);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{NO_ONE_FLAT, Slot};

    /// Every node records the flat surface all triangles below it are on, exactly: a subtree
    /// of one mirror's (or one plane's) triangles has it (so rays leaving that surface skip
    /// it), a mixed one has none.
    #[test]
    fn subtree_flats_are_the_flat_surface_of_every_triangle_below() {
        let quad = |z: f32, x0: f32| {
            let [a, b, c, d] = [
                Vec3::new(x0, 0.0, z),
                Vec3::new(x0 + 1.0, 0.0, z),
                Vec3::new(x0 + 1.0, 1.0, z),
                Vec3::new(x0, 1.0, z),
            ];
            [[a, b, c], [a, c, d]]
        };
        // Two mirrors of two quads each, far apart (flat surfaces 0 and 1), and diffuse quads
        // between them, each on a plane of its own (2, 3, 4).
        let mut triangles = Vec::new();
        let mut flats = Vec::new();
        for (z, mirror) in [(-5.0, 0), (5.0, 1)] {
            for x0 in [0.0, 1.0] {
                triangles.extend(quad(z, x0));
                flats.extend([mirror; 2]);
            }
        }
        for (z, plane) in [(-1.0, 2), (0.0, 3), (1.0, 4)] {
            triangles.extend(quad(z, 0.5));
            flats.extend([plane; 2]);
        }
        let tris: Vec<_> = triangles
            .iter()
            .map(|t| obvhs::triangle::Triangle {
                v0: t[0].into(),
                v1: t[1].into(),
                v2: t[2].into(),
            })
            .collect();
        let bvh = PacketBvh::build(&tris, |i| Slot {
            v: triangles[i as usize],
            flat: flats[i as usize],
        });
        let below = |index: usize| {
            let mut found = Vec::new();
            let mut stack = vec![index];
            while let Some(i) = stack.pop() {
                let n = &bvh.nodes[i];
                if n.count > 0 {
                    found.extend((n.first..n.first + n.count).map(|s| bvh.slots[s as usize].flat));
                } else {
                    stack.extend([n.first as usize, n.first as usize + 1]);
                }
            }
            found
        };
        let mut on_one = [0; 5];
        for index in 0..bvh.nodes.len() {
            let flats = below(index);
            let want = if flats.iter().all(|&m| m == flats[0]) {
                flats[0]
            } else {
                NO_ONE_FLAT
            };
            assert_eq!(bvh.node_flat[index], want, "node {index}: {flats:?}");
            if want != NO_ONE_FLAT {
                on_one[want as usize] += 1;
            }
        }
        assert!(on_one.iter().all(|&n| n > 0), "{on_one:?}");
    }

    /// The lane-parallel shear and permutation are [`WatertightRay::new`]'s, bit for bit,
    /// for directions of every kind: random, axis-aligned, with ties between components,
    /// signed zeros.
    #[test]
    fn prepared_lanes_match_the_single_ray_shear() {
        let mut rng = crate::sampler::SplitMix64::for_pixel(5, 0);
        let mut dirs: Vec<Vec3> = (0..4000)
            .map(|_| {
                let v = Vec3::new(rng.next_unit(), rng.next_unit(), rng.next_unit()) - 0.5;
                v.normalize_or(Vec3::X)
            })
            .collect();
        for a in [-1.0f32, -0.0, 0.0, 1.0] {
            for b in [-1.0f32, -0.0, 0.0, 1.0] {
                for c in [-1.0f32, 1.0] {
                    dirs.extend([Vec3::new(a, b, c), Vec3::new(c, a, b), Vec3::new(b, c, a)]);
                }
            }
        }
        for chunk in dirs.chunks(LANES) {
            let mut packet = RayPacket::default();
            for (lane, &dir) in chunk.iter().enumerate() {
                let ray = Ray {
                    origin: Vec3::ZERO,
                    dir,
                };
                packet.set(lane, &ray, None);
            }
            let q = Prepared::new(&packet);
            for (lane, &dir) in chunk.iter().enumerate() {
                let wt = WatertightRay::new(Vec3::ZERO, dir);
                assert_eq!(axes_of(q.axes[lane]), wt.axes(), "{dir}");
                let shear = [0, 1, 2].map(|k| q.shear[k][lane].to_bits());
                assert_eq!(shear, wt.shear().map(f32::to_bits), "{dir}");
            }
        }
    }
}
