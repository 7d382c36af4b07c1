//! One premultiplied source pixel, scaled by coverage and a part's tint, source-over onto the
//! canvas: 8-bit integer arithmetic with rounding to nearest, four channels per `u32`.
//!
//! In: packed little-endian RGBA8 (red in the low byte), premultiplied; coverage 0..=255; a
//! [`Tint`] (RGBA multipliers in [0, 1]). Out: `src·k + dst·(1 − αsrc·k)` per channel, where
//! colour channels use `k = coverage · tint.rgb · tint.a` and alpha `k = coverage · tint.a`.
//! The result stays a valid premultiplied pixel (every channel ≤ alpha, nothing above 255), and a
//! fully covered, untinted opaque pixel is copied exactly.

use serde::{Deserialize, Serialize};

use super::pixel_math::{mul_255, CHANNEL_MAX};

/// The red/blue lanes of a packed pixel (green/alpha after shifting down by 8).
const LANES: u32 = 0x00FF_00FF;
/// Half a step in each lane, for rounding to nearest.
const LANE_HALF: u32 = 0x0080_0080;

/// A per-part colour multiplier, each component in [0, 1] (out-of-range values are clamped, NaN
/// counts as 0). Applied to premultiplied colour: red, green and blue are multiplied by
/// `r·a`, `g·a`, `b·a`, alpha by `a`; so `a` is the part's opacity and `r, g, b` darken or tint
/// it. Serialized as `[r, g, b, a]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "[f32; 4]", into = "[f32; 4]")]
pub struct Tint {
    pub r: f32,
    pub g: f32,
    pub b: f32,
    pub a: f32,
}

impl Tint {
    /// No change: the part as its texture shows it.
    pub const WHITE: Tint = Tint {
        r: 1.0,
        g: 1.0,
        b: 1.0,
        a: 1.0,
    };

    /// The part's own colours at `opacity` (0..=1).
    pub fn opacity(opacity: f32) -> Tint {
        Tint {
            a: opacity,
            ..Tint::WHITE
        }
    }
}

impl Default for Tint {
    fn default() -> Self {
        Tint::WHITE
    }
}

impl From<[f32; 4]> for Tint {
    fn from([r, g, b, a]: [f32; 4]) -> Self {
        Tint { r, g, b, a }
    }
}

impl From<Tint> for [f32; 4] {
    fn from(t: Tint) -> Self {
        [t.r, t.g, t.b, t.a]
    }
}

/// A tint as 8-bit factors per channel (red, green, blue, alpha), 255 = unchanged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct TintFactors([u32; 4]);

impl TintFactors {
    pub fn new(tint: Tint) -> Self {
        let unit = |v: f32| if v > 0.0 { v.min(1.0) } else { 0.0 };
        let alpha = unit(tint.a);
        let level = |v: f32| (v * CHANNEL_MAX as f32).round() as u32;
        TintFactors([
            level(unit(tint.r) * alpha),
            level(unit(tint.g) * alpha),
            level(unit(tint.b) * alpha),
            level(alpha),
        ])
    }

    /// Whether nothing drawn with this tint can show.
    pub fn is_invisible(self) -> bool {
        self.0[3] == 0
    }

    /// Whether the tint changes nothing.
    pub fn is_identity(self) -> bool {
        self.0 == [CHANNEL_MAX; 4]
    }

    /// The one factor shared by all four channels, if there is one.
    pub fn uniform(self) -> Option<u32> {
        let [r, g, b, a] = self.0;
        (r == a && g == a && b == a).then_some(a)
    }
}

/// Each channel of `px` times `k / 255`, rounded to nearest (`k` ≤ 255).
#[inline]
pub(super) fn scale(px: u32, k: u32) -> u32 {
    let rb = div255_lanes((px & LANES) * k);
    let ga = div255_lanes(((px >> 8) & LANES) * k);
    rb | ga << 8
}

/// `x / 255` rounded, in both 16-bit lanes at once (each lane ≤ 255²).
#[inline]
fn div255_lanes(x: u32) -> u32 {
    let t = x + LANE_HALF;
    ((t + ((t >> 8) & LANES)) >> 8) & LANES
}

/// Premultiplied source-over: `src + dst·(255 − αsrc)/255`.
#[inline]
pub(super) fn source_over(dst: u32, src: u32) -> u32 {
    // Per channel src ≤ αsrc and the scaled dst ≤ 255 − αsrc, so no lane overflows.
    src + scale(dst, CHANNEL_MAX - (src >> 24))
}

/// The source pixel as it lands: scaled by `coverage` (1..=255) and the tint's factors.
#[inline(always)]
pub(super) fn tinted(src: u32, coverage: u32, tint: TintFactors) -> u32 {
    if coverage == CHANNEL_MAX && tint.is_identity() {
        return src;
    }
    match tint.uniform() {
        Some(k) => scale(src, mul_255(coverage, k)),
        None => tinted_per_channel(src, coverage, tint),
    }
}

/// [`tinted`] for a tint that scales the channels differently (rare: kept out of line).
#[cold]
fn tinted_per_channel(src: u32, coverage: u32, tint: TintFactors) -> u32 {
    let bytes = src.to_le_bytes();
    let mut out = [0u8; 4];
    for ((o, &c), &k) in out.iter_mut().zip(&bytes).zip(&tint.0) {
        *o = mul_255(u32::from(c), mul_255(coverage, k)) as u8;
    }
    u32::from_le_bytes(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn px(p: [u8; 4]) -> u32 {
        u32::from_le_bytes(p)
    }

    #[test]
    fn scaling_matches_exact_rounding_for_every_pair() {
        for k in 0..=255u32 {
            for c in 0..=255u32 {
                let want = (f64::from(c * k) / 255.0).round() as u8;
                let got = scale(px([c as u8, 0, c as u8, c as u8]), k).to_le_bytes();
                assert_eq!(got, [want, 0, want, want], "{c} · {k}");
            }
        }
    }

    #[test]
    fn source_over_blends_premultiplied() {
        // 50 % red over opaque blue.
        let out = source_over(px([0, 0, 200, 255]), px([128, 0, 0, 128]));
        assert_eq!(out.to_le_bytes(), [128, 0, 100, 255]);
        // Opaque source replaces; transparent source keeps.
        let dst = px([9, 8, 7, 6]);
        assert_eq!(source_over(dst, px([1, 2, 3, 255])), px([1, 2, 3, 255]));
        assert_eq!(source_over(dst, 0), dst);
    }

    #[test]
    fn source_over_never_leaves_premultiplied_range() {
        for sa in (0..=255u8).step_by(5) {
            for da in (0..=255u8).step_by(5) {
                let out = source_over(px([da, da / 2, 0, da]), px([sa, sa / 3, sa, sa]));
                let [r, g, b, a] = out.to_le_bytes();
                assert!(
                    r <= a && g <= a && b <= a,
                    "{sa} over {da}: {:?}",
                    [r, g, b, a]
                );
            }
        }
    }

    #[test]
    fn tint_multiplies_premultiplied_colour_by_rgb_times_alpha() {
        let tint = TintFactors::new(Tint {
            r: 1.0,
            g: 0.5,
            b: 0.0,
            a: 0.5,
        });
        let out = tinted(px([200, 200, 200, 255]), 255, tint).to_le_bytes();
        // Factors: r 0.5, g 0.25, b 0, alpha 0.5 (as 128, 64, 0, 128 of 255).
        assert_eq!(out, [100, 50, 0, 128]);
        let [r, g, b, a] = tinted(px([90, 10, 250, 255]), 100, tint).to_le_bytes();
        assert!(r <= a && g <= a && b <= a);
    }

    #[test]
    fn coverage_and_opacity_combine() {
        let half = TintFactors::new(Tint::opacity(0.5));
        assert_eq!(half.uniform(), Some(128));
        // 255 · (128 · 128 / 255 = 64) / 255 = 64.
        assert_eq!(tinted(px([255; 4]), 128, half), px([64; 4]));
        let white = TintFactors::new(Tint::WHITE);
        assert_eq!(tinted(px([1, 2, 3, 4]), 255, white), px([1, 2, 3, 4]));
    }

    #[test]
    fn bad_tints_are_clamped() {
        let t = TintFactors::new(Tint {
            r: f32::NAN,
            g: 7.0,
            b: -1.0,
            a: 2.0,
        });
        assert_eq!(t, TintFactors([0, 255, 0, 255]));
        assert!(TintFactors::new(Tint::opacity(f32::NAN)).is_invisible());
        let json = serde_json::to_string(&Tint::opacity(0.25)).expect("serializable");
        assert_eq!(json, "[1.0,1.0,1.0,0.25]");
        let back: Tint = serde_json::from_str(&json).expect("parses");
        assert_eq!(back, Tint::opacity(0.25));
    }
}
