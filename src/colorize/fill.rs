//! From per-vertex color weights to pixels: flat fills, soft blends, per-color masks.
//!
//! In: the [`ImageMesh`], its [`WeightMatrix`] (vertices × colors), the palette, the
//! [`LineArt`] and the original line-art image. Out: the colored image (RGBA8, opaque where the
//! line art is drawn on paper) and, on request, one mask layer per color.
//!
//! Weights are interpolated linearly inside each triangle to every pixel. `flat`: each pixel
//! takes the color of its largest weight (ties: the earlier color); `soft`: colors blended by
//! weight. The line art goes on top: multiplied when it is opaque (ink on paper, as a
//! "multiply" layer in a paint program: white paper leaves the fill untouched), composited
//! "over" when it has transparency (lines on their own layer).

use super::image_mesh::ImageMesh;
use super::lineart::LineArt;
use crate::weights::WeightMatrix;
use image::RgbaImage;
use serde::{Deserialize, Serialize};

/// How weights become colors.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FillMode {
    /// Each pixel takes the color of its largest weight: crisp cartoon fills.
    #[default]
    Flat,
    /// Colors blended by weight.
    Soft,
}

/// The filled image and, if asked for, one RGBA mask per color (the color, with the pixel's
/// share as alpha: 0/255 in flat mode, the weight in soft mode).
#[derive(Clone, Debug, PartialEq)]
pub struct Filled {
    pub image: RgbaImage,
    pub fill_only: RgbaImage,
    pub layers: Vec<RgbaImage>,
}

/// Fills the image. `weights` is `None` when there is a single color (it takes everything).
pub fn fill(
    mesh: &ImageMesh,
    weights: Option<&WeightMatrix>,
    palette: &[[u8; 3]],
    art: &LineArt,
    lineart: &RgbaImage,
    mode: FillMode,
    want_layers: bool,
) -> Filled {
    let (width, height) = (art.width, art.height);
    let m = palette.len();
    let mut fill_only = RgbaImage::new(width, height);
    let mut layers: Vec<RgbaImage> = if want_layers {
        (0..m).map(|_| RgbaImage::new(width, height)).collect()
    } else {
        Vec::new()
    };
    let mut shares = vec![0.0f64; m];
    let fill_raw: &mut [u8] = &mut fill_only;
    let mut layer_raws: Vec<&mut [u8]> = layers.iter_mut().map(|l| &mut **l).collect();
    let mut paint = |i: usize, shares: &[f64]| {
        let best = argmax(shares);
        let color = match mode {
            FillMode::Flat => palette[best],
            FillMode::Soft => {
                let total: f64 = shares.iter().sum();
                let mut c = [0.0; 3];
                for (s, p) in shares.iter().zip(palette) {
                    for k in 0..3 {
                        c[k] += s * p[k] as f64;
                    }
                }
                c.map(|v| (v / total.max(f64::MIN_POSITIVE)).round().clamp(0.0, 255.0) as u8)
            }
        };
        fill_raw[4 * i..4 * i + 4].copy_from_slice(&[color[0], color[1], color[2], 255]);
        for (j, layer) in layer_raws.iter_mut().enumerate() {
            let alpha = match mode {
                FillMode::Flat => 255 * (j == best) as u8,
                FillMode::Soft => (shares[j] * 255.0).round().clamp(0.0, 255.0) as u8,
            };
            let p = palette[j];
            layer[4 * i..4 * i + 4].copy_from_slice(&[p[0], p[1], p[2], alpha]);
        }
    };
    match weights {
        None => {
            shares.fill(1.0);
            for i in 0..art.pixel_count() {
                paint(i, &shares);
            }
        }
        Some(w) => mesh.interpolate(|i, bary| {
            shares.fill(0.0);
            for (v, b) in bary {
                for (s, x) in shares.iter_mut().zip(w.row(v as usize)) {
                    *s += b * x;
                }
            }
            paint(i, &shares);
        }),
    }
    let image = with_lines_on_top(&fill_only, lineart, art.opaque);
    Filled {
        image,
        fill_only,
        layers,
    }
}

/// The first index of the largest value.
pub fn argmax(values: &[f64]) -> usize {
    let mut best = 0;
    for (j, &v) in values.iter().enumerate() {
        if v > values[best] {
            best = j;
        }
    }
    best
}

/// The line art on top of an opaque fill: multiplied if the line art is opaque, composited
/// over it otherwise.
pub fn with_lines_on_top(fill: &RgbaImage, lineart: &RgbaImage, opaque: bool) -> RgbaImage {
    let mut out = fill.clone();
    for (o, l) in out.pixels_mut().zip(lineart.pixels()) {
        for k in 0..3 {
            let (f, c, a) = (o[k] as u32, l[k] as u32, l[3] as u32);
            o[k] = if opaque {
                ((f * c + 127) / 255) as u8
            } else {
                ((a * c + (255 - a) * f + 127) / 255) as u8
            };
        }
    }
    out
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

    #[test]
    fn argmax_prefers_the_earlier_color_on_ties() {
        assert_eq!(argmax(&[0.25, 0.5, 0.5]), 1);
        assert_eq!(argmax(&[0.0, 0.0]), 0);
    }
}
