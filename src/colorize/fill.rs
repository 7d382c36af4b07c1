//! From every pixel's color to pixels: flat fills, antialiased soft fills, per-color masks.
//!
//! In: each pixel's color (a 1-based palette index, from [`super::ink_regions::owners`]), the
//! palette, the [`LineArt`] and the original line-art image. Out: the colored image (RGBA8,
//! opaque where the line art is drawn on paper) and, on request, one mask layer per color.
//!
//! `flat`: each pixel its color; `soft`: each color's share of a small box around the pixel
//! (antialiased region edges, nothing wider). The line art goes on top: multiplied when it is
//! opaque (ink on paper, as a "multiply" layer in a paint program: white paper leaves the fill
//! untouched), composited "over" when it has transparency (lines on their own layer).

use super::lineart::LineArt;
use image::RgbaImage;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How the pixels' colors are drawn.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum FillMode {
    /// Each pixel its color: crisp cartoon fills.
    #[default]
    Flat,
    /// Region edges antialiased: each color's share of a small box around the pixel.
    Soft,
}

/// The filled image and, if asked for, one RGBA mask per color (the color, with the pixel's
/// share as alpha: 0/255 in flat mode, the share of the box in soft mode).
#[derive(Clone, Debug, PartialEq)]
pub struct Filled {
    pub image: RgbaImage,
    pub fill_only: RgbaImage,
    pub layers: Vec<RgbaImage>,
}

/// Fills the image from every pixel's color (`owner`: 1-based palette index, 0 = none:
/// white). `flat`: each pixel its color; `soft`: each color's share of the pixel's
/// `soft_radius_px` box (clamped at the border): region edges are antialiased over about
/// 2·radius + 1 px and nothing spreads further (no halos). Masks: the color with its share as
/// alpha (they sum to 255 wherever every pixel is owned).
pub fn fill_owners(
    owner: &[u16],
    palette: &[[u8; 3]],
    art: &LineArt,
    lineart: &RgbaImage,
    mode: FillMode,
    soft_radius_px: u32,
    want_layers: bool,
) -> Filled {
    let (width, height) = (art.width, art.height);
    let (w, h) = (width as usize, height as usize);
    let m = palette.len();
    let mut fill_only = RgbaImage::new(width, height);
    let mut layers: Vec<RgbaImage> = if want_layers {
        (0..m).map(|_| RgbaImage::new(width, height)).collect()
    } else {
        Vec::new()
    };
    let r = match mode {
        FillMode::Flat => 0,
        FillMode::Soft => soft_radius_px as usize,
    };
    // Per row: its fill and its row of every mask; the rows are independent (rayon).
    let mut layer_rows: Vec<Vec<&mut [u8]>> = (0..h).map(|_| Vec::with_capacity(m)).collect();
    for layer in layers.iter_mut() {
        for (row, chunk) in layer_rows.iter_mut().zip(layer.chunks_mut(4 * w)) {
            row.push(chunk);
        }
    }
    fill_only
        .par_chunks_mut(4 * w)
        .zip(layer_rows.par_iter_mut())
        .enumerate()
        .for_each(|(y, (fill_row, layer_row))| {
            let mut counts = vec![0u32; m + 1];
            for x in 0..w {
                let own = owner[y * w + x] as usize;
                let (y0, y1, x0, x1) = (
                    y.saturating_sub(r),
                    (y + r).min(h - 1),
                    x.saturating_sub(r),
                    (x + r).min(w - 1),
                );
                // Uniform neighborhoods (the common case) skip the counting.
                let uniform = (y0..=y1).all(|yy| {
                    owner[yy * w + x0..=yy * w + x1]
                        .iter()
                        .all(|&o| o as usize == own)
                });
                counts.fill(0);
                let total = if uniform {
                    counts[own] = 1;
                    1
                } else {
                    for yy in y0..=y1 {
                        for &o in &owner[yy * w + x0..=yy * w + x1] {
                            counts[o as usize] += 1;
                        }
                    }
                    ((y1 - y0 + 1) * (x1 - x0 + 1)) as u32
                };
                let color = if uniform {
                    // One color's share is all of it: its color exactly (white for none).
                    own.checked_sub(1).map_or([255; 3], |k| palette[k])
                } else {
                    let mut c = [counts[0] as f64 * 255.0; 3];
                    for (k, p) in palette.iter().enumerate() {
                        for ch in 0..3 {
                            c[ch] += counts[k + 1] as f64 * p[ch] as f64;
                        }
                    }
                    c.map(|v| (v / total as f64).round().clamp(0.0, 255.0) as u8)
                };
                fill_row[4 * x..4 * x + 4].copy_from_slice(&[color[0], color[1], color[2], 255]);
                for (k, layer) in layer_row.iter_mut().enumerate() {
                    let alpha = ((counts[k + 1] as f64 * 255.0) / total as f64).round() as u8;
                    let p = palette[k];
                    layer[4 * x..4 * x + 4].copy_from_slice(&[p[0], p[1], p[2], alpha]);
                }
            }
        });
    let image = with_lines_on_top(&fill_only, lineart, art.opaque);
    Filled {
        image,
        fill_only,
        layers,
    }
}

/// The line art on top of an opaque fill: multiplied if the line art is opaque, composited
/// over it otherwise.
pub fn with_lines_on_top(fill: &RgbaImage, lineart: &RgbaImage, opaque: bool) -> RgbaImage {
    let mut out = fill.clone();
    let row_bytes = (4 * fill.width() as usize).max(1);
    out.par_chunks_mut(row_bytes)
        .zip(lineart.par_chunks(row_bytes))
        .for_each(|(out_row, line_row)| with_lines_on_row(out_row, line_row, opaque));
    out
}

/// [`with_lines_on_top`] on one row of RGBA8 pixels.
fn with_lines_on_row(out: &mut [u8], lineart: &[u8], opaque: bool) {
    for (o, l) in out.chunks_exact_mut(4).zip(lineart.chunks_exact(4)) {
        for k in 0..3 {
            let (f, c, a) = (o[k] as u32, l[k] as u32, l[3] as u32);
            o[k] = if opaque {
                ((f * c + 127) / 255) as u8
            } else {
                ((a * c + (255 - a) * f + 127) / 255) as u8
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    #[test]
    fn lines_multiply_on_paper_and_cover_on_transparency() {
        let fill = RgbaImage::from_pixel(2, 1, Rgba([200, 100, 50, 255]));
        let mut paper = RgbaImage::from_pixel(2, 1, Rgba([255, 255, 255, 255]));
        paper.put_pixel(1, 0, Rgba([0, 0, 0, 255]));
        let out = with_lines_on_top(&fill, &paper, true);
        assert_eq!(out.get_pixel(0, 0).0, [200, 100, 50, 255]);
        assert_eq!(out.get_pixel(1, 0).0, [0, 0, 0, 255]);
        let mut layer = RgbaImage::new(2, 1);
        layer.put_pixel(1, 0, Rgba([0, 0, 255, 255]));
        let out = with_lines_on_top(&fill, &layer, false);
        assert_eq!(out.get_pixel(0, 0).0, [200, 100, 50, 255]);
        assert_eq!(out.get_pixel(1, 0).0, [0, 0, 255, 255]);
    }
}
