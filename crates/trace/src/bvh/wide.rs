//! An 8-wide hierarchy of our own for single rays (issue 56): the rays packets cannot serve
//! (`path`'s scattered continuations and shadow legs, Whitted's remaining single rays).
//!
//! **Build**: obvhs builds the binary hierarchy ([`super::build_binary`], as for
//! [`super::BvhKind::Bvh2`]);
//! it is collapsed here into nodes of up to [`WIDTH`] children — repeatedly opening the inner
//! child with the largest surface area, as Wald et al.'s and obvhs's own collapses do — with
//! the children's boxes stored as structure of arrays (`lo[axis][child]`), uncompressed f32.
//! A leaf child names the first of its blocks (the binary leaf's triangles, up to [`BLOCK`]
//! per block as structure of arrays, tested at once); per child, the one flat surface every
//! triangle below it is on, if any (a ray leaving that surface skips the child, as the packet
//! kernel skips such subtrees; [`super::flat_surfaces`]: a mirror, or a plane's diffuse
//! triangles).
//!
//! **Traversal**: the eight boxes of a node are tested at once (a branch-free loop over the
//! children, compiled for AVX-512, AVX2 or SSE2 by [`crate::cpu_features::widest`]); the
//! nearest hit child is visited next, the others go on a fixed stack with their entry
//! distances, nearest on top (one or two hit children without a branch on which); a popped
//! entry farther than the closest hit so far is dropped (an any-hit query pushes three or
//! more unsorted and stops at a leaf's first hit). Box tests are the packet kernel's
//! (`safe_inverse` reciprocals, the far distance widened by 1 + 2γ₃), so no box that a ray
//! meets is skipped; triangles are the watertight test; of equally distant hits the lowest
//! triangle index wins (within a block, the least integer key of (distance, triangle)). Same
//! answers as the binary hierarchy's traversal, bit for bit (tested: the closest hit's
//! distance and triangle; for an any-hit query whether the ray is blocked), and no corner
//! misses (obvhs's CWBVH misses some, docs/tracer-performance.md).
//!
//! **Stack**: each level pushes at most `WIDTH − 1` entries beyond the one it pops, so a
//! hierarchy `d` levels deep needs `(WIDTH − 1)·d + 1`; one deeper than [`STACK`] holds is not
//! built ([`WideBvh::from_bvh2`] returns `None`) and the binary hierarchy is kept (assimp's
//! `box_longline.obj`).

use super::{NO_ONE_FLAT, Slot};
use crate::cpu_features::lane_bits;
use crate::watertight::{WatertightRay, shear_operands_branch_free};

/// Children per node.
pub const WIDTH: usize = 8;

/// Triangles per leaf block: [`LEAF_TRIANGLES`], so that a leaf is one block. (Blocks of
/// [`WIDTH`] lanes held leaves of at most 4 in twice the memory: `path` ×0.963 / ×0.963 on
/// `mirror_room` / `mirror_box` with blocks of 4, 4 % fewer instructions.)
const BLOCK: usize = LEAF_TRIANGLES as usize;

/// Entries of the traversal stack.
const STACK: usize = 256;

/// What a ray that skips no flat surface compares children's with (never a child's,
/// [`NO_ONE_FLAT`] included).
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

/// A child that is a leaf: [`WideNode::child`]'s high bit, below it the leaf's first block.
const LEAF: u32 = 1 << 31;

/// One node: its children's boxes as structure of arrays, and per child what it is.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
struct WideNode {
    lo: [[f32; WIDTH]; 3],
    hi: [[f32; WIDTH]; 3],
    /// An inner child's node, or [`LEAF`] and a leaf child's first block (its blocks follow
    /// one another, the last with [`TriBlock::more`] false).
    child: [u32; WIDTH],
    /// The flat surface every triangle below the child is on, or [`NO_ONE_FLAT`].
    flat: [u32; WIDTH],
    /// Bit `i`: child `i` exists.
    occupied: u32,
}

impl WideNode {
    fn empty() -> Self {
        WideNode {
            lo: [[f32::INFINITY; WIDTH]; 3],
            hi: [[f32::NEG_INFINITY; WIDTH]; 3],
            child: [0; WIDTH],
            flat: [NO_ONE_FLAT; WIDTH],
            occupied: 0,
        }
    }
}

/// Up to [`BLOCK`] triangles of a leaf as structure of arrays, tested against a ray at once.
#[derive(Clone, Debug)]
#[repr(C, align(32))]
struct TriBlock {
    /// `v[corner][axis][lane]`.
    v: [[[f32; BLOCK]; 3]; 3],
    /// Each lane's flat surface.
    flat: [u32; BLOCK],
    /// The scene's index of each lane's triangle.
    original: [u32; BLOCK],
    /// Lanes in use (from the first).
    count: u32,
    /// Whether the next block belongs to the same leaf.
    more: bool,
}

/// The 8-wide hierarchy: its nodes, and its leaves' triangles in blocks (a leaf child names
/// its first block; its blocks follow one another).
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
    /// The flat surface it leaves ([`SKIP_NOTHING`] for none) and the triangle it skips
    /// (`u32::MAX` for none).
    pub skip_flat: u32,
    pub skip_triangle: u32,
}

impl WideRay {
    /// The traversal's constants of a ray: the watertight shear and the box test's
    /// reciprocals (obvhs's `safe_inverse`), their six divisions done as one lane loop
    /// (compiled inside [`crate::cpu_features::widest`]: one vector division; the same
    /// quotients, so the same bits as [`WatertightRay::new`] and `safe_inverse`).
    #[inline(always)]
    pub fn new(
        origin: glam::Vec3,
        dir: glam::Vec3,
        t_min: f32,
        t_max: f32,
        skip_flat: Option<usize>,
        skip_triangle: Option<usize>,
    ) -> Self {
        let d = dir.to_array();
        let (code, [px, py], dz) = shear_operands_branch_free(d);
        // safe_inverse(x): sign(x) / ε where |x| ≤ ε, else 1 / x.
        let small = d.map(|x| x.abs() <= f32::EPSILON);
        let num = [
            px,
            py,
            1.0,
            if small[0] { d[0].signum() } else { 1.0 },
            if small[1] { d[1].signum() } else { 1.0 },
            if small[2] { d[2].signum() } else { 1.0 },
            1.0,
            1.0,
        ];
        let den = [
            dz,
            dz,
            dz,
            if small[0] { f32::EPSILON } else { d[0] },
            if small[1] { f32::EPSILON } else { d[1] },
            if small[2] { f32::EPSILON } else { d[2] },
            1.0,
            1.0,
        ];
        let mut q = [0.0f32; 8];
        for i in 0..8 {
            q[i] = num[i] / den[i];
        }
        WideRay {
            wt: WatertightRay::from_shear(origin, code, [q[0], q[1], q[2]]),
            origin: origin.to_array(),
            inv: [q[3], q[4], q[5]],
            t_min,
            t_max,
            skip_flat: skip_flat.map_or(SKIP_NOTHING, |m| m as u32),
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
        let flats = binary_flats(bvh, slots);
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
                node.flat[i] = flats[c];
                node.occupied |= 1 << i;
                if b[c].is_leaf() {
                    let first = b[c].first_index as usize;
                    let count = b[c].prim_count as usize;
                    node.child[i] = LEAF | blocks.len() as u32;
                    let slots_of_leaf = (first..first + count).collect::<Vec<_>>();
                    let chunks = slots_of_leaf.chunks(BLOCK);
                    let last = chunks.len() - 1;
                    for (k, chunk) in chunks.enumerate() {
                        let mut block = TriBlock {
                            v: [[[0.0; BLOCK]; 3]; 3],
                            flat: [NO_ONE_FLAT; BLOCK],
                            original: [u32::MAX; BLOCK],
                            count: chunk.len() as u32,
                            more: k < last,
                        };
                        for (lane, &slot) in chunk.iter().enumerate() {
                            for (corner, v) in slots[slot].v.iter().enumerate() {
                                for (axis, x) in v.to_array().into_iter().enumerate() {
                                    block.v[corner][axis][lane] = x;
                                }
                            }
                            block.flat[lane] = slots[slot].flat;
                            block.original[lane] = original[slot];
                        }
                        blocks.push(block);
                    }
                } else {
                    let child = nodes.len();
                    nodes[wi].child[i] = child as u32;
                    nodes.push(WideNode::empty());
                    todo.push((c, child, depth + 1));
                }
            }
        }
        let fits = (WIDTH - 1) * deepest < STACK && blocks.len() < LEAF as usize;
        fits.then_some(WideBvh { nodes, blocks })
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
        let mut far = [0.0f32; WIDTH];
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
            far[i] = min(f, best);
        }
        let meets = lane_bits::<WIDTH>(|i| (near[i] <= far[i]) & (node.flat[i] != ray.skip_flat));
        (meets & node.occupied, near)
    }

    /// The closest hit with `t` in `[t_min, t_max]`, skipping the ray's flat surface and triangle:
    /// `(t, triangle)` in the scene's numbering, of equally distant hits the lowest triangle.
    /// `ANY_HIT`: the first hit found with `t < t_max` instead (its `t` is not the closest).
    /// The ray's axis permutation is `A` (the watertight test's, [`WatertightRay::axes`]).
    #[inline(always)]
    pub(super) fn trace<A: Axes, const ANY_HIT: bool>(&self, ray: &WideRay) -> Option<(f32, u32)> {
        let mut walk = Walk::<A, ANY_HIT>::new(ray);
        while !self.nodes.is_empty() && walk.step(self) {}
        walk.answer()
    }

    /// [`WideBvh::trace`] of two rays at once, a node or leaf of each in turn: the two
    /// traversals have no data in common, so the processor overlaps one's waits (loads,
    /// divisions, the box tests' chains) with the other's work. Their axis permutations
    /// are read at run time ([`RunTimeAxes`]); the same answers.
    #[inline(always)]
    pub(super) fn trace_pair<const ANY_HIT: bool>(
        &self,
        rays: [&WideRay; 2],
    ) -> [Option<(f32, u32)>; 2] {
        let mut a = Walk::<RunTimeAxes, ANY_HIT>::new(rays[0]);
        let mut b = Walk::<RunTimeAxes, ANY_HIT>::new(rays[1]);
        if !self.nodes.is_empty() {
            let (mut more_a, mut more_b) = (true, true);
            while more_a & more_b {
                more_a = a.step(self);
                more_b = b.step(self);
            }
            while more_a {
                more_a = a.step(self);
            }
            while more_b {
                more_b = b.step(self);
            }
        }
        [a.answer(), b.answer()]
    }
}

/// A ray's axis permutation `(kx, ky, kz)` for the watertight test: known when compiling
/// ([`ConstAxes`], one traversal per permutation) or read from the ray ([`RunTimeAxes`]).
pub(super) trait Axes {
    fn of(ray: &WideRay) -> (usize, usize, usize);
    /// The scalar watertight test with these axes ([`WatertightRay::intersect_axes`] or
    /// [`WatertightRay::intersect`]: the same arithmetic).
    fn intersect(ray: &WideRay, v: [glam::Vec3; 3], t_min: f32, t_max: f32) -> f32;
}

/// Axes fixed at compile time.
pub(super) struct ConstAxes<const KX: usize, const KY: usize, const KZ: usize>;

impl<const KX: usize, const KY: usize, const KZ: usize> Axes for ConstAxes<KX, KY, KZ> {
    #[inline(always)]
    fn of(_: &WideRay) -> (usize, usize, usize) {
        (KX, KY, KZ)
    }

    #[inline(always)]
    fn intersect(ray: &WideRay, [a, b, c]: [glam::Vec3; 3], t_min: f32, t_max: f32) -> f32 {
        ray.wt.intersect_axes::<KX, KY, KZ>(a, b, c, t_min, t_max)
    }
}

/// The ray's own axes, read at run time.
pub(super) struct RunTimeAxes;

impl Axes for RunTimeAxes {
    #[inline(always)]
    fn of(ray: &WideRay) -> (usize, usize, usize) {
        ray.wt.axes()
    }

    #[inline(always)]
    fn intersect(ray: &WideRay, [a, b, c]: [glam::Vec3; 3], t_min: f32, t_max: f32) -> f32 {
        ray.wt.intersect(a, b, c, t_min, t_max)
    }
}

/// One ray's traversal, a node or a leaf per [`Walk::step`]: the entry being visited is held
/// apart from the stack (`current`: a child is pushed only to be popped).
struct Walk<'r, A, const ANY_HIT: bool> {
    ray: &'r WideRay,
    best: f32,
    /// The scene's index of the closest triangle so far (u32::MAX: none).
    best_triangle: u32,
    /// `ANY_HIT`: a hit was found (the answer).
    found: Option<(f32, u32)>,
    /// Not initialised: entries below `sp` are written before they are read (zeroing the
    /// stack per query measured as a tenth of the traversal).
    stack: [std::mem::MaybeUninit<Entry>; STACK],
    sp: usize,
    current: Entry,
    axes: std::marker::PhantomData<A>,
}

impl<'r, A: Axes, const ANY_HIT: bool> Walk<'r, A, ANY_HIT> {
    #[inline(always)]
    fn new(ray: &'r WideRay) -> Self {
        Walk {
            ray,
            best: ray.t_max,
            best_triangle: u32::MAX,
            found: None,
            stack: [const { std::mem::MaybeUninit::<Entry>::uninit() }; STACK],
            sp: 0,
            current: Entry {
                child: 0,
                near: ray.t_min,
            },
            axes: std::marker::PhantomData,
        }
    }

    /// The answer once [`Walk::step`] has returned false.
    #[inline(always)]
    fn answer(&self) -> Option<(f32, u32)> {
        if ANY_HIT {
            self.found
        } else {
            (self.best_triangle != u32::MAX).then_some((self.best, self.best_triangle))
        }
    }

    /// Visits the current entry (a node: the nearest of its hit children taken next, the
    /// others pushed, farthest first; a leaf: its blocks tested), else takes the next entry
    /// from the stack no farther than the closest hit so far.
    /// False when the traversal is over.
    #[inline(always)]
    fn step(&mut self, bvh: &WideBvh) -> bool {
        let ray = self.ray;
        let current = self.current;
        if current.child & LEAF != 0 {
            let mut b = (current.child & !LEAF) as usize;
            loop {
                let block = &bvh.blocks[b];
                if let Some((t, triangle)) = bvh.block::<A, ANY_HIT>(block, ray, self.best) {
                    if ANY_HIT {
                        // `occluded`'s answer: a hit at t_min ≤ t < t_max (the block
                        // answers only such hits in this mode).
                        debug_assert!(t < ray.t_max);
                        self.found = Some((t, triangle));
                        return false;
                    } else {
                        // As the binary hierarchy's traversal: a hit at exactly t_max counts
                        // only as a tie with an earlier one.
                        let tie = (t == self.best)
                            & (self.best_triangle != u32::MAX)
                            & (triangle < self.best_triangle);
                        if (t < self.best) | tie {
                            self.best = t;
                            self.best_triangle = triangle;
                        }
                    }
                }
                if !block.more {
                    break;
                }
                b += 1;
            }
        } else {
            let node = &bvh.nodes[current.child as usize];
            let (mut bits, near) = bvh.meets(node, ray, self.best);
            // One or two children hit (77 % of the inner nodes `path`'s scattered rays visit
            // on `mirror_room`, 15 % none): the nearer is visited next without going through
            // the stack, the farther written to its top and kept only where there are two, all
            // without a branch on which case it is (the insertion loop's exit was its most
            // mispredicted branch). Of equally near children the later one goes first, as the
            // insertion below orders them; the answer does not depend on the order.
            let rest = bits & bits.wrapping_sub(1);
            if bits != 0 && rest & rest.wrapping_sub(1) == 0 {
                let i0 = bits.trailing_zeros() as usize;
                let i1 = if rest != 0 {
                    rest.trailing_zeros() as usize
                } else {
                    i0
                };
                let at = |i: usize| Entry {
                    child: node.child[i],
                    near: near[i],
                };
                let (e0, e1) = (at(i0), at(i1));
                // Which is nearer is a coin toss: a select, never a branch (LLVM had turned
                // this one into a branch around a register move; `path` ×0.986–×0.991 /
                // ×0.996–×0.997 on `mirror_room` / `mirror_box` in one process, issue 56's
                // twelfth session).
                let swap = e1.near <= e0.near;
                let nearer = std::hint::select_unpredictable(swap, e1, e0);
                let farther = std::hint::select_unpredictable(swap, e0, e1);
                // SAFETY: sp < STACK, as for the pushes below.
                unsafe { self.stack.get_unchecked_mut(self.sp).write(farther) };
                self.sp += usize::from(rest != 0);
                self.current = nearer;
                return true;
            }
            // Push the hit children farthest first, so the nearest is popped next: an
            // insertion into the stack's top, which holds at most WIDTH entries of this node.
            // (Measured on `mirror_room`'s scattered rays against pushing them in index
            // order: no different; against placing them by rank without this loop: slower.)
            // An any-hit query pushes them in index order: any hit answers it, and the
            // sorting's branches cost more than the order saves (the `ray_sets` any-hit
            // batches ×0.94 / ×0.87 on `mirror_box` / `mirror_room`).
            let base = self.sp;
            let stack = &mut self.stack;
            while bits != 0 {
                let i = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let entry = Entry {
                    child: node.child[i],
                    near: near[i],
                };
                let mut j = self.sp;
                // SAFETY: entries base..sp were written by this loop; sp < STACK, as a level
                // pushes at most WIDTH − 1 entries beyond the one popped and the hierarchy is
                // shallow enough for that ([`WideBvh::from_bvh2`]).
                unsafe {
                    while !ANY_HIT
                        && j > base
                        && stack.get_unchecked(j - 1).assume_init().near < entry.near
                    {
                        *stack.get_unchecked_mut(j) = *stack.get_unchecked(j - 1);
                        j -= 1;
                    }
                    stack.get_unchecked_mut(j).write(entry);
                }
                self.sp += 1;
            }
        }
        loop {
            if self.sp == 0 {
                return false;
            }
            self.sp -= 1;
            // SAFETY: every entry below `sp` was written (a push writes at or below `sp` and
            // then raises it; a pop lowers it).
            let entry = unsafe { self.stack.get_unchecked(self.sp).assume_init() };
            if entry.near <= self.best {
                self.current = entry;
                return true;
            }
        }
    }
}

impl WideBvh {
    /// The watertight test of `ray` against a block's triangles at once, with `t` in
    /// `[t_min, best]`: the closest `(t, triangle)`, of equally distant ones the lowest
    /// triangle. Each lane computes the scalar test's arithmetic
    /// ([`WatertightRay::intersect_axes`]) operation for operation, so the same bits; a lane
    /// with an exact zero edge function is finished by the scalar test (its f64
    /// re-evaluation). Lanes beyond the block's count, on the flat surface the ray leaves or on the
    /// triangle it skips take no part. With `ANY_HIT`: some hit with `t < ray.t_max` (the
    /// first such lane, else the first exact-zero lane the scalar test confirms), or none.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)]
    fn block<A: Axes, const ANY_HIT: bool>(
        &self,
        b: &TriBlock,
        ray: &WideRay,
        best: f32,
    ) -> Option<(f32, u32)> {
        let o = ray.origin;
        let [sx, sy, sz] = ray.wt.shear();
        let (kx, ky, kz) = A::of(ray);
        let mut t = [f32::INFINITY; BLOCK];
        let mut zero = 0u32;
        for i in 0..BLOCK {
            let d = |corner: usize, k: usize| b.v[corner][k][i] - o[k];
            let (a_x, a_y, a_z) = (d(0, kx), d(0, ky), d(0, kz));
            let (b_x, b_y, b_z) = (d(1, kx), d(1, ky), d(1, kz));
            let (c_x, c_y, c_z) = (d(2, kx), d(2, ky), d(2, kz));
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
                & (b.flat[i] != ray.skip_flat)
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
        // An exact-zero lane's distance by the scalar test.
        let scalar = |i: usize| {
            let corner = |c: usize| glam::Vec3::new(b.v[c][0][i], b.v[c][1][i], b.v[c][2][i]);
            A::intersect(ray, [corner(0), corner(1), corner(2)], ray.t_min, best)
        };
        if ANY_HIT {
            // Any lane nearer than the ray's end answers (which one does not matter).
            let blocking = lane_bits::<BLOCK>(|i| t[i] < ray.t_max);
            if blocking == 0 {
                while zero != 0 {
                    let i = zero.trailing_zeros() as usize;
                    zero &= zero - 1;
                    let ti = scalar(i);
                    if ti < ray.t_max {
                        return Some((ti, b.original[i]));
                    }
                }
                return None;
            }
            let i = blocking.trailing_zeros() as usize;
            return Some((t[i], b.original[i]));
        }
        // No lane or one lane hit (nearly every block a ray meets): that lane, without a
        // reduction over the lanes; exact-zero lanes are finished by the scalar test as
        // below. (Against every block building all its lanes' keys and their minimum: `path`
        // ×0.976–×0.990 on `mirror_room`, ×0.994–×1.003 on `mirror_box` in one process, 1.0 %
        // fewer instructions; issue 56's twelfth session.)
        let found = lane_bits::<BLOCK>(|i| t[i] < f32::INFINITY);
        if found & found.wrapping_sub(1) == 0 {
            let mut hit = (found != 0).then(|| {
                let i = found.trailing_zeros() as usize;
                (t[i], b.original[i])
            });
            while zero != 0 {
                let i = zero.trailing_zeros() as usize;
                zero &= zero - 1;
                keep(&mut hit, scalar(i), b.original[i]);
            }
            return hit;
        }
        // The closest of several lanes, of equally distant ones the lowest triangle: each
        // lane as one integer ordered as (t, triangle), whose minimum is a reduction the
        // compiler vectorises (a float one it leaves a serial chain).
        let mut nearest = u64::MAX;
        for i in 0..BLOCK {
            let key = if t[i] < f32::INFINITY {
                (u64::from(ordered_bits(t[i])) << 32) | u64::from(b.original[i])
            } else {
                u64::MAX
            };
            nearest = nearest.min(key);
        }
        let mut hit = (nearest != u64::MAX)
            .then(|| (from_ordered_bits((nearest >> 32) as u32), nearest as u32));
        // The keys order −0 before +0, which the float comparisons tie: a hit at distance
        // zero is decided lane by lane, as the scalar test's answers are compared.
        if hit.is_some_and(|(t, _)| t == 0.0) {
            hit = None;
            for i in 0..b.count as usize {
                keep(&mut hit, t[i], b.original[i]);
            }
        }
        while zero != 0 {
            let i = zero.trailing_zeros() as usize;
            zero &= zero - 1;
            keep(&mut hit, scalar(i), b.original[i]);
        }
        hit
    }
}

/// A stack entry: a child as [`WideNode::child`] names it, with the distance at which the
/// ray enters its box. Eight-byte aligned, so that it is copied as one word and never across
/// a cache line (docs/tracer-performance.md, issue 56's eleventh session).
#[derive(Clone, Copy)]
#[repr(C, align(8))]
struct Entry {
    child: u32,
    near: f32,
}

/// `(ti, triangle)` into `hit` if it is a hit nearer than `hit`'s, or as near and of a lower
/// triangle.
#[inline(always)]
fn keep(hit: &mut Option<(f32, u32)>, ti: f32, triangle: u32) {
    let better = match *hit {
        None => ti.is_finite(),
        Some((bt, btri)) => (ti < bt) | ((ti == bt) & (triangle < btri)),
    };
    if better {
        *hit = Some((ti, triangle));
    }
}

/// `x`'s bits mapped so that unsigned integer order is the order of the floats (−0 just
/// before +0; NaN aside).
#[inline(always)]
fn ordered_bits(x: f32) -> u32 {
    let bits = x.to_bits();
    if bits >> 31 == 1 {
        !bits
    } else {
        bits | 1 << 31
    }
}

/// The float of [`ordered_bits`].
#[inline(always)]
fn from_ordered_bits(bits: u32) -> f32 {
    f32::from_bits(if bits >> 31 == 1 {
        bits & !(1 << 31)
    } else {
        !bits
    })
}

#[inline(always)]
fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

#[inline(always)]
fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// Per binary node, the flat surface all triangles below it are on, or [`NO_ONE_FLAT`]: children
/// before parents (a pre-order walk, reversed), without recursion (hierarchies may be deep).
fn binary_flats(bvh: &obvhs::bvh2::Bvh2, slots: &[Slot]) -> Vec<u32> {
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
    let mut flat = vec![NO_ONE_FLAT; b.len()];
    for &i in order.iter().rev() {
        flat[i] = if b[i].is_leaf() {
            let range = b[i].first_index as usize..(b[i].first_index + b[i].prim_count) as usize;
            let first = slots[range.start].flat;
            if slots[range].iter().all(|s| s.flat == first) {
                first
            } else {
                NO_ONE_FLAT
            }
        } else {
            let first = b[i].first_index as usize;
            if flat[first] == flat[first + 1] {
                flat[first]
            } else {
                NO_ONE_FLAT
            }
        };
    }
    flat
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// One leaf block of `triangles`, lane `i` numbered `original[i]`, on no one flat surface.
    fn block_of(triangles: &[[Vec3; 3]], original: &[u32]) -> TriBlock {
        let mut block = TriBlock {
            v: [[[0.0; BLOCK]; 3]; 3],
            flat: [NO_ONE_FLAT; BLOCK],
            original: [u32::MAX; BLOCK],
            count: triangles.len() as u32,
            more: false,
        };
        for (lane, tri) in triangles.iter().enumerate() {
            for (corner, p) in tri.iter().enumerate() {
                for axis in 0..3 {
                    block.v[corner][axis][lane] = p[axis];
                }
            }
            block.original[lane] = original[lane];
        }
        block
    }

    impl WideBvh {
        /// A hierarchy without nodes or blocks, to call [`WideBvh::block`] on.
        fn no_nodes() -> Self {
            WideBvh {
                nodes: Vec::new(),
                blocks: Vec::new(),
            }
        }
    }

    /// A ray through the shared diagonal of a quad's two triangles meets both on an edge
    /// (an exact-zero edge function: the lanes the scalar test finishes), at t = 1. The
    /// any-hit leaf counts it as blocking before the ray's end and not at or beyond it; the
    /// closest-hit leaf finds it up to and at `best`, on the lower triangle (lane 1 here, so
    /// that keeping the first lane would fail).
    #[test]
    fn a_hit_on_a_shared_edge_blocks_an_any_hit_ray() {
        let v = |x: f32, y: f32| Vec3::new(x, y, 0.0);
        let quad = [
            [v(-1.0, -1.0), v(1.0, -1.0), v(1.0, 1.0)],
            [v(-1.0, -1.0), v(1.0, 1.0), v(-1.0, 1.0)],
        ];
        let block = block_of(&quad, &[6, 5]);
        let bvh = WideBvh::no_nodes();
        for (t_max, blocked, found) in [
            (f32::INFINITY, true, true),
            (2.0, true, true),
            (1.0, false, true),
            (0.5, false, false),
        ] {
            let ray = WideRay::new(Vec3::Z, Vec3::NEG_Z, 0.0, t_max, None, None);
            assert_eq!(ray.wt.axes(), (1, 0, 2));
            let any = bvh.block::<ConstAxes<1, 0, 2>, true>(&block, &ray, t_max);
            assert_eq!(any.is_some(), blocked, "any hit to {t_max}");
            let closest = bvh.block::<ConstAxes<1, 0, 2>, false>(&block, &ray, t_max);
            assert_eq!(closest, found.then_some((1.0, 5)), "closest hit to {t_max}");
        }
    }

    /// A hit at distance zero in one leaf, decided as the scalar answers are compared: a ray
    /// from the origin down −z meets, at t = 0, a triangle through the origin (lane 0,
    /// triangle 0) whose watertight distance is +0 (its terms cancel exactly) and one in the
    /// plane z = 0 (lane 1, triangle 1) whose distance is −0. The floats tie, so the lower
    /// triangle wins, with +0; the leaf's integer keys put −0 first and must not decide.
    #[test]
    fn a_hit_at_distance_zero_in_a_leaf_is_decided_as_floats_tie() {
        let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        let tilted = [v(-1.0, -1.0, 1.0), v(1.0, -1.0, -1.0), v(0.0, 1.0, 0.0)];
        let flat = [v(-1.0, -1.0, 0.0), v(1.0, -1.0, 0.0), v(0.0, 1.0, 0.0)];
        let ray = WideRay::new(Vec3::ZERO, Vec3::NEG_Z, 0.0, f32::INFINITY, None, None);
        assert_eq!(ray.wt.axes(), (1, 0, 2));
        // The configuration really gives zeros of both signs.
        let t_of = |t: [Vec3; 3]| ray.wt.intersect(t[0], t[1], t[2], 0.0, f32::INFINITY);
        assert_eq!(t_of(tilted).to_bits(), 0.0f32.to_bits());
        assert_eq!(t_of(flat).to_bits(), (-0.0f32).to_bits());
        let block = block_of(&[tilted, flat], &[0, 1]);
        let bvh = WideBvh::no_nodes();
        let (t, triangle) = bvh
            .block::<ConstAxes<1, 0, 2>, false>(&block, &ray, f32::INFINITY)
            .unwrap();
        assert_eq!((t.to_bits(), triangle), (0.0f32.to_bits(), 0));
    }

    /// A block whose ray meets several of its triangles answers the nearest, of equally
    /// near ones the lowest triangle, wherever their lanes are; with one hit lane, that lane.
    /// Three parallel triangles across a ray down −z at z = 0.5, 0.75 and 0.25 (lanes 0, 1, 2:
    /// the nearest in the middle lane, so that taking the first or last hit lane fails), then
    /// two at the same height (the later lane the lower triangle), then one in front of the
    /// ray and one behind it, then two behind it.
    #[test]
    fn a_block_answers_its_nearest_hit_lane() {
        let at = |z: f32| {
            let v = |x: f32, y: f32| Vec3::new(x, y, z);
            [v(-1.0, -1.0), v(1.0, -1.0), v(0.0, 1.0)]
        };
        let ray = WideRay::new(Vec3::Z, Vec3::NEG_Z, 0.0, f32::INFINITY, None, None);
        let bvh = WideBvh::no_nodes();
        let closest = |triangles: &[[Vec3; 3]], original: &[u32]| {
            let block = block_of(triangles, original);
            bvh.block::<ConstAxes<1, 0, 2>, false>(&block, &ray, f32::INFINITY)
        };
        assert_eq!(
            closest(&[at(0.5), at(0.75), at(0.25)], &[0, 1, 2]),
            Some((0.25, 1))
        );
        assert_eq!(closest(&[at(0.5), at(0.5)], &[7, 3]), Some((0.5, 3)));
        assert_eq!(closest(&[at(2.0), at(0.5)], &[4, 9]), Some((0.5, 9)));
        assert_eq!(closest(&[at(2.0), at(3.0)], &[4, 9]), None);
    }
}
