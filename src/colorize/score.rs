//! How close a coloring is to the truth.
//!
//! In: a colored image, the true coloring, and the line mask (true = line pixel). Out: the
//! share of non-line pixels whose every channel lies within [`SCORE_TOLERANCE`] of the truth
//! (issue 7's measure), in [0, 1]. Line pixels are left out: they show the line art, and where
//! a region's color ends under a line is a matter of taste.

use image::RgbaImage;

/// Largest channel difference (of 255) that still counts as the right color.
pub const SCORE_TOLERANCE: u8 = 16;

/// The share of non-line pixels colored within [`SCORE_TOLERANCE`] of `truth` (RGB only).
/// Images of different sizes, or no non-line pixel, score 0.
pub fn score(colored: &RgbaImage, truth: &RgbaImage, is_line: &[bool]) -> f64 {
    if colored.dimensions() != truth.dimensions() || is_line.len() != truth.len() / 4 {
        return 0.0;
    }
    let (mut good, mut total) = (0usize, 0usize);
    for ((c, t), &line) in colored.pixels().zip(truth.pixels()).zip(is_line) {
        if line {
            continue;
        }
        total += 1;
        good += (0..3).all(|k| c[k].abs_diff(t[k]) <= SCORE_TOLERANCE) as usize;
    }
    if total == 0 {
        0.0
    } else {
        good as f64 / total as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    #[test]
    fn counts_non_line_pixels_within_the_tolerance() {
        let truth = RgbaImage::from_pixel(4, 1, Rgba([100, 100, 100, 255]));
        let mut colored = truth.clone();
        colored.put_pixel(1, 0, Rgba([116, 84, 100, 255])); // within 16
        colored.put_pixel(2, 0, Rgba([117, 100, 100, 255])); // off by 17
        colored.put_pixel(3, 0, Rgba([0, 0, 0, 255])); // a line pixel: not counted
        let s = score(&colored, &truth, &[false, false, false, true]);
        assert!((s - 2.0 / 3.0).abs() < 1e-12);
        assert_eq!(score(&colored, &RgbaImage::new(3, 1), &[false; 3]), 0.0);
    }
}
