//! A solid background under straight-alpha frames, and the `#rrggbbaa` colour notation.
//!
//! In: frames (straight-alpha RGBA8) and a background colour (straight RGBA8). Out: the frames
//! composited over it ("source over", straight alpha in and out). With an opaque background every
//! output pixel is opaque, so a GIF of them has no 1-bit transparency to lose antialiased edges to.

use super::SequenceError;
use image::RgbaImage;

/// Largest 8-bit channel value, as u32 for the integer blend.
const MAX: u32 = 255;

/// Each frame composited over `background_rgba` (straight alpha).
pub fn composite_over_background(frames: &[RgbaImage], background_rgba: [u8; 4]) -> Vec<RgbaImage> {
    frames
        .iter()
        .map(|frame| {
            let mut out = frame.clone();
            for px in out.pixels_mut() {
                px.0 = over(px.0, background_rgba);
            }
            out
        })
        .collect()
}

/// `front` over `back`, both straight alpha, rounded to nearest.
fn over(front: [u8; 4], back: [u8; 4]) -> [u8; 4] {
    let front_a = u32::from(front[3]);
    let back_a = u32::from(back[3]);
    // Output alpha and the colour weights, all scaled by 255².
    let front_w = front_a * MAX;
    let back_w = back_a * (MAX - front_a);
    let alpha_w = front_w + back_w;
    if alpha_w == 0 {
        return [0; 4];
    }
    let mut out = [0u8; 4];
    for c in 0..3 {
        let sum = u32::from(front[c]) * front_w + u32::from(back[c]) * back_w;
        out[c] = ((sum + alpha_w / 2) / alpha_w) as u8;
    }
    out[3] = ((alpha_w + MAX / 2) / MAX) as u8;
    out
}

/// Parses `#rrggbb` (opaque) or `#rrggbbaa`; the `#` is optional, hex digits any case.
pub fn parse_rgba_hex(text: &str) -> Result<[u8; 4], SequenceError> {
    let bad = || SequenceError::BadColour { text: text.into() };
    let digits = text.strip_prefix('#').unwrap_or(text);
    if !digits.bytes().all(|b| b.is_ascii_hexdigit()) || !matches!(digits.len(), 6 | 8) {
        return Err(bad());
    }
    let mut rgba = [u8::MAX; 4];
    for (i, channel) in rgba.iter_mut().enumerate().take(digits.len() / 2) {
        *channel = u8::from_str_radix(&digits[2 * i..2 * i + 2], 16).map_err(|_| bad())?;
    }
    Ok(rgba)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_hex_colours() {
        assert_eq!(parse_rgba_hex("#ff8000").unwrap(), [255, 128, 0, 255]);
        assert_eq!(parse_rgba_hex("10203040").unwrap(), [16, 32, 48, 64]);
        assert_eq!(parse_rgba_hex("#AbCdEf01").unwrap(), [171, 205, 239, 1]);
        for bad in [
            "",
            "#",
            "#fff",
            "#ff800",
            "#ff8000f",
            "#gg0000",
            "#ff80€0",
            "#ff8000ff00",
        ] {
            let err = parse_rgba_hex(bad).unwrap_err();
            assert!(matches!(err, SequenceError::BadColour { .. }), "{bad}");
        }
    }

    #[test]
    fn source_over_in_straight_alpha() {
        // Opaque front hides the back; transparent front shows it.
        assert_eq!(over([1, 2, 3, 255], [9, 9, 9, 255]), [1, 2, 3, 255]);
        assert_eq!(over([1, 2, 3, 0], [9, 8, 7, 200]), [9, 8, 7, 200]);
        // Half red over opaque blue: purple, opaque.
        assert_eq!(over([255, 0, 0, 128], [0, 0, 255, 255]), [128, 0, 127, 255]);
        // Half red over transparent: unchanged (colour kept, alpha kept).
        assert_eq!(over([255, 0, 0, 128], [0, 0, 255, 0]), [255, 0, 0, 128]);
        // Half over half: alpha 1 - 0.5·0.5 = 0.75; colour weights 2:1.
        assert_eq!(over([255, 0, 0, 128], [0, 0, 255, 128]), [170, 0, 85, 192]);
        assert_eq!(over([0; 4], [0; 4]), [0; 4]);

        let frame = RgbaImage::from_fn(3, 1, |x, _| image::Rgba([200, 100, 0, (x * 120) as u8]));
        let out = composite_over_background(&[frame], [0, 0, 0, 255]);
        assert!(out[0].pixels().all(|p| p[3] == 255));
        assert_eq!(out[0].get_pixel(0, 0).0, [0, 0, 0, 255]);
        assert_eq!(out[0].get_pixel(2, 0).0, [188, 94, 0, 255]);
    }
}
