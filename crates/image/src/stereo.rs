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

/// Where a marked object appears in a picture: the centroid (pixel-centre coordinates, x
/// right, y down) and size of the largest 4-connected blob of pixels whose colour has the
/// marker's chromaticity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blob {
    pub x: f64,
    pub y: f64,
    pub pixels: usize,
}

/// Largest L1 distance between a pixel's chromaticity `rgb / (r + g + b)` and the marker's for
/// the pixel to count as the marker. Under white light and grey mirrors (Lambert, the contract)
/// a marker pixel has its albedo's chromaticity exactly; edge pixels mixing it with a
/// neighbour fall out.
pub const MARKER_CHROMA_TOLERANCE: f32 = 0.05;

/// The largest blob of `image` (linear RGB, `width × height`) coloured like `albedo`
/// ([`MARKER_CHROMA_TOLERANCE`]), ignoring pixels darker than 1e-4 in `r + g + b`; `None` when
/// no pixel is. The first reflection of a marker in a row of reflections is its largest copy.
pub fn marker_blob(pixels: &[[f32; 3]], width: u32, albedo: [f32; 3]) -> Option<Blob> {
    let chroma = |c: [f32; 3]| {
        let sum = c[0] + c[1] + c[2];
        (sum > 1e-4).then(|| c.map(|v| v / sum))
    };
    let target = chroma(albedo)?;
    let marked: Vec<bool> = pixels
        .iter()
        .map(|&c| {
            chroma(c).is_some_and(|k| {
                (0..3).map(|i| (k[i] - target[i]).abs()).sum::<f32>() <= MARKER_CHROMA_TOLERANCE
            })
        })
        .collect();
    let w = width as usize;
    let mut seen = vec![false; marked.len()];
    let mut best: Option<Blob> = None;
    let mut stack = Vec::new();
    for start in 0..marked.len() {
        if !marked[start] || seen[start] {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        let (mut sx, mut sy, mut n) = (0.0f64, 0.0f64, 0usize);
        while let Some(i) = stack.pop() {
            let (x, y) = (i % w, i / w);
            sx += x as f64 + 0.5;
            sy += y as f64 + 0.5;
            n += 1;
            let mut visit = |j: usize| {
                if marked[j] && !seen[j] {
                    seen[j] = true;
                    stack.push(j);
                }
            };
            if x > 0 {
                visit(i - 1);
            }
            if x + 1 < w {
                visit(i + 1);
            }
            if i >= w {
                visit(i - w);
            }
            if i + w < marked.len() {
                visit(i + w);
            }
        }
        if best.is_none_or(|b| n > b.pixels) {
            best = Some(Blob {
                x: sx / n as f64,
                y: sy / n as f64,
                pixels: n,
            });
        }
    }
    best
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

    #[test]
    fn the_marker_is_its_largest_blob_of_its_chromaticity() {
        // 6×3: a 2-pixel green blob (dim and bright: the same chromaticity), a 3-pixel one,
        // a grey pixel and a yellowish-green one that are not the marker.
        let (g, dim, grey, off) = (
            [0.1, 0.8, 0.1],
            [0.01, 0.08, 0.01],
            [0.5, 0.5, 0.5],
            [0.3, 0.8, 0.1],
        );
        let o = [0.0; 3];
        #[rustfmt::skip]
        let px = [
            g,   dim, o,   o,   grey, off,
            o,   o,   o,   g,   o,    o,
            o,   o,   g,   g,   o,    o,
        ];
        let b = marker_blob(&px, 6, [0.2, 1.6, 0.2]).unwrap();
        assert_eq!(b.pixels, 3);
        assert!((b.x - (3.5 + 2.5 + 3.5) / 3.0).abs() < 1e-12, "{b:?}");
        assert!((b.y - (1.5 + 2.5 + 2.5) / 3.0).abs() < 1e-12, "{b:?}");
        assert_eq!(marker_blob(&px, 6, [1.0, 0.0, 0.0]), None);
    }
}
