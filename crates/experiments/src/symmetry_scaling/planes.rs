//! The symmetry methods (seed 001) in a report: ms/frame against the number of symmetry
//! planes p, where the seed's method draws 2^p copies, pruning removes copies whose cell is
//! empty or out of view, and the CPU's split-and-mirror mesh is drawn once.

use mirrorbox_report::document::ms;
use mirrorbox_report::{Record, value};

/// The method that draws the CPU-baked mesh once; the others are compared with it.
pub const BAKED_METHOD: &str = "symmetry-baked";
/// The seed's method (instanced copies).
pub const SEED_METHOD: &str = "symmetry";
/// The seed's method with pruned copies.
pub const PRUNED_METHOD: &str = "symmetry-pruned";

/// One method variant's points over p.
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneScaling {
    /// The method with its non-default options, e.g. `symmetry symmetry-draws=per-copy`.
    pub name: String,
    pub method: String,
    /// Points in p order.
    pub points: Vec<Record>,
}

/// The method and its options as a report names them.
pub use mirrorbox_report::document::variant;

/// Groups the points that carry a plane count by method variant, each in p order.
pub fn plane_scaling(records: &[Record]) -> Vec<PlaneScaling> {
    let mut out: Vec<PlaneScaling> = Vec::new();
    for r in records
        .iter()
        .filter(|r| r.kind == "point" && r.planes().is_some())
    {
        let name = variant(r);
        match out.iter_mut().find(|g| g.name == name) {
            Some(g) => g.points.push(r.clone()),
            None => out.push(PlaneScaling {
                name,
                method: r.method.clone(),
                points: vec![r.clone()],
            }),
        }
    }
    for g in &mut out {
        g.points.sort_by_key(|r| r.planes());
    }
    out
}

/// Where drawing the baked mesh once becomes faster than drawing the copies: the smallest p
/// from which the baked method is faster than `other` at every measured p, with the 95 %
/// intervals apart; and the speed-up there and at the largest p.
pub fn crossover_sentence(baked: &PlaneScaling, other: &PlaneScaling) -> String {
    let pairs: Vec<(u32, &Record, &Record)> = baked
        .points
        .iter()
        .filter_map(|b| {
            let p = b.planes()?;
            let o = other.points.iter().find(|o| o.planes() == Some(p))?;
            Some((p, b, o))
        })
        .collect();
    if pairs.is_empty() {
        return format!("{} and {} share no p.", baked.name, other.name);
    }
    let faster = |b: &Record, o: &Record| match (b.ms_ci(), o.ms_ci()) {
        (Some(ib), Some(io)) => ib.high < io.low,
        _ => false,
    };
    let from = (0..pairs.len())
        .find(|&k| pairs[k..].iter().all(|(_, b, o)| faster(b, o)))
        .map(|k| pairs[k]);
    let (last_p, last_b, last_o) = pairs[pairs.len() - 1];
    match from {
        Some((p, b, o)) => format!(
            "Against `{}`, `{}` is faster from p = {p} on, with the 95 % intervals apart at every p \
             from there: {:.2}× at p = {p} ({} against {} ms), {:.2}× at p = {last_p} \
             ({} against {} ms).",
            other.name,
            baked.name,
            o.ms_median / b.ms_median,
            ms(b.ms_median, 1),
            ms(o.ms_median, 1),
            last_o.ms_median / last_b.ms_median,
            ms(last_b.ms_median, 1),
            ms(last_o.ms_median, 1)
        ),
        None => format!(
            "Against `{}`, `{}` is not shown faster at 95 % up to p = {last_p} on this device \
             ({} against {} ms there).",
            other.name,
            baked.name,
            ms(last_b.ms_median, 1),
            ms(last_o.ms_median, 1)
        ),
    }
}

/// How many of the 2^p copies pruning keeps, at the largest p measured.
pub fn pruning_sentence(pruned: &PlaneScaling) -> Option<String> {
    let r = pruned.points.last()?;
    let (p, drawn, total) = (
        r.planes()?,
        r.value(value::COPIES_DRAWN)? as usize,
        r.value(value::COPIES_TOTAL)? as usize,
    );
    Some(format!(
        "`{}` draws {drawn} of the 2^{p} = {total} copies at p = {p} ({:.1} %: the rest have an \
         empty cell or lie outside the view).",
        pruned.name,
        100.0 * drawn as f64 / total.max(1) as f64
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(method: &str, p: u32, ms: f64, drawn: usize) -> Record {
        let mut r = mirrorbox_report::document::fixtures::record(0, ms, 1, 0.0);
        r.method = method.into();
        r.n = None;
        r.axes
            .insert(mirrorbox_report::axis::PLANES.into(), f64::from(p));
        r.values.insert(value::COPIES_DRAWN.into(), drawn as f64);
        r.values
            .insert(value::COPIES_TOTAL.into(), f64::from(1u32 << p));
        // A tight interval: ±1 %.
        r.ms_interval = Some([ms * 0.99, ms * 1.01]);
        r
    }

    #[test]
    fn baking_wins_from_the_first_p_where_it_stays_ahead() {
        // Copies cost 2^p × 1 ms; the baked mesh 3 ms + 0.5 ms per plane.
        let mut records = Vec::new();
        for p in 0..=6u32 {
            records.push(point(SEED_METHOD, p, f64::from(1 << p), 1 << p));
            records.push(point(BAKED_METHOD, p, 3.0 + 0.5 * f64::from(p), 1));
            records.push(point(PRUNED_METHOD, p, f64::from(1 << p), (1 << p) / 4 + 1));
        }
        let groups = plane_scaling(&records);
        assert_eq!(groups.len(), 3);
        let find = |m: &str| groups.iter().find(|g| g.method == m).unwrap();
        let s = crossover_sentence(find(BAKED_METHOD), find(SEED_METHOD));
        // p = 2: 4 ms against 4 ms (tie); p = 3: 8 against 4.5.
        assert!(s.contains("faster from p = 3 on"), "{s}");
        assert!(s.contains("1.78× at p = 3"), "{s}");
        let s = pruning_sentence(find(PRUNED_METHOD)).unwrap();
        assert!(
            s.contains("draws 17 of the 2^6 = 64 copies at p = 6 (26.6 %"),
            "{s}"
        );
        // Never ahead: said so.
        let slow: Vec<Record> = (0..=3u32)
            .flat_map(|p| {
                [
                    point(SEED_METHOD, p, 1.0, 1),
                    point(BAKED_METHOD, p, 2.0, 1),
                ]
            })
            .collect();
        let g = plane_scaling(&slow);
        assert!(
            crossover_sentence(&g[1], &g[0]).contains("is not shown faster at 95 % up to p = 3")
        );
    }

    #[test]
    fn options_name_their_own_series() {
        let mut per_copy = point(SEED_METHOD, 1, 2.0, 2);
        per_copy.method_options = "symmetry-draws=per-copy".into();
        let groups = plane_scaling(&[point(SEED_METHOD, 1, 1.0, 2), per_copy]);
        assert_eq!(
            groups.iter().map(|g| g.name.as_str()).collect::<Vec<_>>(),
            ["symmetry", "symmetry symmetry-draws=per-copy"]
        );
    }
}
