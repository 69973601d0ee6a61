//! Real assets (issue 40): the paper's method (`auxiliary n = 0…4`, Table 1's sweep) and the
//! exact methods at depth 64 on scenes nobody here modelled by hand — a real CAD mesh (the
//! glTF sample `2CylinderEngine`, 110 k triangles, in the mirror box `mirrorbox import`
//! builds: `scenes/imported/engine_box.json`) and a textured asset (`scenes/textured_box.json`:
//! the project's glTF with base colour and emissive textures, a texture transform and a glTF
//! mirror, in the paper's box) — at 320×180, α = 1 and 0.7. Not in the main job (its budget
//! is spent; `docs/budgets.md`); the engine scene needs Debian's `assimp-testmodels`
//! (`scripts/install-system-deps.sh`).

use crate::{Experiment, Measure, beside};
use mirrorbox_harness::{SweepConfig, swept};
use mirrorbox_report::document::{ms, paired_ratio, sci};
use mirrorbox_report::readme::{ReadmeError, RegionSource};
use mirrorbox_report::{Record, load_sweep};
use std::path::{Path, PathBuf};

/// Table 1's methods on `scene` at 320×180, seven timed frames after one warm-up (enough for
/// the paired intervals of the region's ratios: at least six).
fn sweep(scene: &str, out: &Path) -> SweepConfig {
    let mut methods = swept(crate::table1::rows::PAPER_METHOD, 0..=4);
    for m in ["portal", "unrolled"] {
        methods.extend(swept(m, [64]));
    }
    SweepConfig {
        scene: PathBuf::from(scene),
        width: Some(320),
        height: Some(180),
        frames: 7,
        warmup: 1,
        ..SweepConfig::new(PathBuf::new(), out.to_path_buf(), methods, vec![1.0, 0.7])
    }
}

pub const REAL_ASSETS: Experiment = Experiment {
    name: "real-assets",
    about: "the paper's method and the exact ones on real assets: a 110 k-triangle CAD engine (glTF) and a textured glTF, each in a mirror box",
    folder: "real_assets",
    measure: Measure::Sweeps(|out| {
        vec![
            sweep("scenes/imported/engine_box.json", out),
            sweep("scenes/textured_box.json", &beside(out, "_textured")),
        ]
    }),
    section: None,
    regions: &[RegionSource {
        id: "real-assets",
        source: "real_assets",
        about: "real assets: what the engine's triangles cost each method, equal-cost errors, α's effect, the floors (mirrorbox experiment real-assets)",
        generate: findings,
    }],
    chapter: "real-assets.md",
    main_job: false,
    overview: None,
};

/// The paper's point with `n` auxiliary mirrors at reflectance `alpha`.
fn aux<'a>(
    records: &'a [Record],
    folder: &str,
    n: u32,
    alpha: f32,
) -> Result<&'a Record, ReadmeError> {
    point(records, folder, "auxiliary", n, alpha)
}

/// The point of `method` (with `n` or `depth` as `setting`) at reflectance `alpha`.
fn point<'a>(
    records: &'a [Record],
    folder: &str,
    method: &str,
    setting: u32,
    alpha: f32,
) -> Result<&'a Record, ReadmeError> {
    records
        .iter()
        .find(|r| {
            r.kind == "point"
                && r.method == method
                && r.n.or(r.depth) == Some(setting)
                && r.alpha == alpha
        })
        .ok_or_else(|| {
            ReadmeError(format!(
                "reports/{folder}: no `{method}` point at {setting}, α = {alpha}"
            ))
        })
}

/// The floor's FLIP (raster against trace without the mirrors).
fn floor_flip(records: &[Record], folder: &str) -> Result<f64, ReadmeError> {
    records
        .iter()
        .find(|r| r.kind == "floor")
        .map(|r| r.metrics.flip_mean)
        .ok_or_else(|| ReadmeError(format!("reports/{folder}: no floor record")))
}

/// `a`'s time over `b`'s, with the paired 95 % interval where the two were timed in the same
/// interleaved rounds.
fn ratio(a: &Record, b: &Record) -> String {
    let r = a.ms_median / b.ms_median;
    match paired_ratio(a, b) {
        Some(i) => format!("×{r:.2} [{:.2}–{:.2}]", i.low, i.high),
        None => format!("×{r:.2} (no interval: too few frames)"),
    }
}

/// The chapter's findings from the two sweeps' records: what a real mesh costs each method,
/// the exact methods against the paper's at equal cost, what α = 0.7 saves them, the floors.
fn findings(reports: &Path) -> Result<String, ReadmeError> {
    const ENGINE: &str = "real_assets";
    const TEXTURED: &str = "real_assets_textured";
    let engine = load_sweep(&reports.join(ENGINE))?;
    let textured = load_sweep(&reports.join(TEXTURED))?;
    let (e, t) = (&engine.records[..], &textured.records[..]);
    let (e0, e4) = (aux(e, ENGINE, 0, 1.0)?, aux(e, ENGINE, 4, 1.0)?);
    let (t0, t4) = (aux(t, TEXTURED, 0, 1.0)?, aux(t, TEXTURED, 4, 1.0)?);
    let portal = point(e, ENGINE, "portal", 64, 1.0)?;
    let unrolled = point(e, ENGINE, "unrolled", 64, 1.0)?;
    let t_portal = point(t, TEXTURED, "portal", 64, 1.0)?;
    let t_unrolled = point(t, TEXTURED, "unrolled", 64, 1.0)?;
    let triangles = e0.triangles.map_or(String::new(), |n| {
        format!(" ({n} triangles submitted a frame at `n = 0`)")
    });
    let mut out = format!(
        "- **What a real mesh costs.** On the engine every pass redraws the mesh{triangles}: \
         `auxiliary n = 0` takes {} ms a frame and `n = 4` {} ms at α = 1 ({} and {} ms on the \
         textured box); the exact methods at depth 64 {} ms (`portal`) and {} ms (`unrolled`) \
         ({} and {} ms on the textured box). Medians of {} frames, interleaved.\n",
        ms(e0.ms_median, 1),
        ms(e4.ms_median, 1),
        ms(t0.ms_median, 1),
        ms(t4.ms_median, 1),
        ms(portal.ms_median, 1),
        ms(unrolled.ms_median, 1),
        ms(t_portal.ms_median, 1),
        ms(t_unrolled.ms_median, 1),
        e0.frames,
    );
    // The paper's point nearest `portal` in cost (by the ratio of the medians).
    let nearest = (0..=4)
        .map(|n| aux(e, ENGINE, n, 1.0))
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .min_by(|a, b| {
            let off = |r: &Record| (r.ms_median / portal.ms_median).ln().abs();
            off(a).total_cmp(&off(b))
        })
        .expect("five points");
    let (p_flip, a_flip) = (portal.metrics.flip_mean, nearest.metrics.flip_mean);
    out += &format!(
        "- **At about equal cost the exact methods win.** `portal` depth 64 has FLIP {} at {} ms; \
         the paper's point nearest it in cost, `auxiliary n = {}` at {} ms, has {} ({:.0}× the \
         error).\n",
        sci(p_flip),
        ms(portal.ms_median, 1),
        nearest.n.unwrap_or_default(),
        ms(nearest.ms_median, 1),
        sci(a_flip),
        a_flip / p_flip,
    );
    let portal_07 = point(e, ENGINE, "portal", 64, 0.7)?;
    let unrolled_07 = point(e, ENGINE, "unrolled", 64, 0.7)?;
    let paths = |r: &Record| r.paths.map_or("?".to_string(), |p| p.to_string());
    out += &format!(
        "- **α = 0.7 on the engine:** the exact methods' time {} (`portal`) and {} (`unrolled`) \
         of α = 1's (paired 95 % intervals): reflections fade below the attenuation cut \
         sooner, so `portal` draws {} reflection paths instead of {}.\n",
        ratio(portal_07, portal),
        ratio(unrolled_07, unrolled),
        paths(portal_07),
        paths(portal),
    );
    out += &format!(
        "- **The floor** (raster against trace without the mirrors): FLIP {} on the engine, {} \
         on the textured box. Read each scene's errors against its own.\n",
        sci(floor_flip(e, ENGINE)?),
        sci(floor_flip(t, TEXTURED)?),
    );
    Ok(out)
}
