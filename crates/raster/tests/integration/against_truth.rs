//! Every registered method on one scene against the truth traced to the depth the method
//! reports (`FrameStats::depth`), as the registry test does on `mirror_box`: the corpus tests
//! (`obj_corpus`, `gltf_corpus`) hold each method to its bound on assets nobody here wrote.

use crate::methods::{differences, dump, settings};
use mirrorbox_image::RgbImage;
use mirrorbox_raster::{Gpu, Method, RenderOutput, render};
use mirrorbox_scene::Scene;
use mirrorbox_trace::{SceneBvh, TraceSettings, WhittedSettings};
use std::collections::HashMap;

/// The truth of one scene at any depth, its hierarchy built once.
pub(crate) struct Truth<'a> {
    scene: &'a Scene,
    bvh: SceneBvh,
    by_depth: HashMap<u32, RgbImage>,
}

impl<'a> Truth<'a> {
    pub(crate) fn new(scene: &'a Scene) -> Self {
        Truth {
            scene,
            bvh: SceneBvh::build(&scene.geometry),
            by_depth: HashMap::new(),
        }
    }

    /// The Whitted truth followed to `depth` reflections (throughput cut 1e-4), one sample
    /// per pixel: what `trace_depth` traces.
    pub(crate) fn at(&mut self, depth: u32) -> &RgbImage {
        let (scene, bvh) = (self.scene, &self.bvh);
        self.by_depth.entry(depth).or_insert_with(|| {
            let settings = TraceSettings::whitted(1).with_integrator(WhittedSettings {
                max_depth: depth,
                min_throughput: 1e-4,
            });
            mirrorbox_trace::render(scene, bvh, &settings, &|_| {}).image
        })
    }
}

/// Pixels whose largest channel differs by more than this are "off".
pub(crate) const OFF_BY: f32 = 1e-3;

/// Pixels of `a` and `b` whose largest channel differs by more than [`OFF_BY`].
pub(crate) fn pixels_off(a: &RgbImage, b: &RgbImage) -> usize {
    differences(a, b).iter().filter(|&&d| d > OFF_BY).count()
}

/// One method's render against the truth at its depth.
struct MethodError {
    pub method: String,
    pub name: &'static str,
    pub exact: bool,
    pub depth: u32,
    /// Pixels off the truth by more than [`OFF_BY`], and their share of the image.
    pub off: usize,
    pub off_share: f64,
    pub flip: f64,
    pub image: RgbImage,
}

/// Every registered method at its defaults on `scene`, each against `truth` at the depth it
/// reports. A method that cannot render the scene fails the test, naming it.
fn every_method(gpu: &Gpu, scene: &Scene, truth: &mut Truth, label: &str) -> Vec<MethodError> {
    mirrorbox_raster::METHODS
        .iter()
        .map(|entry| {
            let method = Method::defaults(entry);
            let out = render_at_defaults(gpu, scene, &method, label);
            let depth = out.stats.depth as u32;
            let t = truth.at(depth);
            let off = pixels_off(&out.image, t);
            let flip = mirrorbox_image::metrics::compare(t, &out.image, 1.0)
                .unwrap()
                .flip_mean;
            MethodError {
                method: method.to_string(),
                name: entry.name,
                exact: entry.exact,
                depth,
                off,
                off_share: off as f64 / t.pixels.len() as f64,
                flip,
                image: out.image,
            }
        })
        .collect()
}

/// `method` on `scene`, one frame; a method that cannot render it fails the test, naming it.
fn render_at_defaults(gpu: &Gpu, scene: &Scene, method: &Method, label: &str) -> RenderOutput {
    render(gpu, scene, &settings(method.clone(), 1))
        .unwrap_or_else(|e| panic!("{label} {method}: {e}"))
}

/// Every registered method's render of `scene` at its defaults, in the registry's order.
pub(crate) fn every_render(gpu: &Gpu, scene: &Scene, label: &str) -> Vec<RgbImage> {
    mirrorbox_raster::METHODS
        .iter()
        .map(|entry| render_at_defaults(gpu, scene, &Method::defaults(entry), label).image)
        .collect()
}

/// What a scene looks like without the asset it was made to show: every method's render of
/// it ([`every_render`]), and its truth at any depth.
pub(crate) struct Without<'a, 'b> {
    pub renders: &'a [RgbImage],
    pub truth: &'a mut Truth<'b>,
}

/// The bounds every method is held to against the truth at its depth: the largest share of
/// pixels off (by more than [`OFF_BY`]) and the largest FLIP mean.
pub(crate) struct Bounds {
    /// Every method whose registry row says `exact`.
    pub exact: (f64, f64),
    /// Each inexact method by name; one missing here fails, asking for its bound.
    pub inexact: &'static [(&'static str, f64, f64)],
}

/// Every registered method on `scene` (see [`every_method`]) held to `bounds`, and to
/// drawing the asset: its image differs from its render of the scene `without` the asset on
/// at least half as many pixels as the truth at its depth does (a bound of a share of pixels
/// off, set by the worst asset, would let a method leave a small asset out). The summary line of the
/// errors measured, and a message for each bound exceeded (its images written).
pub(crate) fn check_every_method(
    gpu: &Gpu,
    scene: &Scene,
    truth: &mut Truth,
    label: &str,
    bounds: &Bounds,
    without: &mut Without,
) -> (String, Vec<String>) {
    let mut line = String::new();
    let mut failures = Vec::new();
    for (e, bare) in every_method(gpu, scene, truth, label)
        .into_iter()
        .zip(without.renders)
    {
        let drawn = pixels_off(&e.image, bare);
        let seen = pixels_off(truth.at(e.depth), without.truth.at(e.depth));
        line += &format!(
            "; {} (depth {}) {:.2} % off, FLIP {:.2e}, drawn {:.2}× the truth's",
            e.name,
            e.depth,
            100.0 * e.off_share,
            e.flip,
            drawn as f64 / seen.max(1) as f64
        );
        if drawn * 2 < seen {
            failures.push(format!(
                "{label} {}: its image changes on {drawn} pixels with the asset, the truth's \
                 at depth {} on {seen}: the asset is not drawn",
                e.method, e.depth
            ));
        }
        let (off_bound, flip_bound) = if e.exact {
            bounds.exact
        } else {
            let Some(&(_, off, flip)) = bounds.inexact.iter().find(|b| b.0 == e.name) else {
                failures.push(format!(
                    "{label} {}: an inexact method without a measured bound: measure it and add it",
                    e.name
                ));
                continue;
            };
            (off, flip)
        };
        if e.off_share > off_bound || e.flip > flip_bound {
            failures.push(format!(
                "{label} {}: {} pixels ({:.2} %) off the truth at depth {}, FLIP {:.2e}; \
                 its bound: {} %, FLIP {flip_bound:.2e}; {}",
                e.method,
                e.off,
                100.0 * e.off_share,
                e.depth,
                e.flip,
                100.0 * off_bound,
                dump_failure(label, &e, truth)
            ));
        }
    }
    (line, failures)
}

/// Writes the method's image, the truth and their difference for a failed bound; where.
fn dump_failure(label: &str, e: &MethodError, truth: &mut Truth) -> String {
    let slug: String = label
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    dump(&format!("{slug}_{}", e.name), &e.image, truth.at(e.depth))
}
