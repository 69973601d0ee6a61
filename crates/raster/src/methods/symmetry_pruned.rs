//! `symmetry-pruned`: `symmetry` (seed 001's 2^p copies as instances) after leaving out every
//! copy that cannot show: its cell holds no part of the objects' bounds, or its image lies
//! wholly outside the view frustum ([`crate::symmetry_cells::select_copies`]). The seed names
//! this optimization without doing it: "entire spaces may become invisible", and its
//! six-pointed star (three planes at 60° through one line) makes 6 cells, not 8.
//!
//! Everything else — clipping, winding groups, back-face culling, mirrors at depth 0, the
//! `--symmetry-draws` and `--copy-ids` options, the shaders — is `symmetry`'s
//! ([`super::symmetry`]). `FrameStats::copies` says how many copies were drawn of the 2^p and
//! why the others were not. The pruning runs on the CPU every frame: one convex polytope clip
//! per plane and bitmask prefix, an empty prefix pruning its whole subtree.

use crate::method::{Advise, MethodEntry, PlannedFrame, RasterMethod};
use crate::methods::symmetry::{
    CLIP_DISTANCE_SHADER, COPY_IDS, CopySettings, SHADER, SYMMETRY_DRAWS, SymmetryFrame,
    SymmetryInput, gpu_structs, plan_copies,
};
use crate::methods::unrolled::FRAGMENT_CLIPPING;
use crate::plan::PlanError;
use crate::symmetry_cells::select_copies;
use mirrorbox_scene::Scene;

/// `symmetry` without the copies that cannot show.
pub static SYMMETRY_PRUNED: MethodEntry = MethodEntry {
    name: "symmetry-pruned",
    help: "Seed 001's symmetry planes as `symmetry`, leaving out copies whose cell is empty or outside the view.",
    exact: true,
    depth_limited: true,
    options: crate::method_options![&SYMMETRY_DRAWS, &FRAGMENT_CLIPPING, &COPY_IDS],
    swept: None,
    optional_features: wgpu::Features::CLIP_DISTANCES,
    required_features: wgpu::Features::empty(),
    shaders: &[&SHADER, &CLIP_DISTANCE_SHADER],
    gpu_structs,
    configure: |p| {
        Box::new(SymmetryPrunedMethod {
            settings: CopySettings::of(p),
        })
    },
    advise: Advise::Skip,
};

/// The typed settings of `symmetry-pruned`.
struct SymmetryPrunedMethod {
    settings: CopySettings,
}

impl RasterMethod for SymmetryPrunedMethod {
    fn plan(
        &self,
        scene: &Scene,
        width: u32,
        height: u32,
    ) -> Result<Box<dyn PlannedFrame>, PlanError> {
        let input = SymmetryInput::of(scene);
        let clip_from_world = SymmetryFrame::new(scene, width, height, &[]).clip_from_world();
        let selection = select_copies(&input.planes, input.source.bounds(), Some(clip_from_world));
        plan_copies(scene, &input, width, height, selection, self.settings)
    }
}
