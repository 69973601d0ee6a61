//! A heat colour ramp for scalar images (bounce counts, error heatmaps): black → purple →
//! red → orange → yellow → white, piecewise linear in sRGB between fixed stops, monotonic
//! in lightness so that grey-scale printing keeps the order.

const STOPS: [[f32; 3]; 6] = [
    [0.0, 0.0, 0.0],
    [0.32, 0.07, 0.47],
    [0.78, 0.16, 0.32],
    [0.98, 0.52, 0.10],
    [0.99, 0.88, 0.25],
    [1.0, 1.0, 1.0],
];

/// sRGB bytes for `v` in [0, 1] (clamped; NaN maps to 0).
pub fn heat(v: f32) -> [u8; 3] {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let x = v * (STOPS.len() - 1) as f32;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f32;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    [0, 1, 2].map(|c| ((a[c] + (b[c] - a[c]) * f) * 255.0).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_monotonic_lightness() {
        assert_eq!(heat(0.0), [0, 0, 0]);
        assert_eq!(heat(1.0), [255, 255, 255]);
        assert_eq!(heat(f32::NAN), [0, 0, 0]);
        let luma = |c: [u8; 3]| 0.2126 * c[0] as f32 + 0.7152 * c[1] as f32 + 0.0722 * c[2] as f32;
        let mut last = -1.0;
        for i in 0..=100 {
            let l = luma(heat(i as f32 / 100.0));
            assert!(l >= last - 0.5, "lightness drops at {i}");
            last = l;
        }
    }
}
