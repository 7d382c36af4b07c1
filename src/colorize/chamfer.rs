//! Chamfer propagation over a raster with Borgefors' 3×3 mask (Borgefors 1986, "Distance
//! transformations in digital images"), in sweeps that run rows in parallel or carry no
//! dependency along a row.
//!
//! In: one value per pixel (row-major, `width` per row), the cost of an axial and of a
//! diagonal step, and how a value improves from a neighbour's (`relax`). Out: the same plane
//! with every value improved along every 8-connected path, as the classic two raster passes
//! give it.
//!
//! The sweeps: (1) along each row, left to right then right to left, rows in parallel; (2)
//! down the rows, each from the row above, straight or diagonal; (3) up the rows the same way.
//! They give the classic result because between any two pixels there is a best path whose
//! steps all go the same way vertically (all down or all up) and the same way horizontally:
//! a step and its opposite cancel, and a down-right and an up-right step cost no less than two
//! right steps as long as a diagonal step costs at least an axial one (Borgefors' weights and
//! every mask here). Such a path's steps can be reordered, its steps along the row first and
//! then the ones that go down (or up), without leaving the box its two ends span; a path's
//! cost does not depend on the order of its steps. The vertical sweeps carry no dependency
//! along a row, so the compiler may vectorize them (not checked in the machine code; the
//! measured gain is in docs/colorize-eval.md).

use rayon::prelude::*;

/// Improves every value of `plane` along 8-connected paths: an axial step costs `axial`, a
/// diagonal one `diagonal`, and `relax(current, neighbour, step)` is the value a pixel keeps
/// when its neighbour's value reaches it over a step of that cost: `min(current, neighbour +
/// step)` for a distance transform, `max(current, neighbour − step)` for a dilation by a cone.
/// `relax` must be monotone in the neighbour and compose as a path cost does (so steps
/// commute), and `axial` ≤ `diagonal` (a diagonal step never costs less than an axial one);
/// the module docs say why three sweeps then equal the classic two passes.
pub fn propagate<T, R>(plane: &mut [T], width: usize, axial: T, diagonal: T, relax: R)
where
    T: Copy + Send + Sync,
    R: Fn(T, T, T) -> T + Sync,
{
    if width == 0 {
        return;
    }
    plane.par_chunks_mut(width).for_each(|row| {
        for x in 1..row.len() {
            row[x] = relax(row[x], row[x - 1], axial);
        }
        for x in (0..row.len().saturating_sub(1)).rev() {
            row[x] = relax(row[x], row[x + 1], axial);
        }
    });
    let rows = plane.len() / width;
    for y in 1..rows {
        let (above, rest) = plane.split_at_mut(y * width);
        relax_from_row(
            &mut rest[..width],
            &above[(y - 1) * width..],
            axial,
            diagonal,
            &relax,
        );
    }
    for y in (0..rows.saturating_sub(1)).rev() {
        let (upto, below) = plane.split_at_mut((y + 1) * width);
        relax_from_row(
            &mut upto[y * width..],
            &below[..width],
            axial,
            diagonal,
            &relax,
        );
    }
}

/// One row of a vertical sweep: each pixel of `row` from the three of `from` (the row above or
/// below) it touches.
fn relax_from_row<T: Copy, R: Fn(T, T, T) -> T>(
    row: &mut [T],
    from: &[T],
    axial: T,
    diagonal: T,
    relax: &R,
) {
    for (d, &f) in row.iter_mut().zip(from) {
        *d = relax(*d, f, axial);
    }
    if row.len() > 1 {
        for (d, &f) in row[1..].iter_mut().zip(from) {
            *d = relax(*d, f, diagonal);
        }
        for (d, &f) in row.iter_mut().zip(&from[1..]) {
            *d = relax(*d, f, diagonal);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The classic two raster passes (forward: left, above-left, above, above-right; backward:
    /// the mirror), the reference the sweeps must equal.
    fn two_passes(d: &mut [u32], w: usize, h: usize) {
        let relax = |d: &mut [u32], i: usize, j: usize, step: u32| d[i] = d[i].min(d[j] + step);
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if x > 0 {
                    relax(d, i, i - 1, 2);
                }
                if y > 0 {
                    relax(d, i, i - w, 2);
                    if x > 0 {
                        relax(d, i, i - w - 1, 3);
                    }
                    if x + 1 < w {
                        relax(d, i, i - w + 1, 3);
                    }
                }
            }
        }
        for y in (0..h).rev() {
            for x in (0..w).rev() {
                let i = y * w + x;
                if x + 1 < w {
                    relax(d, i, i + 1, 2);
                }
                if y + 1 < h {
                    relax(d, i, i + w, 2);
                    if x + 1 < w {
                        relax(d, i, i + w + 1, 3);
                    }
                    if x > 0 {
                        relax(d, i, i + w - 1, 3);
                    }
                }
            }
        }
    }

    #[test]
    fn the_sweeps_equal_the_two_raster_passes() {
        // Scattered sources with arbitrary start values (a generalized distance transform),
        // on shapes down to one row and one column.
        for (w, h) in [(37usize, 23usize), (1, 9), (9, 1), (2, 2), (64, 5)] {
            let mut state = 0x9e3779b9u32;
            let start: Vec<u32> = (0..w * h)
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 17;
                    state ^= state << 5;
                    if state.is_multiple_of(7) {
                        state % 40
                    } else {
                        1 << 20
                    }
                })
                .collect();
            let mut classic = start.clone();
            two_passes(&mut classic, w, h);
            let mut swept = start;
            propagate(&mut swept, w, 2, 3, |d, from, step| d.min(from + step));
            assert_eq!(swept, classic, "{w}×{h}");
        }
    }

    #[test]
    fn a_dilation_spreads_a_single_peak_as_an_octagonal_cone() {
        let (w, h) = (9usize, 9usize);
        let mut plane = vec![0u8; w * h];
        plane[4 * w + 4] = 100;
        propagate(&mut plane, w, 10, 14, |d, from, step| {
            d.max(from.saturating_sub(step))
        });
        assert_eq!(plane[4 * w + 7], 70); // three axial steps
        assert_eq!(plane[7 * w + 7], 58); // three diagonal steps
        assert_eq!(plane[w + 6], 62); // two diagonal, one axial
        assert_eq!(plane[0], 44); // four diagonal
    }
}
