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

/// The 8-wide hierarchy; its slots are the binary hierarchy's (the caller's).
pub(super) struct WideBvh {
    nodes: Vec<WideNode>,
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
    pub(super) fn from_bvh2(bvh: &obvhs::bvh2::Bvh2, slots: &[Slot]) -> Option<Self> {
        let b = &bvh.nodes;
        if b.is_empty() {
            return Some(WideBvh { nodes: Vec::new() });
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
                    node.index[i] = b[c].first_index;
                    node.count[i] = b[c].prim_count;
                } else {
                    let child = nodes.len();
                    nodes[wi].index[i] = child as u32;
                    nodes.push(WideNode::empty());
                    todo.push((c, child, depth + 1));
                }
            }
        }
        ((WIDTH - 1) * deepest < STACK).then_some(WideBvh { nodes })
    }

    /// Nodes in the hierarchy (tests, reports).
    #[cfg(test)]
    pub(super) fn len(&self) -> usize {
        self.nodes.len()
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
    /// `(t, slot)`, of equally distant hits the one whose scene triangle (`original`) is
    /// lowest. `ANY_HIT`: the first hit found instead (its `t` is not the closest).
    #[inline(always)]
    pub(super) fn trace<const KX: usize, const KY: usize, const KZ: usize, const ANY_HIT: bool>(
        &self,
        ray: &WideRay,
        slots: &[Slot],
        original: &[u32],
    ) -> Option<(f32, u32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best = ray.t_max;
        let mut best_slot = u32::MAX;
        let mut stack_node = [0u32; STACK];
        let mut stack_near = [0.0f32; STACK];
        // An entry is an inner node (its index, count 0) or a leaf (its first slot, count).
        let mut stack_count = [0u32; STACK];
        let mut sp = 1;
        stack_node[0] = 0;
        stack_near[0] = ray.t_min;
        stack_count[0] = 0;
        while sp > 0 {
            sp -= 1;
            if stack_near[sp] > best {
                continue;
            }
            let (index, count) = (stack_node[sp], stack_count[sp]);
            if count > 0 {
                for slot in index..index + count {
                    let s = &slots[slot as usize];
                    let tri = original[slot as usize];
                    if (s.mirror == ray.skip_mirror) | (tri == ray.skip_triangle) {
                        continue;
                    }
                    let t = ray
                        .wt
                        .intersect_axes::<KX, KY, KZ>(s.v[0], s.v[1], s.v[2], ray.t_min, best);
                    if ANY_HIT {
                        // `occluded`'s answer: a hit at t_min ≤ t < t_max.
                        if t < ray.t_max {
                            return Some((t, slot));
                        }
                        continue;
                    }
                    let tie =
                        (t == best) & (best_slot != u32::MAX) && tri < original[best_slot as usize];
                    if (t < best) | tie {
                        best = t;
                        best_slot = slot;
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
                let (n, idx, cnt) = (near[i], node.index[i], node.count[i]);
                let mut j = sp;
                while j > base && stack_near[j - 1] < n {
                    stack_node[j] = stack_node[j - 1];
                    stack_near[j] = stack_near[j - 1];
                    stack_count[j] = stack_count[j - 1];
                    j -= 1;
                }
                stack_node[j] = idx;
                stack_near[j] = n;
                stack_count[j] = cnt;
                sp += 1;
            }
        }
        (best_slot != u32::MAX).then_some((best, best_slot))
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
