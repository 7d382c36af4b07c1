//! Frame durations in whole ticks (GIF: 1/100 s, sprite sheets: 1 ms) from a frame rate.
//!
//! In: frame count, frames per second, ticks per second. Out: one duration per frame, ticks.
//! Frame `i` starts at the exact time `i / fps` rounded to the nearest tick, so the rounding is
//! spread over the frames and never accumulates: the durations add up to `count / fps` rounded
//! once (24 fps in 1/100 s: 4, 4, 5, 4, 4, 4, 5, … — 100 ticks per 24 frames).

/// GIF delay ticks per second (delays are stored in hundredths of a second).
pub const GIF_TICKS_PER_S: u32 = 100;
/// Sprite-sheet `duration` ticks per second (Aseprite's and Phaser's milliseconds).
pub const MS_PER_S: u32 = 1000;

/// Durations of `count` frames at `fps`, in ticks of `1 / ticks_per_s` s.
///
/// `fps` must be positive and finite (checked by the callers).
pub fn frame_durations(count: usize, fps: f64, ticks_per_s: u32) -> Vec<u32> {
    let start_tick = |i: usize| (i as f64 * f64::from(ticks_per_s) / fps).round();
    (0..count)
        .map(|i| {
            // Both starts are whole numbers below 2^53 for any sane length, so the difference
            // is exact; saturate rather than wrap for absurd inputs.
            (start_tick(i + 1) - start_tick(i)).clamp(0.0, f64::from(u32::MAX)) as u32
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_is_spread_and_the_total_is_exact() {
        let d = frame_durations(24, 24.0, GIF_TICKS_PER_S);
        assert_eq!(d.iter().sum::<u32>(), 100);
        assert!(d.iter().all(|&t| t == 4 || t == 5), "{d:?}");
        assert_eq!(d.iter().filter(|&&t| t == 5).count(), 4);
        assert_eq!(&d[..4], &[4, 4, 5, 4]);

        let d = frame_durations(30, 30.0, MS_PER_S);
        assert_eq!(d.iter().sum::<u32>(), 1000);
        assert!(d.iter().all(|&t| t == 33 || t == 34), "{d:?}");

        // NTSC rate: 1001 frames last 1001 / 29.97 s = 33.4 s.
        let d = frame_durations(1001, 30000.0 / 1001.0, GIF_TICKS_PER_S);
        assert_eq!(d.iter().sum::<u32>(), 3340);
        assert_eq!(frame_durations(3, 10.0, GIF_TICKS_PER_S), vec![10, 10, 10]);
        assert!(frame_durations(0, 10.0, GIF_TICKS_PER_S).is_empty());
    }
}
