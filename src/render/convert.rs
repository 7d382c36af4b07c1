//! Straight-alpha `image::RgbaImage` ↔ premultiplied tiny-skia `Pixmap`.
//!
//! Images on disk and in the `image` crate carry straight (unassociated) alpha; tiny-skia
//! works on premultiplied alpha. Both directions round to nearest, so premultiplied →
//! straight → premultiplied is lossless, while straight → premultiplied loses colour
//! precision where alpha is low (as it must: fewer premultiplied levels exist there).

use image::RgbaImage;
use tiny_skia::Pixmap;

use super::pixel_math::{mul_255, CHANNEL_MAX};
use super::RenderError;

/// Number of bytes of one RGBA8 pixel.
const RGBA_BYTES: usize = 4;
/// Index of the alpha byte within an RGBA8 pixel.
const ALPHA: usize = 3;

/// Converts a straight-alpha image into a premultiplied pixmap of the same size.
///
/// Fails only for an image without pixels, which a `Pixmap` cannot represent.
pub fn pixmap_from_rgba(img: &RgbaImage) -> Result<Pixmap, RenderError> {
    let (width, height) = img.dimensions();
    let mut pixmap = Pixmap::new(width, height).ok_or(RenderError::EmptyImage { width, height })?;
    for (dst, src) in pixmap
        .data_mut()
        .chunks_exact_mut(RGBA_BYTES)
        .zip(img.as_raw().chunks_exact(RGBA_BYTES))
    {
        let alpha = u32::from(src[ALPHA]);
        for channel in 0..ALPHA {
            dst[channel] = mul_255(u32::from(src[channel]), alpha) as u8;
        }
        dst[ALPHA] = src[ALPHA];
    }
    Ok(pixmap)
}

/// Converts a premultiplied pixmap into a straight-alpha image of the same size.
///
/// Fully transparent pixels become (0, 0, 0, 0): their colour is not recoverable.
pub fn rgba_from_pixmap(p: &Pixmap) -> RgbaImage {
    let mut img = RgbaImage::new(p.width(), p.height());
    for (dst, src) in img
        .as_mut()
        .chunks_exact_mut(RGBA_BYTES)
        .zip(p.data().chunks_exact(RGBA_BYTES))
    {
        let alpha = u32::from(src[ALPHA]);
        for channel in 0..ALPHA {
            dst[channel] = unpremultiply(u32::from(src[channel]), alpha);
        }
        dst[ALPHA] = src[ALPHA];
    }
    img
}

/// `premultiplied · 255 / alpha` rounded to nearest; 0 where alpha is 0.
fn unpremultiply(premultiplied: u32, alpha: u32) -> u8 {
    if alpha == 0 {
        return 0;
    }
    // The clamp only matters for invalid pixels whose colour exceeds their alpha.
    ((premultiplied * CHANNEL_MAX + alpha / 2) / alpha).min(CHANNEL_MAX) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One pixel for every valid premultiplied (colour, alpha) pair, colour ≤ alpha.
    fn every_premultiplied_pair() -> Pixmap {
        let pairs: Vec<(u8, u8)> = (0..=u8::MAX)
            .flat_map(|a| (0..=a).map(move |c| (c, a)))
            .collect();
        let mut pixmap = Pixmap::new(pairs.len() as u32, 1).expect("non-empty test pixmap");
        for (px, &(c, a)) in pixmap.data_mut().chunks_exact_mut(RGBA_BYTES).zip(&pairs) {
            px.copy_from_slice(&[c, a - c, c / 2, a]);
        }
        pixmap
    }

    #[test]
    fn premultiplied_round_trip_is_lossless() {
        let pixmap = every_premultiplied_pair();
        let back = pixmap_from_rgba(&rgba_from_pixmap(&pixmap)).expect("non-empty");
        assert_eq!(back.data(), pixmap.data());
    }

    #[test]
    fn straight_round_trip_keeps_alpha_and_opaque_colours_exactly() {
        let mut img = RgbaImage::new(256, 256);
        for (x, y, px) in img.enumerate_pixels_mut() {
            *px = image::Rgba([x as u8, (x ^ y) as u8, (255 - y) as u8, y as u8]);
        }
        let back = rgba_from_pixmap(&pixmap_from_rgba(&img).expect("non-empty"));
        for (a, b) in img.pixels().zip(back.pixels()) {
            let alpha = a[ALPHA];
            assert_eq!(alpha, b[ALPHA]);
            if alpha == 0 {
                assert_eq!(b.0, [0; 4]);
                continue;
            }
            // Rounding to 1/alpha of a premultiplied step spreads over 255/alpha straight steps.
            let tolerance = (f64::from(CHANNEL_MAX) / f64::from(alpha) / 2.0).ceil() as i32;
            for channel in 0..ALPHA {
                let diff = (i32::from(a[channel]) - i32::from(b[channel])).abs();
                assert!(diff <= tolerance, "{a:?} → {b:?}");
            }
        }
    }

    #[test]
    fn premultiplies_with_rounding() {
        let img = RgbaImage::from_pixel(1, 1, image::Rgba([255, 128, 1, 128]));
        let pixmap = pixmap_from_rgba(&img).expect("non-empty");
        // 128·128/255 = 64.25, 1·128/255 = 0.50196…
        assert_eq!(pixmap.data(), &[128, 64, 1, 128]);
    }

    #[test]
    fn empty_image_is_an_error() {
        let img = RgbaImage::new(0, 7);
        assert_eq!(
            pixmap_from_rgba(&img).err(),
            Some(RenderError::EmptyImage {
                width: 0,
                height: 7
            })
        );
    }
}
