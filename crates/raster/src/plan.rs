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
//! - `auxiliary` (§3.1): n auxiliary mirrors coincide with the two real ones, alternating
//!   sides by label parity (odd labels on mirror 1's side, even on mirror 2's), so the queue
//!   holds n + 2 mirrors and chains reach n + 2 reflections. Each instance hides only itself,
//!   so every camera recurses into *every* unhidden instance on the other side.
//!
//! **Pass count.** One scene pass for the frame plus one per `MIRRORTEXTURE` call. With a
//! mirrors on the side the camera sees and b on the other (a = 1 + ⌈n/2⌉, b = 1 + ⌊n/2⌋ when
//! the camera looks into mirror 1), the calls are the alternating chains of distinct
//! instances: a + a·b + a·b·(a−1) + a·b·(a−1)·(b−1) + …, i.e. 3, 7, 15, 46, 139 passes for
//! n = 0…4 on `mirror_box`. The growth is factorial, which is what the paper's Table 1
//! (25, 61, 142, 435, 1330 ms) shows: divided by these counts it is 8.3–9.6 ms per pass.

use glam::{Mat4, Vec2};
use mirrorbox_scene::polygon::{clip_by, screen_footprint};
use mirrorbox_scene::reflection::ReflectedView;
use mirrorbox_scene::{Plane, Scene};

/// Plans are counted exactly up to this many texture renders.
const COUNT_CEILING: usize = 1_000_000;

/// The rendering queue of the paper's recursion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Queue {
    /// `naive`: the scene's mirrors.
    SceneMirrors,
    /// `auxiliary`: the two real mirrors and n auxiliary copies of them.
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
        "the auxiliary method needs exactly 2 mirrors (the paper's setting); the scene has {0}"
    )]
    NotAPair(usize),
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
}

/// The rendering queue of a method.
pub fn instances(scene: &Scene, queue: Queue) -> Result<Vec<MirrorInstance>, PlanError> {
    match queue {
        Queue::SceneMirrors => Ok((0..scene.mirrors.len())
            .map(|i| MirrorInstance {
                mirror: i,
                label: format!("mirror {}", i + 1),
            })
            .collect()),
        Queue::Auxiliary { n } => {
            if scene.mirrors.len() != 2 {
                return Err(PlanError::NotAPair(scene.mirrors.len()));
            }
            let mut queue = vec![
                MirrorInstance {
                    mirror: 0,
                    label: "mirror 1".into(),
                },
                MirrorInstance {
                    mirror: 1,
                    label: "mirror 2".into(),
                },
            ];
            for k in 1..=n as usize {
                let mirror = if k % 2 == 1 { 0 } else { 1 };
                queue.push(MirrorInstance {
                    mirror,
                    label: format!("auxiliary {k}"),
                });
            }
            Ok(queue)
        }
    }
}

struct Planner<'a> {
    scene: &'a Scene,
    instances: &'a [MirrorInstance],
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
        let eye = view.eye();
        let clip_from_world = self.projection * view.view;
        let mut out = Vec::new();
        for (i, inst) in self.instances.iter().enumerate() {
            if hidden.contains(&i) {
                continue;
            }
            let mirror = &self.scene.mirrors[inst.mirror];
            if mirror.plane().signed_distance(eye) <= 0.0 {
                continue; // seen from behind (or edge-on): not a mirror from here
            }
            let mut poly = mirror.corners().to_vec();
            if let Some(plane) = near {
                poly = clip_by(&poly, |p| plane.signed_distance(p));
            }
            let fp = screen_footprint(&poly, clip_from_world, self.size);
            if let Some(rect) = bounding_rect(&fp, self.size) {
                out.push((i, rect));
            }
        }
        out
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

    /// Counts texture renders below `view`, giving up once `budget` is exceeded.
    fn count(
        &self,
        view: &ReflectedView,
        near: Option<&Plane>,
        hidden: &mut Vec<usize>,
        budget: usize,
    ) -> usize {
        let mut total = 0;
        for (i, _) in self.visible(view, near, hidden) {
            if total > budget {
                break;
            }
            let plane = self.scene.mirrors[self.instances[i].mirror].plane();
            let child = view.through(&plane);
            hidden.push(i);
            total += 1 + self.count(&child, Some(&plane), hidden, budget - total);
            hidden.pop();
        }
        total
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

/// Plans a frame of the recursion over `queue` at render resolution `width × height`; refuses, before any
/// work, a plan of more than `max_passes` scene passes.
pub fn plan(
    scene: &Scene,
    queue: Queue,
    width: u32,
    height: u32,
    max_passes: usize,
) -> Result<Plan, PlanError> {
    let instances = instances(scene, queue)?;
    let camera = scene.camera.with_size(width, height);
    let projection = crate::projection::camera_projection(&camera, width, height);
    let planner = Planner {
        scene,
        instances: &instances,
        projection,
        size: Vec2::new(width as f32, height as f32),
    };
    let main = ReflectedView::direct(camera.view());
    // Count exactly (cheap: a few polygon clips per call) up to a hard ceiling, so a refusal
    // can state the predicted count; only astronomically large plans say "or more".
    let textures = planner.count(&main, None, &mut Vec::new(), COUNT_CEILING.max(max_passes));
    if 1 + textures > max_passes {
        return Err(PlanError::TooManyPasses {
            predicted: 1 + textures,
            limit: max_passes,
            exceeded_count: textures > COUNT_CEILING.max(max_passes),
        });
    }
    let roots: Vec<TextureNode> = planner
        .visible(&main, None, &[])
        .into_iter()
        .map(|(i, rect)| planner.node(&main, i, rect, &[]))
        .collect();
    let depth = depth(&roots);
    Ok(Plan {
        instances,
        width,
        height,
        projection,
        roots,
        passes: 1 + textures,
        depth,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_scene::load::bundled_scene as scene;

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
        assert_eq!(
            plan(
                &scene("mirror_room.json"),
                Queue::Auxiliary { n: 1 },
                32,
                18,
                10
            )
            .unwrap_err(),
            PlanError::NotAPair(4)
        );
    }

    #[test]
    fn auxiliary_zero_is_the_naive_queue() {
        let s = scene("mirror_box.json");
        assert_eq!(
            instances(&s, Queue::Auxiliary { n: 0 }).unwrap(),
            instances(&s, Queue::SceneMirrors).unwrap()
        );
        let q = instances(&s, Queue::Auxiliary { n: 3 }).unwrap();
        let sides: Vec<usize> = q.iter().map(|i| i.mirror).collect();
        assert_eq!(sides, vec![0, 1, 0, 1, 0]);
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
}
