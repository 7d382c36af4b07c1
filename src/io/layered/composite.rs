//! Flattening layers: straight-alpha "source over" of each visible layer, with its opacity, in
//! order, as every art tool composites normal-mode layers.
//!
//! In: layers (trimmed, canvas offsets in px) and a target rectangle. Out: a straight-alpha
//! RGBA8 image of the rectangle. Used to merge `[merge]` groups and, in tests, to compare an
//! import with the art tool's own flattened image.

use super::{ArtLayer, LayeredImage};
use image::RgbaImage;

/// The visible layers of `image` flattened over a transparent canvas.
pub fn composite(image: &LayeredImage) -> RgbaImage {
    let mut out = RgbaImage::new(image.canvas_px[0], image.canvas_px[1]);
    for layer in image.layers.iter().filter(|l| l.visible) {
        over(
            &mut out,
            [0, 0],
            &layer.image,
            layer.offset_px,
            layer.opacity,
        );
    }
    out
}

/// Draws `src` (top-left at canvas `src_px`) with `opacity` over `dst` (top-left at canvas
/// `dst_px`), straight alpha, rounding to the nearest 8-bit value.
pub fn over(
    dst: &mut RgbaImage,
    dst_px: [i32; 2],
    src: &RgbaImage,
    src_px: [i32; 2],
    opacity: f32,
) {
    let dx = src_px[0] as i64 - dst_px[0] as i64;
    let dy = src_px[1] as i64 - dst_px[1] as i64;
    let (dw, dh) = (dst.width() as i64, dst.height() as i64);
    for (x, y, s) in src.enumerate_pixels() {
        let (tx, ty) = (x as i64 + dx, y as i64 + dy);
        if tx < 0 || ty < 0 || tx >= dw || ty >= dh {
            continue;
        }
        let sa = s[3] as f32 / 255.0 * opacity;
        if sa <= 0.0 {
            continue;
        }
        let d = dst.get_pixel_mut(tx as u32, ty as u32);
        let da = d[3] as f32 / 255.0;
        let oa = sa + da * (1.0 - sa);
        for c in 0..3 {
            let v = (s[c] as f32 * sa + d[c] as f32 * da * (1.0 - sa)) / oa;
            d[c] = v.round().clamp(0.0, 255.0) as u8;
        }
        d[3] = (oa * 255.0).round().clamp(0.0, 255.0) as u8;
    }
}

/// The layers' union rectangle (top-left px, size px) of the visible ones, if any.
pub fn bounds(layers: &[ArtLayer]) -> Option<([i32; 2], [u32; 2])> {
    let mut it = layers.iter().filter(|l| l.visible && l.image.width() > 0);
    let first = it.next()?;
    // In i64: layers far apart (a PSD's rectangles may lie anywhere in i32) span more than
    // i32 holds; the span of two i32 positions fits u32.
    let rect = |l: &ArtLayer| {
        let [x, y] = l.offset_px.map(i64::from);
        [
            x,
            y,
            x + i64::from(l.image.width()),
            y + i64::from(l.image.height()),
        ]
    };
    let mut r = rect(first);
    for l in it {
        let s = rect(l);
        r = [
            r[0].min(s[0]),
            r[1].min(s[1]),
            r[2].max(s[2]),
            r[3].max(s[3]),
        ];
    }
    let span = |from: i64, to: i64| u32::try_from(to - from).unwrap_or(u32::MAX);
    Some((
        [r[0] as i32, r[1] as i32],
        [span(r[0], r[2]), span(r[1], r[3])],
    ))
}
