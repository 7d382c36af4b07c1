//! Image comparison for tests: PSNR and largest per-channel difference.
//!
//! They compare straight-alpha RGBA8 images channel by channel, alpha included, so a
//! missing or extra pixel counts as much as a wrong colour; [`psnr_premultiplied`] compares
//! what compositing shows instead, ignoring the color of invisible pixels.

use image::RgbaImage;

/// Peak value of an 8-bit channel, the signal in the PSNR ratio.
const PEAK: f64 = 255.0;

/// Peak signal-to-noise ratio in dB over all four channels (8-bit peak 255).
///
/// `+∞` when the images are equal (including two empty images of the same size);
/// `-∞` when their sizes differ, since nothing about them then agrees.
pub fn psnr_rgba(a: &RgbaImage, b: &RgbaImage) -> f64 {
    if a.dimensions() != b.dimensions() {
        return f64::NEG_INFINITY;
    }
    let (squared_error, count) =
        a.as_raw()
            .iter()
            .zip(b.as_raw())
            .fold((0.0, 0u64), |(sum, n), (&x, &y)| {
                let d = f64::from(x) - f64::from(y);
                (sum + d * d, n + 1)
            });
    if squared_error == 0.0 {
        return f64::INFINITY;
    }
    let mean_squared_error = squared_error / count as f64;
    10.0 * (PEAK * PEAK / mean_squared_error).log10()
}

/// PSNR in dB of the premultiplied images: what compositing shows. The color of a fully
/// transparent pixel is invisible and not compared, and a faint pixel's color counts in
/// proportion to its alpha. The inputs are straight-alpha RGBA8.
pub fn psnr_premultiplied(a: &RgbaImage, b: &RgbaImage) -> f64 {
    psnr_rgba(&premultiplied(a), &premultiplied(b))
}

/// Each channel times alpha / 255, rounded to nearest.
pub fn premultiplied(image: &RgbaImage) -> RgbaImage {
    let mut out = image.clone();
    for px in out.pixels_mut() {
        let a = u32::from(px[3]);
        for c in 0..3 {
            px[c] = ((u32::from(px[c]) * a + 127) / 255) as u8;
        }
    }
    out
}

/// The largest absolute difference of any channel of any pixel; 255 when the sizes differ.
pub fn max_channel_diff(a: &RgbaImage, b: &RgbaImage) -> u8 {
    max_channel_diff_where(a, b, |_, _| true)
}

/// Like [`max_channel_diff`], over only the pixels (x, y) for which `include` holds.
pub fn max_channel_diff_where(
    a: &RgbaImage,
    b: &RgbaImage,
    include: impl Fn(u32, u32) -> bool,
) -> u8 {
    if a.dimensions() != b.dimensions() {
        return u8::MAX;
    }
    a.enumerate_pixels()
        .filter(|&(x, y, _)| include(x, y))
        .flat_map(|(x, y, pa)| {
            let pb = b.get_pixel(x, y);
            pa.0.into_iter().zip(pb.0).map(|(ca, cb)| ca.abs_diff(cb))
        })
        .max()
        .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_images_have_infinite_psnr_and_no_difference() {
        let img = RgbaImage::from_pixel(3, 2, image::Rgba([10, 20, 30, 40]));
        assert_eq!(psnr_rgba(&img, &img), f64::INFINITY);
        assert_eq!(max_channel_diff(&img, &img), 0);
    }

    #[test]
    fn psnr_of_a_known_error() {
        let a = RgbaImage::from_pixel(2, 2, image::Rgba([0, 0, 0, 0]));
        let mut b = a.clone();
        b.put_pixel(1, 1, image::Rgba([255, 0, 0, 0]));
        // One channel in 16 off by the peak: MSE = 255²/16, PSNR = 10·log10(16).
        let expected = 10.0 * 16f64.log10();
        assert!((psnr_rgba(&a, &b) - expected).abs() < 1e-9);
        assert_eq!(max_channel_diff(&a, &b), 255);
        assert_eq!(max_channel_diff_where(&a, &b, |x, y| (x, y) != (1, 1)), 0);
    }

    #[test]
    fn different_sizes_compare_as_worst() {
        let a = RgbaImage::new(2, 2);
        let b = RgbaImage::new(2, 3);
        assert_eq!(psnr_rgba(&a, &b), f64::NEG_INFINITY);
        assert_eq!(max_channel_diff(&a, &b), u8::MAX);
    }
}
