//! Splitting a region that holds several scribble colors by ink density: the flood order of
//! G'MIC's "Colorize Lineart [Smart Coloring]" (Fourey, Tschumperlé & Revoy 2018, "A Fast and
//! Efficient Semi-guided Algorithm for Flat Coloring Line-arts", mode "extrapolate color
//! spots"; our own code after reading `_fx_colorize_lineart_smart` in G'MIC's
//! `gmic_stdlib.gmic`).
//!
//! Where the line art draws no boundary between two colors, nothing in it says where the
//! boundary is; the prior here is that colors spread first through open paper, far from any
//! ink, and meet where ink is dense around them: at narrow necks, between the ends of lines
//! that almost close, where strokes crowd. "Far from ink" is measured by blurring the paper
//! mask (1 off the lines, 0 on them) with a Gaussian, which, unlike the distance to the
//! nearest line, also counts the ink on the other side of a line and how much of it there is
//! around a pixel.
//!
//! In: the regions ([`super::InkRegions::region`], 0 on lines and their gap-closing ridges),
//! the image size, two blur radii σ in px (fine and coarse; G'MIC uses 1 px and 1 % of the
//! image's side, our default coarse σ is 12 px, see [`super::ColorizeOptions::split_blur_px`]). Out: per pixel a flood level
//! 0–[`DENSITY_LEVEL_MAX`]: `DENSITY_LEVEL_MAX`·(1 − min(G_fine ∗ paper, G_coarse ∗ paper)),
//! low in open paper, the order [`super::ink_regions::watershed_within`] floods the contested
//! regions in (deepest first, colors meeting on the crests of ink density).

/// The highest flood level: the density is quantized to 16 bits. 8 would not do: deep inside
/// a region the blurred paper comes within 1e-3 of 1, and those differences are what orders
/// the flood there (with 256 levels everything beyond about 3σ from the ink is one plateau,
/// flooded by distance alone).
pub const DENSITY_LEVEL_MAX: u16 = u16::MAX;

/// The Gaussian kernel is cut at this many σ.
pub const KERNEL_RADIUS_SIGMAS: f64 = 4.0;

/// Per pixel, the flood level of the ink density around it (see the module doc).
/// `fine_sigma_px` and `coarse_sigma_px` ≥ 0 (0: no blur at that scale).
pub fn density_levels(
    region: &[u32],
    width: u32,
    height: u32,
    fine_sigma_px: f64,
    coarse_sigma_px: f64,
) -> Vec<u16> {
    let (w, h) = (width as usize, height as usize);
    let paper: Vec<f64> = region
        .iter()
        .map(|&r| if r > 0 { 1.0 } else { 0.0 })
        .collect();
    let fine = gaussian_blur(&paper, w, h, fine_sigma_px);
    let coarse = gaussian_blur(&paper, w, h, coarse_sigma_px);
    fine.iter()
        .zip(&coarse)
        .map(|(&a, &b)| {
            let open = a.min(b).clamp(0.0, 1.0);
            ((1.0 - open) * DENSITY_LEVEL_MAX as f64).round() as u16
        })
        .collect()
}

/// A separable Gaussian blur of a `w`×`h` image, σ = `sigma_px`, the kernel cut at
/// [`KERNEL_RADIUS_SIGMAS`]·σ and normalized, the image mirrored at its edges (edge pixel
/// repeated: d c b a | a b c d).
pub fn gaussian_blur(values: &[f64], w: usize, h: usize, sigma_px: f64) -> Vec<f64> {
    if sigma_px.is_nan() || sigma_px <= 0.0 || w == 0 || h == 0 {
        return values.to_vec();
    }
    let radius = (KERNEL_RADIUS_SIGMAS * sigma_px).ceil() as isize;
    let mut kernel: Vec<f64> = (-radius..=radius)
        .map(|k| (-(k * k) as f64 / (2.0 * sigma_px * sigma_px)).exp())
        .collect();
    let sum: f64 = kernel.iter().sum();
    kernel.iter_mut().for_each(|k| *k /= sum);
    let mirror = |i: isize, n: usize| -> usize {
        let n = n as isize;
        let period = 2 * n;
        let m = i.rem_euclid(period);
        (if m < n { m } else { period - 1 - m }) as usize
    };
    let mut rows = vec![0.0; w * h];
    for y in 0..h {
        let line = &values[y * w..(y + 1) * w];
        for x in 0..w {
            rows[y * w + x] = kernel
                .iter()
                .enumerate()
                .map(|(k, &g)| g * line[mirror(x as isize + k as isize - radius, w)])
                .sum();
        }
    }
    let mut out = vec![0.0; w * h];
    for y in 0..h {
        for x in 0..w {
            out[y * w + x] = kernel
                .iter()
                .enumerate()
                .map(|(k, &g)| g * rows[mirror(y as isize + k as isize - radius, h) * w + x])
                .sum();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_blur_keeps_a_constant_and_spreads_a_point_symmetrically() {
        let flat = gaussian_blur(&[1.0; 35], 7, 5, 2.0);
        assert!(flat.iter().all(|&v| (v - 1.0).abs() < 1e-12));
        let mut dot = vec![0.0; 81];
        dot[40] = 1.0;
        let b = gaussian_blur(&dot, 9, 9, 1.0);
        assert!((b[39] - b[41]).abs() < 1e-15 && (b[31] - b[49]).abs() < 1e-15);
        assert!(b[40] > b[39] && b[39] > b[38]);
        // Mass is kept away from the edges.
        assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn a_narrow_neck_is_denser_than_the_open_parts_it_joins() {
        // Two 9×9 rooms joined by a 3 px neck, walls (region 0) around.
        let (w, h) = (25usize, 11usize);
        let mut region = vec![0u32; w * h];
        for y in 1..10 {
            for x in 1..24 {
                let room = !(10..15).contains(&x);
                let neck = (4..7).contains(&y);
                if room || neck {
                    region[y * w + x] = 1;
                }
            }
        }
        let level = density_levels(&region, w as u32, h as u32, 1.0, 3.0);
        let at = |x: usize, y: usize| level[y * w + x];
        assert!(at(12, 5) > at(5, 5) && at(12, 5) > at(19, 5));
        assert!(at(5, 5).abs_diff(at(19, 5)) <= 1);
        assert!(at(0, 0) > at(5, 5));
    }
}
