//! Sub-pixel sample positions.
//!
//! The default is the fixed `s × s` grid of [`mirrorbox_scene::SubpixelGrid`], which the
//! rasterizer reproduces exactly by `s×` supersampling. `--jitter` instead draws one
//! uniformly random position inside each of the `s × s` strata, from a generator seeded by
//! (`seed`, pixel index) only, so results do not depend on thread scheduling.

use glam::Vec2;
use mirrorbox_scene::SubpixelGrid;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sampling {
    Grid(SubpixelGrid),
    Jittered { grid: SubpixelGrid, seed: u64 },
}

impl Sampling {
    pub fn grid(&self) -> SubpixelGrid {
        match *self {
            Sampling::Grid(g) | Sampling::Jittered { grid: g, .. } => g,
        }
    }

    /// The sample offsets (in `[0,1)²`) for pixel number `pixel` (row-major index).
    pub fn offsets(&self, pixel: u64, out: &mut Vec<Vec2>) {
        out.clear();
        match *self {
            Sampling::Grid(g) => out.extend(g.offsets()),
            Sampling::Jittered { grid, seed } => {
                let s = grid.per_axis;
                let mut rng = SplitMix64::for_pixel(seed, pixel);
                for j in 0..s {
                    for i in 0..s {
                        let u = (i as f32 + rng.next_unit()) / s as f32;
                        let v = (j as f32 + rng.next_unit()) / s as f32;
                        out.push(Vec2::new(u.min(ONE_BELOW), v.min(ONE_BELOW)));
                    }
                }
            }
        }
    }

    pub fn describe(&self) -> String {
        let s = self.grid().per_axis;
        match self {
            Sampling::Grid(_) => format!("{s}x{s} grid"),
            Sampling::Jittered { seed, .. } => format!("{s}x{s} jittered, seed {seed}"),
        }
    }
}

/// Largest f32 below 1, so an offset never reaches the next pixel.
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// SplitMix64's output function: a bijection of u64 with full avalanche.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// SplitMix64 (Steele, Lea, Flood 2014): tiny, fast, well distributed; enough for jitter
/// and for the path integrator's per-pixel streams.
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// The stream of pixel `pixel` for `seed` (independent of thread scheduling).
    ///
    /// The start state goes through the finalizer twice: SplitMix64 walks its state in steps
    /// of γ, so starting pixel p at `seed ^ p·γ` (as an earlier version did) would make pixel
    /// p + 1's stream pixel p's shifted by one number — neighbouring pixels correlated.
    pub fn for_pixel(seed: u64, pixel: u64) -> Self {
        SplitMix64(mix(mix(seed).wrapping_add(pixel)))
    }
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(GAMMA);
        mix(self.0)
    }
    /// A stream of its own for one sample of this stream's pixel, seeded by this stream's
    /// next number (put through the finalizer, so that it does not continue this stream):
    /// the `path` integrator gives every sample its own stream, so a pixel's samples can be
    /// traced side by side (issue 41), yet drawn in the same order one at a time.
    pub fn split(&mut self) -> SplitMix64 {
        SplitMix64(mix(self.next()))
    }

    /// Uniform in [0, 1) with 24 bits.
    pub fn next_unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Streams of neighbouring pixels are unrelated: no stream is another shifted by a few
    /// numbers, and their first values are uncorrelated.
    #[test]
    fn pixel_streams_are_independent() {
        let first: Vec<Vec<f32>> = (0..256u64)
            .map(|p| {
                let mut r = SplitMix64::for_pixel(0, p);
                (0..8).map(|_| r.next_unit()).collect()
            })
            .collect();
        for p in 0..255 {
            for shift in 0..4 {
                assert_ne!(
                    first[p][shift..shift + 4],
                    first[p + 1][..4],
                    "pixel {} = pixel {p} shifted by {shift}",
                    p + 1
                );
            }
        }
        // Lag-1 correlation between neighbouring pixels' first numbers.
        let x: Vec<f64> = first.iter().map(|v| v[0] as f64 - 0.5).collect();
        let c: f64 =
            x.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / x.iter().map(|v| v * v).sum::<f64>();
        assert!(c.abs() < 0.2, "correlation {c}");
    }

    /// A split stream is neither its parent's continuation nor its sibling's.
    #[test]
    fn split_streams_are_independent() {
        let mut parent = SplitMix64::for_pixel(3, 9);
        let mut a = parent.split();
        let mut b = parent.split();
        let next: Vec<u64> = (0..8).map(|_| parent.next()).collect();
        let a8: Vec<u64> = (0..8).map(|_| a.next()).collect();
        let b8: Vec<u64> = (0..8).map(|_| b.next()).collect();
        for (x, y) in [(&a8, &b8), (&a8, &next), (&b8, &next)] {
            for shift in 0..4 {
                assert_ne!(x[shift..shift + 4], y[..4]);
                assert_ne!(y[shift..shift + 4], x[..4]);
            }
        }
    }

    #[test]
    fn jitter_stays_in_its_stratum_and_is_reproducible() {
        let s = Sampling::Jittered {
            grid: SubpixelGrid::new(3),
            seed: 7,
        };
        let (mut a, mut b, mut c) = (Vec::new(), Vec::new(), Vec::new());
        s.offsets(42, &mut a);
        s.offsets(42, &mut b);
        s.offsets(43, &mut c);
        assert_eq!(a, b);
        assert_ne!(a, c);
        for (k, o) in a.iter().enumerate() {
            let (i, j) = ((k % 3) as f32, (k / 3) as f32);
            assert!(o.x >= i / 3.0 && o.x < (i + 1.0) / 3.0, "{o}");
            assert!(o.y >= j / 3.0 && o.y < (j + 1.0) / 3.0, "{o}");
        }
    }
}
