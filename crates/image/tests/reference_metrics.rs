//! Our SSIM, PSNR and FLIP against published implementations on a fixed image pair
//! (`tests/data/*.png`, made by `tests/data/make_reference_pair.py`). Reference values were
//! computed with scikit-image 0.26.0 (`structural_similarity(gaussian_weights=True,
//! sigma=1.5, use_sample_covariance=False, data_range=1.0, channel_axis=2)`), numpy 2.4.6
//! (PSNR) and NVIDIA's flip-evaluator 1.7 (`evaluate(..., "LDR", parameters={"ppd": 67.0})`).

use mirrorbox_image::metrics::{flip, psnr, ssim};
use mirrorbox_image::read_image;
use std::path::Path;

fn pair() -> (Vec<u8>, Vec<u8>, u32, u32) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let r = read_image(&dir.join("reference.png")).unwrap();
    let t = read_image(&dir.join("test.png")).unwrap();
    // PNG → linear → the contract's 8-bit encoding is the identity on 8-bit sRGB values.
    (r.to_srgb8(1.0), t.to_srgb8(1.0), r.width, r.height)
}

#[test]
fn ssim_matches_scikit_image() {
    let (r, t, w, h) = pair();
    let ours = ssim(&r, &t, w as usize, h as usize);
    assert!((ours - 0.766097366515).abs() < 1e-9, "{ours}");
}

#[test]
fn psnr_matches_numpy() {
    let (r, t, _, _) = pair();
    assert!((psnr(&r, &t) - 26.062980986478).abs() < 1e-9);
}

#[test]
fn flip_mean_matches_nvidia_flip_evaluator() {
    let (r, t, w, h) = pair();
    let (mean, p95, p99) = flip(&r, &t, w, h);
    // Both run NVIDIA's C++ FLIP; f32 accumulation order may differ in the last digits.
    assert!((mean - 0.149692491).abs() < 1e-5, "{mean}");
    assert!(mean <= p95 && p95 <= p99 && p99 <= 1.0);
}
