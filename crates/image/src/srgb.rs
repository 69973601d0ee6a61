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

/// The table that lets a GPU write [`encode8`]'s bytes exactly, whatever its `pow`: entry
/// `k` (1…255) is the smallest `f32` that `encode8` maps to `k` or above (entry 0 is unused,
/// 0). `encode8` is monotone, so `encode8(v)` is the number of entries `k ≥ 1` with
/// `v ≥ table[k]` ([`encode8_by_thresholds`]). Found by bisecting the bit patterns of [0, 1],
/// which order as the values do.
pub fn encode8_thresholds() -> [f32; 256] {
    let mut table = [0.0f32; 256];
    let one = 1.0f32.to_bits();
    for (k, entry) in table.iter_mut().enumerate().skip(1) {
        // Smallest bit pattern in [0, one] whose byte is ≥ k (encode8(1.0) = 255).
        let (mut lo, mut hi) = (0u32, one);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if usize::from(encode8(f32::from_bits(mid))) >= k {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        *entry = f32::from_bits(lo);
    }
    table
}

/// [`encode8`] by the table of [`encode8_thresholds`], as `shaders/display_tone_map.wgsl`
/// computes it (its `byte_of`, step for step): the sign and NaN decided on the bit pattern,
/// the rest compared as bit patterns (non-negative floats order as their bits), a guess of
/// the byte from the transfer function, then a walk through the table to the byte whose
/// thresholds enclose the value. `guess` stands for the GPU's `pow`, whose precision WGSL
/// leaves open: the walk ends at the same byte whatever it returns.
pub fn encode8_by_thresholds(v: f32, table: &[f32; 256], guess: impl Fn(f32) -> f32) -> u8 {
    let b = v.to_bits();
    let t = |k: usize| table[k].to_bits();
    if b >= 0x8000_0000 || b > 0x7f80_0000 || b < t(1) {
        return 0;
    }
    if b >= t(255) {
        return 255;
    }
    let e = guess(v.clamp(0.0, 1.0));
    // WGSL's u32(f32) saturates, as Rust's `as` does.
    let mut k = ((e * 255.0 + 0.5) as u32).clamp(1, 254) as usize;
    while b < t(k) {
        k -= 1;
    }
    while b >= t(k + 1) {
        k += 1;
    }
    k as u8
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

    /// The shader's transfer function, as a first guess.
    fn pow_guess(x: f32) -> f32 {
        encode(x)
    }

    /// The table gives encode8's byte: at every threshold and the 2¹⁶ floats on each side
    /// of it (the only places a byte changes), across [0, 1] on a grid, and for what lies
    /// outside — with the transfer function's guess, and with guesses off by far more than
    /// any GPU `pow` could be (the walk must end at the same byte).
    #[test]
    fn thresholds_give_encode8s_bytes() {
        let table = encode8_thresholds();
        let guesses: [&dyn Fn(f32) -> f32; 4] = [
            &pow_guess,
            &|x| (pow_guess(x) + 3.0 / 255.0).min(1.0),
            &|x| (pow_guess(x) - 2.0 / 255.0).max(0.0),
            &|_| f32::NAN,
        ];
        for k in 1..=255usize {
            let t = table[k];
            assert!(usize::from(encode8(t)) >= k, "t_{k} = {t}");
            assert!(usize::from(encode8(f32::from_bits(t.to_bits() - 1))) < k);
            assert!(table[k - 1] <= t, "the table is sorted at {k}");
            for d in -(1i64 << 16)..=(1 << 16) {
                let v = f32::from_bits((i64::from(t.to_bits()) + d) as u32);
                assert_eq!(
                    encode8_by_thresholds(v, &table, pow_guess),
                    encode8(v),
                    "{v:e}"
                );
            }
        }
        let specials = [
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -0.0,
            0.0,
        ];
        let outside = [
            -1.0,
            -1e-30,
            1.0,
            1.000_001,
            7.5,
            f32::MAX,
            f32::MIN_POSITIVE,
            1e-40,
        ];
        let grid = (0..=1_000_000).map(|i| i as f32 / 1_000_000.0);
        for v in specials.into_iter().chain(outside).chain(grid) {
            for guess in guesses {
                assert_eq!(encode8_by_thresholds(v, &table, guess), encode8(v), "{v:e}");
            }
        }
    }

    /// Every f32 in [0, 1] (1.07·10⁹ of them, ~5 s in release): run with `--ignored` after
    /// changing `encode`. Passed on 2026-11-26 (glibc's powf, x86-64).
    #[test]
    #[ignore = "1.07e9 f32s, ~5 s in release: run with --ignored after changing encode"]
    fn thresholds_give_encode8s_bytes_for_every_f32_in_0_1() {
        let table = encode8_thresholds();
        for bits in 0..=1.0f32.to_bits() {
            let v = f32::from_bits(bits);
            assert_eq!(
                encode8_by_thresholds(v, &table, pow_guess),
                encode8(v),
                "{v:e}"
            );
        }
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
