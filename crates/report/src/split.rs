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

/// One sentence per method variant: the range of its approximation error and its
/// truncation; for an exact method at its defaults (a variant such as `lights=direct` leaves
/// something out on purpose), that its approximation is the edge-sample floor; for another,
/// how much of its error the approximation is — or that it lies farther from the cut truth
/// than from the full one.
fn findings(points: &[(&Record, &ErrorSplit)], exact_methods: &[String]) -> Vec<String> {
    let variants = distinct(points.iter().map(|(r, _)| crate::document::variant(r)));
    variants
        .iter()
        .map(|v| {
            let of: Vec<_> = points
                .iter()
                .filter(|(r, _)| crate::document::variant(r) == *v)
                .collect();
            let approx = span(of.iter().map(|(_, s)| approximation(s)), sci);
            let (_, t_hi) = range(&of.iter().map(|(_, s)| truncation(s)).collect::<Vec<_>>());
            let truncation_words = if t_hi == 0.0 {
                "no truncation (it shows every reflection the truth follows)".to_string()
            } else {
                format!(
                    "truncation {}",
                    span(of.iter().map(|(_, s)| truncation(s)), sci)
                )
            };
            let error = span(of.iter().map(|(r, _)| total(r)), sci);
            // Which FLIP [`flip`] took: over the mirror pixels where every point kept them
            // (a scene without mirror pixels, the symmetry planes', had been said to be), over
            // the image where none did, and said to be mixed otherwise.
            let mirror = |(r, s): &&(&Record, &ErrorSplit)| {
                r.mirror_metrics.is_some() && s.approximation_mirror.is_some()
            };
            let over = if of.iter().all(mirror) {
                "FLIP over the mirror pixels"
            } else if !of.iter().any(mirror) {
                "FLIP over the image"
            } else {
                "FLIP over the mirror pixels where kept, else over the image"
            };
            let exact = of
                .iter()
                .all(|(r, _)| exact_methods.contains(&r.method) && r.method_options.is_empty());
            if exact {
                format!(
                    "`{v}` (exact): of its error {error} ({over}), \
                     approximation {approx} — the samples its rasterizer decides within its \
                     sub-pixel grid of an edge — and {truncation_words}."
                )
            } else if of.iter().all(|(r, s)| approximation(s) > total(r)) {
                format!(
                    "`{v}`: against the truth cut at the reflections it shows, its error is \
                     {approx} ({over}) — above its error against the full \
                     truth ({error}): where the cut truth shows the terminal radiance, it shows \
                     something nearer the full truth; {truncation_words}."
                )
            } else {
                let share = span(
                    of.iter().map(|(r, s)| {
                        let t = total(r);
                        if t > 0.0 { approximation(s) / t } else { 0.0 }
                    }),
                    |x| format!("{:.0} %", 100.0 * x),
                );
                format!(
                    "`{v}`: approximation {approx} ({over}), {share} of its \
                     error ({error}); {truncation_words}."
                )
            }
        })
        .collect()
}

/// `lo to hi` of `values` in `format`, or the one value where they agree in it.
fn span(values: impl Iterator<Item = f64>, format: impl Fn(f64) -> String) -> String {
    let (lo, hi) = range(&values.collect::<Vec<_>>());
    let (lo, hi) = (format(lo), format(hi));
    if lo == hi {
        lo
    } else {
        format!("{lo} to {hi}")
    }
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
                r.alpha_text(),
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
        assert!(
            findings[0].contains("50 % of its error (1.000e-1)"),
            "{findings:?}"
        );
        assert!(
            findings[1].starts_with(
                "`portal` (exact): of its error 2.000e-3 (FLIP over the image), \
                 approximation 4.000e-5 "
            ),
            "{findings:?}"
        );
        let Block::Table(_, rows) = &blocks[3] else {
            panic!()
        };
        assert_eq!(rows.len(), 2);
    }

    /// A variant of an exact method that leaves something out on purpose is not called exact.
    #[test]
    fn a_variant_of_an_exact_method_is_not_called_exact() {
        let mut direct = with_split(record(0, 1.0, 1, 0.1), "portal", 0.0, 0.1);
        direct.method_options = "lights=direct".into();
        let Block::Bullets(findings) = &split_section(&[direct], &["portal".to_string()])[1] else {
            panic!("the findings come second")
        };
        assert!(!findings[0].contains("(exact)"), "{findings:?}");
        assert!(findings[0].contains("no truncation"), "{findings:?}");
    }
}
