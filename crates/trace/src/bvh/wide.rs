//! An 8-wide hierarchy of our own for single rays (issue 56): the rays packets cannot serve
//! (`path`'s scattered continuations and shadow legs, Whitted's remaining single rays).
//!
//! **Build**: obvhs builds the binary hierarchy (its `medium_build`, as [`super::BvhKind::Bvh2`]);
//! it is collapsed here into nodes of up to [`WIDTH`] children — repeatedly opening the inner
//! child with the largest surface area, as Wald et al.'s and obvhs's own collapses do — with
//! the children's boxes stored as structure of arrays (`lo[axis][child]`), uncompressed f32.
//! A leaf child is a range of slots (the binary leaf's); per child, the one mirror every
//! triangle below it is on, if any (a ray leaving that mirror skips the child, as the packet
//! kernel skips such subtrees).
//!
//! **Traversal**: the eight boxes of a node are tested at once (a branch-free loop over the
//! children, compiled for AVX-512, AVX2 or SSE2 by [`crate::cpu_features::widest`]); the hit
//! children go on a fixed stack with their entry distances, nearest on top; a popped entry
//! farther than the closest hit so far is dropped. Box tests are the packet kernel's
//! (`safe_inverse` reciprocals, the far distance widened by 1 + 2γ₃), so no box that a ray
//! meets is skipped; triangles are the watertight test; of equally distant hits the lowest
//! triangle index wins. Same answers as the binary hierarchy's traversal, bit for bit
//! (tested), and no corner misses (obvhs's CWBVH misses some, docs/tracer-performance.md).
//!
//! **Stack**: each level pushes at most `WIDTH − 1` entries beyond the one it pops, so a
//! hierarchy `d` levels deep needs `(WIDTH − 1)·d + 1`; one deeper than [`STACK`] holds is not
//! built ([`WideBvh::from_bvh2`] returns `None`) and the binary hierarchy is kept (assimp's
//! `box_longline.obj`).

use super::{NOT_A_MIRROR, Slot};
use crate::watertight::WatertightRay;
use obvhs::ray::safe_inverse;

/// Children per node.
pub const WIDTH: usize = 8;

/// Entries of the traversal stack.
const STACK: usize = 256;

/// What a ray that skips no mirror compares child mirrors with (never a child's mirror,
/// [`NOT_A_MIRROR`] included).
const SKIP_NOTHING: u32 = u32::MAX - 1;

/// `1 + 2γ₃`: the packet kernel's robust far-distance factor.
const FAR_WIDENING: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// The binary hierarchy's build for this one: leaves of at most [`LEAF_TRIANGLES`], collapsed
/// as if a node test cost one triangle test ([`LEAF_COLLAPSE_COST`]; a leaf's triangles are
/// tested at once, [`WideBvh::block`]).
pub(super) fn leaf_params(params: obvhs::BvhBuildParams) -> obvhs::BvhBuildParams {
    obvhs::BvhBuildParams {
        max_prims_per_leaf: LEAF_TRIANGLES,
        collapse_traversal_cost: LEAF_COLLAPSE_COST,
        ..params
    }
}

/// Most triangles per leaf. Measured (`path`, `mirror_room`, 640×360, 16 spp, one thread,
/// 2 rounds each): 8 and collapse cost 3 (obvhs's `medium_build`) 1.01–1.03 s, 8 and 1
/// 0.98–1.02 s, 4 and 1 0.97 s; with the triangles tested one at a time, 4 and 1 0.99 s.
const LEAF_TRIANGLES: u32 = 4;

/// obvhs's node-to-triangle cost ratio for collapsing leaves.
const LEAF_COLLAPSE_COST: f32 = 1.0;

/// One node: its children's boxes as structure of arrays, and per child what it is.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
struct WideNode {
    lo: [[f32; WIDTH]; 3],
    hi: [[f32; WIDTH]; 3],
    /// An inner child's node, or a leaf child's first slot.
    index: [u32; WIDTH],
    /// A leaf child's slots (at least 1); 0 for an inner child.
    count: [u32; WIDTH],
    /// The mirror every triangle below the child is on, or [`NOT_A_MIRROR`].
    mirror: [u32; WIDTH],
    /// Bit `i`: child `i` exists.
    occupied: u32,
}

impl WideNode {
    fn empty() -> Self {
        WideNode {
            lo: [[f32::INFINITY; WIDTH]; 3],
            hi: [[f32::NEG_INFINITY; WIDTH]; 3],
            index: [0; WIDTH],
            count: [0; WIDTH],
            mirror: [NOT_A_MIRROR; WIDTH],
            occupied: 0,
        }
    }
}

/// Up to [`WIDTH`] triangles of a leaf as structure of arrays, tested against a ray at once.
#[derive(Clone, Debug)]
#[repr(C, align(32))]
struct TriBlock {
    /// `v[corner][axis][lane]`.
    v: [[[f32; WIDTH]; 3]; 3],
    mirror: [u32; WIDTH],
    /// The scene's index of each lane's triangle.
    original: [u32; WIDTH],
    /// Lanes in use (from the first).
    count: u32,
}

/// The 8-wide hierarchy: its nodes, and its leaves' triangles in blocks (a leaf child names
/// its first block and its triangle count; its blocks follow one another).
pub(super) struct WideBvh {
    nodes: Vec<WideNode>,
    blocks: Vec<TriBlock>,
}

/// A ray as the traversal holds it.
pub(super) struct WideRay {
    pub wt: WatertightRay,
    pub origin: [f32; 3],
    pub inv: [f32; 3],
    pub t_min: f32,
    pub t_max: f32,
    /// The mirror it leaves ([`SKIP_NOTHING`] for none) and the triangle it skips
    /// (`u32::MAX` for none).
    pub skip_mirror: u32,
    pub skip_triangle: u32,
}

impl WideRay {
    pub fn new(
        origin: glam::Vec3,
        dir: glam::Vec3,
        t_min: f32,
        t_max: f32,
        skip_mirror: Option<usize>,
        skip_triangle: Option<usize>,
    ) -> Self {
        WideRay {
            wt: WatertightRay::new(origin, dir),
            origin: origin.to_array(),
            inv: dir.to_array().map(safe_inverse),
            t_min,
            t_max,
            skip_mirror: skip_mirror.map_or(SKIP_NOTHING, |m| m as u32),
            skip_triangle: skip_triangle.map_or(u32::MAX, |t| t as u32),
        }
    }
}

impl WideBvh {
    /// The binary hierarchy `bvh` collapsed to [`WIDTH`] children per node, or `None` where
    /// it is too deep for the traversal's stack. `slots` are in `bvh`'s primitive order.
    pub(super) fn from_bvh2(
        bvh: &obvhs::bvh2::Bvh2,
        slots: &[Slot],
        original: &[u32],
    ) -> Option<Self> {
        let b = &bvh.nodes;
        let mut blocks = Vec::new();
        if b.is_empty() {
            return Some(WideBvh {
                nodes: Vec::new(),
                blocks,
            });
        }
        let mirrors = binary_mirrors(bvh, slots);
        let area = |i: usize| {
            let d = b[i].aabb.max - b[i].aabb.min;
            d.x * d.y + d.y * d.z + d.z * d.x
        };
        let mut nodes = vec![WideNode::empty()];
        // (binary node, wide node, depth): each binary inner node becomes one wide node.
        let mut todo = vec![(0usize, 0usize, 1usize)];
        let mut deepest = 1;
        while let Some((bi, wi, depth)) = todo.pop() {
            deepest = deepest.max(depth);
            let mut children: Vec<usize> = if b[bi].is_leaf() {
                vec![bi]
            } else {
                let first = b[bi].first_index as usize;
                vec![first, first + 1]
            };
            while children.len() < WIDTH {
                let open = children
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| !b[**c].is_leaf())
                    .max_by(|x, y| area(*x.1).total_cmp(&area(*y.1)))
                    .map(|(k, _)| k);
                let Some(k) = open else { break };
                let c = children.swap_remove(k);
                let first = b[c].first_index as usize;
                children.extend([first, first + 1]);
            }
            for (i, &c) in children.iter().enumerate() {
                let (lo, hi) = (b[c].aabb.min.to_array(), b[c].aabb.max.to_array());
                let node = &mut nodes[wi];
                for k in 0..3 {
                    node.lo[k][i] = lo[k];
                    node.hi[k][i] = hi[k];
                }
                node.mirror[i] = mirrors[c];
                node.occupied |= 1 << i;
                if b[c].is_leaf() {
                    let first = b[c].first_index as usize;
                    let count = b[c].prim_count as usize;
                    node.index[i] = blocks.len() as u32;
                    node.count[i] = count as u32;
                    for chunk in (first..first + count).collect::<Vec<_>>().chunks(WIDTH) {
                        let mut block = TriBlock {
                            v: [[[0.0; WIDTH]; 3]; 3],
                            mirror: [NOT_A_MIRROR; WIDTH],
                            original: [u32::MAX; WIDTH],
                            count: chunk.len() as u32,
                        };
                        for (lane, &slot) in chunk.iter().enumerate() {
                            for (corner, v) in slots[slot].v.iter().enumerate() {
                                for (axis, x) in v.to_array().into_iter().enumerate() {
                                    block.v[corner][axis][lane] = x;
                                }
                            }
                            block.mirror[lane] = slots[slot].mirror;
                            block.original[lane] = original[slot];
                        }
                        blocks.push(block);
                    }
                } else {
                    let child = nodes.len();
                    nodes[wi].index[i] = child as u32;
                    nodes.push(WideNode::empty());
                    todo.push((c, child, depth + 1));
                }
            }
        }
        ((WIDTH - 1) * deepest < STACK).then_some(WideBvh { nodes, blocks })
    }

    /// Children per node, on average (tests).
    #[cfg(test)]
    pub(super) fn mean_children(&self) -> f64 {
        let children: u32 = self.nodes.iter().map(|n| n.occupied.count_ones()).sum();
        f64::from(children) / self.nodes.len() as f64
    }

    /// The children of `node` the ray meets no farther than `best` and does not skip, as
    /// bits, and their entry distances. (A loop over the child index, as the packet kernel's
    /// lane loops: the form the compiler vectorises.)
    #[inline(always)]
    #[allow(clippy::needless_range_loop)]
    fn meets(&self, node: &WideNode, ray: &WideRay, best: f32) -> (u32, [f32; WIDTH]) {
        let mut near = [0.0f32; WIDTH];
        let mut bits = 0u32;
        for i in 0..WIDTH {
            let slab = |k: usize| {
                let t0 = (node.lo[k][i] - ray.origin[k]) * ray.inv[k];
                let t1 = (node.hi[k][i] - ray.origin[k]) * ray.inv[k];
                (min(t0, t1), max(t0, t1))
            };
            let (n0, f0) = slab(0);
            let (n1, f1) = slab(1);
            let (n2, f2) = slab(2);
            let n = max(max(ray.t_min, n0), max(n1, n2));
            let f = min(min(f0, f1), f2) * FAR_WIDENING;
            near[i] = n;
            let meets = (n <= min(f, best)) & (node.mirror[i] != ray.skip_mirror);
            bits |= (meets as u32) << i;
        }
        (bits & node.occupied, near)
    }

    /// The closest hit with `t` in `[t_min, t_max]`, skipping the ray's mirror and triangle:
    /// `(t, triangle)` in the scene's numbering, of equally distant hits the lowest triangle.
    /// `ANY_HIT`: the first hit found with `t < t_max` instead (its `t` is not the closest).
    #[inline(always)]
    pub(super) fn trace<const KX: usize, const KY: usize, const KZ: usize, const ANY_HIT: bool>(
        &self,
        ray: &WideRay,
    ) -> Option<(f32, u32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best = ray.t_max;
        // The scene's index of the closest triangle so far (u32::MAX: none).
        let mut best_triangle = u32::MAX;
        // Not initialised: entries below `sp` are written before they are read (zeroing 3 KB
        // per query measured as a tenth of the traversal).
        let mut stack = [const { std::mem::MaybeUninit::<Entry>::uninit() }; STACK];
        stack[0].write(Entry {
            index: 0,
            count: 0,
            near: ray.t_min,
        });
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            // SAFETY: every entry below `sp` was written (pushes write at `sp` and then raise
            // it; pops lower it).
            let Entry { index, count, near } = unsafe { stack[sp].assume_init() };
            if near > best {
                continue;
            }
            if count > 0 {
                let blocks = index as usize..index as usize + (count as usize).div_ceil(WIDTH);
                for block in &self.blocks[blocks] {
                    let hit = self.block::<KX, KY, KZ>(block, ray, best);
                    if let Some((t, triangle)) = hit {
                        if ANY_HIT {
                            // `occluded`'s answer: a hit at t_min ≤ t < t_max.
                            if t < ray.t_max {
                                return Some((t, triangle));
                            }
                            continue;
                        }
                        let tie =
                            (t == best) & (best_triangle != u32::MAX) && triangle < best_triangle;
                        if (t < best) | tie {
                            best = t;
                            best_triangle = triangle;
                        }
                    }
                }
                continue;
            }
            let node = &self.nodes[index as usize];
            let (mut bits, near) = self.meets(node, ray, best);
            // Push the hit children farthest first, so the nearest is popped next: an
            // insertion into the stack's top, which holds at most WIDTH entries of this node.
            let base = sp;
            while bits != 0 {
                let i = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let entry = Entry {
                    index: node.index[i],
                    count: node.count[i],
                    near: near[i],
                };
                let mut j = sp;
                // SAFETY: entries base..sp were written by this loop.
                while j > base && unsafe { stack[j - 1].assume_init() }.near < entry.near {
                    stack[j] = stack[j - 1];
                    j -= 1;
                }
                stack[j].write(entry);
                sp += 1;
            }
        }
        (best_triangle != u32::MAX).then_some((best, best_triangle))
    }
}

impl WideBvh {
    /// The watertight test of `ray` against a block's triangles at once, with `t` in
    /// `[t_min, best]`: the closest `(t, triangle)`, of equally distant ones the lowest
    /// triangle. Each lane computes the scalar test's arithmetic
    /// ([`WatertightRay::intersect_axes`]) operation for operation, so the same bits; a lane
    /// with an exact zero edge function is finished by the scalar test (its f64
    /// re-evaluation). Lanes beyond the block's count, on the mirror the ray leaves or on the
    /// triangle it skips take no part.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)]
    fn block<const KX: usize, const KY: usize, const KZ: usize>(
        &self,
        b: &TriBlock,
        ray: &WideRay,
        best: f32,
    ) -> Option<(f32, u32)> {
        let o = ray.origin;
        let [sx, sy, sz] = ray.wt.shear();
        let mut t = [f32::INFINITY; WIDTH];
        let mut zero = 0u32;
        for i in 0..WIDTH {
            let d = |corner: usize, k: usize| b.v[corner][k][i] - o[k];
            let (a_x, a_y, a_z) = (d(0, KX), d(0, KY), d(0, KZ));
            let (b_x, b_y, b_z) = (d(1, KX), d(1, KY), d(1, KZ));
            let (c_x, c_y, c_z) = (d(2, KX), d(2, KY), d(2, KZ));
            let ax = a_x - sx * a_z;
            let ay = a_y - sy * a_z;
            let bx = b_x - sx * b_z;
            let by = b_y - sy * b_z;
            let cx = c_x - sx * c_z;
            let cy = c_y - sy * c_z;
            let u = cx * by - cy * bx;
            let v = ax * cy - ay * cx;
            let w = bx * ay - by * ax;
            let asked = ((i as u32) < b.count)
                & (b.mirror[i] != ray.skip_mirror)
                & (b.original[i] != ray.skip_triangle);
            let exact_zero = (u == 0.0) | (v == 0.0) | (w == 0.0);
            zero |= ((asked & exact_zero) as u32) << i;
            // All three of one sign, none zero: the scalar test's "not of both signs,
            // determinant not zero" for these lanes (a NaN lane gets a NaN distance, dropped
            // below as the scalar test drops it).
            let inside = (min(min(u, v), w) > 0.0) | (max(max(u, v), w) < 0.0);
            let det = u + v + w;
            let az = sz * a_z;
            let bz = sz * b_z;
            let cz = sz * c_z;
            let ti = (u * az + v * bz + w * cz) / det;
            let valid = asked & !exact_zero & inside & (ti >= ray.t_min) & (ti <= best);
            t[i] = if valid { ti } else { f32::INFINITY };
        }
        let mut hit: Option<(f32, u32)> = None;
        let mut keep = |ti: f32, tri: u32| {
            let better = match hit {
                None => ti.is_finite(),
                Some((bt, btri)) => (ti < bt) | ((ti == bt) & (tri < btri)),
            };
            if better {
                hit = Some((ti, tri));
            }
        };
        for i in 0..b.count as usize {
            keep(t[i], b.original[i]);
        }
        while zero != 0 {
            let i = zero.trailing_zeros() as usize;
            zero &= zero - 1;
            let corner = |c: usize| glam::Vec3::new(b.v[c][0][i], b.v[c][1][i], b.v[c][2][i]);
            let ti = ray.wt.intersect_axes::<KX, KY, KZ>(
                corner(0),
                corner(1),
                corner(2),
                ray.t_min,
                best,
            );
            keep(ti, b.original[i]);
        }
        hit
    }
}

/// A stack entry: an inner node (its index, `count` 0) or a leaf (its first slot and
/// `count` slots), with the distance at which the ray enters its box.
#[derive(Clone, Copy)]
struct Entry {
    index: u32,
    count: u32,
    near: f32,
}

#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// Per binary node, the mirror all triangles below it are on, or [`NOT_A_MIRROR`]: children
/// before parents (a pre-order walk, reversed), without recursion (hierarchies may be deep).
fn binary_mirrors(bvh: &obvhs::bvh2::Bvh2, slots: &[Slot]) -> Vec<u32> {
    let b = &bvh.nodes;
    let mut order = Vec::with_capacity(b.len());
    let mut stack = vec![0usize];
    while let Some(i) = stack.pop() {
        order.push(i);
        if !b[i].is_leaf() {
            let first = b[i].first_index as usize;
            stack.extend([first, first + 1]);
        }
    }
    let mut mirror = vec![NOT_A_MIRROR; b.len()];
    for &i in order.iter().rev() {
        mirror[i] = if b[i].is_leaf() {
            let range = b[i].first_index as usize..(b[i].first_index + b[i].prim_count) as usize;
            let first = slots[range.start].mirror;
            if slots[range].iter().all(|s| s.mirror == first) {
                first
            } else {
                NOT_A_MIRROR
            }
        } else {
            let first = b[i].first_index as usize;
            if mirror[first] == mirror[first + 1] {
                mirror[first]
            } else {
                NOT_A_MIRROR
            }
        };
    }
    mirror
}
