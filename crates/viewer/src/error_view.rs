//! The live error view: where and how much the method differs from the truth of the same
//! view, as a heat map, with the metrics `compare` reports.
//!
//! Both maps are on the contract's tone-mapped 8-bit sRGB images (`docs/shading.md`):
//! - `difference`: the mean over R, G, B of |method − truth| / 255, times a gain (a gain of
//!   4 paints a difference of a quarter of the range white), through the project's heat
//!   ramp;
//! - `flip`: NVIDIA's LDR-FLIP map (the metric the reports use), values in [0, 1].
//!
//! Only a complete truth (the full-size level) is compared: a coarse level would show the
//! truth's own blur, not the method's error.

use mirrorbox_image::metrics::{self, Metrics, MetricsError};
use mirrorbox_image::{RgbImage, colormap};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorMode {
    Difference,
    Flip,
}

impl ErrorMode {
    pub const ALL: [ErrorMode; 2] = [ErrorMode::Difference, ErrorMode::Flip];

    pub fn name(self) -> &'static str {
        match self {
            ErrorMode::Difference => "difference",
            ErrorMode::Flip => "flip",
        }
    }

    pub fn parse(text: &str) -> Option<ErrorMode> {
        ErrorMode::ALL.into_iter().find(|m| m.name() == text)
    }
}

/// A heat map (RGB 8-bit sRGB, row-major) and the metrics of the method against the truth.
pub struct ErrorImage {
    pub width: u32,
    pub height: u32,
    pub heat_rgb8: Vec<u8>,
    pub metrics: Metrics,
}

/// The error of `method` against `truth` (same size), tone-mapped with `exposure`.
pub fn error_image(
    truth: &RgbImage,
    method: &RgbImage,
    exposure: f32,
    mode: ErrorMode,
    gain: f32,
) -> Result<ErrorImage, MetricsError> {
    let c = metrics::compare_detailed(truth, method, exposure)?;
    let values: Vec<f32> = match mode {
        ErrorMode::Difference => c
            .reference_srgb8
            .chunks_exact(3)
            .zip(c.test_srgb8.chunks_exact(3))
            .map(|(a, b)| {
                let sum: u32 = (0..3).map(|c| u32::from(a[c].abs_diff(b[c]))).sum();
                sum as f32 / (3.0 * 255.0) * gain
            })
            .collect(),
        ErrorMode::Flip => c.flip_map,
    };
    Ok(ErrorImage {
        width: truth.width,
        height: truth.height,
        heat_rgb8: values.iter().flat_map(|&v| colormap::heat(v)).collect(),
        metrics: c.metrics,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(v: impl Fn(u32, u32) -> [f32; 3]) -> RgbImage {
        RgbImage::from_fn(32, 24, v)
    }

    #[test]
    fn identical_images_are_black_and_a_difference_shows_where_it_is() {
        let truth = image(|x, _| [x as f32 / 32.0, 0.2, 0.1]);
        for mode in ErrorMode::ALL {
            let same = error_image(&truth, &truth, 1.0, mode, 4.0).unwrap();
            assert!(same.heat_rgb8.iter().all(|&b| b == 0), "{mode:?}");
            assert_eq!(same.metrics.flip_mean, 0.0);
        }
        // The method is wrong in the right half only.
        let method = image(|x, _| {
            if x >= 16 {
                [1.0, 1.0, 1.0]
            } else {
                [x as f32 / 32.0, 0.2, 0.1]
            }
        });
        for mode in ErrorMode::ALL {
            let e = error_image(&truth, &method, 1.0, mode, 4.0).unwrap();
            let at = |x: usize, y: usize| &e.heat_rgb8[(y * 32 + x) * 3..][..3];
            assert!(at(28, 12).iter().any(|&b| b > 100), "{mode:?}");
            assert_eq!(at(2, 12), [0, 0, 0], "{mode:?}");
            assert!(e.metrics.flip_mean > 0.0);
        }
        assert_eq!(ErrorMode::parse("flip"), Some(ErrorMode::Flip));
        assert_eq!(ErrorMode::parse("nope"), None);
    }

    #[test]
    fn images_of_different_sizes_are_refused() {
        let a = image(|_, _| [0.0; 3]);
        let b = RgbImage::from_fn(16, 24, |_, _| [0.0; 3]);
        assert!(error_image(&a, &b, 1.0, ErrorMode::Difference, 1.0).is_err());
    }
}
