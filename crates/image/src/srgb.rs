//! The contract's output transform: linear radiance × exposure, clamped to [0, 1], then the
//! standard sRGB transfer function (IEC 61966-2-1), quantized to 8 bits by rounding.

/// sRGB OETF for a linear value (clamped to [0, 1]).
pub fn encode(linear: f32) -> f32 {
    let c = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    };
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse of [`encode`] on [0, 1].
pub fn decode(encoded: f32) -> f32 {
    let c = encoded.clamp(0.0, 1.0);
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// [`encode`] quantized to 8 bits (round to nearest).
pub fn encode8(linear: f32) -> u8 {
    (encode(linear) * 255.0).round() as u8
}

pub fn decode8(v: u8) -> f32 {
    decode(v as f32 / 255.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values_and_continuity() {
        assert_eq!(encode8(0.0), 0);
        assert_eq!(encode8(1.0), 255);
        assert_eq!(encode8(2.0), 255);
        assert_eq!(encode8(-1.0), 0);
        assert_eq!(encode8(f32::NAN), 0);
        // Middle grey 0.18 → 0.4614 → 118 (published sRGB tables).
        assert_eq!(encode8(0.18), 118);
        assert_eq!(encode8(0.5), 188);
        // The two pieces meet at the breakpoint.
        let b = 0.003_130_8f32;
        assert!((12.92 * b - (1.055 * b.powf(1.0 / 2.4) - 0.055)).abs() < 1e-6);
    }

    #[test]
    fn decode_inverts_encode() {
        for i in 0..=100 {
            let x = i as f32 / 100.0;
            assert!((decode(encode(x)) - x).abs() < 1e-5);
        }
        for v in 0..=255u8 {
            assert_eq!(encode8(decode8(v)), v);
        }
    }
}
