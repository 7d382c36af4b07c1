//! Closed polylines → how much of each pixel they cover, as exact area (antialiasing).
//!
//! In: the closed boundary loops of a part, in pixels relative to the top-left corner of a
//! `width × height` region. Out: per region pixel, the fraction of its area inside the loops
//! (non-zero winding, clamped to one), as 0..=255.
//!
//! Method: signed-area accumulation. Each edge adds, into the cell of every pixel it crosses and
//! the one after, the change of covered area it causes along the row; a running sum along each
//! row then turns those changes into each pixel's covered area. The area an edge piece covers
//! within a row is integrated exactly (a piecewise quadratic in the column), so coverage is
//! analytic, not sampled. A hole runs opposite to its outer boundary and subtracts; a region
//! covered twice (a fold) sums to two and is clamped. Cost: the length of the edges plus one
//! pass over the region.

use super::raster::round_i64;

/// Per-pixel coverage of closed loops in a region, with its scratch storage kept for reuse.
#[derive(Default)]
pub(super) struct CoverageMask {
    width: usize,
    height: usize,
    /// Row-major, `width + 2` cells per row (an edge at the right border writes one past it),
    /// in units of 1/[`FULL`] of a pixel's area. Integers, so that the running sum is exact and
    /// cheap, and untouched cells are exactly zero. All zero between uses:
    /// [`CoverageMask::finish`] clears what it reads.
    deltas: Vec<i32>,
    /// Row-major `width × height` coverage, 255 = the whole pixel.
    coverage: Vec<u8>,
    /// Per row, the first and last accumulation cell an edge wrote to (first > last: none).
    /// Left of the first the running sum is zero, and right of the last it is zero again (every
    /// loop crosses a row as often downwards as upwards), so only this stretch needs summing.
    touched: Vec<(usize, usize)>,
}

/// A whole pixel's area in accumulation units: 2²⁰, fine enough that the rounding of each edge's
/// share (half a unit) stays far below one coverage level (2²⁰/255 units) even summed over a
/// row, and small enough that any sum (the covered area times the winding, at most a few) stays
/// far inside `i32`.
const FULL: u32 = 1 << 20;
/// Extra accumulation cells per row past the region's right border.
const EXTRA_CELLS: usize = 2;
/// A row no edge has written to.
const UNTOUCHED: (usize, usize) = (usize::MAX, 0);

impl CoverageMask {
    /// Starts a mask over a `width × height` region, everything uncovered.
    pub fn start(&mut self, width: usize, height: usize) {
        self.width = width;
        self.height = height;
        let cells = (width + EXTRA_CELLS) * height;
        if self.deltas.len() < cells {
            self.deltas.resize(cells, 0);
        }
        self.touched.clear();
        self.touched.resize(height, UNTOUCHED);
    }

    /// Adds the directed edge `from → to` (region pixels) of a closed loop.
    pub fn add_edge(&mut self, from: crate::geom::Point, to: crate::geom::Point) {
        let height = self.height as f64;
        // Going down counts +1, going up −1: a loop's sign is its orientation.
        let (direction, top, bottom) = if from[1] < to[1] {
            (1.0, from, to)
        } else if from[1] > to[1] {
            (-1.0, to, from)
        } else {
            return;
        };
        let (y_start, y_end) = (top[1].max(0.0), bottom[1].min(height));
        if y_start >= y_end {
            return;
        }
        let dx_dy = (bottom[0] - top[0]) / (bottom[1] - top[1]);
        let x_at = |y: f64| top[0] + (y - top[1]) * dx_dy;
        let mut row = y_start.floor();
        while row < y_end {
            let (y0, y1) = (row.max(y_start), (row + 1.0).min(y_end));
            self.add_row_piece(row as usize, x_at(y0), x_at(y1), direction * (y1 - y0));
            row += 1.0;
        }
    }

    /// Adds an edge piece within one row running from column position `x0` to `x1` with signed
    /// height `dy`, clamping it to the region's columns.
    ///
    /// Left of the region the piece would cover every region pixel of its row as it does at
    /// x = 0, and right of it none, so replacing x by clamp(x, 0, width) changes no pixel in the
    /// region; the clamp is piecewise linear, so the piece is split where it crosses the borders.
    fn add_row_piece(&mut self, row: usize, x0: f64, x1: f64, dy: f64) {
        let right = self.width as f64;
        if (0.0..=right).contains(&x0) && (0.0..=right).contains(&x1) {
            // The usual case: nothing to clamp.
            self.add_clamped_piece(row, x0, x1, dy);
            return;
        }
        let mut cuts = [0.0, 1.0, 1.0, 1.0];
        let mut n = 1;
        for border in [0.0, right] {
            let t = (border - x0) / (x1 - x0);
            if t > 0.0 && t < 1.0 {
                cuts[n] = t;
                n += 1;
            }
        }
        cuts[..n].sort_by(f64::total_cmp);
        cuts[n] = 1.0;
        let at = |t: f64| (x0 + (x1 - x0) * t).clamp(0.0, right);
        for k in 0..n {
            let (t0, t1) = (cuts[k], cuts[k + 1]);
            if t1 > t0 {
                self.add_clamped_piece(row, at(t0), at(t1), dy * (t1 - t0));
            }
        }
    }

    /// Adds a piece lying within columns [0, width]: each cell gets the covered area of its
    /// pixel minus that of the pixel before, so a running sum gives the covered area.
    fn add_clamped_piece(&mut self, row: usize, x0: f64, x1: f64, dy: f64) {
        let stride = self.width + EXTRA_CELLS;
        let cells = &mut self.deltas[row * stride..(row + 1) * stride];
        let (lo, hi) = (x0.min(x1), x0.max(x1));
        let first = lo.floor();
        let i0 = first as usize;
        let touched = &mut self.touched[row];
        touched.0 = touched.0.min(i0);
        // Each cell gets the rounded cumulative area up to its right side minus the rounded one
        // up to its left side, so a piece's cells always sum to its rounded height exactly.
        let full = f64::from(FULL);
        let height = round_i64(dy * full) as i32;
        if hi - first <= 1.0 {
            touched.1 = touched.1.max(i0 + 1);
            // Within one pixel the covered part is a trapezoid: its width right of the piece is
            // set by the piece's mean position.
            let inside = 0.5 * (lo + hi) - first;
            let left = round_i64(dy * (1.0 - inside) * full) as i32;
            cells[i0] += left;
            cells[i0 + 1] += height - left;
            return;
        }
        // The covered part of pixel i, per unit of height, averaged over the piece:
        // (Φ(i + 1 − lo) − Φ(i + 1 − hi) − Φ(i − lo) + Φ(i − hi)) / (hi − lo), where Φ integrates
        // the clamped ramp clamp(u, 0, 1).
        let scale = dy * full / (hi - lo);
        let cumulative = |edge: f64| {
            round_i64(scale * (ramp_integral(edge - lo) - ramp_integral(edge - hi))) as i32
        };
        let last = (hi.floor() as usize + 1).min(cells.len() - 1);
        touched.1 = touched.1.max(last);
        let mut before = 0;
        for (i, cell) in cells.iter_mut().enumerate().take(last).skip(i0) {
            let after = cumulative(i as f64 + 1.0);
            *cell += after - before;
            before = after;
        }
        cells[last] += height - before;
    }

    /// Turns the accumulated edges into coverage and clears the accumulator for the next use.
    pub fn finish(&mut self) {
        self.coverage.resize(self.width * self.height, 0);
        let stride = self.width + EXTRA_CELLS;
        for ((cells, out), &(first, last)) in self
            .deltas
            .chunks_exact_mut(stride)
            .zip(self.coverage.chunks_exact_mut(self.width.max(1)))
            .zip(&self.touched)
        {
            if first > last {
                out.fill(0);
                continue;
            }
            let end = (last + 1).min(self.width);
            let start = first.min(end);
            out[..start].fill(0);
            // Between edges the sum stays put: most cells are zero, and only a change of the
            // sum needs the conversion.
            let (mut area, mut level) = (0i32, 0u8);
            for (&cell, value) in cells[start..end].iter().zip(&mut out[start..end]) {
                if cell != 0 {
                    area += cell;
                    level = coverage_level(area);
                }
                *value = level;
            }
            out[end..].fill(0);
            cells[first..=last].fill(0);
        }
    }

    /// Marks every pixel of the region fully covered (for a mesh without a boundary).
    pub fn cover_everything(&mut self) {
        self.coverage.clear();
        self.coverage.resize(self.width * self.height, u8::MAX);
    }

    /// The coverage, row-major, `width` per row; writable so that a drawn pixel can be marked.
    pub fn coverage_mut(&mut self) -> &mut [u8] {
        &mut self.coverage[..self.width * self.height]
    }
}

/// A pixel's covered area as 0..=255 from its signed area in 1/[`FULL`] pixels: the magnitude
/// (either orientation counts), clamped to the whole pixel (a fold counts once), rounded.
fn coverage_level(area: i32) -> u8 {
    ((area.unsigned_abs().min(FULL) * 255 + FULL / 2) / FULL) as u8
}

/// ∫₋∞ᵘ clamp(s, 0, 1) ds.
fn ramp_integral(u: f64) -> f64 {
    if u <= 0.0 {
        0.0
    } else if u <= 1.0 {
        0.5 * u * u
    } else {
        u - 0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Point;

    fn mask_of(width: usize, height: usize, loops: &[Vec<[f64; 2]>]) -> Vec<u8> {
        let mut mask = CoverageMask::default();
        mask.start(width, height);
        for ring in loops {
            for k in 0..ring.len() {
                mask.add_edge(ring[k].into(), ring[(k + 1) % ring.len()].into());
            }
        }
        mask.finish();
        mask.coverage_mut().to_vec()
    }

    /// Fraction of pixel (x, y) inside the convex polygon `ring`, by 64 × 64 samples.
    fn sampled_coverage(x: usize, y: usize, ring: &[[f64; 2]]) -> f64 {
        const N: usize = 64;
        let inside = |p: [f64; 2]| {
            let signs: Vec<f64> = (0..ring.len())
                .map(|k| {
                    let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
                    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
                })
                .collect();
            signs.iter().all(|&s| s >= 0.0) || signs.iter().all(|&s| s <= 0.0)
        };
        let hits = (0..N * N)
            .filter(|k| {
                let p = [
                    x as f64 + (k % N) as f64 / N as f64 + 0.5 / N as f64,
                    y as f64 + (k / N) as f64 / N as f64 + 0.5 / N as f64,
                ];
                inside(p)
            })
            .count();
        hits as f64 / (N * N) as f64
    }

    #[test]
    fn an_axis_aligned_rectangle_gets_its_exact_fractional_coverage() {
        // x from 1.25 to 4.5, y from 0.5 to 2.0.
        let rect = vec![[1.25, 0.5], [4.5, 0.5], [4.5, 2.0], [1.25, 2.0]];
        let mask = mask_of(6, 3, &[rect]);
        let expected: [[f64; 6]; 3] = [
            [0.0, 0.375, 0.5, 0.5, 0.25, 0.0],
            [0.0, 0.75, 1.0, 1.0, 0.5, 0.0],
            [0.0; 6],
        ];
        for y in 0..3 {
            for x in 0..6 {
                let want = (expected[y][x] * 255.0 + 0.5).floor() as u8;
                assert_eq!(mask[y * 6 + x], want, "pixel ({x}, {y})");
            }
        }
    }

    #[test]
    fn a_rotated_square_matches_sampled_area_and_total_area() {
        let (c, s) = (25f64.to_radians().cos(), 25f64.to_radians().sin());
        let ring: Vec<[f64; 2]> = [(-9.0, -9.0), (9.0, -9.0), (9.0, 9.0), (-9.0, 9.0)]
            .iter()
            .map(|&(x, y)| [16.3 + c * x - s * y, 15.8 + s * x + c * y])
            .collect();
        let mask = mask_of(32, 32, std::slice::from_ref(&ring));
        let mut total = 0.0;
        for y in 0..32 {
            for x in 0..32 {
                let got = f64::from(mask[y * 32 + x]) / 255.0;
                let want = sampled_coverage(x, y, &ring);
                assert!((got - want).abs() < 0.02, "({x}, {y}): {got} vs {want}");
                total += got;
            }
        }
        assert!((total - 18.0 * 18.0).abs() < 0.5, "total {total}");
    }

    #[test]
    fn orientation_does_not_matter_and_a_hole_subtracts() {
        let outer = vec![[2.0, 2.0], [14.0, 2.0], [14.0, 14.0], [2.0, 14.0]];
        let reversed: Vec<[f64; 2]> = outer.iter().rev().copied().collect();
        assert_eq!(
            mask_of(16, 16, std::slice::from_ref(&outer)),
            mask_of(16, 16, std::slice::from_ref(&reversed))
        );
        // A hole from 5.5 to 10.5, running the other way.
        let hole = vec![[5.5, 5.5], [5.5, 10.5], [10.5, 10.5], [10.5, 5.5]];
        let mask = mask_of(16, 16, &[outer, hole]);
        assert_eq!(mask[3 * 16 + 3], 255);
        assert_eq!(mask[8 * 16 + 8], 0);
        assert!(
            (127..=128).contains(&mask[8 * 16 + 5]),
            "{}",
            mask[8 * 16 + 5]
        );
        assert_eq!(mask[16], 0);
    }

    #[test]
    fn loops_reaching_past_the_region_are_clipped_exactly() {
        // A band from x = −5 to 2.5, slanted, over a 4-px-wide region: inside the region its
        // right edge runs from 2.5 to 3.5 across the rows.
        let ring = vec![[-5.0, -3.0], [2.5, -3.0], [3.5, 7.0], [-5.0, 7.0]];
        let mask = mask_of(4, 4, std::slice::from_ref(&ring));
        for y in 0..4 {
            for x in 0..4 {
                let want = sampled_coverage(x, y, &ring);
                let got = f64::from(mask[y * 4 + x]) / 255.0;
                assert!((got - want).abs() < 0.02, "({x}, {y}): {got} vs {want}");
            }
        }
        assert_eq!(mask[0], 255);
    }

    #[test]
    fn a_fold_covered_twice_stays_fully_covered() {
        let a = vec![[1.0, 1.0], [6.0, 1.0], [6.0, 6.0], [1.0, 6.0]];
        let b = vec![[3.0, 3.0], [8.0, 3.0], [8.0, 8.0], [3.0, 8.0]];
        let mask = mask_of(10, 10, &[a, b]);
        assert_eq!(mask[4 * 10 + 4], 255);
        assert_eq!(mask[2 * 10 + 2], 255);
        assert_eq!(mask[9 * 10 + 9], 0);
    }

    #[test]
    fn the_accumulator_is_clean_for_the_next_use() {
        let mut mask = CoverageMask::default();
        mask.start(8, 8);
        mask.add_edge(Point::from([1.0, 1.0]), Point::from([7.3, 6.2]));
        mask.add_edge(Point::from([7.3, 6.2]), Point::from([1.0, 6.0]));
        mask.add_edge(Point::from([1.0, 6.0]), Point::from([1.0, 1.0]));
        mask.finish();
        assert!(mask.coverage_mut().iter().any(|&c| c > 0));
        mask.start(5, 9);
        mask.finish();
        assert!(mask.coverage_mut().iter().all(|&c| c == 0));
    }
}
