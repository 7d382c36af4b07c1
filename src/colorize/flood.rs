//! The floor to beat: a paint-bucket flood fill between the lines.
//!
//! In: the line mask (true = line pixel, a barrier), the scribble labels per pixel and the
//! palette. Out: the fill (RGBA8, opaque): each scribble color, in palette order and from its
//! pixels in raster order, floods the 4-connected non-line pixels not yet filled, as a paint
//! program's bucket tool does one click at a time; what no bucket reaches (lines, regions
//! without a scribble) stays white. A gap in an outline lets the first bucket run through it.

use image::{Rgba, RgbaImage};

/// The bucket fill from every scribble pixel.
pub fn flood_fill(
    width: u32,
    height: u32,
    is_line: &[bool],
    labels: &[u16],
    palette: &[[u8; 3]],
) -> RgbaImage {
    let (w, h) = (width as usize, height as usize);
    let mut owner = vec![0u16; w * h];
    let mut stack = Vec::new();
    for color in 1..=palette.len() as u16 {
        for seed in 0..w * h {
            if labels[seed] != color || is_line[seed] || owner[seed] != 0 {
                continue;
            }
            owner[seed] = color;
            stack.push(seed);
            while let Some(i) = stack.pop() {
                let (x, y) = (i % w, i / w);
                let mut visit = |j: usize| {
                    if !is_line[j] && owner[j] == 0 {
                        owner[j] = color;
                        stack.push(j);
                    }
                };
                if x > 0 {
                    visit(i - 1);
                }
                if x + 1 < w {
                    visit(i + 1);
                }
                if y > 0 {
                    visit(i - w);
                }
                if y + 1 < h {
                    visit(i + w);
                }
            }
        }
    }
    RgbaImage::from_fn(width, height, |x, y| {
        let o = owner[y as usize * w + x as usize];
        let c = if o == 0 {
            [255; 3]
        } else {
            palette[o as usize - 1]
        };
        Rgba([c[0], c[1], c[2], 255])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn buckets_stop_at_lines_and_leak_through_gaps() {
        // 5×1: pixels 0–1 | line at 2 | 3–4.
        let line = [false, false, true, false, false];
        let fill = flood_fill(5, 1, &line, &[1, 0, 0, 0, 0], &[[255, 0, 0]]);
        let reds: Vec<bool> = fill.pixels().map(|p| p.0 == [255, 0, 0, 255]).collect();
        assert_eq!(reds, vec![true, true, false, false, false]);
        let open = [false; 5];
        let fill = flood_fill(5, 1, &open, &[1, 0, 0, 0, 2], &[[255, 0, 0], [0, 0, 255]]);
        // The first bucket takes everything, the second color's pixel included.
        assert!(fill.pixels().all(|p| p.0 == [255, 0, 0, 255]));
    }
}
