#!/usr/bin/env python3
"""Makes the metric test pair (reference.png, test.png, 64x48 sRGB) and prints the values
that published implementations give for it; crates/image/tests/reference_metrics.rs checks
ours against them. Needs numpy, imageio, scikit-image and flip-evaluator (pip)."""
import numpy as np
import imageio.v3 as iio
from skimage.metrics import structural_similarity
import flip_evaluator

h, w = 48, 64
y, x = np.mgrid[0:h, 0:w]
ref = np.stack([
    0.5 + 0.4 * np.sin(x / 6.0) * np.cos(y / 9.0),
    (x + y) / (w + h),
    0.3 + 0.5 * ((x // 8 + y // 8) % 2),
], axis=-1)
rng = np.random.default_rng(7)
test = np.clip(ref + rng.normal(0, 0.04, ref.shape) + 0.05 * (x > 40)[..., None], 0, 1)
ref8 = np.round(np.clip(ref, 0, 1) * 255).astype(np.uint8)
test8 = np.round(test * 255).astype(np.uint8)
iio.imwrite("reference.png", ref8)
iio.imwrite("test.png", test8)
a, b = ref8 / 255.0, test8 / 255.0
ssim = structural_similarity(a, b, gaussian_weights=True, sigma=1.5, use_sample_covariance=False,
                             data_range=1.0, channel_axis=2)
mse = np.mean((ref8.astype(float) - test8.astype(float)) ** 2)
flip_map, flip_mean, _ = flip_evaluator.evaluate(a.astype(np.float32), b.astype(np.float32), "LDR",
                                                 applyMagma=False, parameters={"ppd": 67.0})
print(f"ssim {ssim:.12f}")
print(f"psnr {10 * np.log10(255 ** 2 / mse):.12f}")
print(f"flip_mean {flip_mean:.9f}")
