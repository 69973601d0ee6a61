//! The exact methods (portal, unrolled) in a report: beside the paper's method in the Table 1
//! comparison, and their cost against reflection depth.
//!
//! The cost of one more bounce is the slope of a least-squares line of ms/frame against the
//! reflections actually shown (a depth cap above the scene's natural end adds none), read
//! against one full-scene pass: the floor point, which renders the scene without mirrors
//! once.

use crate::{Record, linear_fit};

/// Whether `r` is a point of one of the `exact` methods (names from the raster registry,
/// carried by [`crate::SweepInfo::exact_methods`]).
pub fn is_exact(exact: &[String], r: &Record) -> bool {
    r.kind == "point" && exact.contains(&r.method)
}

/// One method's cost against depth at one α.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthScaling {
    pub method: String,
    pub alpha: f32,
    /// Points in depth order.
    pub points: Vec<Record>,
    /// ms/frame per extra reflection shown (fit over every point).
    pub ms_per_bounce: Option<f64>,
}

/// Groups the exact points by (method, α), each with at least two depths.
pub fn depth_scaling(exact: &[String], records: &[Record]) -> Vec<DepthScaling> {
    let mut out: Vec<DepthScaling> = Vec::new();
    for r in records.iter().filter(|r| is_exact(exact, r)) {
        match out
            .iter_mut()
            .find(|g| g.method == r.method && g.alpha == r.alpha)
        {
            Some(g) => g.points.push(r.clone()),
            None => out.push(DepthScaling {
                method: r.method.clone(),
                alpha: r.alpha,
                points: vec![r.clone()],
                ms_per_bounce: None,
            }),
        }
    }
    out.retain(|g| g.points.len() >= 2);
    for g in &mut out {
        g.points.sort_by_key(|r| r.depth);
        let pts: Vec<(f64, f64)> = g
            .points
            .iter()
            .map(|r| (r.reflections as f64, r.ms_median))
            .collect();
        g.ms_per_bounce = linear_fit(&pts).map(|(_, b)| b);
    }
    out
}

/// A sentence on the cost of one more bounce against one full-scene pass (`pass_ms`).
pub fn bounce_sentence(g: &DepthScaling, pass_ms: Option<f64>) -> String {
    let Some(b) = g.ms_per_bounce else {
        return format!("{}: too few distinct depths to fit.", g.method);
    };
    let deepest = g.points.iter().map(|r| r.reflections).max().unwrap_or(0);
    let mut s = format!(
        "{}, α = {}: {:.3} ms per extra reflection (least-squares over {} depths, up to {} reflections shown)",
        g.method,
        g.alpha,
        b,
        g.points.len(),
        deepest
    );
    if let Some(p) = pass_ms.filter(|p| *p > 0.0) {
        s.push_str(&format!(
            "; one full-scene pass (the floor point: the scene without mirrors, rendered once) takes {p:.2} ms, \
             so one more bounce costs {:.1} % of a pass",
            100.0 * b / p
        ));
    }
    s.push('.');
    s
}

/// Among the exact points at α, the one closest to depth 64 per method, for the Table 1
/// comparison.
pub fn comparison_points<'r>(
    exact: &[String],
    records: &'r [Record],
    alpha: f32,
) -> Vec<&'r Record> {
    let mut out: Vec<&Record> = Vec::new();
    for m in exact {
        let best = records
            .iter()
            .filter(|r| r.kind == "point" && &r.method == m && r.alpha == alpha)
            .min_by_key(|r| r.depth.unwrap_or(0).abs_diff(64));
        out.extend(best);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_is_fitted_exactly() {
        let pts: Vec<(f64, f64)> = (0..5).map(|i| (i as f64, 2.0 + 0.5 * i as f64)).collect();
        let (a, b) = linear_fit(&pts).unwrap();
        assert!((a - 2.0).abs() < 1e-12 && (b - 0.5).abs() < 1e-12);
        assert!(linear_fit(&[(1.0, 1.0), (1.0, 2.0)]).is_none());
    }
}
