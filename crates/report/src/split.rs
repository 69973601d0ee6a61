//! Every sweep's error split into **truncation** and **approximation** ([`crate::ErrorSplit`],
//! issue 50): what stopping at a reflection count leaves out, apart from what a method gets
//! wrong of the reflections it shows. Generic: any record that carries a split gets a row; a
//! finding per method, stated first.

use crate::document::{Block, distinct, label, sci};
use crate::{ErrorSplit, MetricValues, Record};

/// FLIP mean over the mirror pixels where the record has them, else over the image.
fn flip(mirror: &Option<MetricValues>, image: &MetricValues) -> f64 {
    mirror.as_ref().unwrap_or(image).flip_mean
}

fn total(r: &Record) -> f64 {
    flip(&r.mirror_metrics, &r.metrics)
}

fn truncation(s: &ErrorSplit) -> f64 {
    flip(&s.truncation_mirror, &s.truncation)
}

fn approximation(s: &ErrorSplit) -> f64 {
    flip(&s.approximation_mirror, &s.approximation)
}

/// One sentence per method (its variants apart): the range of its approximation error, and
/// for a method that is not exact, how much of its error that is.
fn findings(points: &[(&Record, &ErrorSplit)], exact_methods: &[String]) -> Vec<String> {
    let variants = distinct(points.iter().map(|(r, _)| crate::document::variant(r)));
    variants
        .iter()
        .map(|v| {
            let of: Vec<_> = points
                .iter()
                .filter(|(r, _)| crate::document::variant(r) == *v)
                .collect();
            let approx: Vec<f64> = of.iter().map(|(_, s)| approximation(s)).collect();
            let trunc: Vec<f64> = of.iter().map(|(_, s)| truncation(s)).collect();
            let (a_lo, a_hi) = range(&approx);
            let (t_lo, t_hi) = range(&trunc);
            let exact = of.iter().all(|(r, _)| exact_methods.contains(&r.method));
            if exact {
                format!(
                    "`{v}` (exact): approximation {} at every point — the edge samples its \
                     rasterizer decides within its sub-pixel grid; the rest of its error is \
                     truncation ({} to {}).",
                    if a_lo == a_hi {
                        sci(a_hi)
                    } else {
                        format!("{} to {}", sci(a_lo), sci(a_hi))
                    },
                    sci(t_lo),
                    sci(t_hi)
                )
            } else {
                let totals: Vec<f64> = of.iter().map(|(r, _)| total(r)).collect();
                let (e_lo, e_hi) = range(&totals);
                if of.iter().all(|(r, s)| approximation(s) > total(r)) {
                    format!(
                        "`{v}`: against the truth cut at the reflections it shows, its error is \
                         {} to {} (FLIP over the mirror pixels) — above its error against the \
                         full truth ({} to {}): where the cut truth shows the terminal radiance, \
                         it shows something nearer the full truth. Truncation alone: {} to {}.",
                        sci(a_lo),
                        sci(a_hi),
                        sci(e_lo),
                        sci(e_hi),
                        sci(t_lo),
                        sci(t_hi)
                    )
                } else {
                    let shares: Vec<f64> = of
                        .iter()
                        .map(|(r, s)| {
                            let t = total(r);
                            if t > 0.0 { approximation(s) / t } else { 0.0 }
                        })
                        .collect();
                    let (s_lo, s_hi) = range(&shares);
                    format!(
                        "`{v}`: approximation {} to {} (FLIP over the mirror pixels), {:.0}–{:.0} \
                         % of its error ({} to {}); truncation {} to {}.",
                        sci(a_lo),
                        sci(a_hi),
                        100.0 * s_lo,
                        100.0 * s_hi,
                        sci(e_lo),
                        sci(e_hi),
                        sci(t_lo),
                        sci(t_hi)
                    )
                }
            }
        })
        .collect()
}

fn range(values: &[f64]) -> (f64, f64) {
    values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        })
}

/// The section, or nothing where no record carries a split.
pub fn split_section(records: &[Record], exact_methods: &[String]) -> Vec<Block> {
    let points: Vec<(&Record, &ErrorSplit)> = records
        .iter()
        .filter(|r| r.kind == "point")
        .filter_map(|r| r.split.as_ref().map(|s| (r, s)))
        .collect();
    if points.is_empty() {
        return Vec::new();
    }
    let rows = points
        .iter()
        .map(|(r, s)| {
            vec![
                label(r),
                r.alpha.to_string(),
                s.reflections.to_string(),
                sci(total(r)),
                sci(truncation(s)),
                sci(approximation(s)),
                sci(r.metrics.relmse),
                sci(s.truncation.relmse),
                sci(s.approximation.relmse),
            ]
        })
        .collect();
    vec![
        Block::Heading(2, "Truncation and approximation".into()),
        Block::Bullets(findings(&points, exact_methods)),
        Block::Paragraph(
            "Each point's error split at the reflections it shows: **truncation** is the truth \
             traced with at most that many reflections (the terminal radiance beyond) against \
             the full truth — what any method stopping there leaves out; **approximation** is \
             the method against that truncated truth — what it gets wrong of what it shows. \
             FLIP over the full truth's mirror pixels (over the image where the sweep has no \
             mirror mask); relMSE over the image. Neither metric is additive: the parts need \
             not sum to the total."
                .into(),
        ),
        Block::Table(
            [
                "point",
                "α",
                "reflections",
                "FLIP total",
                "truncation",
                "approximation",
                "relMSE total",
                "truncation",
                "approximation",
            ]
            .map(String::from)
            .to_vec(),
            rows,
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::document::fixtures::record;

    fn values(flip: f64) -> MetricValues {
        let mut m = record(0, 1.0, 1, flip).metrics;
        m.flip_mean = flip;
        m
    }

    fn with_split(mut r: Record, method: &str, trunc: f64, approx: f64) -> Record {
        r.method = method.into();
        r.split = Some(ErrorSplit {
            reflections: 2,
            truncation: values(trunc),
            truncation_mirror: None,
            approximation: values(approx),
            approximation_mirror: None,
        });
        r
    }

    #[test]
    fn no_split_no_section() {
        assert!(split_section(&[record(0, 1.0, 1, 0.1)], &[]).is_empty());
    }

    #[test]
    fn exact_methods_and_the_others_are_told_apart() {
        let records = [
            with_split(record(0, 1.0, 1, 0.1), "auxiliary", 0.06, 0.05),
            with_split(record(0, 1.0, 1, 2e-3), "portal", 2e-3, 4e-5),
        ];
        let blocks = split_section(&records, &["portal".to_string()]);
        let Block::Bullets(findings) = &blocks[1] else {
            panic!("the findings come second")
        };
        assert!(
            findings[0].starts_with("`auxiliary`: approximation 5.000e-2"),
            "{findings:?}"
        );
        assert!(findings[0].contains("50–50 % of its error"), "{findings:?}");
        assert!(
            findings[1].starts_with("`portal` (exact): approximation 4.000e-5"),
            "{findings:?}"
        );
        let Block::Table(_, rows) = &blocks[3] else {
            panic!()
        };
        assert_eq!(rows.len(), 2);
    }
}
