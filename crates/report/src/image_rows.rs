//! Image rows a reader can use (issue 38): every truth | raster | FLIP row gets column
//! headers and a FLIP colour bar in the HTML, and a 4× inset of the window where its error is
//! largest — the error of a mirror method lives in a few reflections, too small to see at the
//! row's size.
//!
//! The inset is found on the row's own PNGs: FLIP between the truth's and the raster's 8-bit
//! images (the metric the row shows), summed over every window of an eighth of the image's
//! width and height (a summed-area table), the largest taken; the truth's, the raster's and
//! the FLIP map's crops side by side, each magnified 4× (nearest neighbour: no invented
//! detail), into `<raster>_inset.png` beside the row's images.

use crate::document::Block;
use mirrorbox_image::colormap::heat;
use mirrorbox_image::{read_image, write_png_bytes};
use std::fmt::Write as _;
use std::path::Path;

/// Magnification of the inset.
pub const INSET_ZOOM: u32 = 4;
/// White pixels between the inset's three crops.
const GAP: u32 = 6;

/// The HTML of the FLIP colour bar: the heat ramp the maps are painted with, 0 to 1.
pub fn colour_bar_html() -> String {
    let stops: Vec<String> = (0..=10)
        .map(|i| {
            let [r, g, b] = heat(i as f32 / 10.0);
            format!("rgb({r},{g},{b}) {}%", i * 10)
        })
        .collect();
    format!(
        "<div class=\"bar\"><div style=\"height:10px;background:linear-gradient(to right,{})\"></div>\
         <div class=\"ticks\"><span>0</span><span>FLIP per pixel</span><span>1</span></div></div>",
        stops.join(",")
    )
}

/// The window (an eighth of the image each way, at least 8 px) of the largest summed FLIP of
/// the map `flip` (row-major, `w`×`h`): its corner, size and mean FLIP.
fn worst_window(flip: &[f32], w: u32, h: u32) -> (u32, u32, u32, u32, f64) {
    let (ww, wh) = ((w / 8).max(8).min(w), (h / 8).max(8).min(h));
    let (w_, h_) = (w as usize, h as usize);
    // Summed-area table with a zero row and column.
    let mut sat = vec![0f64; (w_ + 1) * (h_ + 1)];
    for y in 0..h_ {
        let mut row = 0f64;
        for x in 0..w_ {
            row += f64::from(flip[y * w_ + x]);
            sat[(y + 1) * (w_ + 1) + x + 1] = sat[y * (w_ + 1) + x + 1] + row;
        }
    }
    let sum = |x: usize, y: usize, a: usize, b: usize| {
        sat[(y + b) * (w_ + 1) + x + a] - sat[y * (w_ + 1) + x + a] - sat[(y + b) * (w_ + 1) + x]
            + sat[y * (w_ + 1) + x]
    };
    let (mut best, mut at) = (-1.0, (0, 0));
    for y in 0..=(h - wh) as usize {
        for x in 0..=(w - ww) as usize {
            let s = sum(x, y, ww as usize, wh as usize);
            if s > best {
                (best, at) = (s, (x, y));
            }
        }
    }
    (at.0 as u32, at.1 as u32, ww, wh, best / f64::from(ww * wh))
}

/// Writes the inset of a truth | raster | FLIP row (paths relative to `dir`) and returns its
/// image block; `None` where the row's images are not there (a test's records) or differ in
/// size.
pub fn inset(dir: &Path, truth: &str, raster: &str) -> Option<Block> {
    let (t, r) = (
        read_image(&dir.join(truth)).ok()?,
        read_image(&dir.join(raster)).ok()?,
    );
    if (t.width, t.height) != (r.width, r.height) || t.width < 8 || t.height < 8 {
        return None;
    }
    let (w, h) = (t.width, t.height);
    // The PNGs are the tone-mapped images: re-encoding their decoded values gives their bytes.
    let (t8, r8) = (t.to_srgb8(1.0), r.to_srgb8(1.0));
    let flip = mirrorbox_image::metrics::flip_map(&t8, &r8, w, h);
    let (x0, y0, ww, wh, mean) = worst_window(&flip, w, h);
    let heat8: Vec<u8> = flip.iter().flat_map(|&v| heat(v)).collect();
    let (cw, ch) = (ww * INSET_ZOOM, wh * INSET_ZOOM);
    let out_w = 3 * cw + 2 * GAP;
    let mut out = vec![255u8; (out_w * ch * 3) as usize];
    for (k, src) in [&t8, &r8, &heat8].iter().enumerate() {
        let ox = k as u32 * (cw + GAP);
        for y in 0..ch {
            for x in 0..cw {
                let (sx, sy) = (x0 + x / INSET_ZOOM, y0 + y / INSET_ZOOM);
                let s = ((sy * w + sx) * 3) as usize;
                let d = ((y * out_w + ox + x) * 3) as usize;
                out[d..d + 3].copy_from_slice(&src[s..s + 3]);
            }
        }
    }
    let stem = raster.strip_suffix(".png").unwrap_or(raster);
    let rel = format!("{stem}_inset.png");
    write_png_bytes(&dir.join(&rel), out_w, ch, &out).ok()?;
    let mut caption = String::new();
    let _ = write!(
        caption,
        "{INSET_ZOOM}× inset: the {ww}×{wh} px window of largest FLIP (mean {mean:.3}) at x = {x0}, y = {y0} — truth | raster | FLIP"
    );
    Some(Block::Images(vec![(caption, rel)]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use mirrorbox_image::RgbImage;

    fn constant(w: u32, h: u32, v: [f32; 3]) -> RgbImage {
        RgbImage::from_fn(w, h, |_, _| v)
    }

    #[test]
    fn the_inset_finds_the_window_of_largest_error() {
        let dir = tempfile::tempdir().unwrap();
        let (w, h) = (64, 48);
        let truth = constant(w, h, [0.2, 0.3, 0.4]);
        // The raster differs in one 8×8 patch at (40, 24), the window's size.
        let raster = RgbImage::from_fn(w, h, |x, y| {
            if (40..48).contains(&x) && (24..32).contains(&y) {
                [0.9, 0.1, 0.1]
            } else {
                [0.2, 0.3, 0.4]
            }
        });
        mirrorbox_image::write_png(&dir.path().join("t.png"), &truth, 1.0).unwrap();
        mirrorbox_image::write_png(&dir.path().join("r.png"), &raster, 1.0).unwrap();
        let Some(Block::Images(images)) = inset(dir.path(), "t.png", "r.png") else {
            panic!("an inset");
        };
        assert!(images[0].0.contains("at x = 40, y = 24"), "{}", images[0].0);
        let png = read_image(&dir.path().join("r_inset.png")).unwrap();
        assert_eq!(
            (png.width, png.height),
            (3 * 8 * INSET_ZOOM + 2 * GAP, 8 * INSET_ZOOM)
        );
        assert!(inset(dir.path(), "t.png", "missing.png").is_none());
    }
}
