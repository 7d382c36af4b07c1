//! 8-bit channel arithmetic shared by the conversions and the compositor.

/// The largest 8-bit channel value, which stands for 1.0.
pub(super) const CHANNEL_MAX: u32 = 255;

/// `x / 255` rounded to nearest, exact for every `x` in 0..=255².
///
/// The usual shift trick: cheaper than a division, and it lets a product of two 8-bit values
/// (each standing for a fraction of 255) be scaled back to 8 bits without bias.
pub(super) fn div255_round(x: u32) -> u32 {
    let t = x + 128;
    (t + (t >> 8)) >> 8
}

/// `a · b / 255` rounded to nearest, for two 8-bit values.
pub(super) fn mul_255(a: u32, b: u32) -> u32 {
    div255_round(a * b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn div255_round_matches_exact_rounding() {
        for x in 0..=CHANNEL_MAX * CHANNEL_MAX {
            let exact = (f64::from(x) / 255.0).round() as u32;
            assert_eq!(div255_round(x), exact, "x = {x}");
        }
    }
}
