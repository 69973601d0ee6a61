//! The recursion of the seed paper's Algorithm 1, planned on the CPU before any GPU work.
//!
//! `MIRRORTEXTURE(M)` renders the scene from M's mirror camera (the current view composed with
//! M's reflection, seed 002) with M hidden, and first recurses into every mirror visible from
//! that camera: not hidden, facing the camera, and inside its view — its polygon survives
//! clipping by the camera's frustum and by M's plane (which clips M's world). A mirror stays
//! hidden for the whole of its own recursion, so along one chain every mirror is used once.
//!
//! - `naive` (Algorithm 1 as printed): the queue is the scene's mirrors. Two facing mirrors
//!   A, B seen through A give the chain A → B and stop (A is hidden inside B's recursion):
//!   exactly two reflections, the paper's Figure 2.
//! - `auxiliary` (§3.1): n auxiliary mirrors coincide with real ones, alternating sides by
//!   label parity, so chains can use a mirror again. With two mirrors (the paper's setting)
//!   odd labels lie on Mirror 1, the one the viewer looks into, even on Mirror 2: the queue
//!   holds n + 2 mirrors and chains reach n + 2 reflections. With more mirrors every mirror
//!   pairs with its [`partner`] — the mirror it faces most directly — and each pair gets the
//!   paper's n auxiliary mirrors, odd labels on the pair's Mirror 1 (the one the camera sees
//!   larger, [`seen_directly`]; the first in scene order on a tie), even on the other, so
//!   mirror i holds ⌈n/2⌉ or ⌊n/2⌋ copies ([`auxiliary_copies`]). Each instance hides only
//!   itself, so every camera recurses into *every* unhidden instance it sees.
//!
//! **Pass count.** One scene pass for the frame plus one per `MIRRORTEXTURE` call. Coincident
//! instances see the same things, so the calls are counted over chains of mirror *planes*
//! (consecutive planes distinct, each visible from the camera reflected in the previous
//! ones, mirror i used at most c_i + 1 times for its c_i copies): a chain that has used
//! mirror j t times continues into j in c_j + 1 − t ways, so the calls along one plane chain
//! are the product of those counts. For two facing mirrors, with a instances on the side
//! the camera sees and b on the other (a = 1 + ⌈n/2⌉, b = 1 + ⌊n/2⌋ when it looks into
//! mirror 1), there is one plane chain per length and the sum is a + a·b + a·b·(a−1) +
//! a·b·(a−1)·(b−1) + …: 3, 7, 15, 46, 139 passes for n = 0…4 on `mirror_box`. The growth is
//! factorial; the paper's Table 1 (25, 61, 142, 435, 1330 ms) gives no pass counts, and
//! divided by these counts (assuming its recursion is this one) it is 8.3–9.6 ms per pass. Counting visits each plane chain once and
//! stops after `--max-passes` of them, so a refusal costs at most that many visibility
//! tests, however large the plan.

use glam::{Mat4, Vec2};
use mirrorbox_scene::polygon::{clip_by, screen_footprint};
use mirrorbox_scene::reflection::ReflectedView;
use mirrorbox_scene::{Plane, Scene};

/// Plans are counted exactly up to this many texture renders (when that takes at most
/// `--max-passes` plane chains).
const COUNT_CEILING: usize = 1_000_000;

/// The rendering queue of the paper's recursion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Queue {
    /// `naive`: the scene's mirrors.
    SceneMirrors,
    /// `auxiliary`: the real mirrors and, for each mirror and its [`partner`], n auxiliary
    /// copies alternating between the two ([`auxiliary_copies`]).
    Auxiliary { n: u32 },
}

/// One mirror of the rendering queue: a real mirror or an auxiliary copy of one.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MirrorInstance {
    /// Index of the scene mirror whose surface it occupies.
    pub mirror: usize,
    /// The paper's label: "mirror 1", "mirror 2", "auxiliary 1", ...
    pub label: String,
}

pub use crate::culling::Rect;

/// One `MIRRORTEXTURE` call.
#[derive(Clone, Debug)]
pub struct TextureNode {
    pub instance: usize,
    /// The mirror camera: the parent's view composed with this mirror's reflection.
    pub view: ReflectedView,
    /// The mirror's plane (front kept): this pass clips its world to the front.
    pub plane: Plane,
    /// Screen region the texture covers (the mirror's footprint, 1-pixel margin).
    pub footprint: Rect,
    /// Instances hidden in this pass: this one and its ancestors.
    pub hidden: Vec<usize>,
    /// Textures this pass applies, rendered before it.
    pub children: Vec<TextureNode>,
}

#[derive(Clone, Debug)]
pub struct Plan {
    pub instances: Vec<MirrorInstance>,
    /// Render resolution (output × SSAA).
    pub width: u32,
    pub height: u32,
    /// The camera's projection ([`crate::projection::camera_projection`]).
    pub projection: Mat4,
    /// Textures the frame's main pass applies.
    pub roots: Vec<TextureNode>,
    /// Scene passes per frame: 1 + number of texture renders.
    pub passes: usize,
    /// Deepest chain of textures (reflections the method can show).
    pub depth: usize,
}

#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum PlanError {
    #[error(
        "auxiliary mirrors alternate between a mirror and the one it faces, so --n above 0 needs at least 2 mirrors; the scene has {0}"
    )]
    NoMirrorToAlternateWith(usize),
    #[error(
        "more than {limit} reflection paths are visible: raise --min-portal-area (pixels²) or --min-attenuation, or lower --depth"
    )]
    TooManyPaths { limit: usize },
    #[error(
        "this frame would draw {triangles} triangles, above the limit of {limit}: raise --min-portal-area or --min-attenuation, or lower --depth"
    )]
    TooManyTriangles { triangles: usize, limit: usize },
    #[error(
        "this configuration would render {predicted}{} scene passes per frame, above --max-passes {limit}",
        if *.exceeded_count { " or more" } else { "" }
    )]
    TooManyPasses {
        predicted: usize,
        limit: usize,
        exceeded_count: bool,
    },
    #[error(
        "the reflection tree branches {0} levels deep with siblings pending; the 8-bit stencil of --method portal allows 254: lower --depth or use --method unrolled"
    )]
    StencilTooDeep(u32),
    #[error(
        "this frame would submit {triangles} triangles ({copies} copies of the objects' {per_copy}), above the limit of {limit}: use --method symmetry-pruned (drops copies that cannot be seen) or symmetry-baked, or fewer symmetry planes"
    )]
    TooManyCopyTriangles {
        triangles: usize,
        copies: usize,
        per_copy: usize,
        limit: usize,
    },
    #[error("{planes} symmetry planes, the symmetry methods' shaders take at most {limit}")]
    TooManySymmetryPlanes { planes: usize, limit: usize },
    /// `symmetry-baked`'s split-and-mirror refused (too many triangles, a reflected vertex
    /// outside the scene extent).
    #[error("the split-and-mirror bake: {0}")]
    Bake(String),
    /// `--shadows map` would need more layers than the shadow-map budget.
    #[error(transparent)]
    ShadowMaps(#[from] crate::shadow_plan::TooManyShadowLayers),
    /// A render setting out of range (`--ssaa`, `--frames`, `--warmup`, the render size).
    #[error(transparent)]
    Setting(#[from] mirrorbox_scene::limits::SettingError),
    /// The plan's memory estimate exceeds `--memory-budget` ([`crate::memory`]).
    #[error(transparent)]
    OverMemoryBudget(Box<crate::memory::OverMemoryBudget>),
}

impl From<crate::memory::OverMemoryBudget> for PlanError {
    fn from(e: crate::memory::OverMemoryBudget) -> Self {
        PlanError::OverMemoryBudget(Box::new(e))
    }
}

/// The mirror whose copies alternate with mirror `i`'s (§3.1: "an auxiliary mirror at the
/// other side opposite to the previous one"): among the mirrors `i` faces — each one's centre
/// in front of the other's plane — the one whose normal is most opposed to `i`'s (the first
/// in scene order on a tie); if it faces none, the most opposed of all. `None` for a lone
/// mirror. Of two mirrors each is the other's partner, facing or not (the paper's setting).
pub fn partner(scene: &Scene, i: usize) -> Option<usize> {
    let me = &scene.mirrors[i];
    let faces = |j: usize| {
        let other = &scene.mirrors[j];
        me.plane().signed_distance(other.center) > 0.0
            && other.plane().signed_distance(me.center) > 0.0
    };
    let others: Vec<usize> = (0..scene.mirrors.len()).filter(|&j| j != i).collect();
    let facing: Vec<usize> = others.iter().copied().filter(|&j| faces(j)).collect();
    let candidates = if facing.is_empty() { others } else { facing };
    candidates.into_iter().min_by(|&a, &b| {
        let opposed = |j: usize| me.normal.dot(scene.mirrors[j].normal);
        opposed(a).total_cmp(&opposed(b))
    })
}

/// The scene's mirrors as instances, in scene order: "mirror 1", "mirror 2", …
fn scene_mirrors(scene: &Scene) -> Vec<MirrorInstance> {
    (0..scene.mirrors.len())
        .map(|i| MirrorInstance {
            mirror: i,
            label: format!("mirror {}", i + 1),
        })
        .collect()
}

/// Each scene mirror's footprint seen directly from the camera: the area in pixels of the
/// screen rectangle bounding it (not occlusion-tested; 0 where the camera does not see it):
/// which mirror of a pair the viewer looks into.
pub fn seen_directly(scene: &Scene, width: u32, height: u32) -> Vec<u64> {
    let mirrors = scene_mirrors(scene);
    let planner = Planner::new(scene, &mirrors, width, height);
    let mut area = vec![0; scene.mirrors.len()];
    for (i, rect) in planner.visible(&planner.main_view(width, height), None, &[]) {
        area[i] = u64::from(rect.w) * u64::from(rect.h);
    }
    area
}

/// Whether the paper's auxiliary label `k` (1…n) of mirror `i`'s pair lies on `i`: odd labels
/// on the pair's "Mirror 1", even ones on the other. Mirror 1 is the one the viewer looks
/// into (§2: "the texture of Mirror 1 is given by an auxiliary camera looking out of it";
/// each auxiliary goes "at the other side opposite to the previous one"): of the two, the one
/// with the larger footprint `seen` from the camera ([`seen_directly`]), the first in scene
/// order where they tie. By scene order alone, a camera looking into a pair's second mirror
/// had got n + 1 reflections for odd n (n = 1 the same image as `naive`).
fn label_lies_on(scene: &Scene, seen: &[u64], i: usize, k: u32) -> bool {
    let first = partner(scene, i).is_some_and(|p| match seen[i].cmp(&seen[p]) {
        std::cmp::Ordering::Equal => i < p,
        larger => larger == std::cmp::Ordering::Greater,
    });
    (k % 2 == 1) == first
}

/// Auxiliary copies of each scene mirror for `n` auxiliary mirrors per pair, the camera's
/// footprints `seen` ([`seen_directly`]): ⌈n/2⌉ on a pair's Mirror 1, ⌊n/2⌋ on the other
/// (none on a lone mirror).
pub fn auxiliary_copies(scene: &Scene, seen: &[u64], n: u32) -> Vec<u32> {
    (0..scene.mirrors.len())
        .map(|i| {
            if partner(scene, i).is_none() {
                0
            } else {
                (1..=n)
                    .filter(|&k| label_lies_on(scene, seen, i, k))
                    .count() as u32
            }
        })
        .collect()
}

/// The rendering queue of a method: the scene's mirrors, then (`auxiliary`) the copies by
/// label, each label's in scene order — for two mirrors "auxiliary 1" on the paper's Mirror 1
/// (the one the camera looks into, [`label_lies_on`]), "auxiliary 2" on Mirror 2, … as in the
/// paper.
pub fn instances(
    scene: &Scene,
    queue: Queue,
    width: u32,
    height: u32,
) -> Result<Vec<MirrorInstance>, PlanError> {
    let mut instances = scene_mirrors(scene);
    if let Queue::Auxiliary { n } = queue {
        if n > 0 && scene.mirrors.len() < 2 {
            return Err(PlanError::NoMirrorToAlternateWith(scene.mirrors.len()));
        }
        let seen = seen_directly(scene, width, height);
        for k in 1..=n {
            for mirror in 0..scene.mirrors.len() {
                if label_lies_on(scene, &seen, mirror, k) {
                    instances.push(MirrorInstance {
                        mirror,
                        label: format!("auxiliary {k}"),
                    });
                }
            }
        }
    }
    Ok(instances)
}

/// A running count of texture renders over plane chains (see the module docs).
struct Tally {
    /// Texture renders counted so far (saturating).
    renders: usize,
    /// Plane chains visited so far.
    chains: usize,
    /// Stop after this many chains …
    max_chains: usize,
    /// … or this many renders.
    max_renders: usize,
}

impl Tally {
    fn stopped(&self) -> bool {
        self.chains > self.max_chains || self.renders > self.max_renders
    }
}

struct Planner<'a> {
    scene: &'a Scene,
    instances: &'a [MirrorInstance],
    /// Instances of each scene mirror (1 + its auxiliary copies).
    per_mirror: Vec<usize>,
    projection: Mat4,
    size: Vec2,
}

impl Planner<'_> {
    /// Instances visible from `view` (see the module docs), with their footprints.
    fn visible(
        &self,
        view: &ReflectedView,
        near: Option<&Plane>,
        hidden: &[usize],
    ) -> Vec<(usize, Rect)> {
        (0..self.instances.len())
            .filter(|i| !hidden.contains(i))
            .filter_map(|i| Some((i, self.footprint(self.instances[i].mirror, view, near)?)))
            .collect()
    }

    /// Mirror `mirror`'s footprint seen from `view` (clipped by the near plane), if it is a
    /// mirror from there: facing the eye and inside the view.
    fn footprint(&self, mirror: usize, view: &ReflectedView, near: Option<&Plane>) -> Option<Rect> {
        let mirror = &self.scene.mirrors[mirror];
        if mirror.plane().signed_distance(view.eye()) <= 0.0 {
            return None; // seen from behind (or edge-on): not a mirror from here
        }
        let mut poly = mirror.corners().to_vec();
        if let Some(plane) = near {
            poly = clip_by(&poly, |p| plane.signed_distance(p));
        }
        let clip_from_world = self.projection * view.view;
        bounding_rect(
            &screen_footprint(&poly, clip_from_world, self.size),
            self.size,
        )
    }

    fn node(
        &self,
        parent: &ReflectedView,
        instance: usize,
        footprint: Rect,
        hidden: &[usize],
    ) -> TextureNode {
        let plane = self.scene.mirrors[self.instances[instance].mirror].plane();
        let view = parent.through(&plane);
        let mut hidden = hidden.to_vec();
        hidden.push(instance);
        let children = self
            .visible(&view, Some(&plane), &hidden)
            .into_iter()
            .map(|(i, rect)| self.node(&view, i, rect, &hidden))
            .collect();
        TextureNode {
            instance,
            view,
            plane,
            footprint,
            hidden,
            children,
        }
    }

    /// Adds to `tally` the texture renders below `view`, reached through `ways` instance
    /// chains, where mirror j has been used `used[j]` times: each visible mirror with an
    /// instance left is one more plane chain, continued in (instances − used) ways.
    fn count(
        &self,
        view: &ReflectedView,
        near: Option<&Plane>,
        used: &mut [usize],
        ways: usize,
        tally: &mut Tally,
    ) {
        for mirror in 0..self.scene.mirrors.len() {
            let left = self.per_mirror[mirror] - used[mirror];
            if left == 0 || self.footprint(mirror, view, near).is_none() {
                continue;
            }
            let ways = ways.saturating_mul(left);
            tally.chains += 1;
            tally.renders = tally.renders.saturating_add(ways);
            if tally.stopped() {
                return;
            }
            let plane = self.scene.mirrors[mirror].plane();
            used[mirror] += 1;
            self.count(&view.through(&plane), Some(&plane), used, ways, tally);
            used[mirror] -= 1;
            if tally.stopped() {
                return;
            }
        }
    }
}

fn bounding_rect(poly: &[Vec2], size: Vec2) -> Option<Rect> {
    if poly.len() < 3 {
        return None;
    }
    let lo = poly
        .iter()
        .fold(Vec2::splat(f32::INFINITY), |a, p| a.min(*p));
    let hi = poly
        .iter()
        .fold(Vec2::splat(f32::NEG_INFINITY), |a, p| a.max(*p));
    crate::culling::footprint_rect(lo, hi, size)
}

fn depth(nodes: &[TextureNode]) -> usize {
    nodes
        .iter()
        .map(|n| 1 + depth(&n.children))
        .max()
        .unwrap_or(0)
}

/// Scene passes per frame of a plan, counted over plane chains (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassCount {
    /// 1 + the texture renders: exact when `exact`, else a lower bound above the limit.
    pub passes: usize,
    pub exact: bool,
    /// Plane chains visited to count them (each needs one visibility test per mirror): at
    /// most `max_passes + 1`, however large the plan.
    pub chains_visited: usize,
}

impl<'a> Planner<'a> {
    fn new(scene: &'a Scene, instances: &'a [MirrorInstance], width: u32, height: u32) -> Self {
        let mut per_mirror = vec![0; scene.mirrors.len()];
        for inst in instances {
            per_mirror[inst.mirror] += 1;
        }
        Planner {
            scene,
            instances,
            per_mirror,
            projection: crate::projection::camera_projection(
                &scene.camera.with_size(width, height),
                width,
                height,
            ),
            size: Vec2::new(width as f32, height as f32),
        }
    }

    fn main_view(&self, width: u32, height: u32) -> ReflectedView {
        ReflectedView::direct(self.scene.camera.with_size(width, height).view())
    }

    /// Counts exactly up to a hard ceiling, so that a refusal can state the predicted count,
    /// but visits at most `max_passes` plane chains: a plan within the limit has no more
    /// (each chain is at least one render), so any plan over it is refused after that many.
    fn count_passes(&self, main: &ReflectedView, max_passes: usize) -> PassCount {
        let mut tally = Tally {
            renders: 0,
            chains: 0,
            max_chains: max_passes,
            max_renders: COUNT_CEILING.max(max_passes),
        };
        let mut used = vec![0; self.scene.mirrors.len()];
        self.count(main, None, &mut used, 1, &mut tally);
        PassCount {
            passes: tally.renders.saturating_add(1),
            exact: !tally.stopped(),
            chains_visited: tally.chains,
        }
    }
}

/// Counts the scene passes per frame of the recursion over `queue` at render resolution
/// `width × height`, without building the plan; stops once it knows there are more than
/// `max_passes`.
pub fn count_passes(
    scene: &Scene,
    queue: Queue,
    width: u32,
    height: u32,
    max_passes: usize,
) -> Result<PassCount, PlanError> {
    let instances = instances(scene, queue, width, height)?;
    let planner = Planner::new(scene, &instances, width, height);
    Ok(planner.count_passes(&planner.main_view(width, height), max_passes))
}

/// Plans a frame of the recursion over `queue` at render resolution `width × height`;
/// refuses, before any work, a plan of more than `max_passes` scene passes.
pub fn plan(
    scene: &Scene,
    queue: Queue,
    width: u32,
    height: u32,
    max_passes: usize,
) -> Result<Plan, PlanError> {
    let instances = instances(scene, queue, width, height)?;
    let planner = Planner::new(scene, &instances, width, height);
    let main = planner.main_view(width, height);
    let count = planner.count_passes(&main, max_passes);
    if !count.exact || count.passes > max_passes {
        return Err(PlanError::TooManyPasses {
            predicted: count.passes,
            limit: max_passes,
            exceeded_count: !count.exact,
        });
    }
    let roots: Vec<TextureNode> = planner
        .visible(&main, None, &[])
        .into_iter()
        .map(|(i, rect)| planner.node(&main, i, rect, &[]))
        .collect();
    let depth = depth(&roots);
    Ok(Plan {
        projection: planner.projection,
        instances,
        width,
        height,
        roots,
        passes: count.passes,
        depth,
    })
}

/// One mirror's camera in a `feedback` frame ([`feedback_cameras`]).
#[derive(Clone, Debug)]
pub struct MirrorCamera {
    /// The scene mirror whose texture it renders.
    pub mirror: usize,
    /// The mirror camera: the view that first sees the mirror, composed with its reflection.
    pub view: ReflectedView,
    /// The mirror's plane (front kept).
    pub plane: Plane,
    /// Screen region of the texture: the mirror's footprint seen from the parent view.
    pub footprint: Rect,
}

/// The cameras of a `feedback` frame: one per mirror the camera can reach, from the view
/// that reaches it first. Breadth first: the mirrors the camera sees (through no mirror),
/// then those seen through one of them, and so on; a mirror seen from several views of the
/// same level takes the one where its footprint is largest (the first in scene order on a
/// tie). A mirror behind the camera (the paper's box, looking into one mirror) is reached
/// through the mirror in front. Mirrors no chain reaches have no camera.
pub fn feedback_cameras(scene: &Scene, width: u32, height: u32) -> (Mat4, Vec<MirrorCamera>) {
    let instances = scene_mirrors(scene);
    let planner = Planner::new(scene, &instances, width, height);
    let mut cameras: Vec<MirrorCamera> = Vec::new();
    let mut frontier: Vec<(ReflectedView, Option<Plane>)> =
        vec![(planner.main_view(width, height), None)];
    while !frontier.is_empty() {
        let mut level: Vec<Option<MirrorCamera>> = vec![None; scene.mirrors.len()];
        for (view, near) in &frontier {
            let reached: Vec<usize> = cameras.iter().map(|c| c.mirror).collect();
            for (mirror, rect) in planner.visible(view, near.as_ref(), &reached) {
                let area = |r: &Rect| u64::from(r.w) * u64::from(r.h);
                if level[mirror]
                    .as_ref()
                    .is_some_and(|c| area(&c.footprint) >= area(&rect))
                {
                    continue;
                }
                let plane = scene.mirrors[mirror].plane();
                level[mirror] = Some(MirrorCamera {
                    mirror,
                    view: view.through(&plane),
                    plane,
                    footprint: rect,
                });
            }
        }
        let new: Vec<MirrorCamera> = level.into_iter().flatten().collect();
        frontier = new.iter().map(|c| (c.view, Some(c.plane))).collect();
        cameras.extend(new);
    }
    (planner.projection, cameras)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_scene::load::bundled_scene as scene;

    /// `path-textures` on the paper's box: one path per depth (the camera sees one mirror,
    /// each reflection the other), each texture inside its parent's; the attenuation cut
    /// ends the chain where the tracer's throughput cut does; a room's branching is refused
    /// by --max-passes with the numbers.
    #[test]
    fn path_textures_plan_one_texture_per_reflection_path() {
        let s = scene("mirror_box.json");
        let limits = |depth| PathTextureLimits {
            depth,
            min_attenuation: 1e-4,
        };
        for depth in [1, 4, 16] {
            let p = plan_path_textures(&s, limits(depth), 320, 180, 5000).unwrap();
            assert_eq!((p.passes, p.depth), (1 + depth as usize, depth as usize));
            let mut node = &p.roots[0];
            while let Some(child) = node.children.first() {
                let (a, b) = (node.footprint, child.footprint);
                assert!(
                    b.x >= a.x && b.y >= a.y && b.x + b.w <= a.x + a.w && b.y + b.h <= a.y + a.h
                );
                assert_ne!(child.instance, node.instance);
                node = child;
            }
        }
        // 0.9^k ≥ 1e-4 up to k = 87: a depth of 1000 stops there.
        let p = plan_path_textures(&s, limits(1000), 320, 180, 5000).unwrap();
        assert_eq!(p.depth, 87);
        let room = scene("mirror_room.json");
        let e = plan_path_textures(&room, limits(64), 320, 180, 5000).unwrap_err();
        assert!(
            matches!(e, PlanError::TooManyPasses { limit: 5000, .. }),
            "{e}"
        );
        // Coloured mirrors: the cut is on the reflectances' product per channel, as the
        // tracer's. A red and a green mirror: red, green, red leaves (1e-3, 1e-6, 1e-9) and
        // one more green 1e-6 < 1e-4, so the paths end at 3 mirrors; the product of each
        // mirror's largest channel (1 · 1 · …) had kept them to the depth limit, 16.
        let mut coloured = s.clone();
        coloured.mirrors[0].reflectance = glam::Vec3::new(1.0, 1e-3, 1e-3);
        coloured.mirrors[1].reflectance = glam::Vec3::new(1e-3, 1.0, 1e-3);
        let p = plan_path_textures(&coloured, limits(16), 320, 180, 5000).unwrap();
        assert_eq!(p.depth, 3);
    }

    /// The pass counts of the paper's auxiliary method on `mirror_box` (see the module docs
    /// for the formula): factorial growth, as in Table 1.
    #[test]
    fn auxiliary_pass_counts_grow_as_the_chains_do() {
        let s = scene("mirror_box.json");
        let passes: Vec<usize> = (0..=4)
            .map(|n| {
                plan(&s, Queue::Auxiliary { n }, 320, 180, 5000)
                    .unwrap()
                    .passes
            })
            .collect();
        assert_eq!(passes, vec![3, 7, 15, 46, 139]);
        let depths: Vec<usize> = (0..=4)
            .map(|n| {
                plan(&s, Queue::Auxiliary { n }, 320, 180, 5000)
                    .unwrap()
                    .depth
            })
            .collect();
        assert_eq!(
            depths,
            vec![2, 3, 4, 5, 6],
            "n auxiliary mirrors give n + 2 reflections"
        );
    }

    #[test]
    fn naive_shows_exactly_two_reflections_between_facing_mirrors() {
        let p = plan(
            &scene("mirror_box.json"),
            Queue::SceneMirrors,
            320,
            180,
            5000,
        )
        .unwrap();
        assert_eq!(p.depth, 2);
        assert_eq!(p.passes, 3);
        assert_eq!(p.roots.len(), 1, "the camera sees one mirror");
        assert_eq!(p.roots[0].children.len(), 1);
        assert!(
            p.roots[0].children[0].children.is_empty(),
            "mirror 1 is hidden inside mirror 2's recursion"
        );
    }

    #[test]
    fn too_many_passes_are_refused_with_the_prediction() {
        let s = scene("mirror_box.json");
        let err = plan(&s, Queue::Auxiliary { n: 4 }, 320, 180, 100).unwrap_err();
        assert!(
            matches!(err, PlanError::TooManyPasses { limit: 100, .. }),
            "{err:?}"
        );
        let exact = plan(&s, Queue::Auxiliary { n: 4 }, 320, 180, 138).unwrap_err();
        assert_eq!(
            exact,
            PlanError::TooManyPasses {
                predicted: 139,
                limit: 138,
                exceeded_count: false
            }
        );
        // n = 7 would need 11 146 passes (the formula of the module docs): refused, with the
        // count, without building the tree.
        assert_eq!(
            plan(&s, Queue::Auxiliary { n: 7 }, 320, 180, 5000).unwrap_err(),
            PlanError::TooManyPasses {
                predicted: 11_146,
                limit: 5000,
                exceeded_count: false
            }
        );
    }

    #[test]
    fn auxiliary_zero_is_the_naive_queue() {
        let s = scene("mirror_box.json");
        let queue = |s: &Scene, queue| instances(s, queue, 320, 180);
        assert_eq!(
            queue(&s, Queue::Auxiliary { n: 0 }).unwrap(),
            queue(&s, Queue::SceneMirrors).unwrap()
        );
        let q = queue(&s, Queue::Auxiliary { n: 3 }).unwrap();
        let sides: Vec<usize> = q.iter().map(|i| i.mirror).collect();
        assert_eq!(sides, vec![0, 1, 0, 1, 0]);
    }

    /// The paper's Mirror 1 is the mirror the viewer looks into, not the scene file's first:
    /// with mirror_box's two mirrors listed the other way round, the odd labels follow the
    /// mirror the camera sees, and n = 1, 2, 3 reach 3, 4, 5 reflections as before (by file
    /// order they had reached 2, 4, 4: n = 1 was `naive`).
    #[test]
    fn odd_labels_lie_on_the_mirror_the_camera_looks_into() {
        let s = scene("mirror_box.json");
        let mut swapped = s.clone();
        swapped.mirrors.reverse();
        let sides = |s: &Scene| -> Vec<usize> {
            instances(s, Queue::Auxiliary { n: 3 }, 320, 180)
                .unwrap()
                .iter()
                .map(|i| i.mirror)
                .collect()
        };
        assert_eq!(sides(&swapped), vec![0, 1, 1, 0, 1]);
        for n in 1..=3 {
            let depth_of = |s: &Scene| {
                plan(s, Queue::Auxiliary { n }, 320, 180, 5000)
                    .unwrap()
                    .depth
            };
            assert_eq!(depth_of(&swapped), depth_of(&s), "n = {n}");
            assert_eq!(depth_of(&s), n as usize + 2, "n = {n}");
        }
    }

    #[test]
    fn footprints_lie_inside_the_image() {
        let p = plan(
            &scene("mirror_room.json"),
            Queue::SceneMirrors,
            64,
            36,
            5000,
        )
        .unwrap();
        fn walk(n: &TextureNode, w: u32, h: u32) -> usize {
            assert!(n.footprint.x + n.footprint.w <= w && n.footprint.y + n.footprint.h <= h);
            1 + n.children.iter().map(|c| walk(c, w, h)).sum::<usize>()
        }
        let total: usize = p.roots.iter().map(|n| walk(n, 64, 36)).sum();
        assert_eq!(total + 1, p.passes);
    }

    /// Every mirror of the room pairs with the wall opposite it (the one it faces most
    /// directly), and each pair takes the paper's n auxiliary mirrors, odd labels on its
    /// first mirror: north and west hold ⌈n/2⌉ copies, south and east ⌊n/2⌋. Two mirrors
    /// pair with each other whatever their orientation; a lone mirror has no partner.
    #[test]
    fn every_mirror_alternates_with_the_one_opposite() {
        let room = scene("mirror_room.json");
        let names: Vec<&str> = room.mirrors.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["north", "south", "west", "east"]);
        let partners: Vec<Option<usize>> = (0..4).map(|i| partner(&room, i)).collect();
        assert_eq!(partners, [Some(1), Some(0), Some(3), Some(2)]);
        let seen = seen_directly(&room, 320, 180);
        let copies: Vec<Vec<u32>> = (0..=4).map(|n| auxiliary_copies(&room, &seen, n)).collect();
        assert_eq!(
            copies,
            [
                [0, 0, 0, 0],
                [1, 0, 1, 0],
                [1, 1, 1, 1],
                [2, 1, 2, 1],
                [2, 2, 2, 2]
            ]
        );
        let tilted = scene("tilted_pair.json");
        assert_eq!(
            (partner(&tilted, 0), partner(&tilted, 1)),
            (Some(1), Some(0))
        );
        let single = scene("single_mirror.json");
        assert_eq!(partner(&single, 0), None);
        assert_eq!(
            instances(&single, Queue::Auxiliary { n: 1 }, 320, 180).unwrap_err(),
            PlanError::NoMirrorToAlternateWith(1)
        );
        assert_eq!(
            instances(&single, Queue::Auxiliary { n: 0 }, 320, 180).unwrap(),
            instances(&single, Queue::SceneMirrors, 320, 180).unwrap()
        );
    }

    /// In the mirror room each auxiliary label adds a reflection to every chain that uses it:
    /// 4, 6, 8 reflections for n = 0, 1, 2. The closed count over plane chains is the number
    /// of `MIRRORTEXTURE` calls the built tree holds, and n = 3 (120 199 passes) is refused at
    /// the default limit with that count.
    #[test]
    fn the_mirror_room_gains_reflections_with_auxiliary_mirrors() {
        let s = scene("mirror_room.json");
        fn calls(n: &TextureNode) -> usize {
            1 + n.children.iter().map(calls).sum::<usize>()
        }
        let mut seen = Vec::new();
        for n in 0..=2 {
            let p = plan(&s, Queue::Auxiliary { n }, 96, 54, 5000).unwrap();
            assert_eq!(p.passes, 1 + p.roots.iter().map(calls).sum::<usize>());
            seen.push((p.passes, p.depth));
        }
        assert_eq!(seen, [(22, 4), (273, 6), (3761, 8)]);
        assert_eq!(
            plan(&s, Queue::Auxiliary { n: 3 }, 96, 54, 5000).unwrap_err(),
            PlanError::TooManyPasses {
                predicted: 120_199,
                limit: 5000,
                exceeded_count: false
            }
        );
    }

    /// A refusal costs at most `max_passes + 1` plane chains, however large the plan: the
    /// largest `--n` at the largest `--max-passes` is refused after a few (the factorial
    /// count passes the ceiling within the first chains), where counting the calls one by
    /// one would visit a million of them.
    #[test]
    fn refusal_visits_at_most_max_passes_chains() {
        for name in ["mirror_box.json", "mirror_room.json"] {
            let s = scene(name);
            for max_passes in [5000, 1_000_000] {
                let count =
                    count_passes(&s, Queue::Auxiliary { n: 16 }, 640, 360, max_passes).unwrap();
                assert!(!count.exact, "{name}");
                assert!(count.passes > max_passes, "{name}: {count:?}");
                assert!(count.chains_visited <= 100, "{name}: {count:?}");
            }
            // A small limit: refused after at most limit + 1 chains.
            let count = count_passes(&s, Queue::Auxiliary { n: 4 }, 640, 360, 10).unwrap();
            assert!(count.chains_visited <= 11, "{name}: {count:?}");
        }
    }
}

/// The limits of a per-path texture plan ([`plan_path_textures`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathTextureLimits {
    /// Most mirrors along a path (`--depth`).
    pub depth: u32,
    /// Paths whose attenuation (largest channel of the reflectances' product) falls below
    /// this end there (`--min-attenuation`, the tracer's `--min-throughput`).
    pub min_attenuation: f32,
}

/// Where two screen rectangles overlap, if they do.
fn intersect(a: Rect, b: Rect) -> Option<Rect> {
    let x = a.x.max(b.x);
    let y = a.y.max(b.y);
    let right = (a.x + a.w).min(b.x + b.w);
    let bottom = (a.y + a.h).min(b.y + b.h);
    (right > x && bottom > y).then(|| Rect {
        x,
        y,
        w: right - x,
        h: bottom - y,
    })
}

impl Planner<'_> {
    /// The texture of path `…, instance` (seen from `parent` through `parent_plane`, inside
    /// the screen region `rect`) and, below it, every path extending it by one mirror: any
    /// mirror but this one (a plane cannot see itself) that its camera sees inside `rect`,
    /// while the path has fewer than `depth` mirrors and its attenuation stays above the
    /// limit. `budget` counts the passes left.
    #[allow(clippy::too_many_arguments)]
    fn path_node(
        &self,
        parent: &ReflectedView,
        instance: usize,
        rect: Rect,
        mirrors: u32,
        attenuation: glam::Vec3,
        limits: PathTextureLimits,
        budget: &mut usize,
    ) -> Option<TextureNode> {
        if *budget == 0 {
            return None;
        }
        *budget -= 1;
        let plane = self.scene.mirrors[self.instances[instance].mirror].plane();
        let view = parent.through(&plane);
        let mut children = Vec::new();
        if mirrors < limits.depth {
            for (i, r) in self.visible(&view, Some(&plane), &[instance]) {
                // Per channel, as the tracer's throughput and `portal`'s paths: the product's
                // largest channel, not the product of each mirror's largest (the same for
                // grey mirrors; for coloured ones that had kept paths the truth cuts).
                let next = attenuation * self.scene.mirrors[i].reflectance;
                let Some(r) = intersect(r, rect) else {
                    continue;
                };
                if next.max_element() < limits.min_attenuation {
                    continue;
                }
                children.push(self.path_node(&view, i, r, mirrors + 1, next, limits, budget)?);
            }
        }
        Some(TextureNode {
            instance,
            view,
            plane,
            footprint: rect,
            hidden: vec![instance],
            children,
        })
    }
}

/// Plans one mirror texture per reflection path (`path-textures`, exact to `limits.depth`):
/// the paper's recursion without its one-use-per-mirror rule — any mirror may follow any
/// other — each texture cut to the part of the screen its parent's texture covers (a
/// reflection is only seen through its parent's mirror). Refuses, after at most
/// `max_passes` nodes, a plan of more scene passes.
pub fn plan_path_textures(
    scene: &Scene,
    limits: PathTextureLimits,
    width: u32,
    height: u32,
    max_passes: usize,
) -> Result<Plan, PlanError> {
    let instances = instances(scene, Queue::SceneMirrors, width, height)?;
    let planner = Planner::new(scene, &instances, width, height);
    let main = planner.main_view(width, height);
    let mut budget = max_passes.saturating_sub(1);
    let mut roots = Vec::new();
    for (i, rect) in planner.visible(&main, None, &[]) {
        let attenuation = scene.mirrors[i].reflectance;
        if attenuation.max_element() < limits.min_attenuation {
            continue;
        }
        let Some(node) = planner.path_node(&main, i, rect, 1, attenuation, limits, &mut budget)
        else {
            return Err(PlanError::TooManyPasses {
                predicted: max_passes + 1,
                limit: max_passes,
                exceeded_count: true,
            });
        };
        roots.push(node);
    }
    fn count(nodes: &[TextureNode]) -> usize {
        nodes.iter().map(|n| 1 + count(&n.children)).sum()
    }
    let depth = depth(&roots);
    Ok(Plan {
        projection: planner.projection,
        instances,
        width,
        height,
        passes: 1 + count(&roots),
        roots,
        depth,
    })
}
