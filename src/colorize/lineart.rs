//! Line art as the colorizer sees it: every pixel's color on white paper, and its ink.
//!
//! In: an RGBA8 line-art image (straight alpha): dark lines on white, or lines on transparency.
//! Out: [`LineArt`]: per pixel the color composited over white (RGB8), and the ink
//! 1 − luminance in [0, 1] (Rec. 709 weights), from which line pixels are told apart.
//!
//! Compositing over white makes "lines on transparency" and "lines on white" the same drawing,
//! so the 5D lift sees a line as a color change either way (premultiplied color would make a
//! black line on transparency invisible: both are (0, 0, 0)).

use image::RgbaImage;

/// Line art composited over white paper.
#[derive(Clone, Debug)]
pub struct LineArt {
    pub width: u32,
    pub height: u32,
    /// Per pixel, row-major: the color over white.
    pub over_white: Vec<[u8; 3]>,
    /// Per pixel: 1 − luminance of `over_white`, in [0, 1].
    pub ink: Vec<f32>,
    /// Whether every pixel is opaque (lines on paper); otherwise lines on transparency.
    pub opaque: bool,
}

impl LineArt {
    pub fn new(image: &RgbaImage) -> Self {
        let mut over_white = Vec::with_capacity(image.len() / 4);
        let mut ink = Vec::with_capacity(image.len() / 4);
        let mut opaque = true;
        for px in image.pixels() {
            let a = px[3] as u32;
            opaque &= a == 255;
            // a·c + (1 − a)·255, rounded, in integers so the result is exact and portable.
            let c = [0, 1, 2].map(|k| ((a * px[k] as u32 + (255 - a) * 255 + 127) / 255) as u8);
            let luminance =
                (0.2126 * c[0] as f32 + 0.7152 * c[1] as f32 + 0.0722 * c[2] as f32) / 255.0;
            over_white.push(c);
            ink.push((1.0 - luminance).clamp(0.0, 1.0));
        }
        LineArt {
            width: image.width(),
            height: image.height(),
            over_white,
            ink,
            opaque,
        }
    }

    pub fn pixel_count(&self) -> usize {
        self.ink.len()
    }

    /// Per pixel: whether its ink reaches `threshold` (a line pixel).
    pub fn line_mask(&self, threshold: f32) -> Vec<bool> {
        self.ink.iter().map(|&k| k >= threshold).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    #[test]
    fn transparency_reads_as_white_paper() {
        let mut image = RgbaImage::from_pixel(2, 1, Rgba([0, 0, 0, 0]));
        image.put_pixel(1, 0, Rgba([0, 0, 0, 255]));
        let art = LineArt::new(&image);
        assert_eq!(art.over_white, vec![[255; 3], [0; 3]]);
        assert_eq!(art.ink, vec![0.0, 1.0]);
        assert!(!art.opaque);
        assert_eq!(art.line_mask(0.5), vec![false, true]);
        // Half-covered black is mid gray.
        let half = LineArt::new(&RgbaImage::from_pixel(1, 1, Rgba([0, 0, 0, 128])));
        assert_eq!(half.over_white, vec![[127; 3]]);
    }
}
