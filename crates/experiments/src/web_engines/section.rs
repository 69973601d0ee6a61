//! A scored run's section (`mirrorbox score`, issue 53): each external variant beside its
//! client's floor, our equivalent at the scene's own camera and the best exact method at
//! its cost —
//! one table and one finding per variant, computed from the records. Empty for any report
//! without external records (`timing_order` "external").

use mirrorbox_report::document::{Block, distinct, f, ms_cell, sci};
use mirrorbox_report::{Record, SweepInfo};

/// `text` cut to `n` characters, with an ellipsis where cut (a device string can run to
/// hundreds: the full one is in the record and in `variants.md`).
fn short(text: &str, n: usize) -> String {
    if text.chars().count() <= n {
        text.to_string()
    } else {
        format!("{}…", text.chars().take(n).collect::<String>().trim_end())
    }
}

/// A timing source in a few words: up to its first parenthesis or comma.
fn clock(r: &Record) -> String {
    let t = r
        .timing_source
        .split(['(', ','])
        .next()
        .unwrap_or_default()
        .trim();
    short(t, 40)
}

/// `r`'s time as a multiple of `floor`'s, the same renderer's pass without mirrors at the same
/// size on the same clock (ours: [`Record::floor_beside`], its own sweep's). Across renderers
/// only this compares: on one device (SwiftShader) the browser's wall clock and our GPU
/// timestamps put the same no-mirror pass severalfold apart (each report's floors).
fn passes(r: &Record, floor: Option<&Record>) -> Option<f64> {
    floor
        .filter(|fl| {
            fl.ms_median > 0.0
                && (fl.width, fl.height, fl.ssaa) == (r.width, r.height, r.ssaa)
                && clock(fl) == clock(r)
        })
        .map(|fl| r.ms_median / fl.ms_median)
}

/// The view an external record was drawn from ("" where its key names none).
fn view_of(r: &Record) -> &str {
    r.scored_view().unwrap_or_default()
}

pub fn section(info: &SweepInfo, records: &[Record]) -> Vec<Block> {
    let variants: Vec<&Record> = records
        .iter()
        .filter(|r| r.is_external() && r.kind == "point")
        .collect();
    if variants.is_empty() {
        return Vec::new();
    }
    // With several views, each row and finding names its view (they read alike otherwise).
    let several_views = variants.iter().any(|r| view_of(r) != view_of(variants[0]));
    let label = |r: &Record| {
        let l = mirrorbox_report::document::label(r);
        if several_views {
            format!("{l} (view {})", view_of(r))
        } else {
            l
        }
    };
    let ours: Vec<&Record> = records
        .iter()
        .filter(|r| !r.is_external() && r.kind == "point")
        .collect();
    let our_floor = Record::our_floor(records);
    let mut rows = Vec::new();
    let mut findings = Vec::new();
    for r in &variants {
        // The client's floor of the same view.
        let floor = r.floor_beside(records);
        // Ours show the scene's own camera: set beside that view only. With one view, `score
        // --with` has held ours to it (and scores made before the flag was kept had one).
        let at_our_camera =
            !several_views || r.value(mirrorbox_report::value::SCENE_CAMERA) == Some(1.0);
        // Our points of the equivalent method at the variant's size: one is its equivalent;
        // several settings of it (two cube sizes) are none, and are named instead.
        let candidates: Vec<&Record> =
            r.option("equivalent")
                .filter(|_| at_our_camera)
                .map_or(Vec::new(), |m| {
                    ours.iter()
                        .filter(|o| {
                            o.method == m
                                && (o.width, o.height, o.ssaa) == (r.width, r.height, r.ssaa)
                        })
                        .copied()
                        .collect()
                });
        let eq = match candidates.as_slice() {
            [one] => Some(*one),
            _ => None,
        };
        // The best of our exact methods that costs no more: in passes of each side's own floor
        // where both floors were measured, else in ms where both times are of one clock;
        // otherwise the costs do not compare and nothing is said.
        let variant_passes = passes(r, floor);
        let by_passes = variant_passes.is_some()
            && ours
                .iter()
                .any(|o| passes(o, o.floor_beside(records)).is_some());
        let comparable = by_passes || ours.iter().any(|o| clock(o) == clock(r));
        let costs_no_more = |o: &Record| match (variant_passes, passes(o, o.floor_beside(records)))
        {
            (Some(v), Some(p)) => p <= v,
            _ => !by_passes && clock(o) == clock(r) && o.ms_median <= r.ms_median,
        };
        let exact = ours
            .iter()
            .filter(|o| at_our_camera && info.exact_methods.contains(&o.method) && costs_no_more(o))
            .min_by(|a, b| a.mirror_flip().total_cmp(&b.mirror_flip()));
        let in_passes = |x: Option<f64>, whose: &str| {
            x.map_or(String::new(), |x| format!(", {}× {whose} floor", f(x, 2)))
        };
        rows.push(vec![
            label(r),
            short(&r.adapter, 60),
            floor.map_or("–".into(), |fl| sci(fl.metrics.flip_mean)),
            sci(r.mirror_flip()),
            sci(r.metrics.flip_mean),
            ms_cell(r, 3),
            match (eq, candidates.len()) {
                (Some(e), _) => format!(
                    "{} {}",
                    mirrorbox_report::document::label(e),
                    sci(e.mirror_flip())
                ),
                (None, 0) => "–".into(),
                (None, n) => format!("{n} settings: none"),
            },
            eq.map_or("–".into(), |e| ms_cell(e, 3)),
            exact.map_or("–".into(), |e| {
                format!(
                    "{} {}",
                    mirrorbox_report::document::label(e),
                    sci(e.mirror_flip())
                )
            }),
        ]);
        let mut s = format!(
            "**{}**{} ({}): FLIP over the mirror pixels {}",
            r.method,
            if several_views {
                format!(", view {}", view_of(r))
            } else {
                String::new()
            },
            r.backend,
            sci(r.mirror_flip())
        );
        if let Some(e) = eq {
            s.push_str(&format!(
                ", {}× that of our `{}` ({}) at the scene's own camera",
                f(r.mirror_flip() / e.mirror_flip(), 2),
                mirrorbox_report::document::label(e),
                sci(e.mirror_flip())
            ));
        } else if candidates.len() > 1 {
            // Named by setting, and by device where two `--with` sweeps share a setting.
            let labels: Vec<String> = candidates
                .iter()
                .map(|c| mirrorbox_report::document::label(c))
                .collect();
            let named: Vec<String> = if distinct(labels.iter().cloned()).len() == labels.len() {
                labels
            } else {
                candidates
                    .iter()
                    .zip(labels)
                    .map(|(c, l)| format!("{l} on {}", short(&c.adapter, 40)))
                    .collect()
            };
            s.push_str(&format!(
                "; our `{}` was measured {} times here ({}), so none is its equivalent",
                candidates[0].method,
                candidates.len(),
                named.join(", ")
            ));
        }
        if let Some(fl) = floor {
            s.push_str(&format!(
                "; its floor (no mirrors) {}",
                sci(fl.metrics.flip_mean)
            ));
            if let Some(of) = our_floor.filter(|_| at_our_camera) {
                s.push_str(&format!(", ours {}", sci(of.metrics.flip_mean)));
            }
        }
        s.push_str(&format!(
            "; {} ms/frame ({}{})",
            f(r.ms_median, 3),
            clock(r),
            in_passes(variant_passes, "its")
        ));
        if let Some(e) = eq {
            s.push_str(&format!(
                " against our `{}`'s {} ms ({}{}) on {}",
                mirrorbox_report::document::label(e),
                f(e.ms_median, 3),
                clock(e),
                in_passes(passes(e, e.floor_beside(records)), "our"),
                short(&e.adapter, 40)
            ));
        }
        let measure = if by_passes {
            " (in passes of each side's own floor)"
        } else {
            ""
        };
        match exact {
            Some(e) => s.push_str(&format!(
                "; at no more cost{measure} our `{}` reaches {}{}.",
                mirrorbox_report::document::label(e),
                sci(e.mirror_flip()),
                passes(e, e.floor_beside(records))
                    .map_or(String::new(), |p| format!(" at {}× our floor", f(p, 2)))
            )),
            // Said only where our exact methods were measured beside it (`score --with`) and
            // their cost compares with the variant's.
            None if at_our_camera
                && comparable
                && ours.iter().any(|o| info.exact_methods.contains(&o.method)) =>
            {
                s.push_str(&format!(
                    "; none of our exact methods is as cheap{measure}."
                ))
            }
            None => s.push('.'),
        }
        findings.push(s);
    }
    let ms_column = mirrorbox_report::document::ms_heading("ms/frame", variants.iter().copied());
    vec![
        Block::Heading(2, "External renderers against the truth".into()),
        Block::Paragraph(
            "Each variant a client drew (`mirrorbox score`, docs/exchange.md), its client's \
             floor (the scene without mirrors: shading and rasterization alone), our \
             equivalent at the scene's own camera (the view our sweeps show), and the best of \
             our exact methods that costs no more. Times come from different clocks where the \
             devices or timing sources differ (named in each finding), and two clocks on one \
             device can put the same pass severalfold apart: so \"no more cost\" is counted in \
             passes of each side's own floor (a variant's time over its client's floor, ours \
             over our floor) where both floors were measured, and in ms only where one clock \
             timed both."
                .into(),
        ),
        Block::Table(
            [
                "variant",
                "device",
                "client's floor FLIP",
                "FLIP over mirror pixels",
                "FLIP over image",
                ms_column.as_str(),
                "our equivalent: mirror FLIP",
                "our equivalent: ms/frame",
                "our best exact at no more cost",
            ]
            .map(String::from)
            .to_vec(),
            rows,
        ),
        Block::Bullets(findings),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_report::document::fixtures::record;

    fn finding(records: &[Record]) -> String {
        let info = SweepInfo {
            exact_methods: vec!["portal".into()],
            ..Default::default()
        };
        let blocks = section(&info, records);
        blocks
            .iter()
            .find_map(|b| match b {
                Block::Bullets(items) => items
                    .iter()
                    .find(|i| i.starts_with("**three-reflector**"))
                    .cloned(),
                _ => None,
            })
            .expect("a finding for the variant")
    }

    /// "None of our exact methods is as cheap" is said only where ours were measured beside
    /// the variant: a score without `--with` has none to compare.
    #[test]
    fn the_exact_comparison_is_said_only_where_ours_were_measured() {
        let mut variant = record(0, 2.0, 1, 0.05);
        variant.method = "three-reflector".into();
        variant.timing_order = mirrorbox_report::EXTERNAL_TIMING.into();
        let alone = finding(std::slice::from_ref(&variant));
        assert!(!alone.contains("exact"), "{alone}");
        let mut portal = record(0, 5.0, 1, 0.001);
        portal.method = "portal".into();
        let beside = finding(&[variant.clone(), portal.clone()]);
        assert!(
            beside.ends_with("; none of our exact methods is as cheap."),
            "{beside}"
        );
        portal.ms_median = 1.0;
        let cheaper = finding(&[variant.clone(), portal]);
        assert!(cheaper.contains("at no more cost our `portal"), "{cheaper}");
    }

    /// Across clocks, "no more cost" is counted in passes of each side's own floor: the
    /// browser's wall clock put SwiftShader's no-mirror pass at 1.8 ms where our GPU
    /// timestamps put it at 5.4 ms, and raw ms had made every exact method "too dear". With
    /// no floors, times of two clocks are not compared at all.
    #[test]
    fn costs_across_clocks_compare_in_passes_of_each_floor() {
        let mut variant = scored("three", "reflector", "camera", 0.05);
        variant.ms_median = 8.0;
        variant.timing_source = "wall clock (gl.finish)".into();
        let mut client_floor = scored("three", "floor", "camera", 0.001);
        client_floor.ms_median = 2.0;
        client_floor.timing_source = variant.timing_source.clone();
        let mut ours_floor = record(0, 5.0, 1, 0.001);
        ours_floor.kind = "floor".into();
        ours_floor.method = "floor".into();
        let portal = |ms: f64| {
            let mut r = record(0, ms, 1, 0.001);
            r.method = "portal".into();
            r
        };
        let find = |records: &[Record]| {
            let info = SweepInfo {
                exact_methods: vec!["portal".into()],
                ..Default::default()
            };
            mirrorbox_report::document::markdown(&section(&info, records))
        };
        // 15 ms is 3 of our passes, the variant 4 of its own: no dearer.
        let cheaper = find(&[
            variant.clone(),
            client_floor.clone(),
            ours_floor.clone(),
            portal(15.0),
        ]);
        assert!(
            cheaper.contains("at no more cost (in passes of each side's own floor) our `portal")
                && cheaper.contains("reaches 1.000e-3 at 3.00× our floor."),
            "{cheaper}"
        );
        assert!(
            cheaper.contains("8.000 ms/frame (wall clock, 4.00× its floor)"),
            "{cheaper}"
        );
        // 25 ms is 5 passes: dearer, though fewer ms than nothing else would say.
        let dearer = find(&[
            variant.clone(),
            client_floor.clone(),
            ours_floor,
            portal(25.0),
        ]);
        assert!(
            dearer.contains(
                "none of our exact methods is as cheap (in passes of each side's own floor)"
            ),
            "{dearer}"
        );
        // No floors and two clocks: no verdict, either way.
        let apart = find(&[variant, portal(1.0)]);
        assert!(
            !apart.contains("no more cost our") && !apart.contains("as cheap"),
            "{apart}"
        );
    }

    /// With two views, each variant's row and finding name the view, and each takes the
    /// floor of its own view (before: the first view's floor for both, and two rows alike).
    #[test]
    fn each_view_of_a_variant_is_named_and_has_its_own_floor() {
        let external = |method: &str, kind: &str, view: &str, flip: f64| {
            let mut r = record(0, 2.0, 1, flip);
            r.method = method.into();
            r.kind = kind.into();
            r.key = format!("three/x|{view}|a0.9|16x16|ssaa1");
            r.timing_order = mirrorbox_report::EXTERNAL_TIMING.into();
            r
        };
        let records = [
            external("three-reflector", "point", "a", 0.05),
            external("three-reflector", "point", "b", 0.06),
            external("three", "floor", "a", 0.001),
            external("three", "floor", "b", 0.002),
        ];
        let info = SweepInfo::default();
        let blocks = section(&info, &records);
        let text = mirrorbox_report::document::markdown(&blocks);
        assert!(text.contains("**three-reflector**, view a"), "{text}");
        assert!(text.contains("**three-reflector**, view b"), "{text}");
        assert!(text.contains("its floor (no mirrors) 2.000e-3"), "{text}");
        assert!(text.contains("(view b)"), "{text}");
    }

    /// A scored record of `client/variant` at `view`.
    fn scored(client: &str, variant: &str, view: &str, flip: f64) -> Record {
        let mut r = record(0, 2.0, 1, flip);
        r.method = if variant == "floor" {
            client.into()
        } else {
            format!("{client}-{variant}")
        };
        r.kind = if variant == "floor" { "floor" } else { "point" }.into();
        r.key = format!("{client}/{variant}|{view}|a0.9|16x16|ssaa1");
        r.timing_order = mirrorbox_report::EXTERNAL_TIMING.into();
        r
    }

    fn text(records: &[Record]) -> String {
        mirrorbox_report::document::markdown(&section(&SweepInfo::default(), records))
    }

    /// A client's floor is its own, found by its name in the key, not by its method cut at a
    /// `-` (`me-gpu`'s variants had been given `me`'s floor).
    #[test]
    fn a_client_with_a_dash_in_its_name_has_its_own_floor() {
        let t = text(&[
            scored("me-gpu", "grey", "camera", 0.3),
            scored("me", "floor", "camera", 0.0),
            scored("me-gpu", "floor", "camera", 0.55),
        ]);
        assert!(
            t.contains("**me-gpu-grey**") && t.contains("its floor (no mirrors) 5.500e-1"),
            "{t}"
        );
    }

    /// Our equivalent is ours of that method at the variant's size, named with its setting;
    /// several settings of it are none, and said; a view elsewhere than the scene's own
    /// camera (which ours show) gets none.
    #[test]
    fn our_equivalent_is_one_setting_at_the_scene_camera_or_none() {
        let mut variant = scored("three", "cubecamera", "camera", 0.4);
        variant.method_options = "equivalent=cubemap".into();
        let ours = |options: &str| {
            let mut r = record(0, 9.0, 1, 0.5);
            r.method = "cubemap".into();
            r.method_options = options.into();
            r
        };
        let one = text(&[variant.clone(), ours("cube-size=256")]);
        assert!(one.contains("that of our `cubemap cube-size=256"), "{one}");
        let two = text(&[variant.clone(), ours("cube-size=256"), ours("cube-size=32")]);
        assert!(
            two.contains("our `cubemap` was measured 2 times here") && !two.contains("that of our"),
            "{two}"
        );
        // Two views: the one at the scene's camera is compared, the other not.
        let mut elsewhere = variant.clone();
        elsewhere.key = "three/cubecamera|side|a0.9|16x16|ssaa1".into();
        variant
            .values
            .insert(mirrorbox_report::value::SCENE_CAMERA.into(), 1.0);
        let views = text(&[variant, elsewhere, ours("cube-size=256")]);
        assert_eq!(views.matches("that of our `cubemap").count(), 1, "{views}");
        assert!(
            views.contains("**three-cubecamera**, view camera ("),
            "{views}"
        );
    }
}
