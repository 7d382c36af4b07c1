//! A part's layer → the canvas: source-over, scaled by mask coverage and opacity.

use tiny_skia::{Mask, Pixmap};

use super::pixel_math::{mul_255, CHANNEL_MAX};

/// Number of bytes of one premultiplied RGBA8 pixel.
const RGBA_BYTES: usize = 4;
/// Index of the alpha byte within an RGBA8 pixel.
const ALPHA: usize = 3;

/// Which part of the layer is opaque to the canvas.
pub(super) enum Coverage<'a> {
    /// Every layer pixel counts fully.
    Everywhere,
    /// Each layer pixel counts by the mask value at the same position (same size as the layer).
    Masked(&'a Mask),
}

/// Composites `layer`, whose top-left pixel lands on canvas pixel (`x`, `y`), source-over onto
/// `canvas`, each pixel scaled by its coverage and by `opacity` (0..=255).
///
/// Works in premultiplied 8-bit integers with rounding to nearest: a fully covered opaque
/// pixel is copied exactly, and the result stays a valid premultiplied colour.
pub(super) fn composite_layer(
    canvas: &mut Pixmap,
    layer: &Pixmap,
    coverage: Coverage<'_>,
    (x, y): (u32, u32),
    opacity: u8,
) {
    let canvas_width = canvas.width() as usize;
    let layer_width = layer.width() as usize;
    let width = layer_width.min((canvas.width().saturating_sub(x)) as usize);
    let height = layer.height().min(canvas.height().saturating_sub(y)) as usize;
    let mask = match coverage {
        Coverage::Everywhere => None,
        Coverage::Masked(mask)
            if mask.width() == layer.width() && mask.height() == layer.height() =>
        {
            Some(mask.data())
        }
        // A mask that does not match the layer says nothing reliable about coverage.
        Coverage::Masked(_) => return,
    };
    let (x, y) = (x as usize, y as usize);
    let dst = canvas.data_mut();
    let src = layer.data();
    for row in 0..height {
        let dst_start = ((y + row) * canvas_width + x) * RGBA_BYTES;
        let dst_row = &mut dst[dst_start..dst_start + width * RGBA_BYTES];
        let src_start = row * layer_width * RGBA_BYTES;
        let src_row = &src[src_start..src_start + width * RGBA_BYTES];
        match mask {
            Some(mask) => {
                let mask_row = &mask[row * layer_width..row * layer_width + width];
                blend_row(dst_row, src_row, mask_row.iter().copied(), opacity);
            }
            None => blend_row(dst_row, src_row, std::iter::repeat(u8::MAX), opacity),
        }
    }
}

/// Source-over of one row of premultiplied pixels, each scaled by coverage · opacity.
fn blend_row(dst: &mut [u8], src: &[u8], coverage: impl Iterator<Item = u8>, opacity: u8) {
    let opacity = u32::from(opacity);
    for ((d, s), m) in dst
        .chunks_exact_mut(RGBA_BYTES)
        .zip(src.chunks_exact(RGBA_BYTES))
        .zip(coverage)
    {
        let src_alpha = u32::from(s[ALPHA]);
        if src_alpha == 0 || m == 0 {
            continue;
        }
        let scale = mul_255(u32::from(m), opacity);
        if scale == CHANNEL_MAX && src_alpha == CHANNEL_MAX {
            d.copy_from_slice(s);
            continue;
        }
        let alpha = mul_255(src_alpha, scale);
        let keep = CHANNEL_MAX - alpha;
        for channel in 0..RGBA_BYTES {
            let scaled = mul_255(u32::from(s[channel]), scale);
            d[channel] = (scaled + mul_255(u32::from(d[channel]), keep)) as u8;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixmap_of(width: u32, height: u32, rgba: [u8; 4]) -> Pixmap {
        let mut p = Pixmap::new(width, height).expect("non-empty test pixmap");
        for px in p.data_mut().chunks_exact_mut(RGBA_BYTES) {
            px.copy_from_slice(&rgba);
        }
        p
    }

    #[test]
    fn blends_premultiplied_source_over() {
        let mut canvas = pixmap_of(2, 1, [0, 0, 200, 255]);
        // 50 % red, premultiplied.
        let layer = pixmap_of(1, 1, [128, 0, 0, 128]);
        composite_layer(&mut canvas, &layer, Coverage::Everywhere, (1, 0), u8::MAX);
        assert_eq!(canvas.data(), &[0, 0, 200, 255, 128, 0, 100, 255]);
    }

    #[test]
    fn mask_and_opacity_scale_the_layer() {
        let mut canvas = pixmap_of(1, 1, [0, 0, 0, 0]);
        let layer = pixmap_of(1, 1, [255, 255, 255, 255]);
        let mut mask = Mask::new(1, 1).expect("non-empty test mask");
        mask.data_mut()[0] = 128;
        composite_layer(&mut canvas, &layer, Coverage::Masked(&mask), (0, 0), 128);
        // 128 · 128 / 255 = 64.25
        assert_eq!(canvas.data(), &[64, 64, 64, 64]);
    }

    #[test]
    fn layer_beyond_the_canvas_is_clipped() {
        let mut canvas = pixmap_of(2, 2, [0, 0, 0, 0]);
        let layer = pixmap_of(3, 3, [255, 255, 255, 255]);
        composite_layer(&mut canvas, &layer, Coverage::Everywhere, (1, 1), u8::MAX);
        let alphas: Vec<u8> = canvas
            .data()
            .chunks_exact(RGBA_BYTES)
            .map(|p| p[ALPHA])
            .collect();
        assert_eq!(alphas, [0, 0, 0, 255]);
    }
}
