//! Gap closing: every line casts a ridge of ink that fades over a few pixels, so the lift sees
//! a small gap in an outline as a hill, and a one-pixel antialiased line as a wall.
//!
//! In: the line art's colors over white (RGB8, row-major), the image size and the fade
//! distance `fade_px`. Out: the "closed" colors the 5D lift and the mesh use: per channel, the
//! darkness 255 − c becomes max over pixels q of (darkness(q) − 255·|p − q| / fade_px), a
//! grayscale dilation by a cone, computed by chamfer propagation ([`super::chamfer`],
//! Borgefors 1986 weights 1 and √2 per step; exact integer arithmetic, so results are
//! portable).
//!
//! In the middle of a gap g px wide the ridge is still 1 − g / (2·fade_px) of the line's ink:
//! crossing it costs, so the colors on both sides stay apart (LazyBrush and Krita's colorize
//! mask close gaps with a distance field in the same spirit). Away from lines (more than
//! `fade_px`) nothing changes. A thin antialiased line whose pixels are only 8-connected
//! becomes a ridge several pixels wide, which the mesh resolves with well-shaped triangles.

use super::chamfer;
use rayon::prelude::*;

/// The colors with every line's ridge of ink added. `fade_px` ≤ 0 returns the colors as
/// they are.
pub fn close_gaps(colors: &[[u8; 3]], width: u32, height: u32, fade_px: f64) -> Vec<[u8; 3]> {
    if fade_px.is_nan() || fade_px <= 0.0 || fade_px.is_infinite() {
        return colors.to_vec();
    }
    debug_assert_eq!(colors.len(), width as usize * height as usize);
    // Darkness lost per axial and per diagonal step, in 1/255 units (a loss of 255 or more
    // leaves nothing, as does exactly 255).
    let step = |per_px: f64| (per_px / fade_px).round().clamp(1.0, 255.0) as u8;
    let (axial, diagonal) = (step(255.0), step(255.0 * std::f64::consts::SQRT_2));
    // One darkness plane per channel, each dilated; a gray drawing needs only one.
    let plane = |k: usize| -> Vec<u8> {
        let mut dark: Vec<u8> = colors.par_iter().map(|c| 255 - c[k]).collect();
        chamfer::propagate(
            &mut dark,
            width as usize,
            axial,
            diagonal,
            |d, from, step| d.max(from.saturating_sub(step)),
        );
        dark
    };
    if colors.par_iter().all(|c| c[0] == c[1] && c[1] == c[2]) {
        return plane(0).par_iter().map(|&d| [255 - d; 3]).collect();
    }
    let (r, (g, b)) = rayon::join(|| plane(0), || rayon::join(|| plane(1), || plane(2)));
    (r.par_iter().zip(&g).zip(&b))
        .map(|((&r, &g), &b)| [255 - r, 255 - g, 255 - b])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_casts_a_fading_ridge_and_a_gap_becomes_a_hill() {
        // A 1-px black row segment with a 4-px gap in the middle of a 21×9 white image.
        let (w, h) = (21u32, 9u32);
        let mut colors = vec![[255u8; 3]; (w * h) as usize];
        for x in (0..21).filter(|x| !(8..12).contains(x)) {
            colors[(4 * w + x) as usize] = [0; 3];
        }
        let closed = close_gaps(&colors, w, h, 4.0);
        let at = |x: u32, y: u32| closed[(y * w + x) as usize][0];
        assert_eq!(at(2, 4), 0); // on the line
        assert_eq!(at(2, 3), 64); // one step away: a quarter of the ink gone
        assert_eq!(at(2, 0), 255); // four steps away: nothing left
                                   // The gap's middle pixels are 2 steps from the nearest line end: half the ink.
        assert_eq!(at(9, 4), 128);
        assert_eq!(at(10, 4), 128);
        // Off means unchanged.
        assert_eq!(close_gaps(&colors, w, h, 0.0), colors);
    }

    #[test]
    fn each_channel_of_a_colored_drawing_closes_as_that_channel_drawn_in_gray() {
        // A red row and a blue column crossing, with a gap each, over white.
        let (w, h) = (15u32, 11u32);
        let mut colors = vec![[255u8; 3]; (w * h) as usize];
        for x in (0..w).filter(|x| !(6..8).contains(x)) {
            colors[(5 * w + x) as usize] = [220, 30, 40];
        }
        for y in (0..h).filter(|&y| y != 2) {
            colors[(y * w + 10) as usize] = [20, 60, 230];
        }
        let closed = close_gaps(&colors, w, h, 3.0);
        for k in 0..3 {
            let gray: Vec<[u8; 3]> = colors.iter().map(|c| [c[k]; 3]).collect();
            let expected: Vec<u8> = close_gaps(&gray, w, h, 3.0).iter().map(|c| c[0]).collect();
            let got: Vec<u8> = closed.iter().map(|c| c[k]).collect();
            assert_eq!(got, expected, "channel {k}");
        }
        assert_ne!(closed, colors);
    }
}
