//! Stereo pairs as a person looks at them: side by side (left eye on the left, for parallel
//! free viewing and VR players) and as a red–cyan anaglyph (red from the left eye's picture,
//! green and blue from the right's — the "colour anaglyph"). Both work on the displayed
//! 8-bit sRGB pictures (`docs/shading.md`, "Output transform").

/// The two pictures (`w × h` RGB bytes each) side by side: `2w × h`.
pub fn side_by_side(left: &[u8], right: &[u8], width: u32, height: u32) -> Vec<u8> {
    let row = 3 * width as usize;
    let mut out = Vec::with_capacity(2 * left.len());
    for y in 0..height as usize {
        out.extend_from_slice(&left[y * row..(y + 1) * row]);
        out.extend_from_slice(&right[y * row..(y + 1) * row]);
    }
    out
}

/// The red–cyan anaglyph of two pictures of the same size.
pub fn anaglyph(left: &[u8], right: &[u8]) -> Vec<u8> {
    left.chunks_exact(3)
        .zip(right.chunks_exact(3))
        .flat_map(|(l, r)| [l[0], r[1], r[2]])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_are_composed_pixel_for_pixel() {
        let l = [10, 20, 30, 40, 50, 60];
        let r = [1, 2, 3, 4, 5, 6];
        assert_eq!(
            side_by_side(&l, &r, 1, 2),
            vec![10, 20, 30, 1, 2, 3, 40, 50, 60, 4, 5, 6]
        );
        assert_eq!(anaglyph(&l, &r), vec![10, 2, 3, 40, 5, 6]);
    }
}
