//! Image error metrics between a reference (the truth) and a test image of the same size.
//!
//! On linear HDR radiance, over all pixels and the three channels:
//! - RMSE = √mean((x − y)²);
//! - relMSE = mean((x − y)² / (y² + ε)) and SMAPE = mean(|x − y| / (|x| + |y| + ε)), ε = 0.01,
//!   with y the reference (the definitions of the rendering literature's denoising work);
//! - the largest absolute difference.
//!
//! On the contract's tone-mapped 8-bit sRGB images ([`crate::srgb`], the camera's exposure):
//! - PSNR = 10·log10(255² / MSE) (infinite for identical images);
//! - SSIM (Wang et al. 2004): 11×11 Gaussian window, σ = 1.5, K1 = 0.01, K2 = 0.03, on values
//!   in [0, 1], over the "valid" region (window fully inside the image), averaged over the
//!   three channels — the same numbers as scikit-image's `structural_similarity` with
//!   `gaussian_weights=True, sigma=1.5, use_sample_covariance=False, data_range=1`;
//! - FLIP (NVIDIA's LDR-FLIP through the `nv-flip` crate) at [`FLIP_PIXELS_PER_DEGREE`]: mean
//!   and the 95th/99th percentiles (nearest rank) of the per-pixel error map.
//!
//! [`compare_masked`] gives the same metrics over a subset of the pixels (a mirror mask): the
//! sums run over the masked pixels only; FLIP's map and SSIM's windows are computed on the
//! whole images (their filters see the neighbours) and averaged over the masked pixels (SSIM:
//! the valid windows centred on one).

use crate::RgbImage;

/// FLIP's default viewing condition: a 0.7 m wide 4K monitor seen from 0.7 m (67 px/°).
pub const FLIP_PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;
/// ε of relMSE and SMAPE.
pub const EPSILON: f64 = 0.01;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    pub rmse: f64,
    pub relmse: f64,
    pub smape: f64,
    pub max_abs: f64,
    /// dB; `f64::INFINITY` when the tone-mapped images are identical.
    pub psnr: f64,
    pub ssim: f64,
    pub flip_mean: f64,
    pub flip_p95: f64,
    pub flip_p99: f64,
}

/// Smallest image side the metrics accept: SSIM's window.
pub const MIN_SIDE: u32 = 11;

#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum MetricsError {
    #[error("images differ in size: reference {0}x{1}, test {2}x{3}")]
    SizeMismatch(u32, u32, u32, u32),
    #[error("images of {0}x{1} are too small for SSIM's 11x11 window")]
    TooSmall(u32, u32),
}

/// Every metric of `test` against `reference`; tone mapping uses `exposure`.
pub fn compare(
    reference: &RgbImage,
    test: &RgbImage,
    exposure: f32,
) -> Result<Metrics, MetricsError> {
    compare_detailed(reference, test, exposure).map(|c| c.metrics)
}

/// [`compare`] with what it computed on the way: both tone-mapped images and FLIP's map (an
/// error view paints them without computing them again).
pub struct Comparison {
    pub metrics: Metrics,
    /// RGB 8-bit sRGB after the contract's tone mapping, row-major.
    pub reference_srgb8: Vec<u8>,
    pub test_srgb8: Vec<u8>,
    /// FLIP's per-pixel error, row-major, in [0, 1].
    pub flip_map: Vec<f32>,
}

/// [`compare`], keeping the tone-mapped images and the FLIP map ([`Comparison`]).
pub fn compare_detailed(
    reference: &RgbImage,
    test: &RgbImage,
    exposure: f32,
) -> Result<Comparison, MetricsError> {
    check_sizes(reference, test)?;
    let r8 = reference.to_srgb8(exposure);
    let t8 = test.to_srgb8(exposure);
    let flip_map = flip_map(&r8, &t8, reference.width, reference.height);
    let metrics = metrics_over(reference, test, &r8, &t8, &flip_map, None)
        .expect("an unmasked image has pixels");
    Ok(Comparison {
        metrics,
        reference_srgb8: r8,
        test_srgb8: t8,
        flip_map,
    })
}

impl Comparison {
    /// The metrics over the pixels where `mask` (row-major, one per pixel) is true, from the
    /// images this comparison was made of; `None` when no pixel is, or the mask is not one per
    /// pixel.
    pub fn masked(&self, reference: &RgbImage, test: &RgbImage, mask: &[bool]) -> Option<Metrics> {
        if mask.len() != reference.pixels.len() || reference.pixels.len() != test.pixels.len() {
            return None;
        }
        metrics_over(
            reference,
            test,
            &self.reference_srgb8,
            &self.test_srgb8,
            &self.flip_map,
            Some(mask),
        )
    }
}

fn check_sizes(reference: &RgbImage, test: &RgbImage) -> Result<(), MetricsError> {
    if (reference.width, reference.height) != (test.width, test.height) {
        return Err(MetricsError::SizeMismatch(
            reference.width,
            reference.height,
            test.width,
            test.height,
        ));
    }
    if reference.width < MIN_SIDE || reference.height < MIN_SIDE {
        return Err(MetricsError::TooSmall(reference.width, reference.height));
    }
    Ok(())
}

/// Every metric over the pixels `mask` keeps (all without one); `None` when it keeps none.
fn metrics_over(
    reference: &RgbImage,
    test: &RgbImage,
    r8: &[u8],
    t8: &[u8],
    flip_map: &[f32],
    mask: Option<&[bool]>,
) -> Option<Metrics> {
    let kept = |i: usize| mask.is_none_or(|m| m[i]);
    let (mut se, mut rel, mut smape, mut max_abs) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut pixels = 0usize;
    for (i, (y, x)) in reference.pixels.iter().zip(&test.pixels).enumerate() {
        if !kept(i) {
            continue;
        }
        pixels += 1;
        for c in 0..3 {
            let (x, y) = (x[c] as f64, y[c] as f64);
            let d = x - y;
            se += d * d;
            rel += d * d / (y * y + EPSILON);
            smape += d.abs() / (x.abs() + y.abs() + EPSILON);
            max_abs = max_abs.max(d.abs());
        }
    }
    if pixels == 0 {
        return None;
    }
    let n = (pixels * 3) as f64;
    let bytes = |img: &[u8]| -> Vec<u8> {
        img.chunks_exact(3)
            .enumerate()
            .filter(|(i, _)| kept(*i))
            .flat_map(|(_, p)| p.iter().copied())
            .collect()
    };
    let flips: Vec<f32> = flip_map
        .iter()
        .enumerate()
        .filter(|(i, _)| kept(*i))
        .map(|(_, v)| *v)
        .collect();
    let (flip_mean, flip_p95, flip_p99) = flip_stats(&flips);
    let (w, h) = (reference.width as usize, reference.height as usize);
    Some(Metrics {
        rmse: (se / n).sqrt(),
        relmse: rel / n,
        smape: smape / n,
        max_abs,
        psnr: match mask {
            None => psnr(r8, t8),
            Some(_) => psnr(&bytes(r8), &bytes(t8)),
        },
        ssim: ssim_over(r8, t8, w, h, mask),
        flip_mean,
        flip_p95,
        flip_p99,
    })
}

/// PSNR of two 8-bit images (same length).
pub fn psnr(a: &[u8], b: &[u8]) -> f64 {
    let mse = a
        .iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y as f64).powi(2))
        .sum::<f64>()
        / a.len() as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    }
}

/// Normalized 1-D Gaussian of 11 taps, σ = 1.5.
fn gaussian_11() -> [f64; 11] {
    let mut k = [0.0; 11];
    for (i, v) in k.iter_mut().enumerate() {
        let x = i as f64 - 5.0;
        *v = (-(x * x) / (2.0 * 1.5 * 1.5)).exp();
    }
    let sum: f64 = k.iter().sum();
    k.map(|v| v / sum)
}

/// Separable valid filtering of the `w × h` plane `src` by the 11 taps `k`: rows, then
/// columns; `(w − 10) × (h − 10)` values. Each output is `Σₜ k[t]·x[t]` added in tap order
/// from −0.0, as `Iterator::sum` over the window adds it; the taps are the outer loop, so
/// that the inner one runs along a row over independent outputs and vectorises. The
/// reference [`ssim_over`] streams row by row, held by the tests to a direct sum.
#[cfg(test)]
fn gaussian_11_valid(k: &[f64; 11], src: &[f64], w: usize, h: usize) -> Vec<f64> {
    debug_assert_eq!(src.len(), w * h);
    let (vw, vh) = (w - 10, h - 10);
    if vw == 0 || vh == 0 {
        return Vec::new();
    }
    let mut rows = vec![-0.0; vw * h];
    for (row, line) in rows.chunks_exact_mut(vw).zip(src.chunks_exact(w)) {
        for (t, &kt) in k.iter().enumerate() {
            for (acc, &v) in row.iter_mut().zip(&line[t..t + vw]) {
                *acc += kt * v;
            }
        }
    }
    let mut out = vec![-0.0; vw * vh];
    for (j, row) in out.chunks_exact_mut(vw).enumerate() {
        for (t, &kt) in k.iter().enumerate() {
            let line = &rows[(j + t) * vw..(j + t + 1) * vw];
            for (acc, &v) in row.iter_mut().zip(line) {
                *acc += kt * v;
            }
        }
    }
    out
}

/// Mean SSIM of two interleaved RGB 8-bit images (values taken as /255), averaged over the
/// channels, on the valid region.
pub fn ssim(a: &[u8], b: &[u8], w: usize, h: usize) -> f64 {
    ssim_over(a, b, w, h, None)
}

/// [`ssim`] averaged over the valid windows centred on a pixel `mask` keeps (all without
/// one); NaN where it keeps none of them.
///
/// Row by row: each source row's five planes (x, y, x², y², xy) filtered along the row into a
/// ring of the last 11, and each output row filtered down the ring and summed as it is made —
/// memory of 11 rows, not of ten whole planes (an 8192² comparison had needed 8 GB). The
/// arithmetic is [`gaussian_11_valid`]'s, term for term and in its order, and the windows are
/// summed in the same row-major order: the same bits as filtering whole planes (tested).
fn ssim_over(a: &[u8], b: &[u8], w: usize, h: usize, mask: Option<&[bool]>) -> f64 {
    let k = gaussian_11();
    let (c1, c2) = ((0.01f64).powi(2), (0.03f64).powi(2));
    let (vw, vh) = (w - 10, h - 10);
    let mut total = 0.0;
    for c in 0..3 {
        // The five planes of one source row, and the ring of filtered rows: [plane][slot][col].
        let mut line = vec![0.0f64; 5 * w];
        let mut ring = vec![-0.0f64; 5 * 11 * vw];
        let mut out = vec![-0.0f64; 5 * vw];
        let (mut sum, mut windows) = (0.0, 0usize);
        for r in 0..h {
            for i in 0..w {
                let x = a[3 * (r * w + i) + c] as f64 / 255.0;
                let y = b[3 * (r * w + i) + c] as f64 / 255.0;
                for (q, v) in [x, y, x * x, y * y, x * y].into_iter().enumerate() {
                    line[q * w + i] = v;
                }
            }
            let slot = r % 11;
            for q in 0..5 {
                let src = &line[q * w..(q + 1) * w];
                let row = &mut ring[(q * 11 + slot) * vw..(q * 11 + slot + 1) * vw];
                row.fill(-0.0);
                for (t, &kt) in k.iter().enumerate() {
                    for (acc, &v) in row.iter_mut().zip(&src[t..t + vw]) {
                        *acc += kt * v;
                    }
                }
            }
            if r < 10 || vw == 0 {
                continue;
            }
            let j = r - 10;
            for q in 0..5 {
                let o = &mut out[q * vw..(q + 1) * vw];
                o.fill(-0.0);
                for (t, &kt) in k.iter().enumerate() {
                    let s = (q * 11 + (j + t) % 11) * vw;
                    for (acc, &v) in o.iter_mut().zip(&ring[s..s + vw]) {
                        *acc += kt * v;
                    }
                }
            }
            for col in 0..vw {
                // The window's centre pixel.
                let centre = (j + 5) * w + col + 5;
                if mask.is_some_and(|m| !m[centre]) {
                    continue;
                }
                let [ux, uy, mxx, myy, mxy] = [0, 1, 2, 3, 4].map(|q| out[q * vw + col]);
                let (vx, vy, cxy) = (mxx - ux * ux, myy - uy * uy, mxy - ux * uy);
                sum += ((2.0 * ux * uy + c1) * (2.0 * cxy + c2))
                    / ((ux * ux + uy * uy + c1) * (vx + vy + c2));
                windows += 1;
            }
        }
        debug_assert!(vh == 0 || windows <= vw * vh);
        total += sum / windows as f64;
    }
    total / 3.0
}

/// FLIP mean, 95th and 99th percentile (nearest rank) of two interleaved RGB 8-bit images.
pub fn flip(reference: &[u8], test: &[u8], w: u32, h: u32) -> (f64, f64, f64) {
    flip_stats(&flip_map(reference, test, w, h))
}

/// Mean, 95th and 99th percentile (nearest rank) of a FLIP map.
fn flip_stats(map: &[f32]) -> (f64, f64, f64) {
    let mut v = map.to_vec();
    let mean = v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
    v.sort_by(f32::total_cmp);
    let rank =
        |p: f64| v[(((p * v.len() as f64).ceil() as usize).max(1) - 1).min(v.len() - 1)] as f64;
    (mean, rank(0.95), rank(0.99))
}

/// Host memory a comparison of two images needs per pixel, bytes: FLIP's filtered colour
/// images (nv_flip's C++, ~76 bytes a pixel) and our linear and sRGB copies of both images
/// with the FLIP map (~30); measured with heaptrack at 1024² (106 bytes a pixel at the peak)
/// and by peak RSS at 4096² (1.75 GB, 104), with a margin. SSIM streams its planes.
pub const COMPARE_BYTES_PER_PIXEL: u64 = 112;

/// Host memory a comparison of two `width × height` images needs, bytes
/// ([`COMPARE_BYTES_PER_PIXEL`] a pixel): what `compare` and `score` hold to a budget.
pub fn compare_bytes(width: u32, height: u32) -> u64 {
    u64::from(width) * u64::from(height) * COMPARE_BYTES_PER_PIXEL
}

/// FLIP's per-pixel error map (row-major, values in [0, 1]).
pub fn flip_map(reference: &[u8], test: &[u8], w: u32, h: u32) -> Vec<f32> {
    let r = nv_flip::FlipImageRgb8::with_data(w, h, reference);
    let t = nv_flip::FlipImageRgb8::with_data(w, h, test);
    nv_flip::flip(r, t, FLIP_PIXELS_PER_DEGREE).to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The window filter gives the bits of the direct sum over each window, `Σₜ k[t]·x` one
    /// output at a time in tap order (the code it replaced), on planes of SSIM's values.
    #[test]
    fn the_vectorised_window_filter_gives_the_direct_sums_bits() {
        let k = gaussian_11();
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        for (w, h) in [(10, 14), (11, 11), (12, 17), (37, 23), (640, 24)] {
            let src: Vec<f64> = (0..w * h)
                .map(|_| {
                    if w == 11 {
                        return -0.0; // a plane of negative zeros keeps its sign
                    }
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    let v = (state % 256) as f64 / 255.0;
                    // A plane of values, of squares and of products, as SSIM filters.
                    v * ((state >> 8) % 256) as f64 / 255.0
                })
                .collect();
            let (vw, vh) = (w - 10, h - 10);
            let mut rows = vec![0.0; vw * h];
            for r in 0..h {
                for i in 0..vw {
                    rows[r * vw + i] = (0..11).map(|t| k[t] * src[r * w + i + t]).sum();
                }
            }
            let direct: Vec<f64> = (0..vw * vh)
                .map(|o| {
                    let (j, i) = (o / vw, o % vw);
                    (0..11).map(|t| k[t] * rows[(j + t) * vw + i]).sum()
                })
                .collect();
            let filtered = gaussian_11_valid(&k, &src, w, h);
            assert_eq!(filtered.len(), direct.len());
            for (o, (a, b)) in filtered.iter().zip(&direct).enumerate() {
                assert_eq!(a.to_bits(), b.to_bits(), "{w}×{h}, output {o}: {a} vs {b}");
            }
        }
    }

    /// The whole-plane SSIM that [`ssim_over`] streams (the reference for its bits).
    fn ssim_over_planes(a: &[u8], b: &[u8], w: usize, h: usize, mask: Option<&[bool]>) -> f64 {
        let k = gaussian_11();
        let (c1, c2) = ((0.01f64).powi(2), (0.03f64).powi(2));
        let (vw, vh) = (w - 10, h - 10);
        let mut total = 0.0;
        for c in 0..3 {
            let plane = |img: &[u8]| -> Vec<f64> {
                (0..w * h).map(|i| img[3 * i + c] as f64 / 255.0).collect()
            };
            let (x, y) = (plane(a), plane(b));
            let xx: Vec<f64> = x.iter().map(|v| v * v).collect();
            let yy: Vec<f64> = y.iter().map(|v| v * v).collect();
            let xy: Vec<f64> = x.iter().zip(&y).map(|(p, q)| p * q).collect();
            let filter = |src: &[f64]| gaussian_11_valid(&k, src, w, h);
            let (mx, my, mxx, myy, mxy) = (
                filter(&x),
                filter(&y),
                filter(&xx),
                filter(&yy),
                filter(&xy),
            );
            let (mut sum, mut windows) = (0.0, 0usize);
            for i in 0..vw * vh {
                // The window's centre pixel.
                let centre = (i / vw + 5) * w + i % vw + 5;
                if mask.is_some_and(|m| !m[centre]) {
                    continue;
                }
                let (ux, uy) = (mx[i], my[i]);
                let (vx, vy, cxy) = (mxx[i] - ux * ux, myy[i] - uy * uy, mxy[i] - ux * uy);
                sum += ((2.0 * ux * uy + c1) * (2.0 * cxy + c2))
                    / ((ux * ux + uy * uy + c1) * (vx + vy + c2));
                windows += 1;
            }
            total += sum / windows as f64;
        }
        total / 3.0
    }
    /// Streamed row by row, SSIM is the whole planes' to the bit, with and without a mask,
    /// at sizes down to the one window.
    #[test]
    fn ssim_by_rows_is_ssim_by_planes_to_the_bit() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut byte = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 24) as u8
        };
        for (w, h) in [(11, 11), (12, 30), (37, 23), (64, 36)] {
            let a: Vec<u8> = (0..3 * w * h).map(|_| byte()).collect();
            // b: a, partly disturbed (so the structure term is not 1 everywhere).
            let b: Vec<u8> = a
                .iter()
                .map(|&v| if byte() % 3 == 0 { byte() } else { v })
                .collect();
            let mask: Vec<bool> = (0..w * h).map(|_| byte() % 2 == 0).collect();
            for m in [None, Some(mask.as_slice())] {
                let (rows, planes) = (
                    ssim_over(&a, &b, w, h, m),
                    ssim_over_planes(&a, &b, w, h, m),
                );
                assert_eq!(
                    rows.to_bits(),
                    planes.to_bits(),
                    "{w}×{h}: {rows} vs {planes}"
                );
            }
        }
    }

    #[test]
    fn a_mask_restricts_the_error_to_its_pixels() {
        // Identical images but for the left half: the error over the right half is zero,
        // over the left half larger than over the whole image.
        let (w, h) = (32, 24);
        let reference = pattern(w, h, 1);
        let mut test = reference.clone();
        for y in 0..h {
            for x in 0..w / 2 {
                test.pixels[(y * w + x) as usize] = [0.9, 0.1, 0.1];
            }
        }
        let c = compare_detailed(&reference, &test, 1.0).unwrap();
        let left: Vec<bool> = (0..w * h).map(|i| i % w < w / 2).collect();
        let right: Vec<bool> = left.iter().map(|l| !l).collect();
        let l = c.masked(&reference, &test, &left).unwrap();
        let r = c.masked(&reference, &test, &right).unwrap();
        assert!(l.rmse > c.metrics.rmse && c.metrics.rmse > 0.0);
        assert_eq!(r.rmse, 0.0);
        assert!(l.flip_mean > c.metrics.flip_mean);
        assert!(r.ssim > l.ssim);
        // Whole image = pixel-weighted mean of the halves (for the mean-type metrics).
        assert!((c.metrics.flip_mean - (l.flip_mean + r.flip_mean) / 2.0).abs() < 1e-9);
        assert!(
            c.masked(&reference, &test, &vec![false; (w * h) as usize])
                .is_none()
        );
    }

    fn constant(w: u32, h: u32, v: [f32; 3]) -> RgbImage {
        RgbImage::from_fn(w, h, |_, _| v)
    }

    fn pattern(w: u32, h: u32, seed: u32) -> RgbImage {
        RgbImage::from_fn(w, h, |x, y| {
            let v = ((x * 7 + y * 13 + seed * 31) % 17) as f32 / 17.0;
            [v, (v * 0.5 + 0.1 * (x % 3) as f32).min(1.0), 1.0 - v]
        })
    }

    #[test]
    fn identical_images() {
        let a = pattern(32, 24, 1);
        let m = compare(&a, &a, 1.0).unwrap();
        assert_eq!((m.rmse, m.relmse, m.smape, m.max_abs), (0.0, 0.0, 0.0, 0.0));
        assert_eq!(m.psnr, f64::INFINITY);
        assert!((m.ssim - 1.0).abs() < 1e-12);
        assert_eq!((m.flip_mean, m.flip_p95, m.flip_p99), (0.0, 0.0, 0.0));
    }

    /// Constant images: every metric has a closed form.
    #[test]
    fn closed_forms_on_constant_images() {
        let (y, x) = (0.25f32, 0.5f32);
        let r = constant(20, 16, [y; 3]);
        let t = constant(20, 16, [x; 3]);
        let m = compare(&r, &t, 1.0).unwrap();
        let (x, y) = (x as f64, y as f64);
        assert!((m.rmse - 0.25).abs() < 1e-12);
        assert!((m.max_abs - 0.25).abs() < 1e-12);
        assert!((m.relmse - (x - y).powi(2) / (y * y + 0.01)).abs() < 1e-12);
        assert!((m.smape - (x - y).abs() / (x + y + 0.01)).abs() < 1e-12);
        // Tone mapped: 0.25 → sRGB 137, 0.5 → 188 (round(255·sRGB(v))).
        let (a8, b8) = (
            crate::srgb::encode8(0.25) as f64,
            crate::srgb::encode8(0.5) as f64,
        );
        assert_eq!((a8, b8), (137.0, 188.0));
        assert!((m.psnr - 10.0 * (255.0f64.powi(2) / (a8 - b8).powi(2)).log10()).abs() < 1e-9);
        // Flat windows: variances and covariance vanish, only the luminance term is left.
        let (ua, ub, c1) = (a8 / 255.0, b8 / 255.0, 1e-4);
        let expected = (2.0 * ua * ub + c1) / (ua * ua + ub * ub + c1);
        assert!((m.ssim - expected).abs() < 1e-9, "{} vs {expected}", m.ssim);
    }

    #[test]
    fn size_mismatch_and_tiny_images_are_errors() {
        assert_eq!(
            compare(
                &constant(20, 16, [0.0; 3]),
                &constant(16, 20, [0.0; 3]),
                1.0
            )
            .unwrap_err(),
            MetricsError::SizeMismatch(20, 16, 16, 20)
        );
        assert_eq!(
            compare(&constant(8, 8, [0.0; 3]), &constant(8, 8, [0.0; 3]), 1.0).unwrap_err(),
            MetricsError::TooSmall(8, 8)
        );
    }

    #[test]
    fn flip_grows_with_the_difference() {
        let r = constant(32, 32, [0.2; 3]);
        let small = compare(&r, &constant(32, 32, [0.22; 3]), 1.0)
            .unwrap()
            .flip_mean;
        let large = compare(&r, &constant(32, 32, [0.6; 3]), 1.0)
            .unwrap()
            .flip_mean;
        assert!(
            0.0 < small && small < large && large <= 1.0,
            "{small} {large}"
        );
    }
}
