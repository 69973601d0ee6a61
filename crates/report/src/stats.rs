//! Statistics of timings on a noisy machine: medians, and bootstrap confidence intervals
//! (percentile method, resampling frames with replacement; Efron & Tibshirani 1993, ch. 13).
//! Deterministic: the resampling draws from a fixed-seed generator, so a report is a pure
//! function of its records.

/// Resamples per interval; the 2.5 % and 97.5 % quantiles of 2 000 medians are stable to
/// a few tenths of a percent of the spread.
pub const BOOTSTRAP_RESAMPLES: usize = 2000;
/// The seed of every resampling (any fixed value; recorded here, not in the records).
pub const BOOTSTRAP_SEED: u64 = 0x6d69_7272_6f72_626f;

/// SplitMix64: small and good enough to draw resampling indices.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// A uniform index in `0..n` (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    /// Shuffles `items` in place (Fisher–Yates).
    pub fn shuffle<T>(&mut self, items: &mut [T]) {
        for i in (1..items.len()).rev() {
            items.swap(i, self.below(i + 1));
        }
    }
}

/// The median (mean of the middle two for an even count); NaN for no values.
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => v[n / 2],
        _ => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// The `q` quantile of sorted `v` (nearest rank).
fn quantile(v: &[f64], q: f64) -> f64 {
    let i = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
    v[i]
}

/// A 95 % interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    pub low: f64,
    pub high: f64,
}

impl Interval {
    pub fn contains(&self, x: f64) -> bool {
        self.low <= x && x <= self.high
    }
    pub fn overlaps(&self, other: &Interval) -> bool {
        self.low <= other.high && other.low <= self.high
    }
}

/// The 95 % percentile-bootstrap interval of `statistic` over samples drawn with replacement
/// from each of `groups` (each group resampled to its own size, independently). `None` when a
/// group is empty.
pub fn bootstrap(
    groups: &[&[f64]],
    statistic: impl Fn(&[Vec<f64>]) -> f64,
    seed: u64,
) -> Option<Interval> {
    if groups.iter().any(|g| g.is_empty()) || groups.is_empty() {
        return None;
    }
    let mut rng = Rng::new(seed);
    let mut resampled: Vec<Vec<f64>> = groups.iter().map(|g| vec![0.0; g.len()]).collect();
    let mut values = Vec::with_capacity(BOOTSTRAP_RESAMPLES);
    for _ in 0..BOOTSTRAP_RESAMPLES {
        for (g, out) in groups.iter().zip(&mut resampled) {
            for x in out.iter_mut() {
                *x = g[rng.below(g.len())];
            }
        }
        let v = statistic(&resampled);
        if v.is_finite() {
            values.push(v);
        }
    }
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    Some(Interval {
        low: quantile(&values, 0.025),
        high: quantile(&values, 0.975),
    })
}

/// Fewest frames for a median interval. The percentile bootstrap of a median returns order
/// statistics of the frames; with 6 or more it covers the true median about 95 % of the time
/// or better (n = 9: x₍₂₎…x₍₈₎, 96 %), with 5 it is [min, max] (94 %), and with 1 a single
/// point — too few to call it a 95 % interval.
pub const MIN_FRAMES_FOR_INTERVAL: usize = 6;

/// The 95 % bootstrap interval of the median of `frames`; `None` below
/// [`MIN_FRAMES_FOR_INTERVAL`] frames.
pub fn median_interval(frames: &[f64]) -> Option<Interval> {
    if frames.len() < MIN_FRAMES_FOR_INTERVAL {
        return None;
    }
    bootstrap(&[frames], |g| median(&g[0]), BOOTSTRAP_SEED)
}

/// The 95 % interval of the ratio of two medians, `median(a) / median(b)`, by a **paired**
/// bootstrap: `a[k]` and `b[k]` were timed in the same interleaved round `k`, so whole rounds
/// are resampled (the same indices for both) and drift of the machine between rounds, which
/// moves both alike, cancels in the ratio instead of widening it. `None` unless both have the
/// same number of frames, at least [`MIN_FRAMES_FOR_INTERVAL`].
pub fn paired_ratio_interval(a: &[f64], b: &[f64]) -> Option<Interval> {
    if a.len() != b.len() || a.len() < MIN_FRAMES_FOR_INTERVAL {
        return None;
    }
    let mut rng = Rng::new(BOOTSTRAP_SEED);
    let (mut ra, mut rb) = (vec![0.0; a.len()], vec![0.0; b.len()]);
    let mut ratios = Vec::with_capacity(BOOTSTRAP_RESAMPLES);
    for _ in 0..BOOTSTRAP_RESAMPLES {
        for k in 0..a.len() {
            let round = rng.below(a.len());
            ra[k] = a[round];
            rb[k] = b[round];
        }
        let r = median(&ra) / median(&rb);
        if r.is_finite() {
            ratios.push(r);
        }
    }
    if ratios.is_empty() {
        return None;
    }
    ratios.sort_by(f64::total_cmp);
    Some(Interval {
        low: quantile(&ratios, 0.025),
        high: quantile(&ratios, 0.975),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
    }

    #[test]
    fn the_median_interval_holds_the_median_and_narrows_with_more_frames() {
        let mut rng = Rng::new(1);
        let noisy = |n: usize, rng: &mut Rng| -> Vec<f64> {
            (0..n)
                .map(|_| 50.0 + (rng.next_u64() % 1000) as f64 / 100.0)
                .collect()
        };
        let few = noisy(9, &mut rng);
        let many = noisy(200, &mut rng);
        let (a, b) = (
            median_interval(&few).unwrap(),
            median_interval(&many).unwrap(),
        );
        assert!(a.contains(median(&few)) && b.contains(median(&many)));
        assert!(b.high - b.low < a.high - a.low, "{a:?} {b:?}");
        // The true median (55) lies inside the wide-sample interval.
        assert!(b.contains(55.0), "{b:?}");
        // Identical frames: a zero-width interval.
        let flat = median_interval(&[7.0; 6]).unwrap();
        assert_eq!((flat.low, flat.high), (7.0, 7.0));
        assert!(median_interval(&[]).is_none());
        assert!(
            median_interval(&[1.0, 2.0, 3.0, 4.0, 5.0]).is_none(),
            "too few frames"
        );
    }

    #[test]
    fn pairing_by_round_cancels_drift_that_unpaired_intervals_cannot() {
        // Two points timed in the same 9 rounds; the machine slows down round by round
        // (x1 … x1.8), and b always costs 1.2× a in its round.
        let drift: Vec<f64> = (0..9).map(|k| 1.0 + 0.1 * k as f64).collect();
        let a: Vec<f64> = drift.iter().map(|d| 10.0 * d).collect();
        let b: Vec<f64> = drift.iter().map(|d| 12.0 * d).collect();
        let (ia, ib) = (median_interval(&a).unwrap(), median_interval(&b).unwrap());
        assert!(
            ia.overlaps(&ib),
            "drift hides the difference: {ia:?} {ib:?}"
        );
        let ratio = paired_ratio_interval(&b, &a).unwrap();
        assert!(
            (ratio.low - 1.2).abs() < 1e-9 && (ratio.high - 1.2).abs() < 1e-9,
            "{ratio:?}"
        );
        // Unrelated noise: the paired interval holds 1 when the points cost the same.
        let mut rng = Rng::new(3);
        let noise = |rng: &mut Rng| 20.0 + (rng.next_u64() % 1000) as f64 / 100.0;
        let c: Vec<f64> = (0..9).map(|_| noise(&mut rng)).collect();
        let d: Vec<f64> = (0..9).map(|_| noise(&mut rng)).collect();
        assert!(paired_ratio_interval(&c, &d).unwrap().contains(1.0));
        assert!(paired_ratio_interval(&c[..5], &d[..5]).is_none(), "too few");
        assert!(paired_ratio_interval(&c, &d[..8]).is_none(), "not paired");
    }

    #[test]
    fn intervals_overlap_or_not() {
        let a = Interval {
            low: 1.0,
            high: 2.0,
        };
        assert!(a.overlaps(&Interval {
            low: 2.0,
            high: 3.0
        }));
        assert!(!a.overlaps(&Interval {
            low: 2.1,
            high: 3.0
        }));
    }

    #[test]
    fn a_shuffle_is_a_permutation_and_depends_on_the_seed() {
        let mut a: Vec<usize> = (0..20).collect();
        let mut b = a.clone();
        Rng::new(1).shuffle(&mut a);
        Rng::new(2).shuffle(&mut b);
        assert_ne!(a, b);
        let mut sorted = a.clone();
        sorted.sort();
        assert_eq!(sorted, (0..20).collect::<Vec<_>>());
    }
}
