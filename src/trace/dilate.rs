//! Grey dilation of the alpha channel by a pixel disk.
//!
//! In: an RGBA image and a radius in pixels. Out: an [`AlphaGrid`]: every alpha sample replaced
//! by the largest alpha within the disk around it, on a grid that extends the canvas far enough
//! for the dilation to spill over the image border, plus a frame of zeros so that every contour
//! traced on it closes.

use image::RgbaImage;

/// Alpha samples on a grid that extends the canvas by `margin` pixels on every side.
///
/// Grid sample (gx, gy) is canvas pixel (gx − margin, gy − margin). The outermost row and
/// column on every side are always 0.
pub(super) struct AlphaGrid {
    pub width: usize,
    pub height: usize,
    pub margin: usize,
    pub values: Vec<u8>,
}

impl AlphaGrid {
    pub fn at(&self, gx: usize, gy: usize) -> u8 {
        self.values[gy * self.width + gx]
    }
}

/// Bytes per pixel of an `RgbaImage`, and where its alpha sits.
const RGBA_CHANNELS: usize = 4;
pub(super) const ALPHA_CHANNEL: usize = 3;

/// Source rows dilated together: few enough that the band stays in cache across the passes
/// over it (one per disk row), many enough that each pass has some length.
const BAND_ROWS: usize = 64;

/// Dilates the alpha of `image` by the pixel disk {(dx, dy) : dx² + dy² ≤ radius²}.
///
/// The disk is split into its rows: row dy is a horizontal run of half-width w(dy), so the
/// result is the max over dy of the horizontal running max of width w(dy), shifted by dy. Rows
/// dy and −dy share their running max, and the running maxima are grown one pixel at a time in
/// increasing width: ⌊radius⌋ + (2⌊radius⌋ + 1) vectorizable passes over the image, done band
/// by band of source rows so the data stays in cache.
pub(super) fn dilate_alpha(image: &RgbaImage, radius: f64) -> AlphaGrid {
    let half_widths = disk_half_widths(radius);
    let reach = half_widths.len() - 1;
    // The dilation reaches `reach` pixels past the image; one more pixel of zeros closes contours.
    let margin = reach + 1;
    let (width, height) = (image.width() as usize, image.height() as usize);
    let mut grid = AlphaGrid {
        width: width + 2 * margin,
        height: height + 2 * margin,
        margin,
        values: vec![0; (width + 2 * margin) * (height + 2 * margin)],
    };
    if width == 0 || height == 0 {
        return grid;
    }

    // Source rows widened by `reach` zeros on each side, so running maxima can spill over.
    let row_len = width + 2 * reach;
    let mut band = vec![0u8; row_len * BAND_ROWS.min(height)];
    let mut row_has_alpha = [false; BAND_ROWS];
    let mut scratch = vec![0u8; row_len];
    for (band_index, pixels) in image
        .as_raw()
        .chunks(RGBA_CHANNELS * width * BAND_ROWS)
        .enumerate()
    {
        let first_row = band_index * BAND_ROWS;
        let band_rows = pixels.len() / (RGBA_CHANNELS * width);
        let band = &mut band[..band_rows * row_len];
        let row_has_alpha = &mut row_has_alpha[..band_rows];
        if !load_alpha(pixels, width, reach, band, row_has_alpha) {
            continue;
        }
        let mut current_width = 0;
        // Half-widths shrink as |dy| grows, so walking dy downwards visits them in increasing
        // order.
        for dy in (0..=reach).rev() {
            while current_width < half_widths[dy] {
                widen_rows_by_one(band, row_len, row_has_alpha, &mut scratch);
                current_width += 1;
            }
            for (j, row) in band.chunks_exact(row_len).enumerate() {
                if !row_has_alpha[j] {
                    continue;
                }
                // Widened row column c is canvas pixel c − reach, i.e. grid column c + 1.
                let below = (first_row + j + margin + dy) * grid.width + 1;
                max_into(&mut grid.values[below..below + row_len], row);
                if dy > 0 {
                    let above = (first_row + j + margin - dy) * grid.width + 1;
                    max_into(&mut grid.values[above..above + row_len], row);
                }
            }
        }
    }
    grid
}

/// Copies the alpha of `pixels` (whole RGBA rows) into `band`, row by row with `reach` zeros on
/// either side, noting which rows have any alpha; false when none has.
fn load_alpha(
    pixels: &[u8],
    width: usize,
    reach: usize,
    band: &mut [u8],
    row_has_alpha: &mut [bool],
) -> bool {
    // The band still holds the previous band's widened rows.
    band.fill(0);
    let row_len = width + 2 * reach;
    for ((row, pixel_row), has_alpha) in band
        .chunks_exact_mut(row_len)
        .zip(pixels.chunks_exact(RGBA_CHANNELS * width))
        .zip(row_has_alpha.iter_mut())
    {
        for (dst, px) in row[reach..reach + width]
            .iter_mut()
            .zip(pixel_row.chunks_exact(RGBA_CHANNELS))
        {
            *dst = px[ALPHA_CHANNEL];
        }
        // A max rather than `any`: it vectorizes, and most rows have to be scanned to the end.
        *has_alpha = row.iter().copied().max().unwrap_or(0) > 0;
    }
    row_has_alpha.iter().any(|&has_alpha| has_alpha)
}

/// Entry dy (0 ≤ dy ≤ ⌊radius⌋) is the largest integer dx with dx² + dy² ≤ radius².
fn disk_half_widths(radius: f64) -> Vec<usize> {
    let r2 = radius * radius;
    let reach = radius.floor() as usize;
    (0..=reach)
        .map(|dy| {
            let rest = r2 - (dy * dy) as f64;
            let mut dx = rest.sqrt().floor() as usize;
            // sqrt may land on the wrong side of an integer: settle on the exact bound.
            while (((dx + 1) * (dx + 1)) as f64) <= rest {
                dx += 1;
            }
            while dx > 0 && ((dx * dx) as f64) > rest {
                dx -= 1;
            }
            dx
        })
        .collect()
}

/// Grows the horizontal running max of every non-empty row of the band by one pixel on each
/// side.
fn widen_rows_by_one(rows: &mut [u8], row_len: usize, row_has_alpha: &[bool], scratch: &mut [u8]) {
    if row_len < 2 {
        return;
    }
    for (row, _) in rows
        .chunks_exact_mut(row_len)
        .zip(row_has_alpha)
        .filter(|(_, &has_alpha)| has_alpha)
    {
        scratch.copy_from_slice(row);
        row[0] = scratch[0].max(scratch[1]);
        row[row_len - 1] = scratch[row_len - 2].max(scratch[row_len - 1]);
        // Three shifted views instead of an indexed loop, so the compiler vectorizes it.
        for (((out, &left), &mid), &right) in row[1..row_len - 1]
            .iter_mut()
            .zip(&scratch[..row_len - 2])
            .zip(&scratch[1..row_len - 1])
            .zip(&scratch[2..])
        {
            *out = left.max(mid).max(right);
        }
    }
}

fn max_into(dst: &mut [u8], src: &[u8]) {
    for (d, &s) in dst.iter_mut().zip(src) {
        *d = (*d).max(s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_widths_match_the_disk_definition() {
        for radius in [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.9, 7.0] {
            let widths = disk_half_widths(radius);
            for (dy, &w) in widths.iter().enumerate() {
                let inside = |dx: usize| ((dx * dx + dy * dy) as f64) <= radius * radius;
                assert!(inside(w) && !inside(w + 1), "radius {radius} dy {dy} w {w}");
            }
        }
    }

    #[test]
    fn dilation_equals_brute_force() {
        // The tall image spans several bands.
        for (w, h) in [(13, 9), (6, 2 * BAND_ROWS as u32 + 7)] {
            let mut image = RgbaImage::new(w, h);
            for (i, px) in image.pixels_mut().enumerate() {
                // A sparse, uneven pattern of alpha values.
                px[3] = if i % 7 == 3 { (i * 37 % 256) as u8 } else { 0 };
            }
            for radius in [0.0, 1.0, 1.5, 2.0, 3.3] {
                assert_matches_brute_force(&image, radius);
            }
        }
    }

    fn assert_matches_brute_force(image: &RgbaImage, radius: f64) {
        let grid = dilate_alpha(image, radius);
        let m = grid.margin as i64;
        for gy in 0..grid.height {
            for gx in 0..grid.width {
                let (x, y) = (gx as i64 - m, gy as i64 - m);
                let mut expected = 0u8;
                for (sx, sy, px) in image.enumerate_pixels() {
                    let d2 = ((sx as i64 - x).pow(2) + (sy as i64 - y).pow(2)) as f64;
                    if d2 <= radius * radius {
                        expected = expected.max(px[3]);
                    }
                }
                assert_eq!(grid.at(gx, gy), expected, "radius {radius} at ({x}, {y})");
            }
        }
    }
}
