//! A part's image as the rasterizer samples it: premultiplied RGBA8 texels, read bilinearly.
//!
//! In: a straight-alpha `RgbaImage` or a premultiplied tiny-skia `Pixmap`. Out: texels packed
//! as little-endian `u32` (red in the low byte, alpha in the high byte), and [`Texture::sample`],
//! which reads the bilinear blend of the four texels around a position given in fixed point
//! ([`sampler_coord`]). Positions past the border read the nearest border texel (clamp to edge).
//!
//! Bilinear weights have 8 bits (1/256 texel) and the weighted sum is rounded once, so a sample
//! is within one level of the exact blend per channel; at a texel center the texel comes back
//! exactly. Blending premultiplied texels keeps colour ≤ alpha.

use image::RgbaImage;
use tiny_skia::PixmapRef;

use super::pixel_math::mul_255;
use super::raster::round_within_range;
use super::RenderError;

/// Fraction bits of a sampler coordinate.
pub(super) const COORD_FRACTION_BITS: u32 = 16;
/// Bits of a bilinear weight.
const WEIGHT_BITS: u32 = 8;
/// Largest texture coordinate magnitude, texels, kept before conversion to fixed point, so that
/// a coordinate stepped across any row stays far inside `i64`.
const MAX_COORD_TEXELS: f64 = (1u64 << 30) as f64;
/// Largest per-pixel step, texels, for the same reason.
const MAX_STEP_TEXELS: f64 = (1u64 << 20) as f64;

/// The red and blue bytes of a packed texel (green and alpha after shifting down by 8).
const LANES: u32 = 0x00FF_00FF;
/// The low bytes of the four 16-bit lanes of a [`spread`] pixel.
const SPREAD_LANES: u64 = 0x00FF_00FF_00FF_00FF;
/// Half of one 8-bit step in each 16-bit lane, for rounding to nearest.
const LANE_HALVES: u64 = 0x0080_0080_0080_0080;

/// A premultiplied RGBA8 image for sampling.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    width: u32,
    height: u32,
    /// Row-major, each texel [`spread`] into 16-bit lanes: twice the memory of packed texels,
    /// but the sampler then blends four texels with four multiplications and nothing else.
    texels: Vec<u64>,
}

impl Texture {
    /// Premultiplies a straight-alpha image (rounding to nearest, as [`super::pixmap_from_rgba`]).
    /// Fails for an image without pixels.
    pub fn from_rgba(image: &RgbaImage) -> Result<Self, RenderError> {
        let (width, height) = image.dimensions();
        if width == 0 || height == 0 {
            return Err(RenderError::EmptyImage { width, height });
        }
        let texels = image
            .pixels()
            .map(|p| {
                let [r, g, b, a] = p.0.map(u32::from);
                spread(mul_255(r, a) | mul_255(g, a) << 8 | mul_255(b, a) << 16 | a << 24)
            })
            .collect();
        Ok(Texture {
            width,
            height,
            texels,
        })
    }

    /// The texels of an already premultiplied pixmap.
    pub fn from_pixmap(pixmap: PixmapRef) -> Self {
        Texture {
            width: pixmap.width(),
            height: pixmap.height(),
            texels: pixmap
                .data()
                .chunks_exact(4)
                .map(|p| spread(u32::from_le_bytes([p[0], p[1], p[2], p[3]])))
                .collect(),
        }
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// The bilinear sample at fixed-point position (`u`, `v`) (see [`sampler_coord`]); with
    /// `CLAMP` false the caller promises that the four texels lie inside (see
    /// [`Texture::holds_run`]), which saves the clamping.
    #[inline(always)]
    pub(super) fn sample<const CLAMP: bool>(&self, u: i64, v: i64) -> u32 {
        let (w, h) = (i64::from(self.width), i64::from(self.height));
        let (ix, iy) = (u >> COORD_FRACTION_BITS, v >> COORD_FRACTION_BITS);
        let weight_shift = COORD_FRACTION_BITS - WEIGHT_BITS;
        let fx = ((u >> weight_shift) & 0xFF) as u32;
        let fy = ((v >> weight_shift) & 0xFF) as u32;
        let t = &self.texels;
        let [p00, p10, p01, p11] = if CLAMP {
            let (x0, x1) = (ix.clamp(0, w - 1), (ix + 1).clamp(0, w - 1));
            let (r0, r1) = (iy.clamp(0, h - 1) * w, (iy + 1).clamp(0, h - 1) * w);
            [r0 + x0, r0 + x1, r1 + x0, r1 + x1].map(|i| t[i as usize])
        } else {
            // One bounds check per texel pair.
            let top = (iy * w + ix) as usize;
            let bottom = top + w as usize;
            let (top, bottom) = (&t[top..top + 2], &t[bottom..bottom + 2]);
            [top[0], top[1], bottom[0], bottom[1]]
        };
        blend4([p00, p10, p01, p11], fx, fy)
    }

    /// Whether `count` samples from (`u`, `v`) on, `step` apart, all read texels inside the
    /// texture, so that [`Texture::sample`] may skip clamping.
    pub(super) fn holds_run(&self, [u, v]: [i64; 2], [du, dv]: [i64; 2], count: i64) -> bool {
        let inside = |start: i64, step: i64, size: u32| {
            let end = start + step * (count - 1);
            let (lo, hi) = (start.min(end), start.max(end));
            lo >= 0 && (hi >> COORD_FRACTION_BITS) + 1 < i64::from(size)
        };
        count > 0 && inside(u, du, self.width) && inside(v, dv, self.height)
    }
}

/// A texture position (texture pixels: texel (i, j) covers [i, i+1) × [j, j+1)) as a sampler
/// coordinate: relative to texel centers, in 1/2¹⁶ texel, plus half a weight step, so that
/// cutting it to the weight's 8 bits rounds to the nearest 1/256 texel.
pub(super) fn sampler_coord(position_px: f64) -> i64 {
    let centered = (position_px - 0.5).clamp(-MAX_COORD_TEXELS, MAX_COORD_TEXELS);
    round_within_range(centered * f64::from(1u32 << COORD_FRACTION_BITS))
        + (1 << (COORD_FRACTION_BITS - WEIGHT_BITS - 1))
}

/// A texture step per output pixel (texels) in sampler units.
pub(super) fn sampler_step(step_texels: f64) -> i64 {
    let step = step_texels.clamp(-MAX_STEP_TEXELS, MAX_STEP_TEXELS);
    round_within_range(step * f64::from(1u32 << COORD_FRACTION_BITS))
}

/// The four [`spread`] texels (top-left, top-right, bottom-left, bottom-right) weighted by the
/// 8-bit fractions `fx`, `fy`, rounded once to nearest, packed again.
///
/// The weights are integers summing to exactly 256 (so a flat colour comes back unchanged), and
/// each channel is spread into its own 16-bit lane of a `u64`: a weighted sum is at most
/// 255 · 256, so the four channels are blended by four multiplications without carrying into
/// each other.
#[inline(always)]
fn blend4(texels: [u64; 4], fx: u32, fy: u32) -> u32 {
    let (fx, fy) = (u64::from(fx), u64::from(fy));
    let w11 = (fx * fy + 128) >> 8;
    let weights = [256 + w11 - fx - fy, fx - w11, fy - w11, w11];
    let mut sum = LANE_HALVES;
    for (texel, weight) in texels.into_iter().zip(weights) {
        sum += texel * weight;
    }
    let lanes = (sum >> 8) & SPREAD_LANES;
    (lanes as u32) | ((lanes >> 32) as u32) << 8
}

/// A packed RGBA8 pixel with each channel in its own 16-bit lane: red, blue, green, alpha at
/// bits 0, 16, 32, 48.
#[inline(always)]
fn spread(px: u32) -> u64 {
    u64::from(px & LANES) | u64::from((px >> 8) & LANES) << 32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texture_2x2() -> Texture {
        // Premultiplied: opaque red, half-transparent green, transparent, opaque white.
        let pixels = [[255, 0, 0, 255], [0, 128, 0, 128], [0, 0, 0, 0], [255; 4]];
        Texture {
            width: 2,
            height: 2,
            texels: pixels
                .iter()
                .map(|&p| spread(u32::from_le_bytes(p)))
                .collect(),
        }
    }

    fn at(t: &Texture, x: f64, y: f64) -> [u8; 4] {
        t.sample::<true>(sampler_coord(x), sampler_coord(y))
            .to_le_bytes()
    }

    #[test]
    fn texel_centers_give_the_texels_exactly() {
        let t = texture_2x2();
        assert_eq!(at(&t, 0.5, 0.5), [255, 0, 0, 255]);
        assert_eq!(at(&t, 1.5, 0.5), [0, 128, 0, 128]);
        assert_eq!(at(&t, 0.5, 1.5), [0, 0, 0, 0]);
        assert_eq!(at(&t, 1.5, 1.5), [255; 4]);
    }

    #[test]
    fn between_centers_the_texels_blend_bilinearly() {
        let t = texture_2x2();
        // Halfway between red and green along the top row.
        assert_eq!(at(&t, 1.0, 0.5), [128, 64, 0, 192]);
        // The middle: the mean of all four.
        assert_eq!(at(&t, 1.0, 1.0), [128, 96, 64, 160]);
        // A quarter of the way from red to green: 3/4 red.
        assert_eq!(at(&t, 0.75, 0.5), [191, 32, 0, 223]);
    }

    #[test]
    fn outside_the_texture_reads_the_border() {
        let t = texture_2x2();
        assert_eq!(at(&t, -3.0, 0.5), [255, 0, 0, 255]);
        assert_eq!(at(&t, 9.0, 9.0), [255; 4]);
        assert_eq!(at(&t, 0.0, 0.0), [255, 0, 0, 255]);
        assert_eq!(at(&t, f64::MAX, f64::MIN), [0, 128, 0, 128]);
    }

    #[test]
    fn unclamped_samples_agree_where_the_run_fits() {
        let t = Texture::from_rgba(&RgbaImage::from_fn(6, 5, |x, y| {
            image::Rgba([(x * 40) as u8, (y * 50) as u8, 7, 200])
        }))
        .expect("non-empty");
        let start = [sampler_coord(0.6), sampler_coord(0.9)];
        let step = [sampler_step(0.7), sampler_step(0.5)];
        // Seven samples from (0.6, 0.9) end at (4.8, 3.9), reading texels up to x = 5, y = 4, the
        // last ones; an eighth, at x = 5.5, would need x = 6.
        assert!(t.holds_run(start, step, 7));
        assert!(!t.holds_run(start, step, 8));
        assert!(!t.holds_run([sampler_coord(0.4), start[1]], step, 2));
        for k in 0..7 {
            let (u, v) = (start[0] + k * step[0], start[1] + k * step[1]);
            assert_eq!(t.sample::<false>(u, v), t.sample::<true>(u, v));
        }
    }

    #[test]
    fn samples_stay_premultiplied() {
        let t = Texture::from_rgba(&RgbaImage::from_fn(7, 5, |x, y| {
            image::Rgba([(x * 40) as u8, 255, (y * 60) as u8, (x * 37 + y * 11) as u8])
        }))
        .expect("non-empty");
        for k in 0..400 {
            let (x, y) = (f64::from(k % 20) * 0.37, f64::from(k / 20) * 0.29);
            let [r, g, b, a] = at(&t, x, y);
            assert!(r <= a && g <= a && b <= a, "({x}, {y}): {:?}", [r, g, b, a]);
        }
    }

    #[test]
    fn from_rgba_premultiplies_like_the_pixmap_conversion() {
        let image = RgbaImage::from_fn(9, 4, |x, y| {
            image::Rgba([(x * 29) as u8, (y * 70) as u8, 200, (x * 31 + y * 3) as u8])
        });
        let pixmap = super::super::pixmap_from_rgba(&image).expect("non-empty");
        assert_eq!(
            Texture::from_rgba(&image).expect("non-empty"),
            Texture::from_pixmap(pixmap.as_ref())
        );
        assert!(matches!(
            Texture::from_rgba(&RgbaImage::new(0, 3)),
            Err(RenderError::EmptyImage { .. })
        ));
    }
}
